#pragma once
// NumPy .npy files (format version 1.0; https://numpy.org/doc/stable/reference/generated/
// numpy.lib.format.html): a magic string, a Python-literal header describing dtype, order and
// shape, then the raw little-endian data. Researchers load them with numpy.load.

#include <cstddef>
#include <string>
#include <vector>

namespace lamina {

/// The bytes of a C-ordered float32 array of the given shape (data.size() must equal the product).
std::string npy_float32(const std::vector<float>& data, const std::vector<std::size_t>& shape);

/// Parses a float32 .npy written by npy_float32 (InputError naming `where` otherwise).
std::vector<float> read_npy_float32(const std::string& bytes, const std::string& where,
                                    std::vector<std::size_t>* shape = nullptr);

}  // namespace lamina

#pragma once
// NumPy .npy files (format version 1.0; https://numpy.org/doc/stable/reference/generated/
// numpy.lib.format.html): a magic string, a Python-literal header describing dtype, order and
// shape, then the raw little-endian data. Researchers load them with numpy.load.

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace lamina {

/// The bytes of a C-ordered float32 array of the given shape (data.size() must equal the product).
std::string npy_float32(const std::vector<float>& data, const std::vector<std::size_t>& shape);

struct NpyFloat32 {
    std::vector<std::size_t> shape;
    std::vector<float> data;  ///< C order (last index fastest)
};

/// Reads a float32 .npy file (version 1.0/2.0, little-endian, C order). Throws InputError naming
/// the file for anything else or a data size that does not match the header.
NpyFloat32 read_npy_float32(const std::filesystem::path& path);

}  // namespace lamina

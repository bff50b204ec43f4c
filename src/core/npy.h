#pragma once
// NumPy .npy files (format version 1.0; https://numpy.org/doc/stable/reference/generated/
// numpy.lib.format.html): a magic string, a Python-literal header describing dtype, order and
// shape, then the raw little-endian data. Researchers load them with numpy.load.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <numeric>
#include <string>
#include <vector>

namespace lamina {

/// The number of elements of an array of this shape (the product of its extents).
inline std::size_t element_count(const std::vector<std::size_t>& shape) {
    return std::accumulate(shape.begin(), shape.end(), std::size_t(1), std::multiplies<>());
}

/// The bytes of a C-ordered float32 array of the given shape (data.size() must equal the product).
std::string npy_float32(const std::vector<float>& data, const std::vector<std::size_t>& shape);

/// The same as float16 ('<f2', IEEE 754 binary16: 11 significant bits, normal from 6.1·10⁻⁵, 0
/// below about 6·10⁻⁸): half the bytes. Values beyond ±65504 (the largest half) are clamped to it;
/// NaN stays NaN.
std::string npy_float16(const std::vector<float>& data, const std::vector<std::size_t>& shape);

/// The largest finite float16, and the conversions npy_float16 uses (round to nearest, ties to
/// even; float_to_half clamps to ±kHalfMax).
inline constexpr float kHalfMax = 65504.0f;
std::uint16_t float_to_half(float v);
float half_to_float(std::uint16_t bits);

struct NpyFloat32 {
    std::vector<std::size_t> shape;
    std::vector<float> data;  ///< C order (last index fastest)
    bool half = false;        ///< the file held float16 (converted exactly to float)
};

/// Reads a float32 or float16 .npy file (version 1.0/2.0, little-endian, C order). Throws
/// InputError naming the file for anything else or a data size that does not match the header.
NpyFloat32 read_npy_float32(const std::filesystem::path& path);

}  // namespace lamina

#pragma once
// Reading NumPy .npy arrays of float32 (version 1.0/2.0, little-endian, C order): the tables of a
// study directory (docs/formats.md, configs/<id>/tables.npy and reference_se.npy).

#include <cstddef>
#include <filesystem>
#include <vector>

namespace lamina {

struct NpyFloat32 {
    std::vector<std::size_t> shape;
    std::vector<float> data;  ///< C order (last index fastest)
};

/// Reads `path`. Throws InputError naming the file for anything but a little-endian float32 C-order
/// array whose data size matches its header.
NpyFloat32 read_npy_float32(const std::filesystem::path& path);

}  // namespace lamina

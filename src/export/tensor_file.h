#pragma once
// The "tensor file" container of the RGL material database (Dupuy & Jakob 2018, "An adaptive
// parameterization for efficient material acquisition and rendering"), which pbrt-v4's `measured`
// material and Mitsuba 3's `measured` plugin read. Little-endian throughout:
//
//   12 bytes  "tensor_file" and a NUL
//    2 bytes  version: major 1, minor 0
//    4 bytes  u32 number of fields, then per field:
//             u16 name length, the name (no NUL), u16 ndim, u8 dtype, u64 byte offset of the data
//             from the start of the file, ndim × u64 shape
//   the fields' data, C order (last index fastest), each at its offset.
//
// dtype codes: 1 uint8, 2 int8, 3 uint16, 4 int16, 5 uint32, 6 int32, 7 uint64, 8 int64,
// 9 float16, 10 float32, 11 float64.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace lamina {

enum class TensorType : std::uint8_t {
    UInt8 = 1,
    Int8,
    UInt16,
    Int16,
    UInt32,
    Int32,
    UInt64,
    Int64,
    Float16,
    Float32,
    Float64
};

/// Bytes per element of a type.
std::size_t tensor_type_size(TensorType type);

struct TensorField {
    TensorType type = TensorType::Float32;
    std::vector<std::uint64_t> shape;
    std::string data;  ///< raw little-endian bytes, size = product(shape) × element size

    std::uint64_t count() const;
    /// The data as floats; the field must be Float32 (LAMINA_CHECK otherwise).
    std::vector<float> floats() const;
};

using TensorFile = std::map<std::string, TensorField>;

TensorField tensor_float32(const std::vector<float>& values, std::vector<std::uint64_t> shape);
TensorField tensor_uint8(const std::string& bytes, std::vector<std::uint64_t> shape);

/// The bytes of a tensor file (fields in name order, each 8-byte aligned).
std::string tensor_file_bytes(const TensorFile& file);

/// Parses a tensor file. InputError naming `where` for a wrong magic or version, a truncated
/// header, an unknown dtype, a field whose data lies outside the file or whose size overflows,
/// and a repeated field name.
TensorFile parse_tensor_file(const std::string& bytes, const std::string& where);
TensorFile read_tensor_file(const std::filesystem::path& path);

}  // namespace lamina

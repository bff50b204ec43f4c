#include "core/npy.h"

#include "core/check.h"
#include "core/error.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <cstdint>
#include <fstream>
#include <string>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <numeric>

namespace lamina {

static_assert(std::endian::native == std::endian::little, "npy writer assumes little-endian");

namespace {

// Magic, version 1.0, the header dict padded to 64 bytes, then `bytes` of data.
std::string npy_bytes(const char* descr, const void* data, std::size_t bytes,
                      const std::vector<std::size_t>& shape) {
    std::string dims;
    for (std::size_t d : shape)
        dims += fmt::format("{}, ", d);
    if (shape.size() > 1) dims.resize(dims.size() - 2);  // "(n,)" for one dimension
    std::string header =
        fmt::format("{{'descr': '{}', 'fortran_order': False, 'shape': ({}), }}", descr, dims);
    // Pad with spaces so that magic (6) + version (2) + length (2) + header + '\n' is a multiple
    // of 64 (the format asks for 16; 64 aligns the data for any reader).
    const std::size_t unpadded = 10 + header.size() + 1;
    header.append((64 - unpadded % 64) % 64, ' ');
    header += '\n';
    std::string out = "\x93NUMPY";
    out += char(1);
    out += char(0);
    const std::uint16_t len = std::uint16_t(header.size());
    out += char(len & 0xff);
    out += char(len >> 8);
    out += header;
    const std::size_t offset = out.size();
    out.resize(offset + bytes);
    std::memcpy(out.data() + offset, data, bytes);
    return out;
}

}  // namespace

std::string npy_float32(const std::vector<float>& data, const std::vector<std::size_t>& shape) {
    LAMINA_CHECK(element_count(shape) == data.size());
    return npy_bytes("<f4", data.data(), data.size() * sizeof(float), shape);
}

std::uint16_t float_to_half(float v) {
    // IEEE 754 binary16 by the compiler's conversion (round to nearest, ties to even), after
    // clamping to the largest finite half so that nothing becomes infinite.
    if (!std::isnan(v)) v = std::clamp(v, -kHalfMax, kHalfMax);
    const _Float16 h = static_cast<_Float16>(v);
    return std::bit_cast<std::uint16_t>(h);
}

float half_to_float(std::uint16_t bits) {
    return static_cast<float>(std::bit_cast<_Float16>(bits));
}

std::string npy_float16(const std::vector<float>& data, const std::vector<std::size_t>& shape) {
    LAMINA_CHECK(element_count(shape) == data.size());
    std::vector<std::uint16_t> half(data.size());
    for (std::size_t i = 0; i < data.size(); ++i)
        half[i] = float_to_half(data[i]);
    return npy_bytes("<f2", half.data(), half.size() * sizeof(std::uint16_t), shape);
}

namespace {

// The value of `key` in the header dict, e.g. 'descr': '<f4' → "'<f4'" (up to the next comma at
// depth 0, parentheses included).
std::string header_value(const std::string& header, const std::string& key) {
    const std::size_t k = header.find("'" + key + "'");
    if (k == std::string::npos) return {};
    std::size_t i = header.find(':', k);
    if (i == std::string::npos) return {};
    ++i;
    int depth = 0;
    std::string out;
    for (; i < header.size(); ++i) {
        const char c = header[i];
        if (c == '(') ++depth;
        if (c == ')') --depth;
        if (depth == 0 && (c == ',' || c == '}')) break;
        out += c;
        if (depth < 0) break;
    }
    const auto b = out.find_first_not_of(" ");
    return b == std::string::npos ? std::string() : out.substr(b);
}

}  // namespace

NpyFloat32 read_npy_float32(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))  // a pipe is not opened: it would wait
        throw InputError(where, "", "cannot read the file: it is not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(where, "", "cannot read the file");
    char magic[8];
    if (!in.read(magic, 8) || std::memcmp(magic, "\x93NUMPY", 6) != 0)
        throw InputError(where, "", "not a NumPy .npy file");
    std::uint32_t header_len = 0;
    if (magic[6] == 1) {
        unsigned char b[2];
        in.read(reinterpret_cast<char*>(b), 2);
        header_len = b[0] | (b[1] << 8);
    } else {
        unsigned char b[4];
        in.read(reinterpret_cast<char*>(b), 4);
        header_len = b[0] | (b[1] << 8) | (b[2] << 16) | (std::uint32_t(b[3]) << 24);
    }
    std::string header(header_len, '\0');
    if (!in.read(header.data(), header_len)) throw InputError(where, "", "truncated header");
    const std::string descr = header_value(header, "descr");
    if (descr != "'<f4'" && descr != "'<f2'")
        throw InputError(where, "descr",
                         fmt::format("{}: expected '<f4' or '<f2' (little-endian float32 or "
                                     "float16)",
                                     descr));
    const bool half = descr == "'<f2'";
    if (header_value(header, "fortran_order") != "False")
        throw InputError(where, "fortran_order", "expected False (C order)");
    const std::string shape_text = header_value(header, "shape");
    NpyFloat32 a;
    std::size_t count = 1;
    for (std::size_t i = 0; i < shape_text.size();) {
        if (std::isdigit(static_cast<unsigned char>(shape_text[i]))) {
            std::size_t used = 0;
            const std::size_t n = std::stoull(shape_text.substr(i), &used);
            a.shape.push_back(n);
            count *= n;
            i += used;
        } else {
            ++i;
        }
    }
    if (a.shape.empty())
        throw InputError(where, "shape", fmt::format("cannot read {}", shape_text));
    a.data.resize(count);
    a.half = half;
    std::vector<std::uint16_t> bits(half ? count : 0);
    char* target =
        half ? reinterpret_cast<char*>(bits.data()) : reinterpret_cast<char*>(a.data.data());
    if (!in.read(target, std::streamsize(count * (half ? 2 : sizeof(float)))))
        throw InputError(
            where, "",
            fmt::format("truncated: the header announces shape [{}]", fmt::join(a.shape, ", ")));
    for (std::size_t i = 0; i < bits.size(); ++i)
        a.data[i] = half_to_float(bits[i]);
    return a;
}

}  // namespace lamina

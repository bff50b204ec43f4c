#include "core/npy.h"

#include "core/check.h"
#include "core/error.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <numeric>

namespace lamina {

static_assert(std::endian::native == std::endian::little, "npy writer assumes little-endian");

std::string npy_float32(const std::vector<float>& data, const std::vector<std::size_t>& shape) {
    const std::size_t count =
        std::accumulate(shape.begin(), shape.end(), std::size_t(1), std::multiplies<>());
    LAMINA_CHECK(count == data.size());
    std::string dims;
    for (std::size_t d : shape)
        dims += fmt::format("{}, ", d);
    if (shape.size() > 1) dims.resize(dims.size() - 2);  // "(n,)" for one dimension
    std::string header =
        fmt::format("{{'descr': '<f4', 'fortran_order': False, 'shape': ({}), }}", dims);
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
    out.resize(offset + data.size() * sizeof(float));
    std::memcpy(out.data() + offset, data.data(), data.size() * sizeof(float));
    return out;
}

std::vector<float> read_npy_float32(const std::string& bytes, const std::string& where,
                                    std::vector<std::size_t>* shape) {
    if (bytes.size() < 10 || bytes.compare(0, 6, "\x93NUMPY") != 0 || bytes[6] != 1)
        throw InputError(where, "", "not a version 1.0 .npy file");
    const std::size_t len = std::uint8_t(bytes[8]) | (std::size_t(std::uint8_t(bytes[9])) << 8);
    if (bytes.size() < 10 + len) throw InputError(where, "", "truncated .npy header");
    const std::string header = bytes.substr(10, len);
    if (header.find("'descr': '<f4'") == std::string::npos ||
        header.find("'fortran_order': False") == std::string::npos)
        throw InputError(where, "", "expected a C-ordered little-endian float32 array");
    const auto open = header.find("'shape': (");
    const auto close = header.find(')', open);
    if (open == std::string::npos || close == std::string::npos)
        throw InputError(where, "", "no shape in the .npy header");
    std::vector<std::size_t> dims;
    std::size_t count = 1;
    const std::string list = header.substr(open + 10, close - open - 10);
    std::size_t pos = 0;
    while (pos < list.size()) {
        while (pos < list.size() && (list[pos] == ' ' || list[pos] == ','))
            ++pos;
        if (pos >= list.size()) break;
        std::size_t used = 0;
        const std::size_t d = std::stoull(list.substr(pos), &used);
        dims.push_back(d);
        count *= d;
        pos += used;
    }
    const std::size_t offset = 10 + len;
    if (bytes.size() != offset + count * sizeof(float))
        throw InputError(where, "", "the .npy data size does not match its shape (truncated?)");
    std::vector<float> data(count);
    std::memcpy(data.data(), bytes.data() + offset, count * sizeof(float));
    if (shape) *shape = dims;
    return data;
}

}  // namespace lamina

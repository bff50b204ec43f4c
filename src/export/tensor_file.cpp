#include "export/tensor_file.h"

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"
#include "export/bytes.h"

#include <fmt/format.h>

#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>
#include <vector>

namespace lamina {

static_assert(std::endian::native == std::endian::little, "tensor files are little-endian");

namespace {
constexpr char kMagic[12] = {'t', 'e', 'n', 's', 'o', 'r', '_', 'f', 'i', 'l', 'e', '\0'};

struct Reader {
    const std::string& bytes;
    const std::string& where;
    std::size_t at = 0;

    template <typename T>
    T get(const char* what) {
        if (bytes.size() - at < sizeof(T) || at > bytes.size())
            throw InputError(where, "header",
                             fmt::format("the file ends inside the header ({}): truncated?", what));
        T v;
        std::memcpy(&v, bytes.data() + at, sizeof(T));
        at += sizeof(T);
        return v;
    }
};
}  // namespace

std::size_t tensor_type_size(TensorType type) {
    switch (type) {
        case TensorType::UInt8:
        case TensorType::Int8:
            return 1;
        case TensorType::UInt16:
        case TensorType::Int16:
        case TensorType::Float16:
            return 2;
        case TensorType::UInt32:
        case TensorType::Int32:
        case TensorType::Float32:
            return 4;
        case TensorType::UInt64:
        case TensorType::Int64:
        case TensorType::Float64:
            return 8;
    }
    return 0;
}

std::uint64_t TensorField::count() const {
    std::uint64_t n = 1;
    for (std::uint64_t s : shape)
        n *= s;
    return n;
}

std::vector<float> TensorField::floats() const {
    LAMINA_CHECK(type == TensorType::Float32);
    std::vector<float> out(data.size() / 4);
    std::memcpy(out.data(), data.data(), out.size() * 4);
    return out;
}

TensorField tensor_float32(const std::vector<float>& values, std::vector<std::uint64_t> shape) {
    TensorField f{TensorType::Float32, std::move(shape), {}};
    LAMINA_CHECK(f.count() == values.size());
    f.data.assign(reinterpret_cast<const char*>(values.data()), values.size() * 4);
    return f;
}

TensorField tensor_uint8(const std::string& bytes, std::vector<std::uint64_t> shape) {
    TensorField f{TensorType::UInt8, std::move(shape), bytes};
    LAMINA_CHECK(f.count() == bytes.size());
    return f;
}

std::string tensor_file_bytes(const TensorFile& file) {
    // Header size first, so that every data offset is known when the header is written.
    std::size_t header = 12 + 2 + 4;
    for (const auto& [name, field] : file)
        header += 2 + name.size() + 2 + 1 + 8 + 8 * field.shape.size();
    auto align = [](std::size_t n) { return (n + 7) / 8 * 8; };
    std::string out;
    out.append(kMagic, 12);
    append_bytes<std::uint8_t>(out, 1);
    append_bytes<std::uint8_t>(out, 0);
    append_bytes<std::uint32_t>(out, std::uint32_t(file.size()));
    std::size_t offset = align(header);
    for (const auto& [name, field] : file) {
        append_bytes<std::uint16_t>(out, std::uint16_t(name.size()));
        out += name;
        append_bytes<std::uint16_t>(out, std::uint16_t(field.shape.size()));
        append_bytes<std::uint8_t>(out, std::uint8_t(field.type));
        append_bytes<std::uint64_t>(out, offset);
        for (std::uint64_t s : field.shape)
            append_bytes<std::uint64_t>(out, s);
        offset = align(offset + field.data.size());
    }
    for (const auto& [name, field] : file) {
        out.resize(align(out.size()), '\0');
        out += field.data;
    }
    return out;
}

TensorFile parse_tensor_file(const std::string& bytes, const std::string& where) {
    if (bytes.size() < 18 || std::memcmp(bytes.data(), kMagic, 12) != 0)
        throw InputError(where, "header",
                         "not a tensor file (.bsdf): it does not start with 'tensor_file'");
    Reader r{bytes, where, 12};
    const auto major = r.get<std::uint8_t>("version"), minor = r.get<std::uint8_t>("version");
    if (major != 1 || minor != 0)
        throw InputError(where, "header",
                         fmt::format("tensor file version {}.{}: only 1.0 is known", major, minor));
    const auto n_fields = r.get<std::uint32_t>("field count");
    TensorFile out;
    std::vector<std::pair<std::string, std::uint64_t>> offsets;  // checked against the header's end
    for (std::uint32_t k = 0; k < n_fields; ++k) {
        const auto name_length = r.get<std::uint16_t>("field name");
        if (bytes.size() - r.at < name_length)
            throw InputError(where, "header", "the file ends inside a field name: truncated?");
        std::string name = bytes.substr(r.at, name_length);
        r.at += name_length;
        const auto ndim = r.get<std::uint16_t>("field rank");
        const auto dtype = r.get<std::uint8_t>("field type");
        const auto offset = r.get<std::uint64_t>("field offset");
        if (dtype < 1 || dtype > 11)
            throw InputError(where, name, fmt::format("unknown dtype code {}", dtype));
        TensorField f;
        f.type = TensorType(dtype);
        std::uint64_t size = tensor_type_size(f.type);
        for (std::uint16_t d = 0; d < ndim; ++d) {
            const auto s = r.get<std::uint64_t>("field shape");
            if (s != 0 && size > std::numeric_limits<std::uint64_t>::max() / s)
                throw InputError(where, name, "the field's size overflows");
            size *= s;
            f.shape.push_back(s);
        }
        if (offset > bytes.size() || size > bytes.size() - offset)
            throw InputError(where, name,
                             fmt::format("the field's data ({} bytes at offset {}) lies past the "
                                         "end of the file ({} bytes): truncated?",
                                         size, offset, bytes.size()));
        f.data = bytes.substr(offset, size);
        if (size > 0) offsets.emplace_back(name, offset);
        if (!out.emplace(name, std::move(f)).second)
            throw InputError(where, name, "the field appears twice");
    }
    // A field's data follows the header: an offset into it would read the header as numbers.
    for (const auto& [name, offset] : offsets)
        if (offset < r.at)
            throw InputError(where, name,
                             fmt::format("the field's data starts at offset {}, inside the header "
                                         "(which ends at {})",
                                         offset, r.at));
    return out;
}

TensorFile read_tensor_file(const std::filesystem::path& path) {
    return parse_tensor_file(read_file_bounded(path, kMaxTableFileBytes, "the file"),
                             path.string());
}

}  // namespace lamina

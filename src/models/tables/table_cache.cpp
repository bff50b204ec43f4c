#include "models/tables/table_cache.h"

#include "core/atomic_file.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <system_error>

namespace lamina {

namespace {
constexpr char kMagic[8] = {'L', 'M', 'N', 'T', 'A', 'B', 'L', 'E'};
constexpr std::uint32_t kFormatVersion = 1;

template <typename T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof(T));
}
template <typename T>
bool get(const std::string& in, std::size_t& pos, T& v) {
    if (pos + sizeof(T) > in.size()) return false;
    std::memcpy(&v, in.data() + pos, sizeof(T));
    pos += sizeof(T);
    return true;
}
std::uint64_t checksum(const std::vector<float>& values) {
    return fnv1a64(std::string_view(reinterpret_cast<const char*>(values.data()),
                                    values.size() * sizeof(float)));
}
}  // namespace

std::uint64_t fnv1a64(std::string_view bytes) {
    std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a 64-bit offset basis
    for (const unsigned char b : bytes) {
        h ^= b;
        h *= 0x100000001b3ull;  // FNV 64-bit prime
    }
    return h;
}

std::size_t TableKey::count() const {
    std::size_t n = 1;
    for (const auto d : dims)
        n *= d;
    return n;
}

std::filesystem::path table_cache_dir() {
    if (const char* dir = std::getenv("LAMINA_CACHE_DIR"); dir && *dir) return dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
        return std::filesystem::path(xdg) / "lamina";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::filesystem::path(home) / ".cache" / "lamina";
    return std::filesystem::temp_directory_path() / "lamina-cache";
}

std::filesystem::path table_cache_path(const TableKey& key) {
    return table_cache_dir() / fmt::format("{}-{:016x}.bin", key.name, key.hash());
}

std::optional<std::filesystem::path> build_table_dir() {
#ifdef LAMINA_BUILD_TABLE_DIR
    return std::filesystem::path(LAMINA_BUILD_TABLE_DIR);
#else
    return std::nullopt;
#endif
}

namespace {
std::optional<std::vector<float>> load_table_file(const std::filesystem::path& path,
                                                  const TableKey& key) {
    // A regular file of the entry's size at most (its header is far below 1 kB): a pipe or a
    // device in its place is never opened, a larger file never read.
    const std::optional<std::string> bytes =
        read_cache_file(path, std::size_t(key.count()) * sizeof(float) + 1024);
    if (!bytes) return std::nullopt;
    const std::string& in = *bytes;
    std::size_t pos = 0;
    char magic[8];
    if (in.size() < sizeof(magic) || std::memcmp(in.data(), kMagic, sizeof(magic)) != 0)
        return std::nullopt;
    pos = sizeof(magic);
    std::uint32_t version = 0, ndims = 0;
    if (!get(in, pos, version) || version != kFormatVersion) return std::nullopt;
    if (!get(in, pos, ndims) || ndims != key.dims.size()) return std::nullopt;
    for (const auto d : key.dims) {
        std::uint32_t v = 0;
        if (!get(in, pos, v) || v != d) return std::nullopt;
    }
    std::uint64_t hash = 0, count = 0;
    if (!get(in, pos, hash) || hash != key.hash()) return std::nullopt;
    if (!get(in, pos, count) || count != key.count()) return std::nullopt;
    if (in.size() != pos + count * sizeof(float) + sizeof(std::uint64_t)) return std::nullopt;
    std::vector<float> values(count);
    std::memcpy(values.data(), in.data() + pos, count * sizeof(float));
    pos += count * sizeof(float);
    std::uint64_t sum = 0;
    if (!get(in, pos, sum) || sum != checksum(values)) return std::nullopt;
    for (const float v : values)
        if (!std::isfinite(v)) return std::nullopt;
    return values;
}
}  // namespace

std::optional<std::vector<float>> load_cached_table(const TableKey& key) {
    if (auto values = load_table_file(table_cache_path(key), key)) return values;
    if (const auto dir = build_table_dir())
        return load_table_file(*dir / table_cache_path(key).filename(), key);
    return std::nullopt;
}

bool store_cached_table(const TableKey& key, const std::vector<float>& values) {
    std::string out(kMagic, sizeof(kMagic));
    put(out, kFormatVersion);
    put(out, std::uint32_t(key.dims.size()));
    for (const auto d : key.dims)
        put(out, d);
    put(out, key.hash());
    put(out, std::uint64_t(values.size()));
    out.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
    put(out, checksum(values));
    try {
        std::error_code ec;
        std::filesystem::create_directories(table_cache_dir(), ec);
        write_file_atomic(table_cache_path(key), out);
        return true;
    } catch (const std::exception&) {
        return false;  // an unwritable cache only costs recomputation
    }
}

}  // namespace lamina

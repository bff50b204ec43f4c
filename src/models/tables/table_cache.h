#pragma once
// On-disk cache of the tables lamina computes for Belcour's model (FGD, TIR).
//
// Directory: $LAMINA_CACHE_DIR, else $XDG_CACHE_HOME/lamina, else $HOME/.cache/lamina. One binary
// file per table, `<name>-<hash>.bin`: magic "LMNTABLE", format version (u32), number of axes
// (u32), their sizes (u32 each), the content hash (u64) of everything that generates the table
// (axes, quadrature, code version), the value count (u64), the float32 values, and an FNV-1a
// checksum (u64) of the values. A file that is missing, truncated, or mismatched in any field is
// recomputed and rewritten (atomically, write_file_atomic) — never trusted. A cache that cannot
// be written is not an error: the table then lives in memory only.
//
// A table missing from the cache is then looked for, read-only and checked the same way, in the
// folder the build filled when it built lamina (build_table_dir: `lamina tables` run by the
// build, models/tables/every_table.h), so that a freshly built lamina's first study does not
// compute them; a lamina built elsewhere (a Python wheel, a moved build folder) finds no folder
// there and computes them on first use as before.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

/// 64-bit FNV-1a hash (Fowler–Noll–Vo; http://www.isthe.com/chongo/tech/comp/fnv/).
std::uint64_t fnv1a64(std::string_view bytes);

struct TableKey {
    std::string name;       ///< e.g. "fgd"
    std::string generator;  ///< every parameter of the computation, incl. a code version
    std::vector<std::uint32_t> dims;
    std::uint64_t hash() const { return fnv1a64(generator); }
    std::size_t count() const;
};

/// The cache directory (not created).
std::filesystem::path table_cache_dir();
/// The file a table is cached in.
std::filesystem::path table_cache_path(const TableKey& key);

/// The folder of tables the build computed (`<build>/tables`), where this lamina was built with
/// one; it may be missing or incomplete, and is only read.
std::optional<std::filesystem::path> build_table_dir();

/// The cached values, or nothing when absent or not exactly matching `key`: from the cache
/// folder, else from build_table_dir.
std::optional<std::vector<float>> load_cached_table(const TableKey& key);
/// Best effort: returns false (and leaves no partial file) when the cache cannot be written.
bool store_cached_table(const TableKey& key, const std::vector<float>& values);

/// load_cached_table, else compute() then store_cached_table.
template <typename Compute>
std::vector<float> cached_table(const TableKey& key, Compute&& compute) {
    if (auto cached = load_cached_table(key)) return std::move(*cached);
    std::vector<float> values = compute();
    store_cached_table(key, values);
    return values;
}

}  // namespace lamina

#pragma once
// Every table lamina computes for its models and caches on disk (models/tables/table_cache.h),
// listed once: what `lamina tables` computes ahead of their first use, and what the build fills
// its own table folder with (table_cache.h, build_table_dir).

#include <functional>
#include <string>
#include <vector>

namespace lamina {

struct CachedTable {
    std::string name;           ///< the cache file's stem, e.g. "fgd"
    std::string what;           ///< one line for a user
    std::function<void()> get;  ///< loads or computes the process-wide table (thread-safe)
};

/// The tables, in the order `lamina tables` computes them.
std::vector<CachedTable> every_cached_table();

}  // namespace lamina

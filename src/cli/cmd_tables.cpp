// lamina tables: computes the tables lamina's models read (models/tables/every_table.h) into the
// cache now, rather than on their first use; the build runs it for its own table folder.
#include "cli/commands.h"
#include "models/tables/every_table.h"
#include "models/tables/table_cache.h"

#include <fmt/format.h>

#include <chrono>

namespace lamina::cli {

Runner add_tables(CLI::App& app) {
    app.add_subcommand("tables",
                       "Compute the tables the models read (FGD, TIR, ...) into the cache now "
                       "instead of on first use ($LAMINA_CACHE_DIR, else ~/.cache/lamina)");
    return [] {
        fmt::print("cache: {}\n", table_cache_dir().string());
        if (const auto built = build_table_dir())
            fmt::print("then, read only: {} (the build's)\n", built->string());
        for (const CachedTable& table : every_cached_table()) {
            const auto start = std::chrono::steady_clock::now();
            table.get();
            const std::chrono::duration<double> took = std::chrono::steady_clock::now() - start;
            fmt::print("{:<11} {:6.2f} s  {}\n", table.name, took.count(), table.what);
        }
        return 0;
    };
}

}  // namespace lamina::cli

// lamina explorer DIR: (re)writes a study directory's explorer page (docs/explorer.md).
#include "cli/commands.h"
#include "report/explorer.h"

#include <fmt/format.h>

#include <filesystem>
#include <memory>

namespace lamina::cli {

Runner add_explorer(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "explorer", "Write a study directory's explorer page: DIR/index.html, opened from disk");
    auto dir = std::make_shared<std::string>();
    cmd->add_option("DIR", *dir,
                    "A study directory (written by `lamina study` or `lamina compare`)")
        ->required();
    return [dir] {
        const ExplorerSummary s = write_explorer(*dir);
        fmt::print("{}/index.html: {} configurations, {:.1f} MB of page data\n", *dir,
                   s.configurations, s.data_bytes / 1e6);
        // The page is written without it (the leaderboard then says no model has a metric), but
        // a study always has one: say so rather than leave an empty leaderboard unexplained.
        const std::filesystem::path metrics = std::filesystem::path(*dir) / "metrics.csv";
        if (!std::filesystem::exists(metrics))
            fmt::print(stderr,
                       "lamina: warning: {} is missing: the page's leaderboard is empty (run "
                       "the study again to write it)\n",
                       metrics.string());
        return 0;
    };
}

}  // namespace lamina::cli

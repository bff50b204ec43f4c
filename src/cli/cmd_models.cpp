// lamina models: the analytic models of the registry, their supports and options.
#include "cli/commands.h"
#include "models/registry.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

namespace lamina::cli {

Runner add_models(CLI::App& app) {
    auto* cmd = app.add_subcommand("models", "List the analytic layered models and their options");
    auto verbose = std::make_shared<bool>(false);
    cmd->add_flag("--options", *verbose, "Also list each model's --option flags and defaults");
    return [verbose] {
        std::size_t width = 16;
        for (const ModelEntry& e : model_registry())
            width = std::max(width, e.name.size());
        // By family (ModelEntry::group), in the registry's order within each.
        for (const std::string& group : model_groups()) {
            bool first = true;
            for (const ModelEntry& e : model_registry()) {
                if (e.group != group) continue;
                if (first) fmt::print("[{}]\n", group);
                first = false;
                fmt::print("{:<{}} {}\n{:<{}} {}\n", e.name, width, e.description, "", width,
                           e.supports);
                if (*verbose)
                    for (const OptionSpec& o : e.options())
                        fmt::print("{:<{}}   --option {}={{{}}} (default {}): {}\n", "", width,
                                   o.key, fmt::join(o.values, ","), o.default_value, o.help);
            }
        }
        return 0;
    };
}

}  // namespace lamina::cli

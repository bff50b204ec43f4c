// lamina models: the analytic models of the registry, their supports and options.
#include "cli/commands.h"
#include "models/registry.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace lamina::cli {

Runner add_models(CLI::App& app) {
    auto* cmd = app.add_subcommand("models", "List the analytic layered models and their options");
    auto verbose = std::make_shared<bool>(false);
    cmd->add_flag("--options", *verbose, "Also list each model's --option flags and defaults");
    return [verbose] {
        for (const ModelEntry& e : model_registry()) {
            fmt::print("{:<16} {}\n{:<16} {}\n", e.name, e.description, "", e.supports);
            if (*verbose)
                for (const OptionSpec& o : e.options())
                    fmt::print("{:<16}   --option {}={{{}}} (default {}): {}\n", "", o.key,
                               fmt::join(o.values, ","), o.default_value, o.help);
        }
        return 0;
    };
}

}  // namespace lamina::cli

// lamina validate STACK.json…: checks stack files, describes each valid one.
#include "cli/commands.h"
#include "core/error.h"
#include "layers/stack.h"

#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

namespace lamina::cli {

Runner add_validate(CLI::App& app) {
    auto files = std::make_shared<std::vector<std::string>>();
    auto* cmd = app.add_subcommand("validate", "Check stack files and describe each valid stack");
    cmd->add_option("STACK", *files, "Stack JSON files")->required();
    return [files] {
        int failures = 0;
        for (const auto& file : *files) {
            try {
                fmt::print("{}\n", describe(load_stack(file)));
            } catch (const InputError& e) {
                fmt::print(stderr, "lamina: {}\n", e.what());
                ++failures;
            }
        }
        return failures ? 1 : 0;
    };
}

}  // namespace lamina::cli

// lamina command-line interface.
#include "core/error.h"
#include "lamina/version.h"
#include "layers/stack.h"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    CLI::App app{"lamina: a lab for layered materials in physically based rendering"};
    app.set_version_flag("--version", std::string("lamina ") + lamina::kVersion);
    app.require_subcommand(1);

    std::vector<std::string> validate_files;
    auto* validate =
        app.add_subcommand("validate", "Check stack files and describe each valid stack");
    validate->add_option("STACK", validate_files, "Stack JSON files")->required();

    CLI11_PARSE(app, argc, argv);
    try {
        if (validate->parsed()) {
            int failures = 0;
            for (const auto& file : validate_files) {
                try {
                    fmt::print("{}\n", lamina::describe(lamina::load_stack(file)));
                } catch (const lamina::InputError& e) {
                    fmt::print(stderr, "lamina: {}\n", e.what());
                    ++failures;
                }
            }
            return failures ? 1 : 0;
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "lamina: {}\n", e.what());
        return 1;
    }
    return 0;
}

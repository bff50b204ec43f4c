// lamina command-line interface: one subcommand per cmd_*.cpp, registered in the table below.
#include "cli/commands.h"
#include "core/error.h"
#include "lamina/version.h"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <exception>
#include <utility>
#include <vector>

int main(int argc, char** argv) {
    CLI::App app{"lamina: a lab for layered materials in physically based rendering"};
    app.set_version_flag("--version", std::string("lamina ") + lamina::kVersion);
    app.require_subcommand(1);

    // The subcommands, in the order `lamina --help` lists them.
    std::vector<std::pair<CLI::App*, lamina::cli::Runner>> commands;
    auto add = [&](lamina::cli::Runner (*registrar)(CLI::App&)) {
        lamina::cli::Runner runner = registrar(app);
        commands.emplace_back(app.get_subcommands({}).back(), std::move(runner));
    };
    add(lamina::cli::add_validate);
    add(lamina::cli::add_simulate);
    add(lamina::cli::add_models);
    add(lamina::cli::add_eval);
    add(lamina::cli::add_render);
    add(lamina::cli::add_compare);
    add(lamina::cli::add_study);
    add(lamina::cli::add_explorer);
    add(lamina::cli::add_figures);

    CLI11_PARSE(app, argc, argv);
    try {
        for (auto& [sub, run] : commands)
            if (sub->parsed()) return run();
    } catch (const lamina::InputError& e) {
        fmt::print(stderr, "lamina: {}\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        fmt::print(stderr, "lamina: error: {}\n", e.what());
        return 1;
    }
    return 0;
}

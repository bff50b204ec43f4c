// lamina command-line interface: one subcommand per cmd_*.cpp, registered in the table below. The
// executable's main() and the Python package's `python3 -m lamina` both run it.
#include "cli/commands.h"
#include "cli/parse_errors.h"
#include "core/error.h"
#include "core/setting.h"
#include "distributed/communicator.h"
#include "lamina/version.h"
#include "simulator/kernel_simd.h"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <exception>
#include <new>
#include <string>
#include <utility>
#include <vector>

namespace lamina::cli {

int run(int argc, char** argv) {
    CLI::App app{"lamina: a lab for layered materials in physically based rendering"};
    // The version, and the instruction set the goniophotometer's SIMD kernel takes on this
    // machine: tables are bitwise reproducible for one instruction set (docs/scaling.md).
    app.set_version_flag("--version", [] {
        return fmt::format("lamina {}\nSIMD kernel: {}", lamina::kVersion,
                           lamina::simd_target_name());
    });
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
    add(lamina::cli::add_export);
    add(lamina::cli::add_tables);

    // Under an MPI launcher every process gets here; an error on any of them ends them all
    // (distributed/communicator.h), so that none waits forever for the others.
    lamina::Communicator* world = nullptr;
    auto fail = [&](const std::string& message) {
        if (world && world->distributed()) world->abort(message);
        fmt::print(stderr, "lamina: {}\n", message);
        return 1;
    };
    try {
        app.parse(argc, argv);
    } catch (const CLI::Success& e) {
        return app.exit(e);  // --help, --version: printed by CLI11, exit code 0
    } catch (const CLI::ParseError& e) {
        // CLI11's errors exit like lamina's: one "lamina: command line: ..." line, exit code 1.
        return fail(lamina::cli::input_error_from(e, app).what());
    } catch (const lamina::InputError& e) {
        return fail(e.what());  // a setting's value, read as CLI11 parses (cli/settings_options.h)
    }
    try {
        world = &lamina::Communicator::world();
        for (auto& [sub, run] : commands) {
            if (!sub->parsed()) continue;
            if (world->distributed() && sub->get_name() != "simulate" && sub->get_name() != "study")
                throw lamina::InputError(
                    "command line", sub->get_name(),
                    fmt::format("runs in one process, not {}: only simulate and study are "
                                "spread over processes (mpirun -n K)",
                                world->size()));
            return run();
        }
    } catch (const lamina::InputError& e) {
        // A setting refused by the library (where "settings", the field its snake_case name) is
        // the command line's option here.
        if (e.where() == "settings")
            return fail(
                lamina::InputError("command line", lamina::option_name(e.field()), e.problem())
                    .what());
        return fail(e.what());
    } catch (const std::bad_alloc&) {
        return fail(
            "error: out of memory (a coarser --grid, fewer --threads or fewer incidences "
            "per run need less)");
    } catch (const std::exception& e) {
        return fail(fmt::format("error: {}", e.what()));
    }
    return 0;
}

}  // namespace lamina::cli

#pragma once
// Each subcommand lives in its own cmd_*.cpp and registers itself through one function listed in
// run.cpp. A command's run function returns the process exit code; InputError escaping it is
// printed as "lamina: <file>: <field>: <problem>" with exit code 1.

#include <CLI/CLI.hpp>

#include <functional>

namespace lamina::cli {

using Runner = std::function<int()>;

/// The whole command line: parses argv (argv[0] names the program in --help), runs the subcommand
/// and returns the exit code (0, or 1 with one "lamina: ..." line on stderr). The executable's
/// main() and `python3 -m lamina` (the Python module's `cli`) call it.
int run(int argc, char** argv);

/// Adds the subcommand to `app` and returns what runs it once parsed.
Runner add_validate(CLI::App& app);
Runner add_simulate(CLI::App& app);
/// `lamina study` and `lamina compare` (cmd_study.cpp).
Runner add_study(CLI::App& app);
Runner add_compare(CLI::App& app);
/// `lamina models`: the analytic models of the registry (cmd_models.cpp).
Runner add_models(CLI::App& app);
/// `lamina eval`: a model at points, a batch of directions, or on the bins (cmd_eval.cpp).
Runner add_eval(CLI::App& app);
/// `lamina explorer DIR`: a study directory's explorer page (cmd_explorer.cpp).
Runner add_explorer(CLI::App& app);
/// `lamina figures DIR`: a study directory's paper figures (cmd_figures.cpp).
Runner add_figures(CLI::App& app);
/// `lamina render`: sphere renderings and the comparison sheet (cmd_render.cpp).
Runner add_render(CLI::App& app);
/// `lamina export`: .bsdf, MERL .binary or .npz files (cmd_export.cpp).
Runner add_export(CLI::App& app);
/// `lamina tables`: the models' tables computed into the cache now (cmd_tables.cpp).
Runner add_tables(CLI::App& app);

}  // namespace lamina::cli

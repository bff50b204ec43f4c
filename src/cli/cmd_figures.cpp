// lamina figures DIR: paper-ready figures of a study directory (docs/explorer.md).
#include "cli/commands.h"
#include "cli/options.h"
#include "core/error.h"
#include "report/figures.h"

#include <fmt/format.h>

#include <memory>
#include <sstream>

namespace lamina::cli {

Runner add_figures(CLI::App& app) {
    auto* cmd = app.add_subcommand(
        "figures",
        "Write a study directory's figures (PNG; PDF, SVG on request) into DIR/figures/");
    struct Args {
        std::string dir, formats = "png", only, python;
        bool force = false;
    };
    auto a = std::make_shared<Args>();
    cmd->add_option("DIR", a->dir,
                    "A study directory (written by `lamina study` or `lamina compare`)")
        ->required();
    cmd->add_option("--formats", a->formats, "Comma-separated: png, pdf, svg")
        ->capture_default_str();
    cmd->add_flag("--force", a->force,
                  "Redraw every figure (by default only those whose inputs changed)");
    cmd->add_option("--only", a->only,
                    "Configuration ids (globs, comma-separated) for the per-configuration slices")
        ->check(some_patterns());
    cmd->add_option(
        "--python", a->python,
        "Python interpreter with matplotlib (default: $LAMINA_PYTHON, /usr/bin/python3)");
    return [a] {
        FigureOptions o;
        o.formats.clear();
        std::stringstream ss(a->formats);
        for (std::string f; std::getline(ss, f, ',');)
            if (!f.empty()) o.formats.push_back(f);
        o.only = a->only;
        o.python = a->python;
        o.force = a->force;
        write_figures(a->dir, o);
        fmt::print("{}/figures/: written\n", a->dir);
        return 0;
    };
}

}  // namespace lamina::cli

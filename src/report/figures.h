#pragma once
// Paper-ready figures of a study directory (docs/explorer.md), drawn by scripts/figures.py with
// matplotlib (Debian's python3-matplotlib, installed by `make deps`). The script is embedded in the
// binary at build time.

#include <filesystem>
#include <string>
#include <vector>

namespace lamina {

struct FigureOptions {
    std::vector<std::string> formats = {"png"};  ///< any of png, pdf, svg
    std::string only;  ///< configuration ids (globs, comma-separated) for the slices; all if empty
    std::string
        python;  ///< interpreter; empty: $LAMINA_PYTHON, else /usr/bin/python3, else python3
    bool force = false;  ///< redraw every figure, not only those whose inputs changed
};

/// Writes DIR/figures/: per-configuration incident-plane slices, the configurations × models
/// misplaced-energy matrix, albedo curves per category. Only the figures whose inputs changed since
/// they were drawn (DIR/figures/.inputs.json), in parallel over the cores. Throws InputError if
/// DIR/study.json is missing, a format is unknown, or the script fails (its own message is printed
/// on stderr).
void write_figures(const std::filesystem::path& study_dir, const FigureOptions& options = {});

}  // namespace lamina

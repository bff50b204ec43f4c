#include "report/figures.h"

#include "core/error.h"
#include "core/hash.h"
#include "report/assets.h"

#include <fmt/format.h>

#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <cstdlib>

namespace fs = std::filesystem;

namespace lamina {

namespace {

std::string shell_quote(const std::string& s) {
    std::string out = "'";
    for (char c : s)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string choose_python(const std::string& requested) {
    if (!requested.empty()) return requested;
    if (const char* env = std::getenv("LAMINA_PYTHON"); env && *env) return env;
    // Debian's interpreter first: python3-matplotlib lives there, whatever else is on the PATH.
    if (::access("/usr/bin/python3", X_OK) == 0) return "/usr/bin/python3";
    return "python3";
}

}  // namespace

void write_figures(const fs::path& study_dir, const FigureOptions& options) {
    const fs::path study_path = study_dir / "study.json";
    if (!fs::exists(study_path))
        throw InputError(study_path.string(), "",
                         "not found: expected a study directory written by `lamina study` or "
                         "`lamina compare`");
    std::string formats;
    for (const std::string& f : options.formats) {
        if (f != "pdf" && f != "svg" && f != "png")
            throw InputError("command line", "--formats",
                             fmt::format("'{}' is not a figure format; allowed: pdf, svg, png", f));
        formats += (formats.empty() ? "" : ",") + f;
    }
    if (formats.empty())
        throw InputError("command line", "--formats", "no format given; allowed: pdf, svg, png");
    const fs::path out = study_dir / "figures";
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec || ::access(out.c_str(), W_OK) != 0)
        throw InputError(out.string(), "", "cannot create or write the figures folder");

    // The script is embedded; python reads it from standard input ("-").
    const std::string python = choose_python(options.python);
    const std::string_view script = assets::figures_py();
    // The script's digest (it reads itself from stdin, so it cannot hash its own file): part of
    // every figure's inputs, so a new lamina redraws what its script draws differently.
    std::string command =
        fmt::format("{} - {} --formats {} --script-id {:016x}", shell_quote(python),
                    shell_quote(study_dir.string()), formats, fnv1a(script));
    if (!options.only.empty()) command += " --only " + shell_quote(options.only);
    if (options.force) command += " --force";
    // The palette the explorer page uses too (web/model-colors.json, embedded).
    ::setenv("LAMINA_MODEL_COLORS", std::string(assets::model_colors_json()).c_str(), 1);
    // The reader of the tables' packed arrays (src/python/lamina/arrays.py, embedded).
    ::setenv("LAMINA_ARRAYS_PY", std::string(assets::arrays_py()).c_str(), 1);
    std::FILE* pipe = ::popen(command.c_str(), "w");
    if (!pipe) throw InputError(python, "", "cannot start the figure script's interpreter");
    // An interpreter that exits before reading the script must not kill lamina with SIGPIPE.
    const auto previous = std::signal(SIGPIPE, SIG_IGN);
    std::fwrite(script.data(), 1, script.size(), pipe);
    const int status = ::pclose(pipe);
    std::signal(SIGPIPE, previous);
    if (status == -1 || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        throw InputError(
            study_dir.string(), "figures",
            code == 127 ? fmt::format("cannot run '{}': install python3 (`make deps`)", python)
            : code == 3
                ? "matplotlib or numpy is missing: run `make deps` (Debian's "
                  "python3-matplotlib and python3-numpy), or set LAMINA_PYTHON"
                : fmt::format("the figure script failed (exit {}); its message is above", code));
    }
}

}  // namespace lamina

#include "report/figures.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hash.h"
#include "report/assets.h"

#include <fmt/format.h>

#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string_view>
#include <vector>

extern char** environ;

namespace fs = std::filesystem;

namespace lamina {

namespace {

/// Runs `argv` (its first word looked up on the PATH) with `input` on its standard input and
/// returns its exit code: 127 when it cannot be started, −1 when it did not exit (a signal). The
/// child is registered with the interrupt handler (core/atomic_file.h), so that a lamina stopped
/// by SIGINT, SIGTERM or SIGHUP stops it too (the figure script then removes its temporary files).
int run_with_input(const std::vector<std::string>& argv, std::string_view input) {
    int fds[2];
    if (::pipe(fds) != 0) return 127;
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[0], 0);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_addclose(&actions, fds[1]);
    std::vector<char*> args;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    pid_t pid = 0;
    const int spawned = ::posix_spawnp(&pid, args[0], &actions, nullptr, args.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(fds[0]);
    if (spawned != 0) {
        ::close(fds[1]);
        return 127;
    }
    const int slot = register_interrupt_child(int(pid), {}, {});
    // An interpreter that exits before reading the script must not kill lamina with SIGPIPE.
    const auto previous = std::signal(SIGPIPE, SIG_IGN);
    for (std::size_t at = 0; at < input.size();) {
        const ssize_t n = ::write(fds[1], input.data() + at, input.size() - at);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        at += std::size_t(n);
    }
    ::close(fds[1]);
    std::signal(SIGPIPE, previous);
    int status = 0;
    pid_t waited = 0;
    while ((waited = ::waitpid(pid, &status, 0)) < 0 && errno == EINTR) {
    }
    unregister_interrupt_child(slot);
    if (waited < 0 || !WIFEXITED(status)) return -1;
    return WEXITSTATUS(status);
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
    std::vector<std::string> argv = {python,
                                     "-",
                                     study_dir.string(),
                                     "--formats",
                                     formats,
                                     "--script-id",
                                     fmt::format("{:016x}", fnv1a(script))};
    if (!options.only.empty()) argv.insert(argv.end(), {"--only", options.only});
    if (options.force) argv.push_back("--force");
    // The palette the explorer page uses too (web/model-colors.json, embedded).
    ::setenv("LAMINA_MODEL_COLORS", std::string(assets::model_colors_json()).c_str(), 1);
    // The reader of the tables' packed arrays (src/python/lamina/arrays.py, embedded).
    ::setenv("LAMINA_ARRAYS_PY", std::string(assets::arrays_py()).c_str(), 1);
    const int code = run_with_input(argv, script);
    if (code != 0) {
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

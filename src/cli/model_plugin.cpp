#include "cli/model_plugin.h"

#include "core/atomic_file.h"
#include "core/error.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <spawn.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

extern char** environ;

namespace lamina::cli {

#ifdef LAMINA_PYTHON_EXECUTABLE
namespace {

// Runs argv (searched on PATH) with PYTHONPATH prepended by `python_path`; returns the exit status.
// Until it has ended, an interrupt of lamina ends it too and removes `temp_dir`'s `temp_files`.
int run_process(const std::vector<std::string>& argv, const std::string& python_path,
                const std::filesystem::path& temp_dir, const std::vector<std::string>& temp_files) {
    std::vector<std::string> env_strings;
    for (char** e = environ; *e; ++e)
        if (std::string(*e).rfind("PYTHONPATH=", 0) != 0) env_strings.emplace_back(*e);
    const char* old = std::getenv("PYTHONPATH");
    std::string path_entry = "PYTHONPATH=";
    path_entry.append(python_path);
    if (old && *old) path_entry.append(":").append(old);
    env_strings.push_back(path_entry);
    std::vector<char*> args, env;
    for (const std::string& a : argv)
        args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    for (const std::string& e : env_strings)
        env.push_back(const_cast<char*>(e.c_str()));
    env.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawnp(&pid, args[0], nullptr, nullptr, args.data(), env.data()) != 0) return -1;
    const int slot = register_interrupt_child(int(pid), temp_dir, temp_files);
    int status = 0;
    const pid_t waited = waitpid(pid, &status, 0);
    unregister_interrupt_child(slot);
    if (waited < 0) return -1;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// What lamina.plugin_table writes in place of a table when the model supports neither side.
constexpr std::string_view kPluginUnsupported = "unsupported\n";

// The plugin's table of `c` lit from phi_i at the incidences theta_i (python3 -m
// lamina.plugin_table), or a table with neither side when the model supports neither.
BinnedTable plugin_table(const std::string& file, const std::string& python,
                         const StudyConfiguration& c, const std::vector<double>& theta_i,
                         double phi_i, const HemisphereGrid& grid) {
    std::string dir_template =
        (std::filesystem::temp_directory_path() / "lamina-plugin-XXXXXX").string();
    if (!mkdtemp(dir_template.data()))
        throw InputError(file, "--model-plugin", "cannot create a temporary folder");
    const std::filesystem::path dir = dir_template;
    struct Cleanup {
        std::filesystem::path dir;
        ~Cleanup() {
            std::error_code ec;
            std::filesystem::remove_all(dir, ec);
        }
    } cleanup{dir};
    std::ofstream(dir / "stack.json") << stack_to_json(c.stack).dump();
    const int rc = run_process(
        {python, "-m", "lamina.plugin_table", file, "--stack", (dir / "stack.json").string(),
         "--theta-i", fmt::format("{}", fmt::join(theta_i, ",")), "--phi-i",
         fmt::format("{}", phi_i), "--grid", grid.to_string(), "--out",
         (dir / "table.csv").string()},
        LAMINA_PYTHON_DIR, dir, {"stack.json", "table.csv"});
    if (rc != 0)
        throw InputError(file, "--model-plugin",
                         fmt::format("the Python model failed on {} (exit status {}; its "
                                     "message is above; interpreter: {})",
                                     c.id, rc, python));
    // The table, or the line saying the model supports neither side of this stack (written to the
    // same file, so that no exit status of the plugin's own can be read as it).
    std::error_code ec;
    if (!std::filesystem::is_regular_file(dir / "table.csv", ec))
        throw InputError(file, "--model-plugin",
                         fmt::format("the Python model's process ended on {} without writing its "
                                     "table (did the model call sys.exit or os._exit?)",
                                     c.id));
    const std::string text =
        read_file_bounded(dir / "table.csv", kMaxTableFileBytes, "the Python model's table");
    if (text == kPluginUnsupported) {
        BinnedTable none;
        none.has_reflection = false;
        return none;
    }
    try {
        return BinnedTable::from_csv(text, "the table of " + file);
    } catch (const InputError& e) {
        throw InputError(file, "--model-plugin",
                         fmt::format("its binned table on {} is not readable ({}: {})", c.id,
                                     e.field(), e.problem()));
    }
}

}  // namespace
#endif

ExternalModel model_plugin(const std::string& assignment) {
#ifndef LAMINA_PYTHON_EXECUTABLE
    throw InputError("command line", "--model-plugin",
                     fmt::format("'{}': this lamina was built without the Python module "
                                 "(install python3-dev and pybind11-dev, then rebuild)",
                                 assignment));
#else
    const auto eq = assignment.find('=');
    const std::string file = eq == std::string::npos ? assignment : assignment.substr(eq + 1);
    ExternalModel m;
    m.name = eq == std::string::npos ? std::filesystem::path(file).stem().string()
                                     : assignment.substr(0, eq);
    if (!std::filesystem::is_regular_file(file))
        throw InputError(file, "--model-plugin", "cannot read the file");
    m.source = file;
    const char* python_env = std::getenv("LAMINA_PYTHON");
    const std::string python = python_env && *python_env ? python_env : LAMINA_PYTHON_EXECUTABLE;
    m.unfolded = true;  // the plugin is evaluated at any wi
    // A brdf.csv row carries θi alone: the model is binned once per light azimuth of the
    // configuration (once for a folded one), and the tables gathered in the incidences' order.
    m.table = [file, python](const StudyConfiguration& c,
                             const std::vector<StudyIncidence>& incidences,
                             const HemisphereGrid& grid) {
        return gather_azimuths(incidences, file,
                               [&](const std::vector<double>& theta_i, double phi_i) {
                                   return plugin_table(file, python, c, theta_i, phi_i, grid);
                               });
    };
    return m;
#endif
}

}  // namespace lamina::cli

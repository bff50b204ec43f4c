// lamina study [--preset quick|standard|paper] [--only PATTERN] [--models …] [--configs FILE]
//              [--out DIR]: the 60 configurations (or a user's list) against every model.
//              Under `mpirun -n K` the reference is spread over K processes (docs/scaling.md).
// lamina compare STACK.json [--theta-i …] [--particles N] [--models …] --out DIR: one stack.
#include "cli/commands.h"
#include "cli/model_plugin.h"
#include "cli/options.h"
#include "cli/settings_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/incidences.h"
#include "distributed/communicator.h"
#include "models/random_walk/random_walk_model.h"
#include "render/contact_sheet.h"
#include "report/explorer.h"
#include "report/figures.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"
#include "study/distributed_reference.h"
#include "study/study.h"

#include <fmt/format.h>

#include <filesystem>
#include <memory>
#include <sstream>

namespace lamina::cli {

namespace {

struct CommonArgs {
    CLI::App* cmd = nullptr;
    StudySettings settings;  ///< the options write into it; settings_from completes it
    std::string models, out, formats = "png";
    bool no_figures = false;
    std::vector<std::string> model_tables;   ///< NAME=FILE.csv (FILE may hold {id})
    std::vector<std::string> model_plugins;  ///< [NAME=]FILE.py (docs/python.md)
};

void add_common(CLI::App* cmd, CommonArgs& a) {
    a.cmd = cmd;
    // The reference's settings (the goniophotometer's, core/setting.h) and the study's own.
    add_physics_option(cmd, a.settings.reference.transport);
    add_settings_options(cmd, a.settings.reference);
    add_settings_options(cmd, a.settings);
    cmd->add_option("--models", a.models,
                    "Models to compare, comma-separated (default: all); NAME:KEY=VALUE adds a "
                    "model's flag");
    cmd->add_flag("--ablations", a.settings.ablations,
                  "Also each production coat with one flag switched (openpbr:darkening=off, ...)");
    cmd->add_option("--model-table", a.model_tables,
                    "A model evaluated elsewhere, as NAME=FILE.csv in the brdf.csv format (lamina "
                    "eval --binned writes it) on the study's grid and incidences; {id} in FILE "
                    "stands for the configuration id; repeatable");
    cmd->add_option("--model-plugin", a.model_plugins,
                    "A Python model, [NAME=]FILE.py defining MODEL (a class with a vectorized "
                    "eval(wi, wo), docs/python.md), binned by lamina's quadrature; repeatable");
    cmd->add_option("--formats", a.formats, "Figure formats, comma-separated: png, pdf, svg")
        ->capture_default_str();
    cmd->add_flag("--recompute", a.settings.recompute,
                  "Recompute the models, metrics and outputs even where their inputs are "
                  "unchanged (the reference pieces are still reused), and redraw every figure");
    cmd->add_flag("--no-figures", a.no_figures,
                  "Skip the paper figures (the explorer page is always written)");
}

// --model-table NAME=FILE.csv: the table of each configuration read from FILE ({id} replaced by
// the configuration's id); a missing file for a configuration means "not supported".
ExternalModel model_table(const std::string& assignment) {
    const auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == assignment.size())
        throw InputError("command line", "--model-table",
                         fmt::format("'{}' is not NAME=FILE.csv", assignment));
    ExternalModel m;
    m.name = assignment.substr(0, eq);
    const std::string pattern = assignment.substr(eq + 1);
    const bool per_config = pattern.find("{id}") != std::string::npos;
    if (!per_config && !std::filesystem::is_regular_file(pattern))
        throw InputError(pattern, "--model-table", "cannot read the file");
    m.source = pattern;
    m.table = [pattern, per_config](const StudyConfiguration& c, const std::vector<StudyIncidence>&,
                                    const HemisphereGrid&) {
        std::string path = pattern;
        for (auto at = path.find("{id}"); at != std::string::npos; at = path.find("{id}"))
            path.replace(at, 4, c.id);
        std::ifstream in(path, std::ios::binary);
        if (!in) {
            if (per_config) {  // this configuration has no table: not supported
                BinnedTable none;
                none.has_reflection = false;
                return none;
            }
            throw InputError(path, "--model-table", "cannot read the file");
        }
        in.close();
        return BinnedTable::from_csv(read_file_bounded(path, kMaxTableFileBytes, "the table"),
                                     path);
    };
    return m;
}

FigureOptions figure_options(const CommonArgs& a) {
    FigureOptions o;
    o.formats.clear();
    std::stringstream ss(a.formats);
    for (std::string f; std::getline(ss, f, ',');)
        if (!f.empty()) {
            if (f != "png" && f != "pdf" && f != "svg")
                throw InputError(
                    "command line", "--formats",
                    fmt::format("'{}' is not a figure format; allowed: png, pdf, svg", f));
            o.formats.push_back(f);
        }
    if (o.formats.empty())
        throw InputError("command line", "--formats", "no format given; allowed: png, pdf, svg");
    o.force = a.settings.recompute;
    return o;
}

StudySettings settings_from(const CommonArgs& a, const std::string& preset) {
    StudySettings s = a.settings;
    const std::uint64_t budget = preset_particles(preset);  // validates --preset in every case
    // A particle count given by hand is not the preset's budget: say so wherever it is shown.
    const bool by_hand = a.cmd->count("--particles") > 0;
    if (!by_hand) s.reference.particles = budget;
    check_reference_particles(s);
    s.preset = by_hand ? "custom" : preset;
    figure_options(a);  // validates --formats before any work
    if (!a.models.empty()) {
        std::stringstream ss(a.models);
        for (std::string m; std::getline(ss, m, ',');)
            if (!m.empty()) s.models.push_back(m);
    }
    // Their names are cells of metrics.csv and legends.
    for (const std::string& assignment : a.model_tables) {
        s.external_models.push_back(model_table(assignment));
        check_study_label(s.external_models.back().name, "model name", "command line",
                          "--model-table");
    }
    for (const std::string& assignment : a.model_plugins) {
        s.external_models.push_back(model_plugin(assignment));
        check_study_label(s.external_models.back().name, "model name", "command line",
                          "--model-plugin");
    }
    return s;
}

// A table file given for several configurations must name each one's file with {id}.
void check_model_tables(const CommonArgs& a, const std::vector<StudyConfiguration>& configs) {
    for (const std::string& assignment : a.model_tables)
        if (configs.size() > 1 && assignment.find("{id}") == std::string::npos)
            throw InputError("command line", "--model-table",
                             fmt::format("'{}': a table describes one stack, and {} configurations "
                                         "are selected: write FILE with {{id}} (e.g. "
                                         "NAME=tables/{{id}}.csv) or select one with --only",
                                         assignment, configs.size()));
}

// Every --model-table file read and checked against its configuration's grid, incidences and
// sides before any work: a wrong table is refused before the reference is simulated, not after.
// (They are the first of the settings' external models, in the order given.)
void check_model_tables_fit(const CommonArgs& a, const StudySettings& s,
                            const std::vector<StudyConfiguration>& configs) {
    for (std::size_t k = 0; k < a.model_tables.size(); ++k) {
        const ExternalModel& e = s.external_models[k];
        for (const StudyConfiguration& c : configs) {
            const HemisphereGrid grid = study_grid(c.stack, s.reference);
            if (grid.is_unfolded()) continue;  // reported not supported by the study
            const std::vector<StudyIncidence> incidences = study_incidences(c.stack, s.reference);
            const BinnedTable table = e.table(c, incidences, grid);
            if (!table.has_reflection && !table.has_transmission) continue;
            std::vector<double> theta_i;
            for (const StudyIncidence& inc : incidences)
                theta_i.push_back(inc.theta_i);
            check_external_table(table, grid, theta_i, c.stack.transmits(), e.source);
        }
    }
}

// The explorer page, then the figures (a failure there is a warning: the study itself is done).
// Without tables (--tables none) there is no page to draw: only the error matrices.
void write_report(const std::filesystem::path& dir, const CommonArgs& a, const StudySettings& s,
                  StudyTimes& times) {
    if (s.tables != TablesFormat::None) {
        PhaseTimer explorer;
        write_explorer(dir);
        explorer.add_to(times.explorer);
    }
    if (a.no_figures) return;
    PhaseTimer figures;
    try {
        write_figures(dir, figure_options(a));
    } catch (const InputError& e) {
        fmt::print(stderr, "lamina: warning: figures not written: {}\n", e.what());
    }
    figures.add_to(times.figures);
}

// What the run did, then the findings (the part of summary.md a reader wants first).
void print_outcome(const StudyResult& r, const std::filesystem::path& dir, const StudySettings& s) {
    fmt::print("\nWork: {}\n{}\n\n{}", describe_work(r.work), describe_times(r.times),
               findings_headline(r.findings));
    fmt::print("\nReport: {0}/summary.md (metrics: {0}/metrics.csv){1}\n", dir.string(),
               s.tables == TablesFormat::None
                   ? std::string("; no explorer page (--tables none)")
                   : fmt::format("; explorer: {}/index.html", dir.string()));
}

}  // namespace

Runner add_study(CLI::App& app) {
    struct Args : CommonArgs {
        std::string preset = "quick", only, configs;
        bool render = false;
        int render_size = 160, render_spp = 32;
    };
    auto a = std::make_shared<Args>();
    auto* cmd = app.add_subcommand("study",
                                   "Compare every model with the reference on the study's "
                                   "configurations (60; 76 in the standard and paper presets)");
    cmd->add_option("--preset", a->preset,
                    "Particle budget: quick (10^6 per incidence), standard (10^7), paper (1.6e8)")
        ->capture_default_str();
    cmd->add_option("--only", a->only, "Only configurations whose id matches (globs, commas)")
        ->check(some_patterns());
    cmd->add_option("--configs", a->configs, "A JSON list of your own configurations");
    add_common(cmd, *a);
    cmd->add_option(
        "--out,-o", a->out,
        "Output folder (default out/study-PRESET, out/study-PRESET-bpb19 for --physics bpb19)");
    cmd->add_flag(
        "--render", a->render,
        "Also render every configuration (reference and models, studio lighting) into "
        "OUT/configs/ID/renders/ (compare.png, PNG + EXR per model, errors.csv), shown by "
        "the explorer");
    cmd->add_option("--render-size", a->render_size, "Pixels of each rendering (default 160)")
        ->check(CLI::Range(8, 4096));
    cmd->add_option("--render-spp", a->render_spp, "Samples per pixel (default 32)")
        ->check(CLI::Range(1, 1 << 20));
    return [a] {
        // Under mpirun every process runs this: the reference pieces are spread over them
        // (study/distributed_reference.h); the root alone reads the inputs, then runs the rest
        // of the study (models, metrics, report) on the cached pieces.
        Communicator& world = Communicator::world();
        const StudySettings s = settings_from(*a, a->preset);
        std::vector<StudyConfiguration> configs;
        // The default folder names the preset, and the reference when it is not the exact one.
        const std::string physics = physics_name(s.reference.transport);
        const std::filesystem::path out =
            a->out.empty() ? std::filesystem::path("out") /
                                 ("study-" + a->preset + (physics == "exact" ? "" : "-" + physics))
                           : std::filesystem::path(a->out);
        if (world.is_root()) {
            configs = a->configs.empty() ? preset_configurations(a->preset)
                                         : load_configurations(a->configs);
            configs = filter_configurations(std::move(configs), a->only);
            check_model_tables(*a, configs);
            check_model_tables_fit(*a, s, configs);
        }
        // Under mpirun: the pieces the processes computed before run_study, and their time (the
        // root's wall and CPU seconds), counted in the Work and Time lines with run_study's.
        std::size_t computed_before = 0;
        StudyTimes::Span reference_before;
        if (world.distributed()) {
            const PhaseTimer timer;
            std::vector<ReferenceKey> keys;
            if (world.is_root()) {
                study_models(s);          // validates --models before any work
                StagedOutput probe(out);  // and the output folder
                keys = study_reference_keys(configs, s);
            }
            const int threads =
                s.reference.threads > 0 ? s.reference.threads : default_threads_per_process(world);
            const std::size_t computed = share_reference_pieces(
                world, world.is_root() ? reference_cache_dir(out) : std::filesystem::path(), keys,
                threads);
            if (!world.is_root()) return 0;
            fmt::print("Reference: {} pieces computed over {} processes × {} threads\n", computed,
                       world.size(), threads);
            computed_before = computed;
            timer.add_to(reference_before);
        }
        StudyResult result = run_study(configs, s, out);
        result.work.reference_pieces_computed += computed_before;
        result.times.reference.wall += reference_before.wall;
        result.times.reference.cpu += reference_before.cpu;
        if (a->render) {
            // Renderings of every configuration: reproducible (seed), the same settings for all.
            RenderSettings rs;
            rs.size = a->render_size;
            rs.spp = a->render_spp;
            rs.seed = s.reference.seed;
            rs.threads = s.reference.threads;
            rs.progress = !s.quiet;
            const Environment env = Environment::named("studio");
            std::string index = "config,model,rel_rmse,seconds\n";
            for (const StudyConfiguration& c : configs) {
                const std::string csv =
                    write_comparison(c.stack, env, rs, out / "configs" / c.id / "renders", 0.0,
                                     random_walk_assignments(s.reference.transport));
                std::stringstream lines(csv);
                std::string line;
                std::getline(lines, line);  // header
                while (std::getline(lines, line))
                    index += c.id + "," + line + "\n";
            }
            write_file_atomic(out / "renders.csv", index);
            fmt::print("Renderings: {0}/configs/ID/renders/compare.png (errors: {0}/renders.csv)\n",
                       out.string());
        }
        write_report(out, *a, s, result.times);
        print_outcome(result, out, s);
        return 0;
    };
}

Runner add_compare(CLI::App& app) {
    struct Args : CommonArgs {
        std::string stack;
    };
    auto a = std::make_shared<Args>();
    auto* cmd = app.add_subcommand(
        "compare", "Simulate one stack and compare every model with it on the same bins");
    cmd->add_option("STACK", a->stack, "Stack JSON file")->required();
    add_common(cmd, *a);
    cmd->add_option("--out,-o", a->out, "Output folder")->required();
    return [a] {
        const StudySettings s = settings_from(*a, "quick");
        StudyConfiguration c;
        c.stack = load_stack(a->stack);
        validate_kernel_for(c.stack, s.reference, a->stack);  // before DIR is made
        c.id = std::filesystem::path(a->stack).stem().string();
        c.category = "custom";
        c.parameters = describe_parameters(c.stack);
        check_model_tables_fit(*a, s, {c});
        StudyResult result = run_study({c}, s, a->out);
        write_report(a->out, *a, s, result.times);
        print_outcome(result, a->out, s);
        return 0;
    };
}

}  // namespace lamina::cli

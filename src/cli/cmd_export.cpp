// lamina export: a simulate output, a study configuration's source or a model, as an RGL .bsdf
// tensor file (pbrt-v4, Mitsuba 3), a MERL .binary or a NumPy .npz (docs/formats.md, "Exports").
#include "cli/commands.h"
#include "cli/options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/json_text.h"
#include "core/npy.h"
#include "core/packed_array.h"
#include "export/brdf_source.h"
#include "export/merl.h"
#include "export/npz.h"
#include "export/rgl_bsdf.h"
#include "export/rgl_fidelity.h"
#include "export/rgl_reader.h"
#include "lamina/version.h"
#include "layers/stack.h"
#include "models/lamina1/lamina1.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "simulator/goniophotometer.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

namespace lamina::cli {

namespace {

struct ExportArgs {
    std::string check;           ///< a file to check instead of writing one
    std::string lamina1_tables;  ///< lamina-1's data file to write instead of an export
    std::string lamina1_gpu;     ///< lamina-1's GLSL state of --stack to write instead
    bool strict = false;         ///< --check: exit 2 when the figures miss the goals
    std::string simulation, study, config, source = "reference", model, stack, out, format;
    std::string theta_i, grid = "90x90";
    bool grid_given = false;  ///< whether --grid was given
    std::vector<std::string> options;
    int resolution = RglOptions{}.resolution, vndf_resolution = RglOptions{}.vndf_resolution,
        ndf_resolution = RglOptions{}.ndf_resolution, azimuths = RglOptions{}.azimuths;
    double phi_i = 0;  ///< a model's .npz: the light's azimuth (degrees)
};

std::string read_text(const std::filesystem::path& path) {
    return read_file_bounded(path, kMaxTableFileBytes, "the file");
}

nlohmann::json read_json(const std::filesystem::path& path) {
    try {
        return nlohmann::json::parse(read_text(path));
    } catch (const nlohmann::json::exception& e) {
        throw InputError(path.string(), "",
                         fmt::format("not valid JSON: {}", json_exception_text(e)));
    }
}

// A study configuration's source (the reference or a model): its binned table with the azimuth
// of each incidence, and what a model source needs to be evaluated directly.
struct StudySource {
    BinnedTable table;
    std::vector<double> phi_i_deg;  ///< the light's azimuth per incidence (0 when folded)
    nlohmann::json stack;           ///< the configuration's (config.json)
    std::string group;              ///< the source's group in study.json (model_groups)
    std::string config_path;        ///< config.json, for messages
};

StudySource study_table(const ExportArgs& a) {
    const std::filesystem::path dir = std::filesystem::path(a.study) / "configs" / a.config;
    const nlohmann::json study = read_json(std::filesystem::path(a.study) / "study.json");
    if (!std::filesystem::is_directory(dir))
        throw InputError(a.study, "--config", fmt::format("no configuration '{}'", a.config));
    const nlohmann::json cfg = read_json(dir / "config.json");
    StudySource out;
    out.config_path = (dir / "config.json").string();
    try {
        const auto sources = cfg.at("sources").get<std::vector<std::string>>();
        const auto it = std::find(sources.begin(), sources.end(), a.source);
        if (it == sources.end())
            throw InputError(out.config_path, "--source",
                             fmt::format("no source '{}'; this configuration has: {}", a.source,
                                         fmt::join(sources, ", ")));
        const std::size_t k = std::size_t(it - sources.begin());
        const auto theta_i = cfg.at("theta_i").get<std::vector<double>>();
        const auto sides = cfg.at("sides").get<std::vector<std::string>>();
        // Counts in range (they size the table); read wide so that 1e18 is not wrapped.
        HemisphereGrid grid = HemisphereGrid::checked(
            study.at("grid").at("n_theta").get<long long>(),
            study.at("grid").at("n_phi").get<long long>(),
            (std::filesystem::path(a.study) / "study.json").string(), "/grid");
        // An unfolded configuration (docs/formats.md): its incidences' azimuths and its grid.
        out.phi_i_deg.assign(theta_i.size(), 0.0);
        if (cfg.contains("phi_i")) {
            out.phi_i_deg = cfg.at("phi_i").get<std::vector<double>>();
            grid = grid.unfolded();
            if (out.phi_i_deg.size() != theta_i.size())
                throw InputError(out.config_path, "phi_i", "does not match theta_i");
            if (cfg.value("grid", grid.to_string()) != grid.to_string())
                throw InputError(out.config_path, "grid",
                                 fmt::format("'{}' does not match study.json's grid ({})",
                                             cfg.value("grid", ""), grid.to_string()));
        }
        out.stack = cfg.value("stack", nlohmann::json());
        if (study.contains("model_groups"))
            out.group = study.at("model_groups").value(a.source, std::string());
        const NpyFloat32 t = read_study_array(dir, "tables");
        const std::vector<std::size_t> want = {sources.size(),
                                               theta_i.size(),
                                               sides.size(),
                                               std::size_t(grid.n_theta()),
                                               std::size_t(grid.n_phi()),
                                               3};
        if (t.shape != want)
            throw InputError(study_array_path(dir, "tables").string(), "shape",
                             "does not match config.json and study.json");
        // The reference's standard errors go with it.
        std::optional<NpyFloat32> se;
        if (k == 0 && std::filesystem::exists(study_array_path(dir, "reference_se"))) {
            se = read_study_array(dir, "reference_se");
            if (std::vector<std::size_t>(want.begin() + 1, want.end()) != se->shape)
                throw InputError(study_array_path(dir, "reference_se").string(), "shape",
                                 "does not match config.json and study.json");
        }
        BinnedTable& table = out.table;
        table = BinnedTable::zeros(grid, theta_i, true, sides.size() == 2);
        const std::size_t source_offset = k * theta_i.size() * sides.size() * grid.size() * 3;
        for (std::size_t i = 0; i < theta_i.size(); ++i)
            for (std::size_t s = 0; s < sides.size(); ++s) {
                BinnedLobe& lobe = table.lobe(i, s == 0 ? Side::Reflection : Side::Transmission);
                if (se) lobe.se.assign(grid.size(), Rgbd(0.0));
                const std::size_t lobe_offset = (i * sides.size() + s) * grid.size() * 3;
                for (std::size_t j = 0; j < grid.size(); ++j)
                    for (std::size_t c = 0; c < 3; ++c) {
                        lobe.f[j][int(c)] = t.data[source_offset + lobe_offset + j * 3 + c];
                        if (se) lobe.se[j][int(c)] = se->data[lobe_offset + j * 3 + c];
                    }
            }
        // A side the source does not support is NaN in every bin (the study's convention), any
        // other finite in every bin; a standard error finite and ≥ 0. Anything else is damage.
        for (std::size_t i = 0; i < theta_i.size(); ++i)
            for (std::size_t s = 0; s < sides.size(); ++s) {
                const BinnedLobe& lobe =
                    table.lobe(i, s == 0 ? Side::Reflection : Side::Transmission);
                const auto finite = [](const Rgbd& v) {
                    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
                };
                const auto n_finite = std::count_if(lobe.f.begin(), lobe.f.end(), finite);
                if (n_finite != 0 && std::size_t(n_finite) != lobe.f.size())
                    throw InputError(
                        study_array_path(dir, "tables").string(), a.source,
                        fmt::format("{} of {} bins are not finite at θi = {}°, side {} (a "
                                    "damaged file?)",
                                    lobe.f.size() - std::size_t(n_finite), lobe.f.size(),
                                    theta_i[i], sides[s]));
                for (const Rgbd& v : lobe.se)
                    for (int c = 0; c < 3; ++c)
                        if (!(v[c] >= 0 && std::isfinite(v[c])))
                            throw InputError(
                                study_array_path(dir, "reference_se").string(), "",
                                fmt::format("a standard error at θi = {}°, side {} is {}: allowed "
                                            "finite, ≥ 0 (a damaged file?)",
                                            theta_i[i], sides[s], v[c]));
            }
        for (const auto& lobe : table.lobe(0, Side::Reflection).f)
            if (!std::isfinite(lobe[0]))
                throw k == 0 ? InputError(study_array_path(dir, "tables").string(), a.source,
                                          "the reference's BRDF is not finite (a damaged file?)")
                             : InputError(out.config_path, "--source",
                                          fmt::format("'{}' does not support this "
                                                      "configuration's BRDF",
                                                      a.source));
        return out;
    } catch (const nlohmann::json::exception& e) {
        throw InputError(
            out.config_path, "",
            fmt::format("not lamina's configuration: {} (damaged?)", json_exception_text(e)));
    }
}

// The source of an export (or of a check): a binned table (simulate, study) or a model.
struct Source {
    BinnedTable table;
    bool have_table = false;
    std::vector<double> phi_i_deg;  ///< a table's: the light's azimuth per incidence
    std::shared_ptr<const Model> model;
    std::shared_ptr<const Stack> stack;  ///< the model's
    StudySource study;                   ///< --study: the configuration's source
    nlohmann::json meta;
};

bool has_source(const ExportArgs& a) {
    return !a.simulation.empty() || !a.study.empty() || !a.model.empty();
}

Source load_source(const ExportArgs& a) {
    const int sources = int(!a.simulation.empty()) + int(!a.study.empty()) + int(!a.model.empty());
    if (sources != 1)
        throw InputError("command line", "--simulation",
                         "give one source: --simulation DIR, --study DIR --config ID, or --model "
                         "NAME --stack FILE");
    Source src;
    src.meta["lamina_version"] = kVersion;
    if (!a.simulation.empty()) {
        const std::filesystem::path dir = a.simulation;
        src.table = BinnedTable::from_csv(read_text(dir / "brdf.csv"), (dir / "brdf.csv").string());
        src.have_table = true;
        src.meta["source"] = "simulation";
        double phi_i = 0;
        if (const std::filesystem::path path = dir / "result.json"; std::filesystem::exists(path)) {
            nlohmann::json result = read_json(path);
            if (!result.is_object())
                throw InputError(path.string(), "",
                                 "not a simulation's result.json: a JSON object is expected "
                                 "(the one `lamina simulate` writes beside brdf.csv)");
            // The light's azimuth places the table on the hemisphere: a value that is not one is
            // refused rather than read as 0.
            if (const auto it = result.find("phi_i"); it != result.end()) {
                if (!it->is_number() || !(it->get<double>() >= 0 && it->get<double>() <= 360))
                    throw InputError(path.string(), "/phi_i",
                                     fmt::format("{}: the light's azimuth in degrees is expected; "
                                                 "allowed: a number in [0, 360]",
                                                 it->dump()));
                phi_i = it->get<double>();
            }
            src.meta["result"] = std::move(result);
        }
        src.phi_i_deg.assign(src.table.theta_i_deg.size(), phi_i);
    } else if (!a.study.empty()) {
        if (a.config.empty()) throw InputError("command line", "--config", "required with --study");
        src.study = study_table(a);
        src.table = src.study.table;
        src.phi_i_deg = src.study.phi_i_deg;
        src.have_table = true;
        src.meta["source"] = {{"study", a.study}, {"config", a.config}, {"source", a.source}};
    } else {
        if (a.stack.empty()) throw InputError("command line", "--stack", "required with --model");
        const ModelEntry& entry = find_model(a.model);
        require_tabulable(entry, "command line", "--model");
        src.stack = std::make_shared<const Stack>(load_stack(a.stack));
        src.model = entry.make(*src.stack, resolve_options(entry, a.options));
        src.meta["source"] = {{"model", a.model}, {"stack", stack_to_json(*src.stack)}};
    }
    return src;
}

// A model source of an unfolded study configuration as a BRDF: its table holds the light at the
// configuration's azimuths only, and a .bsdf or MERL file needs every φi, so the model (its name
// and flags, as the study ran it) is evaluated on the configuration's stack. The reference and an
// external model's table cannot be: InputError saying what to write instead.
BrdfSource unfolded_study_brdf(const StudySource& st, const ExportArgs& a) {
    std::vector<double> azimuths;
    for (double phi : st.phi_i_deg)
        if (std::find(azimuths.begin(), azimuths.end(), phi) == azimuths.end())
            azimuths.push_back(phi);
    const std::string held = fmt::format(
        "'{}' is compared on the unfolded grid ({}), its light from φi = {}° only, "
        "and a .bsdf or MERL file needs the BRDF at every φi",
        a.config, st.table.grid.to_string(), fmt::join(azimuths, "°, "));
    if (a.source == "reference")
        throw InputError(st.config_path, "--source",
                         held +
                             ": write the reference as .npz (every incidence as the study has "
                             "it), or export one of the study's models (--source MODEL), "
                             "which is evaluated at every φi");
    if (st.group == "external")
        throw InputError(st.config_path, "--source",
                         held + fmt::format(": '{}' is an external model, known by its table "
                                            "alone: write it as .npz",
                                            a.source));
    if (st.stack.is_null()) throw InputError(st.config_path, "stack", "missing");
    const Stack stack = stack_from_json(st.stack, st.config_path + ": stack");
    const std::shared_ptr<const Model> model = make_model(a.source, stack);
    BrdfSource brdf = model_brdf(model, stack, st.config_path);
    brdf.name = a.source;
    return brdf;
}

/// The reflection side of a source as a BRDF.
BrdfSource brdf_of(const Source& src, const ExportArgs& a) {
    if (!src.have_table) return model_brdf(src.model, *src.stack, a.stack);
    if (!a.study.empty() && src.table.grid.is_unfolded()) return unfolded_study_brdf(src.study, a);
    return table_brdf(src.table, a.simulation.empty() ? a.source : "reference",
                      a.simulation.empty() ? a.study : a.simulation);
}

// The figures of rgl_fidelity.h, as a table: how close a renderer reading the file gets to its
// source. Returns whether they meet the goals.
bool print_fidelity(const TensorFile& file, const std::string& path, const BrdfSource& brdf) {
    using Goals = RglFidelityGoals;
    const RglReader reader(file, path);
    const RglFidelityOptions options;
    const RglFidelity r = rgl_fidelity(reader, brdf, options, path);
    fmt::print(
        "\nA renderer reading {} (pbrt-v4, Mitsuba 3) against its source, {}:\n"
        "directional albedo (luminance; error: the channel where it is largest, goal ≤ {:g}%)\n"
        "  θi (°){}   source     file     error\n",
        path, brdf.name, 100 * Goals::kAlbedo, brdf.isotropic ? "" : "  φi (°)");
    for (const RglAlbedoRow& row : r.albedo)
        fmt::print("  {:6.1f}{}  {:8.5f}  {:8.5f}  {:6.2f}%{}\n", row.theta_i_deg,
                   brdf.isotropic ? "" : fmt::format("  {:6.1f}", row.phi_i_deg),
                   luminance(row.source), luminance(row.file), 100 * row.error,
                   row.error > Goals::kAlbedo ? "  over the goal" : "");
    const auto worst = std::max_element(
        r.albedo.begin(), r.albedo.end(),
        [](const RglAlbedoRow& x, const RglAlbedoRow& y) { return x.error < y.error; });
    fmt::print("  worst: {:.2f}% at θi = {:g}°{}\n", 100 * worst->error, worst->theta_i_deg,
               brdf.isotropic ? "" : fmt::format(", φi = {:g}°", worst->phi_i_deg));
    fmt::print(
        "values f at {} random direction pairs (θi, θo ≤ {:g}°, luminance): relative error "
        "{:.2f}% for half of them, {:.2f}% for {:g}% (goal ≤ {:g}%), {:.2f}% for 99%{}\n",
        r.value_errors.size(), options.max_theta_deg, 100 * r.value_error(0.5),
        100 * r.value_error(Goals::kValueQuantile), 100 * Goals::kValueQuantile,
        100 * Goals::kValue, 100 * r.value_error(0.99),
        r.pairs_skipped ? fmt::format(" ({} pairs where the source is 0 left out)", r.pairs_skipped)
                        : "");
    const bool ok = r.meets_goals();
    fmt::print("{}: {} the goals\n", path, ok ? "meets" : "misses");
    return ok;
}

// --check FILE: reads a .bsdf or MERL .binary as a reader would and describes it (InputError
// naming the file and what is wrong for a malformed or truncated one); with a source, also how
// close a renderer reading a .bsdf gets to it.
int run_check(const ExportArgs& a) {
    const std::string& path = a.check;
    const std::string bytes = read_text(path);
    if (bytes.rfind("tensor_file", 0) == 0 || std::filesystem::path(path).extension() == ".bsdf") {
        const TensorFile file = parse_tensor_file(bytes, path);
        // Read as a renderer's reader reads it (RglReader: check_rgl_bsdf, then the incidences'
        // and azimuths' order and symmetry, the distributions' signs), with or without a source.
        const RglReader reader(file, path);
        const auto& spectra = file.at("spectra").shape;
        fmt::print(
            "{}: RGL .bsdf ({:.1f} MB), {} incidences, {} × {} samples, {} wavelengths: "
            "\"{}\"\n",
            path, double(bytes.size()) / 1e6, spectra[1], spectra[3], spectra[4], spectra[2],
            file.at("description").data);
        if (!has_source(a)) {
            if (a.strict)
                throw InputError("command line", "--strict",
                                 "give the file's source (--model NAME --stack FILE, --simulation "
                                 "DIR or --study DIR --config ID) to check it against");
            return 0;
        }
        const bool ok = print_fidelity(file, path, brdf_of(load_source(a), a));
        return ok || !a.strict ? 0 : 2;
    }
    if (has_source(a) || a.strict)
        throw InputError("command line", "--check",
                         "a MERL .binary is checked for its structure only: give no source");
    const MerlBrdf merl = parse_merl(bytes, path);
    fmt::print(
        "{}: MERL .binary, 90 × 90 × 180 × RGB, f at normal incidence and exit ({}, {}, {})\n",
        path, merl.values[0], merl.values[90 * 90 * 180], merl.values[2 * 90 * 90 * 180]);
    return 0;
}

int run_export(const ExportArgs& a) {
    if (!a.check.empty()) return run_check(a);
    if (!a.lamina1_gpu.empty()) {
        // lamina-1's per-material state for its GLSL form (include/lamina1/gpu.h).
        if (a.stack.empty()) throw InputError("command line", "--stack", "give the stack file");
        if (has_source(a) || !a.out.empty())
            throw InputError("command line",
                             !a.model.empty()        ? "--model"
                             : !a.simulation.empty() ? "--simulation"
                             : !a.study.empty()      ? "--study"
                                                     : "--out",
                             "--lamina1-gpu writes lamina-1's state of --stack (with its "
                             "--option flags) to its own file: leave this out");
        std::string why;
        const std::vector<float> state = lamina1_gpu_state(
            load_stack(a.stack), resolve_options(find_model("lamina-1"), a.options), why);
        if (state.empty())
            throw InputError(a.stack, "--lamina1-gpu", "not covered by the GLSL form: " + why);
        write_file_atomic(a.lamina1_gpu, std::string(reinterpret_cast<const char*>(state.data()),
                                                     state.size() * sizeof(float)));
        fmt::print("wrote {} (lamina-1's GLSL state, {} floats)\n", a.lamina1_gpu, state.size());
        return 0;
    }
    if (!a.lamina1_tables.empty()) {
        // The tables lamina-1's header library reads (include/lamina1/tables.h, docs/lamina1.md).
        if (has_source(a) || !a.out.empty() || !a.stack.empty())
            throw InputError("command line",
                             !a.model.empty()        ? "--model"
                             : !a.simulation.empty() ? "--simulation"
                             : !a.study.empty()      ? "--study"
                             : !a.out.empty()        ? "--out"
                                                     : "--stack",
                             "--lamina1-tables writes lamina-1's tables, the same for every "
                             "material, to its own file: leave this out");
        const std::string bytes = lamina1_tables_file();
        write_file_atomic(a.lamina1_tables, bytes);
        fmt::print("wrote {} (lamina-1's tables, {:.2f} MB)\n", a.lamina1_tables,
                   bytes.size() / 1e6);
        return 0;
    }
    if (a.strict) throw InputError("command line", "--strict", "goes with --check FILE");
    if (!(a.phi_i >= 0 && a.phi_i <= 360))  // NaN too
        throw InputError("command line", "--phi-i",
                         fmt::format("{} degrees is outside [0, 360]", a.phi_i));
    if (a.out.empty()) throw InputError("command line", "--out", "give the output file");
    std::string format = a.format;
    if (format.empty()) {
        const std::string ext = std::filesystem::path(a.out).extension().string();
        format = ext == ".bsdf" ? "bsdf" : ext == ".binary" ? "merl" : ext == ".npz" ? "npz" : "";
        if (format.empty())
            throw InputError("command line", "--format",
                             "give --format bsdf|merl|npz or an --out ending in .bsdf, .binary "
                             "or .npz");
    }
    if (format != "bsdf" && format != "merl" && format != "npz")
        throw InputError("command line", "--format",
                         fmt::format("'{}' is not a format: bsdf, merl or npz", format));

    if (a.phi_i != 0 && format != "npz")
        throw InputError("command line", "--phi-i",
                         "goes with --format npz (a .bsdf holds every φi; a MERL file one BRDF "
                         "of θi alone)");
    Source src = load_source(a);
    BinnedTable& table = src.table;
    const bool have_table = src.have_table;
    // An option the export has no use for is refused, not ignored.
    if (a.grid_given && (format != "npz" || have_table))
        throw InputError("command line", "--grid",
                         format != "npz" ? "the bins of a model's .npz; a .bsdf or MERL file "
                                           "samples the BRDF its own way"
                                         : "a table's bins are the ones it was computed on; "
                                           "--grid goes with --model");
    if (!a.theta_i.empty() && (format == "merl" || (format == "npz" && have_table)))
        throw InputError("command line", "--theta-i",
                         format == "merl" ? "a MERL file samples θi its own way"
                                          : "a table's incidences are the ones it was computed "
                                            "at; --theta-i goes with --model");
    const std::shared_ptr<const Model>& model = src.model;
    nlohmann::json& meta = src.meta;

    std::string bytes;
    if (format == "npz") {
        if (!have_table) {
            const Support s = model->support();
            if (!s.brdf && !s.btdf)
                throw InputError(a.stack, "--model", "not supported: " + s.reason);
            // The bins the goniophotometer tabulates for this stack and φi (unfolded for an
            // anisotropic stack or φi ≠ 0).
            SimulationSettings binning;
            binning.grid = HemisphereGrid::parse(a.grid, "--grid");
            binning.phi_i_deg = a.phi_i;
            table = bin_model(
                *model, simulation_grid(*src.stack, binning),
                parse_incidences(a.theta_i.empty() ? default_incidences_text() : a.theta_i,
                                 "--theta-i"),
                a.phi_i);
            meta["phi_i"] = a.phi_i;
            src.phi_i_deg.assign(table.theta_i_deg.size(), a.phi_i);
        } else if (a.phi_i != 0) {
            throw InputError("command line", "--phi-i",
                             "a table's light azimuth is the one it was simulated with; --phi-i "
                             "goes with --model");
        }
        const std::size_t n_inc = table.theta_i_deg.size(),
                          n_sides = table.has_transmission ? 2 : 1;
        const HemisphereGrid& g = table.grid;
        std::vector<float> f, se;
        for (std::size_t i = 0; i < n_inc; ++i)
            for (std::size_t s = 0; s < n_sides; ++s) {
                const BinnedLobe& lobe =
                    table.lobe(i, s == 0 ? Side::Reflection : Side::Transmission);
                for (std::size_t j = 0; j < g.size(); ++j)
                    for (int c = 0; c < 3; ++c) {
                        f.push_back(float(lobe.f[j][c]));
                        se.push_back(float(lobe.se.empty() ? 0.0 : lobe.se[j][c]));
                    }
            }
        const std::vector<std::size_t> shape = {n_inc, n_sides, std::size_t(g.n_theta()),
                                                std::size_t(g.n_phi()), 3};
        std::vector<float> theta_i(table.theta_i_deg.begin(), table.theta_i_deg.end()),
            phi_i(src.phi_i_deg.begin(), src.phi_i_deg.end()), te, pe;
        for (int t = 0; t <= g.n_theta(); ++t)
            te.push_back(float(90.0 * t / g.n_theta()));
        for (int p = 0; p <= g.n_phi(); ++p)
            pe.push_back(float(g.phi_span_deg() * p / g.n_phi()));
        meta["axes"] = {"incidence", "side", "theta_bin", "phi_bin", "channel"};
        meta["sides"] = n_sides == 2 ? nlohmann::json{"R", "T"} : nlohmann::json{"R"};
        meta["theta_i"] = table.theta_i_deg;
        meta["grid"] = {
            {"n_theta", g.n_theta()}, {"n_phi", g.n_phi()}, {"unfolded", g.is_unfolded()}};
        bytes = zip_stored({{"f.npy", npy_float32(f, shape)},
                            {"se.npy", npy_float32(se, shape)},
                            {"theta_i.npy", npy_float32(theta_i, {theta_i.size()})},
                            {"phi_i.npy", npy_float32(phi_i, {phi_i.size()})},
                            {"theta_edges.npy", npy_float32(te, {te.size()})},
                            {"phi_edges.npy", npy_float32(pe, {pe.size()})},
                            {"metadata.json", meta.dump(1) + "\n"}});
    } else {
        const BrdfSource brdf = brdf_of(src, a);
        if (format == "bsdf") {
            RglOptions o;
            o.resolution = a.resolution;
            o.vndf_resolution = a.vndf_resolution;
            o.ndf_resolution = a.ndf_resolution;
            o.azimuths = a.azimuths;
            if (!a.theta_i.empty()) o.theta_i_deg = parse_incidences(a.theta_i, "--theta-i");
            o.description = fmt::format("lamina {} export: {}", kVersion, meta["source"].dump());
            const TensorFile file = rgl_bsdf(brdf, o);
            check_rgl_bsdf(file, a.out);
            bytes = tensor_file_bytes(file);
        } else {
            bytes = merl_binary(brdf);
        }
    }
    write_file_atomic(a.out, bytes);
    fmt::print("wrote {} ({}, {:.1f} MB){}\n", a.out, format, bytes.size() / 1e6,
               format == "npz" ? "" : ": the reflection side (BRDF) only");
    return 0;
}

}  // namespace

Runner add_export(CLI::App& app) {
    auto a = std::make_shared<ExportArgs>();
    auto* cmd = app.add_subcommand(
        "export",
        "Write a reference or a model as an RGL .bsdf (pbrt-v4, Mitsuba 3), MERL "
        ".binary or NumPy .npz file");
    cmd->add_option("--simulation", a->simulation, "A `lamina simulate` output folder");
    cmd->add_option("--study", a->study, "A study folder (with --config, --source)");
    cmd->add_option("--config", a->config, "The study configuration id");
    cmd->add_option("--source", a->source, "reference or a model of the study")
        ->capture_default_str();
    cmd->add_option("--model", a->model, "A model name (with --stack, --option)");
    cmd->add_option("--stack", a->stack, "The model's stack JSON file");
    cmd->add_option("--option", a->options, "Model flag KEY=VALUE, repeatable");
    cmd->add_option("--format", a->format, "bsdf, merl or npz (default: from --out's extension)");
    cmd->add_option(
        "--theta-i", a->theta_i,
        fmt::format("Incidences (degrees): a model's .bsdf nodes (default {:.4g}, "
                    "denser towards grazing) or .npz bins (default {})",
                    fmt::join(rgl_default_incidences(), ","), default_incidences_text()));
    cmd->add_option("--grid", a->grid,
                    "Bins of a model's .npz, NTHETAxNPHI (φ over [0, 180]; unfolded over [0, "
                    "360) with twice the bins for an anisotropic stack or --phi-i ≠ 0)")
        ->capture_default_str()
        ->each([a](const std::string&) { a->grid_given = true; });
    cmd->add_option("--phi-i", a->phi_i, "A model's .npz: the light's azimuth in degrees, [0, 360]")
        ->capture_default_str();
    cmd->add_option("--azimuths", a->azimuths,
                    ".bsdf of an anisotropic stack: φi slices over [−180°, 180°] (intervals)")
        ->capture_default_str();
    cmd->add_option("--resolution", a->resolution, ".bsdf: sample-grid nodes a side")
        ->capture_default_str();
    cmd->add_option("--vndf-resolution", a->vndf_resolution,
                    ".bsdf: warp (vndf) nodes along θ of the half vector")
        ->capture_default_str();
    cmd->add_option("--ndf-resolution", a->ndf_resolution, ".bsdf: ndf and sigma nodes along θ")
        ->capture_default_str();
    cmd->add_option("--out,-o", a->out, "Output file");
    cmd->add_option("--check", a->check,
                    "Read a .bsdf or MERL .binary file as a renderer would and describe it (a "
                    "malformed or truncated file is refused with what is wrong); with the .bsdf's "
                    "source, report how close a renderer gets to it: directional albedo and "
                    "values against the goals (docs/formats.md)");
    cmd->add_option("--lamina1-tables", a->lamina1_tables,
                    "Write the data file of lamina-1's header library (include/lamina1/, "
                    "docs/lamina1.md): its generic tables, which a renderer ships beside it");
    cmd->add_option("--lamina1-gpu", a->lamina1_gpu,
                    "Write the per-material state of lamina-1's GLSL form for --stack (and "
                    "--option) as float32 (include/lamina1/gpu.h, docs/lamina1.md)");
    cmd->add_flag("--strict", a->strict,
                  "With --check and a source: exit with status 2 when the figures miss the goals");
    return [a] { return run_export(*a); };
}

}  // namespace lamina::cli

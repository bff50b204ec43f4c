#include "study/study.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/npy.h"
#include "core/progress.h"
#include "lamina/version.h"
#include "models/binned.h"
#include "models/registry.h"
#include "study/reference.h"
#include "study/summary.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <memory>

namespace lamina {

namespace {

constexpr const char* kChannels[3] = {"r", "g", "b"};

nlohmann::json rgb(const Rgbd& v) {
    return nlohmann::json::array({v[0], v[1], v[2]});
}

std::string csv_number(double v) {
    return std::isfinite(v) ? fmt::format("{}", v) : "";
}

struct ConfigResult {
    std::vector<MetricRow> rows;
    std::vector<Rgbd> lost_microsurface;  ///< the reference's, per incidence
};

// Evaluates one configuration: reference pieces, models, metrics; writes configs/<id>/.
ConfigResult run_configuration(const StudyConfiguration& config, const StudySettings& s,
                               const std::vector<std::string>& model_names,
                               const std::filesystem::path& out_dir, Progress& progress) {
    const std::size_t n_inc = s.theta_i_deg.size();
    const HemisphereGrid& grid = s.grid;

    // 1. The reference, one resumable piece per incidence.
    std::vector<ReferencePiece> pieces;
    for (double theta_i : s.theta_i_deg) {
        ReferenceKey key{config.id, config.stack, theta_i,  s.particles,
                         s.seed,    grid,         s.kernel, s.microsurface};
        key.transmission_masking = s.transmission_masking;
        pieces.push_back(reference_piece(reference_cache_dir(out_dir), key, s.threads,
                                         [&](std::uint64_t n) { progress.advance(n); }));
    }
    const bool transmits = pieces.front().has_transmission;
    const int n_sides = transmits ? 2 : 1;

    // 2. Every model on the same bins.
    struct ModelOutcome {
        std::string name;
        Support support;
        BinnedTable table;
    };
    std::vector<ModelOutcome> models;
    for (const std::string& name : model_names) {
        ModelOutcome m{name, {}, {}};
        const std::unique_ptr<Model> model = make_model(name, config.stack);
        m.support = model->support();
        if (m.support.brdf || m.support.btdf) m.table = bin_model(*model, grid, s.theta_i_deg);
        models.push_back(std::move(m));
    }

    // 3. Metrics.
    ConfigResult result;
    for (const ModelOutcome& m : models) {
        for (std::size_t i = 0; i < n_inc; ++i) {
            for (int side = 0; side < n_sides; ++side) {
                const bool supported = side == 0 ? m.support.brdf : m.support.btdf;
                for (int c = 0; c < 3; ++c) {
                    MetricRow row{config.id,
                                  config.category,
                                  m.name,
                                  s.theta_i_deg[i],
                                  side == 0 ? 'R' : 'T',
                                  c,
                                  supported,
                                  {},
                                  pieces[i].floor[side][c]};
                    if (supported) {
                        const BinnedLobe& lobe =
                            m.table.lobe(i, side == 0 ? Side::Reflection : Side::Transmission);
                        row.metrics = lobe_metrics(grid, pieces[i].f[side], lobe.f, c);
                    }
                    result.rows.push_back(row);
                }
            }
        }
    }

    // 4. configs/<id>/: config.json, tables.npy, reference_se.npy.
    const std::size_t bins = grid.size();
    const std::size_t n_sources = 1 + models.size();
    std::vector<float> tables(n_sources * n_inc * n_sides * bins * 3, NAN);
    std::vector<float> ses(n_inc * n_sides * bins * 3);
    auto at = [&](std::size_t src, std::size_t i, int side, std::size_t j, int c) {
        return (((src * n_inc + i) * n_sides + side) * bins + j) * 3 + c;
    };
    nlohmann::json albedo;
    for (std::size_t i = 0; i < n_inc; ++i)
        for (int side = 0; side < n_sides; ++side) {
            Rgbd a(0.0);
            for (std::size_t j = 0; j < bins; ++j)
                for (int c = 0; c < 3; ++c) {
                    tables[at(0, i, side, j, c)] = float(pieces[i].f[side][j][c]);
                    ses[at(0, i, side, j, c)] = float(pieces[i].se[side][j][c]);
                    a[c] += pieces[i].f[side][j][c] * grid.projected_solid_angle(j);
                }
            albedo["reference"][side == 0 ? "R" : "T"].push_back(rgb(a));
        }
    nlohmann::json supported = nlohmann::json::object();
    nlohmann::json sources = {"reference"};
    for (std::size_t k = 0; k < models.size(); ++k) {
        const ModelOutcome& m = models[k];
        sources.push_back(m.name);
        supported[m.name] = {
            {"R", m.support.brdf}, {"T", m.support.btdf}, {"reason", m.support.reason}};
        for (int side = 0; side < n_sides; ++side) {
            const bool ok = side == 0 ? m.support.brdf : m.support.btdf;
            for (std::size_t i = 0; i < n_inc; ++i) {
                if (!ok) {
                    albedo[m.name][side == 0 ? "R" : "T"].push_back(nullptr);
                    continue;
                }
                const BinnedLobe& lobe =
                    m.table.lobe(i, side == 0 ? Side::Reflection : Side::Transmission);
                Rgbd a(0.0);
                for (std::size_t j = 0; j < bins; ++j)
                    for (int c = 0; c < 3; ++c) {
                        tables[at(1 + k, i, side, j, c)] = float(lobe.f[j][c]);
                        a[c] += lobe.f[j][c] * grid.projected_solid_angle(j);
                    }
                albedo[m.name][side == 0 ? "R" : "T"].push_back(rgb(a));
            }
        }
    }
    nlohmann::json energy = nlohmann::json::array();
    for (std::size_t i = 0; i < n_inc; ++i) {
        result.lost_microsurface.push_back(pieces[i].budget[BudgetTerm::LostMicrosurface]);
        nlohmann::json e;
        e["theta_i"] = s.theta_i_deg[i];
        for (int t = 0; t < kBudgetTerms; ++t)
            e[kBudgetTermNames[t]] = rgb(pieces[i].budget.term[t]);
        e["reflected_se"] = rgb(pieces[i].budget.reflected_se);
        e["transmitted_se"] = rgb(pieces[i].budget.transmitted_se);
        energy.push_back(e);
    }
    nlohmann::json cj;
    cj["id"] = config.id;
    cj["category"] = config.category;
    cj["parameters"] = config.parameters;
    cj["stack"] = stack_to_json(config.stack);
    cj["sides"] = transmits ? nlohmann::json{"R", "T"} : nlohmann::json{"R"};
    cj["theta_i"] = s.theta_i_deg;
    cj["sources"] = sources;
    cj["supported"] = supported;
    cj["albedo"] = albedo;
    cj["energy"] = energy;
    cj["tables"] = {{"file", "tables.npy"},
                    {"shape", {n_sources, n_inc, n_sides, grid.n_theta(), grid.n_phi(), 3}},
                    {"axes", {"source", "incidence", "side", "theta_bin", "phi_bin", "channel"}}};
    StagedOutput out(out_dir / "configs" / config.id);
    out.add("tables.npy",
            npy_float32(tables, {n_sources, n_inc, std::size_t(n_sides),
                                 std::size_t(grid.n_theta()), std::size_t(grid.n_phi()), 3}));
    out.add("reference_se.npy",
            npy_float32(ses, {n_inc, std::size_t(n_sides), std::size_t(grid.n_theta()),
                              std::size_t(grid.n_phi()), 3}));
    out.add("config.json", cj.dump(1) + "\n");
    out.commit();
    return result;
}

}  // namespace

std::uint64_t preset_particles(const std::string& preset) {
    if (preset == "quick") return 1'000'000;
    if (preset == "standard") return 10'000'000;
    if (preset == "paper") return 160'000'000;
    throw InputError("command line", "--preset",
                     fmt::format("'{}' is not a preset: use quick (10^6 particles per incidence), "
                                 "standard (10^7) or paper (1.6·10^8)",
                                 preset));
}

std::string metrics_csv(const std::vector<MetricRow>& rows) {
    std::string out = std::string(kMetricsCsvHeader) + "\n";
    for (const MetricRow& r : rows) {
        fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},", r.config, r.category, r.model,
                       r.theta_i, r.side, kChannels[r.channel]);
        if (r.supported)
            fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{},true\n",
                           csv_number(r.metrics.misplaced_energy), csv_number(r.metrics.albedo_ref),
                           csv_number(r.metrics.albedo_model), csv_number(r.metrics.albedo_error),
                           csv_number(r.metrics.rmse), csv_number(r.metrics.log_rmse),
                           csv_number(r.floor.misplaced_energy));
        else
            out += ",,,,,,,false\n";
    }
    return out;
}

std::vector<std::string> study_models(const StudySettings& s) {
    std::vector<std::string> model_names = s.models;
    if (model_names.empty())
        for (const ModelEntry& e : model_registry())
            if (!e.stochastic) model_names.push_back(e.name);
    for (const std::string& name : model_names)
        find_model(name, "--models");  // validates
    return model_names;
}

std::filesystem::path reference_cache_dir(const std::filesystem::path& out_dir) {
    return out_dir / "cache" / "reference";
}

std::vector<MetricRow> run_study(const std::vector<StudyConfiguration>& configs,
                                 const StudySettings& s, const std::filesystem::path& out_dir) {
    const std::vector<std::string> model_names = study_models(s);

    StagedOutput probe(out_dir);  // the folder must be writable before any work starts
    const auto start = std::chrono::steady_clock::now();
    Progress progress("study", "particles", configs.size() * s.theta_i_deg.size() * s.particles);
    std::vector<MetricRow> rows;
    ReferenceLoss lost;
    for (std::size_t k = 0; k < configs.size(); ++k) {
        const auto t0 = std::chrono::steady_clock::now();
        ConfigResult r = run_configuration(configs[k], s, model_names, out_dir, progress);
        rows.insert(rows.end(), r.rows.begin(), r.rows.end());
        lost[configs[k].id] = r.lost_microsurface;
        if (!s.quiet) {
            progress.clear_line();
            fmt::print(
                "[{}/{}] {} ({:.1f} s)\n", k + 1, configs.size(), configs[k].id,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
            std::fflush(stdout);
        }
    }
    progress.finish();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

    nlohmann::json sj;
    sj["lamina_version"] = kVersion;
    sj["preset"] = s.preset;
    sj["particles"] = s.particles;
    sj["seed"] = s.seed;
    sj["kernel"] = kernel_description(s.kernel);
    sj["microsurface"] = microsurface_name(s.microsurface);
    sj["transmission_masking"] = transmission_masking_name(s.transmission_masking);
    sj["theta_i"] = s.theta_i_deg;
    sj["grid"] = {{"n_theta", s.grid.n_theta()}, {"n_phi", s.grid.n_phi()}};
    sj["models"] = model_names;
    sj["seconds"] = seconds;
    nlohmann::json list = nlohmann::json::array();
    for (const StudyConfiguration& c : configs)
        list.push_back(
            {{"id", c.id},
             {"category", c.category},
             {"parameters", c.parameters},
             {"sides", c.stack.transmits() ? nlohmann::json{"R", "T"} : nlohmann::json{"R"}}});
    sj["configurations"] = list;
    write_file_atomic(out_dir / "study.json", sj.dump(1) + "\n");
    write_file_atomic(out_dir / "metrics.csv", metrics_csv(rows));
    write_summary(out_dir, configs, s, model_names, rows, lost);
    return rows;
}

}  // namespace lamina

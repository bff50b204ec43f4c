#include "study/summary.h"

#include "core/atomic_file.h"
#include "lamina/version.h"
#include "layers/transport_settings.h"
#include "study/engine_findings.h"
#include "study/report_values.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <set>

namespace lamina {

namespace {

// ==== Computing the findings =====================================================================

// Running sums of one (group, model) over its supported rows.
struct Accumulator {
    double sum_mf = 0, sum_mf_noise = 0, sum_me = 0, sum_me_noise = 0, sum_abs_albedo = 0;
    int n_mf = 0, n_me = 0, n_albedo = 0;
    double worst_mf = -1, worst_me = -1, worst_albedo = 0;
    const MetricRow *worst_mf_row = nullptr, *worst_me_row = nullptr, *worst_albedo_row = nullptr;
    std::set<std::string> configs;

    void add(const MetricRow& r) {
        if (!r.supported || !std::isfinite(r.metrics.misplaced_floor)) return;
        const double mf = r.metrics.misplaced_floor;
        sum_mf += mf;
        sum_mf_noise += std::isfinite(r.floor.misplaced_floor) ? r.floor.misplaced_floor : 0;
        ++n_mf;
        configs.insert(r.config);
        if (mf > worst_mf) {
            worst_mf = mf;
            worst_mf_row = &r;
        }
        if (std::isfinite(r.metrics.misplaced_energy)) {
            sum_me += r.metrics.misplaced_energy;
            sum_me_noise += std::isfinite(r.floor.misplaced_energy) ? r.floor.misplaced_energy : 0;
            ++n_me;
            if (r.metrics.misplaced_energy > worst_me) {
                worst_me = r.metrics.misplaced_energy;
                worst_me_row = &r;
            }
        }
        if (std::isfinite(r.metrics.albedo_error)) {
            sum_abs_albedo += std::abs(r.metrics.albedo_error);
            ++n_albedo;
            if (std::abs(r.metrics.albedo_error) > std::abs(worst_albedo)) {
                worst_albedo = r.metrics.albedo_error;
                worst_albedo_row = &r;
            }
        }
    }

    static std::optional<RowPlace> place(const MetricRow* r) {
        if (!r) return std::nullopt;
        return RowPlace{r->config, r->theta_i, r->side, r->channel, r->phi_i};
    }

    ModelAggregate result() const {
        ModelAggregate a;
        a.rows = n_mf;
        a.configurations_supported = configs.size();
        if (n_mf) {
            a.mean_misplaced_floor = sum_mf / n_mf;
            a.mean_misplaced_floor_noise = sum_mf_noise / n_mf;
            a.worst_misplaced_floor = worst_mf;
            a.worst_misplaced_floor_at = place(worst_mf_row);
        }
        if (n_me) {
            a.mean_misplaced_energy = sum_me / n_me;
            a.mean_noise_floor = sum_me_noise / n_me;
            a.worst_misplaced_energy = worst_me;
            a.worst_misplaced_energy_at = place(worst_me_row);
        }
        if (n_albedo) {
            a.mean_abs_albedo_error = sum_abs_albedo / n_albedo;
            a.worst_albedo_error = worst_albedo;
            a.worst_albedo_error_at = place(worst_albedo_row);
        }
        return a;
    }
};

// Models with rows in `aggregates`, by mean misplaced_floor (ties keep the study's order).
std::vector<std::string> rank(const std::vector<std::string>& models,
                              const std::map<std::string, ModelAggregate>& aggregates,
                              bool keep_unsupported = false) {
    std::vector<std::string> ranked;
    for (const std::string& m : models)
        if (keep_unsupported || (aggregates.count(m) && aggregates.at(m).rows > 0))
            ranked.push_back(m);
    auto mean = [&](const std::string& m) {
        const auto it = aggregates.find(m);
        return it == aggregates.end() || it->second.rows == 0
                   ? std::numeric_limits<double>::infinity()
                   : it->second.mean_misplaced_floor;
    };
    std::stable_sort(ranked.begin(), ranked.end(),
                     [&](const auto& a, const auto& b) { return mean(a) < mean(b); });
    return ranked;
}

double parameter(const StudyConfiguration& c, const std::string& key) {
    const auto it = c.parameters.find(key);
    if (it == c.parameters.end()) return NAN;
    try {
        return std::stod(it->second);
    } catch (...) {
        return NAN;
    }
}

// A factor of the approximations assessment: named levels, each a predicate on a row.
struct Factor {
    std::string title, explanation;
    std::vector<std::pair<std::string, std::function<bool(const MetricRow&)>>> levels;
};

std::vector<Factor> assessment_factors(
    const std::map<std::string, const StudyConfiguration*>& by_id) {
    auto config_of = [&by_id](const MetricRow& r) -> const StudyConfiguration& {
        return *by_id.at(r.config);
    };
    return {
        {"Coat roughness (transmission through the top interface)",
         "Rows grouped by the top interface's roughness α0. The WW family refracts through a "
         "single normal; Belcour's operators approximate rough transmission by lobe statistics.",
         {{"smooth coat (α0 ≤ 0.05)",
           [=](const MetricRow& r) { return parameter(config_of(r), "alpha0") <= 0.05; }},
          {"rough coat (α0 ≥ 0.3)",
           [=](const MetricRow& r) { return parameter(config_of(r), "alpha0") >= 0.3; }}}},
        {"Base albedo (multiple bounces between base and coat)",
         "Lambertian bases, per channel: a low albedo leaves mostly the first bounce, a high "
         "albedo needs every inter-reflection (models without them fall short).",
         {{"low (ρ ≤ 0.2)",
           [=](const MetricRow& r) {
               const auto& c = config_of(r);
               return c.stack.base().type == InterfaceType::Lambertian &&
                      c.stack.base().albedo[r.channel] <= 0.2;
           }},
          {"high (ρ ≥ 0.5)",
           [=](const MetricRow& r) {
               const auto& c = config_of(r);
               return c.stack.base().type == InterfaceType::Lambertian &&
                      c.stack.base().albedo[r.channel] >= 0.5;
           }}}},
        {"Incidence (grazing angles)",
         "Rows grouped by θi: Fresnel, masking and path lengths in the coat all grow towards "
         "grazing incidence.",
         {{"θi ≤ 30°", [](const MetricRow& r) { return r.theta_i <= 30; }},
          {"45° ≤ θi ≤ 60°", [](const MetricRow& r) { return r.theta_i >= 45 && r.theta_i <= 60; }},
          {"θi ≥ 70°", [](const MetricRow& r) { return r.theta_i >= 70; }}}},
    };
}

}  // namespace

const GroupFindings* StudyFindings::group(const std::string& name) const {
    for (const GroupFindings& g : groups)
        if (g.name == name) return &g;
    return nullptr;
}

namespace {

using PerConfig = std::map<std::string, std::map<std::string, Accumulator>>;

// The rankings of each group: each category's BRDF, then the BTDF of the categories that transmit
// (a model's reflection and transmission errors are never averaged together: most models have no
// BTDF), then all; what each model does not support; each configuration's BRDF rows per model.
void find_groups(const std::vector<StudyConfiguration>& configs,
                 const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                 StudyFindings& f, PerConfig& per_config) {
    std::map<std::string, int> configs_in;
    bool any_transmission = false;
    for (const StudyConfiguration& c : configs) {
        f.category_of[c.id] = c.category;
        if (std::find(f.categories.begin(), f.categories.end(), c.category) == f.categories.end())
            f.categories.push_back(c.category);
        ++configs_in[c.category];
        ++configs_in["all"];
        if (c.stack.transmits()) {
            ++configs_in[c.category + " BTDF"];
            ++configs_in["all BTDF"];
            any_transmission = true;
        }
    }

    std::vector<std::string> group_names = f.categories;
    for (const std::string& c : f.categories)
        if (configs_in.count(c + " BTDF")) group_names.push_back(c + " BTDF");
    group_names.push_back("all");
    if (any_transmission) group_names.push_back("all BTDF");
    std::map<std::string, std::map<std::string, Accumulator>> acc;
    for (const MetricRow& r : rows) {
        acc[r.side == 'T' ? r.category + " BTDF" : r.category][r.model].add(r);
        acc[r.side == 'T' ? "all BTDF" : "all"][r.model].add(r);
        if (r.side == 'R') per_config[r.config][r.model].add(r);
        if (!r.supported) {
            std::string& sides = f.not_supported[r.model][r.config];
            if (sides.find(r.side) == std::string::npos) {
                sides += r.side;
                std::sort(sides.begin(), sides.end());
            }
        }
    }
    for (const std::string& g : group_names) {
        GroupFindings gf;
        gf.name = g;
        gf.configurations = configs_in[g];
        for (const std::string& m : models)
            gf.models[m] = acc[g][m].result();
        gf.ranking = rank(models, gf.models);
        f.groups.push_back(std::move(gf));
    }
}

// Like for like: the ranking of the configurations whose BRDF every model supports.
void find_common(const std::vector<StudyConfiguration>& configs,
                 const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                 const PerConfig& per_config, StudyFindings& f) {
    // The overall ranking above averages each model over the configurations it
    // supports, so a model that skips the hard ones (Belcour's have no Lambertian base) looks
    // better than it is. This one averages the BRDF rows of the configurations whose BRDF every
    // model supports. When no configuration is supported by all (a model made for one category
    // only, such as ddb22's Lambertian bases), the model supporting the fewest configurations is
    // left out, then the next, until some configurations are common; the summary names them.
    auto supports_r = [&](const std::string& m, const std::string& id) {
        const auto it = per_config.find(id);
        const bool unsupported_r = f.not_supported.count(m) && f.not_supported.at(m).count(id) &&
                                   f.not_supported.at(m).at(id).find('R') != std::string::npos;
        return it != per_config.end() && it->second.count(m) && it->second.at(m).n_mf > 0 &&
               !unsupported_r;
    };
    std::vector<std::string> compared = models;
    std::set<std::string> common;
    while (!compared.empty()) {
        common.clear();
        for (const StudyConfiguration& c : configs) {
            bool all = true;
            for (const std::string& m : compared)
                all = all && supports_r(m, c.id);
            if (all) common.insert(c.id);
        }
        if (!common.empty() || compared.size() <= 2) break;
        // The model with the fewest supported BRDFs (the last such in the study's order).
        std::size_t fewest = 0;
        int fewest_n = -1;
        for (std::size_t k = 0; k < compared.size(); ++k) {
            int n = 0;
            for (const StudyConfiguration& c : configs)
                n += supports_r(compared[k], c.id);
            if (fewest_n < 0 || n <= fewest_n) {
                fewest_n = n;
                fewest = k;
            }
        }
        f.common.left_out.push_back(compared[fewest]);
        compared.erase(compared.begin() + long(fewest));
    }
    if (common.empty()) f.common.left_out.clear();
    std::map<std::string, Accumulator> acc_common;
    for (const MetricRow& r : rows)
        if (r.side == 'R' && common.count(r.config) &&
            std::find(compared.begin(), compared.end(), r.model) != compared.end())
            acc_common[r.model].add(r);
    for (const StudyConfiguration& c : configs)
        if (common.count(c.id)) f.common.ids.push_back(c.id);
    std::sort(f.common.ids.begin(), f.common.ids.end());
    for (const std::string& m : compared)
        f.common.models[m] = acc_common[m].result();
    if (!common.empty()) f.common.ranking = rank(compared, f.common.models, true);
}

// What the reference itself drops to its single-scattering microsurfaces, per category: the mean
// over configurations, incidences and channels, and the worst.
void find_reference_loss(const std::vector<StudyConfiguration>& configs,
                         const SimulationSettings& reference, const ReferenceLoss& lost,
                         StudyFindings& f) {
    std::map<std::string, std::pair<double, int>> loss_sum;
    for (const StudyConfiguration& c : configs) {
        const auto it = lost.find(c.id);
        if (it == lost.end()) continue;
        const std::vector<StudyIncidence> incidences = study_incidences(c.stack, reference);
        for (std::size_t i = 0; i < it->second.size() && i < incidences.size(); ++i)
            for (int ch = 0; ch < 3; ++ch) {
                const double v = it->second[i][ch];
                for (const std::string& g : {c.category, std::string("all")}) {
                    auto& [sum, n] = loss_sum[g];
                    LossFindings& l = f.reference_loss[g];
                    if (n == 0 || v > l.worst) {
                        l.worst = v;
                        l.worst_at = {c.id, incidences[i].theta_i, 'R', ch, incidences[i].phi_i};
                    }
                    sum += v;
                    ++n;
                    l.mean = sum / n;
                }
            }
    }
}

// Challenging cases: the best supporting model still misplaces > threshold on average.
void find_challenging(const std::vector<StudyConfiguration>& configs,
                      const std::vector<std::string>& models, PerConfig& per_config,
                      StudyFindings& f) {
    for (const StudyConfiguration& c : configs) {
        ChallengingCase best;
        double best_mf = std::numeric_limits<double>::infinity();
        for (const std::string& m : models) {
            const ModelAggregate a = per_config[c.id][m].result();
            if (a.rows > 0 && a.mean_misplaced_floor < best_mf) {
                best_mf = a.mean_misplaced_floor;
                best = {c.id, m, a.mean_misplaced_floor, a.mean_misplaced_floor_noise,
                        a.mean_misplaced_energy};
            }
        }
        // Noise-dominated configurations are not flagged: the best model must also be clearly
        // (2×) above the reference's noise floor.
        if (!best.best_model.empty() && best_mf > kChallengingThreshold &&
            !(best_mf <= 2 * best.mean_misplaced_floor_noise))
            f.challenging.push_back(best);
    }
}

// The approximations assessment: each factor's levels, each model's errors at each.
void find_assessment(const std::vector<StudyConfiguration>& configs,
                     const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                     StudyFindings& f) {
    std::map<std::string, const StudyConfiguration*> by_id;
    for (const StudyConfiguration& c : configs)
        by_id[c.id] = &c;
    const std::vector<Factor> factors = assessment_factors(by_id);
    for (const Factor& factor : factors) {
        std::map<std::string, std::vector<Accumulator>> level_acc;
        for (const std::string& m : models)
            level_acc[m].resize(factor.levels.size());
        for (const MetricRow& r : rows)
            if (r.side == 'R' && level_acc.count(r.model))
                for (std::size_t l = 0; l < factor.levels.size(); ++l)
                    if (factor.levels[l].second(r)) level_acc[r.model][l].add(r);
        FactorFindings ff;
        ff.title = factor.title;
        ff.explanation = factor.explanation;
        for (const auto& level : factor.levels)
            ff.levels.push_back(level.first);
        for (const std::string& m : models)
            for (const Accumulator& a : level_acc[m])
                ff.models[m].push_back(a.result());
        f.assessment.push_back(std::move(ff));
    }
}

}  // namespace

StudyFindings compute_findings(const std::vector<StudyConfiguration>& configs,
                               const StudySettings& s, const std::vector<std::string>& models,
                               const std::vector<MetricRow>& rows, const ReferenceLoss& lost) {
    StudyFindings f;
    f.preset = s.preset;
    f.particles = s.reference.particles;
    f.microsurface = enum_text(s.reference.transport.microsurface);
    f.physics = physics_name(s.reference.transport);
    f.polarization = s.reference.transport.polarization;
    f.theta_i = s.reference.theta_i_deg;
    f.grid = s.reference.grid.to_string();
    f.models = models;
    f.configurations = configs.size();
    PerConfig per_config;
    find_groups(configs, models, rows, f, per_config);
    find_common(configs, models, rows, per_config, f);
    find_reference_loss(configs, s.reference, lost, f);
    find_challenging(configs, models, per_config, f);
    find_assessment(configs, models, rows, f);
    // For engine developers (study/engine_findings.h): computed from the same rows.
    f.engine = compute_engine_findings(rows, models);
    return f;
}

// ==== Writing the findings =======================================================================
//
// Each section of summary.json and summary.md is one function of the findings; the tables below
// list them in order. A new section of StudyFindings gets its writers here.

namespace {

nlohmann::json place_json(const std::optional<RowPlace>& p, bool with_side = true) {
    if (!p) return nullptr;
    nlohmann::json j = {{"config", p->config}, {"theta_i", p->theta_i}};
    if (p->phi_i != 0) j["phi_i"] = p->phi_i;
    if (with_side) j["side"] = std::string(1, p->side);
    j["channel"] = kChannelNames[p->channel];
    return j;
}

nlohmann::json aggregate_json(const ModelAggregate& a) {
    return {{"mean_misplaced_floor", json_number(a.mean_misplaced_floor)},
            {"worst_misplaced_floor", json_number(a.worst_misplaced_floor)},
            {"worst_misplaced_floor_at", place_json(a.worst_misplaced_floor_at)},
            {"mean_misplaced_floor_noise", json_number(a.mean_misplaced_floor_noise)},
            {"mean_misplaced_energy", json_number(a.mean_misplaced_energy)},
            {"worst_misplaced_energy", json_number(a.worst_misplaced_energy)},
            {"worst_misplaced_energy_at", place_json(a.worst_misplaced_energy_at)},
            {"mean_abs_albedo_error", json_number(a.mean_abs_albedo_error)},
            {"worst_albedo_error", json_number(a.worst_albedo_error)},
            {"worst_albedo_error_at", place_json(a.worst_albedo_error_at)},
            {"mean_noise_floor", json_number(a.mean_noise_floor)},
            {"configurations_supported", a.configurations_supported}};
}

void json_header(const StudyFindings& f, nlohmann::json& j) {
    j["lamina_version"] = kVersion;
    j["preset"] = f.preset;
    j["particles"] = f.particles;
    j["microsurface"] = f.microsurface;
    j["physics"] = f.physics;
    j["polarization"] = f.polarization;
    j["theta_i"] = f.theta_i;
    j["grid"] = f.grid;
    j["models"] = f.models;
    j["ranking_metric"] = "misplaced_floor";
    j["misplaced_floor_energy"] = kMisplacedFloorEnergy;
    j["challenging_threshold"] = kChallengingThreshold;
}

void json_groups(const StudyFindings& f, nlohmann::json& j) {
    for (const GroupFindings& g : f.groups) {
        j["groups"][g.name]["configurations"] = g.configurations;
        for (const auto& [m, a] : g.models)
            j["groups"][g.name]["models"][m] = aggregate_json(a);
        j["groups"][g.name]["ranking"] = g.ranking;
    }
}

void json_common(const StudyFindings& f, nlohmann::json& j) {
    j["common"]["configurations"] = f.common.ids.size();
    j["common"]["ids"] = f.common.ids;
    j["common"]["ranking"] = f.common.ranking;
    j["common"]["left_out"] = f.common.left_out;
    for (const auto& [m, a] : f.common.models)
        j["common"]["models"][m] = {
            {"mean_misplaced_floor", json_number(a.mean_misplaced_floor)},
            {"mean_misplaced_floor_noise", json_number(a.mean_misplaced_floor_noise)},
            {"mean_misplaced_energy", json_number(a.mean_misplaced_energy)},
            {"mean_noise_floor", json_number(a.mean_noise_floor)}};
}

void json_loss(const StudyFindings& f, nlohmann::json& j) {
    j["reference_lost_microsurface"] = nlohmann::json::object();
    for (const auto& [g, l] : f.reference_loss)
        j["reference_lost_microsurface"][g] = {
            {"mean", l.mean}, {"worst", l.worst}, {"worst_at", place_json(l.worst_at, false)}};
}

void json_challenging(const StudyFindings& f, nlohmann::json& j) {
    j["challenging"] = nlohmann::json::array();
    for (const ChallengingCase& c : f.challenging)
        j["challenging"].push_back(
            {{"config", c.config},
             {"best_model", c.best_model},
             {"best_mean_misplaced_floor", json_number(c.best_mean_misplaced_floor)},
             {"mean_misplaced_floor_noise", json_number(c.mean_misplaced_floor_noise)},
             {"best_mean_misplaced_energy", json_number(c.best_mean_misplaced_energy)}});
}

void json_assessment(const StudyFindings& f, nlohmann::json& j) {
    j["assessment"] = nlohmann::json::array();
    for (const FactorFindings& ff : f.assessment) {
        nlohmann::json fj;
        fj["factor"] = ff.title;
        fj["levels"] = ff.levels;
        for (const auto& [m, levels] : ff.models)
            for (const ModelAggregate& a : levels) {
                fj["mean_misplaced_floor"][m].push_back(json_number(a.mean_misplaced_floor));
                fj["mean_misplaced_energy"][m].push_back(json_number(a.mean_misplaced_energy));
            }
        j["assessment"].push_back(fj);
    }
}

void json_not_supported(const StudyFindings& f, nlohmann::json& j) {
    j["not_supported"] = nlohmann::json::object();
    for (const auto& [m, cfgs] : f.not_supported)
        for (const auto& [cfg, sides] : cfgs)
            j["not_supported"][m][cfg] = sides;
}

// summary.json, section by section.
using JsonSection = void (*)(const StudyFindings&, nlohmann::json&);
void json_engine(const StudyFindings& f, nlohmann::json& j) {
    if (!f.engine.empty()) j["engine_developers"] = engine_findings_json(f.engine);
}

constexpr JsonSection kJsonSections[] = {json_header,        json_groups,      json_common,
                                         json_loss,          json_challenging, json_assessment,
                                         json_not_supported, json_engine};

// ---- summary.md ----

std::string where(const std::optional<RowPlace>& p) {
    if (!p) return "";
    const std::string phi = p->phi_i != 0 ? fmt::format(", φi {}°", p->phi_i) : "";
    return fmt::format("{}, θi {}°{}, {}, {}", p->config, p->theta_i, phi, p->side,
                       kChannelNames[p->channel]);
}

struct Markdown {
    std::string text;
    template <typename... A>
    void operator()(fmt::format_string<A...> format, A&&... args) {
        fmt::format_to(std::back_inserter(text), format, std::forward<A>(args)...);
    }
};

bool is_total(const std::string& group) {
    return group == "all" || group == "all BTDF";
}

void md_header(const StudyFindings& f, Markdown& out) {
    out("# lamina study: which layered model, for which material, how wrong\n\n");
    const char* which = f.physics == "exact"   ? "the exact reference"
                        : f.physics == "bpb19" ? "the 2019 study's reference (`--physics bpb19`)"
                                               : "a mixed reference";
    out("Preset `{}`: {:.3g} particles per incidence (two independent halves), incidences {}°, "
        "{} bins, {} configurations, models {}. Against {}: light {}, and rough interfaces that "
        "{}. How much of each model's error the exact reference's two corrections account for "
        "is measured in docs/models.md (\"Against which reference?\"). lamina {}.\n\n",
        f.preset, double(f.particles), fmt::join(f.theta_i, "°, "), f.grid, f.configurations,
        fmt::join(f.models, ", "), which,
        f.polarization ? "polarized at every event (Stokes vectors through Mueller matrices)"
                       : "unpolarized at every event (the mean of the s and p Fresnel factors)",
        f.microsurface == "multiple"
            ? "scatter multiply on their microsurfaces (Heitz et al. 2016: nothing is lost there)"
            : "scatter once on their microsurfaces (the masked energy is lost and reported)",
        kVersion);
    out("The primary metric is the **misplaced energy**: the energy a model puts in the wrong "
        "place, adds or removes, as a fraction of the reference's reflected (or transmitted) "
        "energy — or of {} of the incident light where the reference holds less (0 is perfect; "
        "`misplaced_floor`, so that a lobe holding almost nothing cannot dominate a mean). "
        "Models are ranked by it; the purely relative misplaced energy is shown beside it. "
        "Every number is next to the reference's **noise floor** — what Monte-Carlo noise alone "
        "would show for a perfect model; differences below it mean nothing.\n\n",
        percent_text(kMisplacedFloorEnergy));
}

void md_findings(const StudyFindings& f, Markdown& out) {
    out("## Findings\n\n");
    for (const GroupFindings& g : f.groups) {
        if (is_total(g.name)) continue;
        const auto& rk = g.ranking;
        if (rk.empty()) {
            out("- **{}** ({} configurations): no model supports it.\n", g.name, g.configurations);
            continue;
        }
        // A model's mean covers the configurations it supports: say so where that is not all of
        // them, and name the best model that covers all (a mean over an easier subset is not
        // a recommendation for the category).
        auto covered = [&](const std::string& m) {
            return int(g.models.at(m).configurations_supported) >= g.configurations;
        };
        auto coverage = [&](const std::string& m) {
            return covered(m) ? std::string()
                              : fmt::format(", {} of {}", g.models.at(m).configurations_supported,
                                            g.configurations);
        };
        const ModelAggregate& best = g.models.at(rk.front());
        out("- **{}** ({} configuration{}): use **{}**{} — mean misplaced energy {} (noise floor "
            "{}; relative {}), worst {} ({}); mean |albedo error| {}.",
            g.name, g.configurations, g.configurations == 1 ? "" : "s", rk.front(),
            covered(rk.front()) ? ""
                                : fmt::format(" (on the {} of {} configurations it supports)",
                                              best.configurations_supported, g.configurations),
            percent_text(best.mean_misplaced_floor), percent_text(best.mean_misplaced_floor_noise),
            percent_text(best.mean_misplaced_energy), percent_text(best.worst_misplaced_floor),
            where(best.worst_misplaced_floor_at), percent_text(best.mean_abs_albedo_error));
        if (!covered(rk.front()))
            for (const std::string& m : rk)
                if (covered(m)) {
                    out(" Of the models that support all {}: **{}** ({}).", g.configurations, m,
                        percent_text(g.models.at(m).mean_misplaced_floor));
                    break;
                }
        if (rk.size() > 1) {
            out(" Then ");
            for (std::size_t k = 1; k < rk.size(); ++k)
                out("{}{} ({}{})", k > 1 ? ", " : "", rk[k],
                    percent_text(g.models.at(rk[k]).mean_misplaced_floor), coverage(rk[k]));
            out(".");
        }
        std::vector<std::string> none;
        for (const std::string& m : f.models)
            if (g.models.at(m).rows == 0) none.push_back(m);
        if (!none.empty()) out(" Not supported: {}.", fmt::join(none, ", "));
        out("\n");
    }
    auto chain = [](const std::vector<std::string>& ranking,
                    const std::map<std::string, ModelAggregate>& models) {
        std::string t;
        for (std::size_t k = 0; k < ranking.size(); ++k)
            t += fmt::format("{}{} {}", k ? " < " : "", ranking[k],
                             percent_text(models.at(ranking[k]).mean_misplaced_floor));
        return t;
    };
    if (const GroupFindings* all = f.group("all"); all && !all->ranking.empty()) {
        std::string t;
        for (std::size_t k = 0; k < all->ranking.size(); ++k) {
            const ModelAggregate& a = all->models.at(all->ranking[k]);
            t += fmt::format("{}{} {}", k ? " < " : "", all->ranking[k],
                             percent_text(a.mean_misplaced_floor));
            if (int(a.configurations_supported) < all->configurations)
                t += fmt::format(" ({} of {})", a.configurations_supported, all->configurations);
        }
        out("- **Overall**: {} (mean misplaced energy over the configurations each supports; "
            "\"of\": how many).\n",
            t);
    }
    if (f.models.size() > 1) {
        if (f.common.ranking.empty())
            out("- **Like for like**: no configuration's BRDF is supported by every model.\n");
        else
            out("- **Like for like** (the BRDF of the {} configuration{} every model{} "
                "supports): {}.\n",
                f.common.ids.size(), f.common.ids.size() == 1 ? "" : "s",
                f.common.left_out.empty() ? std::string()
                                          : fmt::format(" but {} (made for fewer configurations)",
                                                        fmt::join(f.common.left_out, ", ")),
                chain(f.common.ranking, f.common.models));
    }
    // Said when it matters (a multiple-scattering reference loses only the rare walk it gives up).
    if (f.reference_loss.count("all") && f.reference_loss.at("all").worst >= 1e-3) {
        std::string per_category;
        for (const std::string& c : f.categories)
            if (f.reference_loss.count(c))
                per_category += fmt::format("{}{} {}", per_category.empty() ? "" : ", ", c,
                                            percent_text(f.reference_loss.at(c).mean));
        const LossFindings& l = f.reference_loss.at("all");
        out("- **What the reference itself drops**: its single-scattering microfacet interfaces "
            "lose, on average over incidences and channels, {} of the incident energy (worst {}: "
            "{}, θi {}°, {}) — masked light, on neither side of the reference. A model that keeps "
            "this energy overshoots the reference's albedo by up to that much; where it belongs "
            "(R, T) is what multiple scattering on the microsurfaces would decide. The explorer's "
            "albedo view draws it.\n",
            per_category, percent_text(l.worst), l.worst_at.config, l.worst_at.theta_i,
            kChannelNames[l.worst_at.channel]);
    }
    std::string list;
    for (std::size_t k = 0; k < f.challenging.size(); ++k)
        list += fmt::format("{}`{}`", k ? ", " : "", f.challenging[k].config);
    out("- **Challenging cases** (even the best model misplaces more than {} of the reflected "
        "energy on average, and more than twice the noise floor): {}.\n\n",
        percent_text(kChallengingThreshold), list.empty() ? std::string("none") : list);
}

void md_tables(const StudyFindings& f, Markdown& out) {
    auto table = [&](const char* title, auto cell) {
        out("## {}\n\n| model |", title);
        for (const GroupFindings& g : f.groups)
            out(" {} |", g.name);
        out("\n|---|");
        for (std::size_t k = 0; k < f.groups.size(); ++k)
            out("---|");
        out("\n");
        for (const std::string& m : f.models) {
            out("| {} |", m);
            for (const GroupFindings& g : f.groups)
                out(" {} |", cell(g.models.at(m), g));
            out("\n");
        }
        out("\n");
    };
    table("Misplaced energy (5% floor, the ranking metric): mean / worst (noise floor)",
          [](const ModelAggregate& a, const GroupFindings&) {
              return a.rows ? fmt::format("{} / {} ({})", percent_text(a.mean_misplaced_floor),
                                          percent_text(a.worst_misplaced_floor),
                                          percent_text(a.mean_misplaced_floor_noise))
                            : std::string("not supported");
          });
    table("Misplaced energy (relative to the reference's energy): mean / worst (noise floor)",
          [](const ModelAggregate& a, const GroupFindings&) {
              return a.rows ? fmt::format("{} / {} ({})", percent_text(a.mean_misplaced_energy),
                                          percent_text(a.worst_misplaced_energy),
                                          percent_text(a.mean_noise_floor))
                            : std::string("not supported");
          });
    table("Albedo error: mean |error| / worst", [](const ModelAggregate& a, const GroupFindings&) {
        return std::isfinite(a.mean_abs_albedo_error)
                   ? fmt::format("{} / {:+.1f}%", percent_text(a.mean_abs_albedo_error),
                                 100 * a.worst_albedo_error)
                   : std::string("not supported");
    });
    table("Coverage: configurations supported",
          [](const ModelAggregate& a, const GroupFindings& g) {
              return fmt::format("{}/{}", a.configurations_supported, g.configurations);
          });
}

void md_worst(const StudyFindings& f, Markdown& out) {
    out("## Worst cases\n\n| model | group | worst misplaced energy (5% floor) | where | worst "
        "relative | where |\n|---|---|---|---|---|---|\n");
    for (const std::string& m : f.models)
        for (const GroupFindings& g : f.groups)
            if (!is_total(g.name) && g.models.at(m).rows) {
                const ModelAggregate& a = g.models.at(m);
                out("| {} | {} | {} | {} | {} | {} |\n", m, g.name,
                    percent_text(a.worst_misplaced_floor), where(a.worst_misplaced_floor_at),
                    percent_text(a.worst_misplaced_energy), where(a.worst_misplaced_energy_at));
            }
    out("\n");
}

void md_challenging(const StudyFindings& f, Markdown& out) {
    out("## Challenging cases\n\nConfigurations where even the best supporting model misplaces "
        "more than {} of the reflected energy (5% floor) on average over incidences and "
        "channels, and more than twice the reference's noise floor.\n\n",
        percent_text(kChallengingThreshold));
    if (f.challenging.empty()) {
        out("None.\n\n");
        return;
    }
    out("| configuration | best model | its mean misplaced energy (5% floor) | noise floor | "
        "relative |\n|---|---|---|---|---|\n");
    for (const ChallengingCase& c : f.challenging)
        out("| {} | {} | {} | {} | {} |\n", c.config, c.best_model,
            percent_text(c.best_mean_misplaced_floor), percent_text(c.mean_misplaced_floor_noise),
            percent_text(c.best_mean_misplaced_energy));
    out("\n");
}

void md_assessment(const StudyFindings& f, Markdown& out) {
    out("## Approximations assessment\n\nMean misplaced energy (5% floor) of each model's BRDF, "
        "rows grouped by the factor that stresses an approximation (as in the original study's "
        "assessment); in parentheses the noise floor.\n\n");
    for (const FactorFindings& ff : f.assessment) {
        out("### {}\n\n{}\n\n| model |", ff.title, ff.explanation);
        for (const std::string& level : ff.levels)
            out(" {} |", level);
        out("\n|---|");
        for (std::size_t l = 0; l < ff.levels.size(); ++l)
            out("---|");
        out("\n");
        for (const std::string& m : f.models) {
            out("| {} |", m);
            for (const ModelAggregate& a : ff.models.at(m))
                out(" {} |", a.rows ? fmt::format("{} ({})", percent_text(a.mean_misplaced_floor),
                                                  percent_text(a.mean_misplaced_floor_noise))
                                    : std::string("–"));
            out("\n");
        }
        out("\n");
    }
}

void md_engine(const StudyFindings& f, Markdown& out) {
    out.text += engine_findings_markdown(f.engine);
}

void md_not_supported(const StudyFindings& f, Markdown& out) {
    out("## Not supported\n\n");
    if (f.not_supported.empty()) out("Every model supports every configuration.\n");
    for (const auto& [m, cfgs] : f.not_supported) {
        std::map<std::string, int> per_category;
        for (const auto& [cfg, sides] : cfgs) {
            const auto it = f.category_of.find(cfg);
            const std::string category = it == f.category_of.end() ? cfg : it->second;
            per_category[category + (sides.find('R') != std::string::npos ? "" : " (BTDF)")]++;
        }
        out("- **{}**:", m);
        bool first = true;
        for (const auto& [cat, n] : per_category) {
            out("{} {} × {}", first ? "" : ",", n, cat);
            first = false;
        }
        out(" (see `configs/<id>/config.json` → `supported` for the reasons).\n");
    }
    out("\nDefinitions, formats and the noise floor: `docs/formats.md`. Per-row numbers: "
        "`metrics.csv`.\n");
}

// summary.md, section by section.
using MarkdownSection = void (*)(const StudyFindings&, Markdown&);
constexpr MarkdownSection kMarkdownSections[] = {md_header, md_findings,     md_tables,
                                                 md_worst,  md_challenging,  md_assessment,
                                                 md_engine, md_not_supported};

}  // namespace

nlohmann::json findings_json(const StudyFindings& f) {
    nlohmann::json j;
    for (JsonSection section : kJsonSections)
        section(f, j);
    return j;
}

std::string findings_markdown(const StudyFindings& f) {
    Markdown out;
    for (MarkdownSection section : kMarkdownSections)
        section(f, out);
    return out.text;
}

std::string findings_headline(const StudyFindings& f) {
    Markdown out;
    md_findings(f, out);
    return out.text;
}

int write_summary(const std::filesystem::path& out_dir, const StudyFindings& f) {
    int written = 0;
    written += write_file_if_changed(out_dir / "summary.json", findings_json(f).dump(1) + "\n");
    written += write_file_if_changed(out_dir / "summary.md", findings_markdown(f));
    return written;
}

}  // namespace lamina

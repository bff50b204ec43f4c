#include "study/summary.h"

#include "core/atomic_file.h"
#include "lamina/version.h"
#include "study/engine_findings.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>

namespace lamina {

namespace {

constexpr const char* kChannels[3] = {"r", "g", "b"};

// Mean and worst of the supported rows of one (group, model).
struct Aggregate {
    double sum_e = 0, sum_abs_albedo = 0, sum_floor = 0;
    int n = 0, n_albedo = 0;
    double worst_e = -1;
    const MetricRow* worst_e_row = nullptr;
    double worst_albedo = 0;
    const MetricRow* worst_albedo_row = nullptr;
    std::set<std::string> configs;

    void add(const MetricRow& r) {
        if (!r.supported || !std::isfinite(r.metrics.misplaced_energy)) return;
        sum_e += r.metrics.misplaced_energy;
        sum_floor += std::isfinite(r.floor.misplaced_energy) ? r.floor.misplaced_energy : 0;
        ++n;
        configs.insert(r.config);
        if (r.metrics.misplaced_energy > worst_e) {
            worst_e = r.metrics.misplaced_energy;
            worst_e_row = &r;
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
    double mean_e() const { return n ? sum_e / n : NAN; }
    double mean_floor() const { return n ? sum_floor / n : NAN; }
    double mean_abs_albedo() const { return n_albedo ? sum_abs_albedo / n_albedo : NAN; }
};

std::string pct(double v) {
    if (!std::isfinite(v)) return "–";
    return fmt::format("{:.1f}%", 100 * v);
}

std::string where(const MetricRow* r) {
    if (!r) return "";
    return fmt::format("{}, θi {}°, {}, {}", r->config, r->theta_i, r->side, kChannels[r->channel]);
}

nlohmann::json where_json(const MetricRow* r) {
    if (!r) return nullptr;
    return {{"config", r->config},
            {"theta_i", r->theta_i},
            {"side", std::string(1, r->side)},
            {"channel", kChannels[r->channel]}};
}

nlohmann::json num(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
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

}  // namespace

void write_summary(const std::filesystem::path& out_dir,
                   const std::vector<StudyConfiguration>& configs, const StudySettings& s,
                   const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                   const ReferenceLoss& lost) {
    std::map<std::string, const StudyConfiguration*> by_id;
    std::vector<std::string> categories;
    std::map<std::string, int> configs_in;
    bool any_transmission = false;
    for (const StudyConfiguration& c : configs) {
        by_id[c.id] = &c;
        if (std::find(categories.begin(), categories.end(), c.category) == categories.end())
            categories.push_back(c.category);
        ++configs_in[c.category];
        ++configs_in["all"];
        if (c.stack.transmits()) {
            ++configs_in[c.category + " BTDF"];
            ++configs_in["all BTDF"];
            any_transmission = true;
        }
    }
    // Groups: each category's BRDF, then the BTDF of the categories that transmit (a model's
    // reflection and transmission errors are never averaged together: most models have no BTDF).
    std::vector<std::string> groups = categories;
    for (const std::string& c : categories)
        if (configs_in.count(c + " BTDF")) groups.push_back(c + " BTDF");
    groups.push_back("all");
    if (any_transmission) groups.push_back("all BTDF");
    auto group_of = [](const MetricRow& r) {
        return r.side == 'T' ? r.category + " BTDF" : r.category;
    };

    // Aggregates per (group, model).
    std::map<std::string, std::map<std::string, Aggregate>> agg;
    for (const MetricRow& r : rows) {
        agg[group_of(r)][r.model].add(r);
        agg[r.side == 'T' ? "all BTDF" : "all"][r.model].add(r);
    }

    // Per configuration and model: the mean misplaced energy; support.
    std::map<std::string, std::map<std::string, Aggregate>> per_config;
    std::map<std::string, std::map<std::string, std::set<char>>> unsupported;
    for (const MetricRow& r : rows) {
        if (r.side == 'R') per_config[r.config][r.model].add(r);  // challenging: the BRDF
        if (!r.supported) unsupported[r.model][r.config].insert(r.side);
    }

    // Rankings: models by mean misplaced energy within each group (supported rows only).
    std::map<std::string, std::vector<std::string>> ranking;
    for (const std::string& g : groups) {
        std::vector<std::string> ranked;
        for (const std::string& m : models)
            if (agg[g][m].n > 0) ranked.push_back(m);
        std::stable_sort(ranked.begin(), ranked.end(), [&](const auto& a, const auto& b) {
            return agg[g][a].mean_e() < agg[g][b].mean_e();
        });
        ranking[g] = ranked;
    }

    // Like for like: the overall ranking above averages each model over the configurations it
    // supports, so a model that skips the hard ones (Belcour's have no Lambertian base) looks
    // better than it is. This one averages the BRDF rows of the configurations whose BRDF every
    // model supports.
    std::set<std::string> common;
    for (const StudyConfiguration& c : configs) {
        bool all = !models.empty();
        for (const std::string& m : models) {
            const auto it = per_config.find(c.id);
            if (it == per_config.end() || !it->second.count(m) || it->second.at(m).n == 0 ||
                (unsupported.count(m) && unsupported.at(m).count(c.id) &&
                 unsupported.at(m).at(c.id).count('R')))
                all = false;
        }
        if (all) common.insert(c.id);
    }
    std::map<std::string, Aggregate> agg_common;
    for (const MetricRow& r : rows)
        if (r.side == 'R' && common.count(r.config)) agg_common[r.model].add(r);
    std::vector<std::string> ranking_common;
    if (!common.empty()) {
        ranking_common = models;
        std::stable_sort(ranking_common.begin(), ranking_common.end(),
                         [&](const auto& a, const auto& b) {
                             return agg_common[a].mean_e() < agg_common[b].mean_e();
                         });
    }

    // What the reference itself drops to its single-scattering microsurfaces, per category: the
    // mean over configurations, incidences and channels, and the worst.
    struct Loss {
        double sum = 0, worst = -1;
        int n = 0;
        std::string worst_config;
        double worst_theta_i = 0;
        int worst_channel = 0;
    };
    std::map<std::string, Loss> loss;
    for (const StudyConfiguration& c : configs) {
        const auto it = lost.find(c.id);
        if (it == lost.end()) continue;
        for (std::size_t i = 0; i < it->second.size() && i < s.theta_i_deg.size(); ++i)
            for (int ch = 0; ch < 3; ++ch) {
                const double v = it->second[i][ch];
                for (const std::string& g : {c.category, std::string("all")}) {
                    Loss& l = loss[g];
                    l.sum += v;
                    ++l.n;
                    if (v > l.worst) {
                        l.worst = v;
                        l.worst_config = c.id;
                        l.worst_theta_i = s.theta_i_deg[i];
                        l.worst_channel = ch;
                    }
                }
            }
    }

    // Challenging cases: the best supporting model still misplaces > threshold on average.
    struct Challenge {
        std::string config, best;
        double best_e, floor;
    };
    std::vector<Challenge> challenging;
    for (const StudyConfiguration& c : configs) {
        std::string best;
        double best_e = std::numeric_limits<double>::infinity();
        double floor = NAN;
        for (const std::string& m : models) {
            const Aggregate& a = per_config[c.id][m];
            if (a.n > 0 && a.mean_e() < best_e) {
                best_e = a.mean_e();
                best = m;
                floor = a.mean_floor();
            }
        }
        // Noise-dominated configurations are not flagged: the best model must also be clearly
        // (2×) above the reference's noise floor.
        if (!best.empty() && best_e > kChallengingThreshold && !(best_e <= 2 * floor))
            challenging.push_back({c.id, best, best_e, floor});
    }

    // The approximations assessment.
    auto config_of = [&](const MetricRow& r) { return by_id.at(r.config); };
    const std::vector<Factor> factors = {
        {"Coat roughness (transmission through the top interface)",
         "Rows grouped by the top interface's roughness α0. The WW family refracts through a "
         "single normal; Belcour's operators approximate rough transmission by lobe statistics.",
         {{"smooth coat (α0 ≤ 0.05)",
           [&](const MetricRow& r) { return parameter(*config_of(r), "alpha0") <= 0.05; }},
          {"rough coat (α0 ≥ 0.3)",
           [&](const MetricRow& r) { return parameter(*config_of(r), "alpha0") >= 0.3; }}}},
        {"Base albedo (multiple bounces between base and coat)",
         "Lambertian bases, per channel: a low albedo leaves mostly the first bounce, a high "
         "albedo needs every inter-reflection (models without them fall short).",
         {{"low (ρ ≤ 0.2)",
           [&](const MetricRow& r) {
               const auto& c = *config_of(r);
               return c.stack.base().type == InterfaceType::Lambertian &&
                      c.stack.base().albedo[r.channel] <= 0.2;
           }},
          {"high (ρ ≥ 0.5)",
           [&](const MetricRow& r) {
               const auto& c = *config_of(r);
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
    std::vector<std::map<std::string, std::vector<Aggregate>>> assessment(factors.size());
    for (std::size_t f = 0; f < factors.size(); ++f)
        for (const std::string& m : models)
            assessment[f][m].resize(factors[f].levels.size());
    for (const MetricRow& r : rows)
        if (r.side == 'R')
            for (std::size_t f = 0; f < factors.size(); ++f)
                for (std::size_t l = 0; l < factors[f].levels.size(); ++l)
                    if (factors[f].levels[l].second(r)) assessment[f][r.model][l].add(r);

    // ---- summary.json ----
    nlohmann::json j;
    j["lamina_version"] = kVersion;
    j["preset"] = s.preset;
    j["particles"] = s.particles;
    j["microsurface"] = microsurface_name(s.microsurface);
    j["theta_i"] = s.theta_i_deg;
    j["grid"] = s.grid.to_string();
    j["models"] = models;
    j["challenging_threshold"] = kChallengingThreshold;
    for (const std::string& g : groups) {
        for (const std::string& m : models) {
            const Aggregate& a = agg[g][m];
            j["groups"][g]["configurations"] = configs_in[g];
            j["groups"][g]["models"][m] = {
                {"mean_misplaced_energy", num(a.mean_e())},
                {"worst_misplaced_energy", num(a.n ? a.worst_e : NAN)},
                {"worst_misplaced_energy_at", where_json(a.worst_e_row)},
                {"mean_abs_albedo_error", num(a.mean_abs_albedo())},
                {"worst_albedo_error", num(a.n_albedo ? a.worst_albedo : NAN)},
                {"worst_albedo_error_at", where_json(a.worst_albedo_row)},
                {"mean_noise_floor", num(a.mean_floor())},
                {"configurations_supported", a.configs.size()}};
        }
        j["groups"][g]["ranking"] = ranking[g];
    }
    j["common"]["configurations"] = common.size();
    j["common"]["ids"] = common;
    j["common"]["ranking"] = ranking_common;
    for (const std::string& m : models)
        j["common"]["models"][m] = {{"mean_misplaced_energy", num(agg_common[m].mean_e())},
                                    {"mean_noise_floor", num(agg_common[m].mean_floor())}};
    j["reference_lost_microsurface"] = nlohmann::json::object();
    for (const auto& [g, l] : loss)
        j["reference_lost_microsurface"][g] = {{"mean", l.sum / l.n},
                                               {"worst", l.worst},
                                               {"worst_at",
                                                {{"config", l.worst_config},
                                                 {"theta_i", l.worst_theta_i},
                                                 {"channel", kChannels[l.worst_channel]}}}};
    j["challenging"] = nlohmann::json::array();
    for (const Challenge& c : challenging)
        j["challenging"].push_back({{"config", c.config},
                                    {"best_model", c.best},
                                    {"best_mean_misplaced_energy", c.best_e},
                                    {"mean_noise_floor", num(c.floor)}});
    for (std::size_t f = 0; f < factors.size(); ++f) {
        nlohmann::json fj;
        fj["factor"] = factors[f].title;
        for (std::size_t l = 0; l < factors[f].levels.size(); ++l) {
            fj["levels"].push_back(factors[f].levels[l].first);
            for (const std::string& m : models)
                fj["mean_misplaced_energy"][m].push_back(num(assessment[f][m][l].mean_e()));
        }
        j["assessment"].push_back(fj);
    }
    j["not_supported"] = nlohmann::json::object();
    for (const auto& [m, cfgs] : unsupported)
        for (const auto& [cfg, sides] : cfgs) {
            std::string side_list;
            for (char c : sides)
                side_list += c;
            j["not_supported"][m][cfg] = side_list;
        }

    // ---- summary.md ----
    std::string md;
    auto out = [&]<typename... A>(fmt::format_string<A...> format, A&&... args) {
        fmt::format_to(std::back_inserter(md), format, std::forward<A>(args)...);
    };
    out("# lamina study: which layered model, for which material, how wrong\n\n");
    out("Preset `{}`: {:.3g} particles per incidence (two independent halves), incidences {}°, "
        "{} bins, {} configurations, models {}; the reference's rough interfaces {}. lamina "
        "{}.\n\n",
        s.preset, double(s.particles), fmt::join(s.theta_i_deg, "°, "), s.grid.to_string(),
        configs.size(), fmt::join(models, ", "),
        s.microsurface == Microsurface::Multiple
            ? "scatter multiply on their microsurfaces (Heitz et al. 2016: nothing is lost there)"
            : "scatter once on their microsurfaces (the masked energy is lost and reported)",
        kVersion);
    out("The primary metric is the **misplaced energy**: the fraction of the reference's reflected "
        "(or transmitted) energy a model puts in the wrong place, adds or removes (0 is perfect). "
        "Every number is next to the reference's **noise floor** — what Monte-Carlo noise alone "
        "would show for a perfect model; differences below it mean nothing.\n\n");

    out("## Findings\n\n");
    for (const std::string& g : groups) {
        const auto& rk = ranking[g];
        if (g == "all" || g == "all BTDF") continue;
        if (rk.empty()) {
            out("- **{}** ({} configurations): no model supports it.\n", g, configs_in[g]);
            continue;
        }
        const Aggregate& best = agg[g][rk.front()];
        out("- **{}** ({} configuration{}): use **{}** — mean misplaced energy {} (noise floor "
            "{}), "
            "worst {} ({}); mean |albedo error| {}.",
            g, configs_in[g], configs_in[g] == 1 ? "" : "s", rk.front(), pct(best.mean_e()),
            pct(best.mean_floor()), pct(best.worst_e), where(best.worst_e_row),
            pct(best.mean_abs_albedo()));
        if (rk.size() > 1) {
            out(" Then ");
            for (std::size_t k = 1; k < rk.size(); ++k)
                out("{}{} ({})", k > 1 ? ", " : "", rk[k], pct(agg[g][rk[k]].mean_e()));
            out(".");
        }
        std::vector<std::string> none;
        for (const std::string& m : models)
            if (agg[g][m].n == 0) none.push_back(m);
        if (!none.empty()) out(" Not supported: {}.", fmt::join(none, ", "));
        out("\n");
    }
    if (!ranking["all"].empty())
        out("- **Overall**: {}.\n", [&] {
            std::string t;
            for (std::size_t k = 0; k < ranking["all"].size(); ++k)
                t += fmt::format("{}{} {}", k ? " < " : "", ranking["all"][k],
                                 pct(agg["all"][ranking["all"][k]].mean_e()));
            return t + " (mean misplaced energy over the configurations each supports)";
        }());
    if (models.size() > 1) {
        if (ranking_common.empty())
            out("- **Like for like**: no configuration's BRDF is supported by every model.\n");
        else
            out("- **Like for like** (the BRDF of the {} configuration{} every model supports): "
                "{}.\n",
                common.size(), common.size() == 1 ? "" : "s", [&] {
                    std::string t;
                    for (std::size_t k = 0; k < ranking_common.size(); ++k)
                        t += fmt::format("{}{} {}", k ? " < " : "", ranking_common[k],
                                         pct(agg_common[ranking_common[k]].mean_e()));
                    return t;
                }());
    }
    // Said when it matters (a multiple-scattering reference loses only the rare walk it gives up).
    if (loss.count("all") && loss.at("all").worst >= 1e-3) {
        std::string per_category;
        for (const std::string& c : categories)
            if (loss.count(c))
                per_category += fmt::format("{}{} {}", per_category.empty() ? "" : ", ", c,
                                            pct(loss.at(c).sum / loss.at(c).n));
        const Loss& l = loss.at("all");
        out("- **What the reference itself drops**: its single-scattering microfacet interfaces "
            "lose, on average over incidences and channels, {} of the incident energy (worst {}: "
            "{}, θi {}°, {}) — masked light, on neither side of the reference. A model that keeps "
            "this energy overshoots the reference's albedo by up to that much; where it belongs "
            "(R, T) is what multiple scattering on the microsurfaces would decide. The explorer's "
            "albedo view draws it.\n",
            per_category, pct(l.worst), l.worst_config, l.worst_theta_i,
            kChannels[l.worst_channel]);
    }
    out(
        "- **Challenging cases** (even the best model misplaces more than {} of the reflected "
        "energy on average, and more than twice the noise floor): {}.\n\n",
        pct(kChallengingThreshold), challenging.empty() ? std::string("none") : [&] {
            std::string t;
            for (std::size_t k = 0; k < challenging.size(); ++k)
                t += fmt::format("{}`{}`", k ? ", " : "", challenging[k].config);
            return t;
        }());

    auto table_by_group = [&](const char* title, auto cell) {
        out("## {}\n\n| model |", title);
        for (const std::string& g : groups)
            out(" {} |", g);
        out("\n|---|");
        for (std::size_t k = 0; k < groups.size(); ++k)
            out("---|");
        out("\n");
        for (const std::string& m : models) {
            out("| {} |", m);
            for (const std::string& g : groups)
                out(" {} |", cell(agg[g][m], g));
            out("\n");
        }
        out("\n");
    };
    table_by_group("Misplaced energy: mean / worst (noise floor)",
                   [&](const Aggregate& a, const std::string&) {
                       return a.n ? fmt::format("{} / {} ({})", pct(a.mean_e()), pct(a.worst_e),
                                                pct(a.mean_floor()))
                                  : std::string("not supported");
                   });
    table_by_group("Albedo error: mean |error| / worst", [&](const Aggregate& a,
                                                             const std::string&) {
        return a.n_albedo
                   ? fmt::format("{} / {:+.1f}%", pct(a.mean_abs_albedo()), 100 * a.worst_albedo)
                   : std::string("not supported");
    });
    table_by_group("Coverage: configurations supported",
                   [&](const Aggregate& a, const std::string& g) {
                       return fmt::format("{}/{}", a.configs.size(), configs_in[g]);
                   });

    out("## Worst cases\n\n| model | group | worst misplaced energy | where "
        "|\n|---|---|---|---|\n");
    for (const std::string& m : models)
        for (const std::string& g : groups)
            if (g != "all" && g != "all BTDF" && agg[g][m].n)
                out("| {} | {} | {} | {} |\n", m, g, pct(agg[g][m].worst_e),
                    where(agg[g][m].worst_e_row));
    out("\n");

    out("## Challenging cases\n\nConfigurations where even the best supporting model misplaces "
        "more than {} of the reflected energy on average over incidences and channels, and more "
        "than twice the reference's noise floor.\n\n",
        pct(kChallengingThreshold));
    if (challenging.empty()) {
        out("None.\n\n");
    } else {
        out("| configuration | best model | its mean misplaced energy | noise floor |\n"
            "|---|---|---|---|\n");
        for (const Challenge& c : challenging)
            out("| {} | {} | {} | {} |\n", c.config, c.best, pct(c.best_e), pct(c.floor));
        out("\n");
    }

    out("## Approximations assessment\n\nMean misplaced energy of each model's BRDF, rows grouped "
        "by the factor that stresses an approximation (as in the original study's assessment); "
        "in parentheses the noise floor.\n\n");
    for (std::size_t f = 0; f < factors.size(); ++f) {
        out("### {}\n\n{}\n\n| model |", factors[f].title, factors[f].explanation);
        for (const auto& level : factors[f].levels)
            out(" {} |", level.first);
        out("\n|---|");
        for (std::size_t l = 0; l < factors[f].levels.size(); ++l)
            out("---|");
        out("\n");
        for (const std::string& m : models) {
            out("| {} |", m);
            for (std::size_t l = 0; l < factors[f].levels.size(); ++l) {
                const Aggregate& a = assessment[f][m][l];
                out(" {} |", a.n ? fmt::format("{} ({})", pct(a.mean_e()), pct(a.mean_floor()))
                                 : std::string("–"));
            }
            out("\n");
        }
        out("\n");
    }

    // The engine developers' section (study/engine_findings.h): computed from the same rows.
    const EngineFindings engine = compute_engine_findings(rows, models);
    md += engine_findings_markdown(engine);
    if (!engine.empty()) j["engine_developers"] = engine_findings_json(engine);

    out("## Not supported\n\n");
    if (unsupported.empty()) out("Every model supports every configuration.\n");
    for (const auto& [m, cfgs] : unsupported) {
        std::map<std::string, int> per_category;
        std::string reason;
        for (const auto& [cfg, sides] : cfgs) {
            per_category[by_id.at(cfg)->category + (sides.count('R') ? "" : " (BTDF)")]++;
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

    write_file_atomic(out_dir / "summary.json", j.dump(1) + "\n");
    write_file_atomic(out_dir / "summary.md", md);
}

}  // namespace lamina

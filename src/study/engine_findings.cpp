#include "study/engine_findings.h"

#include "models/registry.h"
#include "study/coat_costs.h"
#include "study/report_values.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <tuple>

namespace lamina {

namespace {

std::string signed_pct(double v) {
    return std::isfinite(v) ? fmt::format("{:+.1f}%", 100 * v) : "–";
}

const ModelEntry* entry_of(const std::string& name) {
    try {
        return parse_model_spec(name).entry;
    } catch (...) {
        return nullptr;  // a model this lamina no longer has: not a production coat
    }
}

bool is_production(const std::string& name) {
    const ModelEntry* e = entry_of(name);
    return e && e->group == "production" && name.find(':') == std::string::npos;
}

using RowKey = std::tuple<std::string, double, double, int>;  // config, θi, φi, channel

}  // namespace

EngineFindings compute_engine_findings(const std::vector<MetricRow>& rows,
                                       const std::vector<std::string>& models) {
    EngineFindings f;
    std::set<double> thetas;
    for (const MetricRow& r : rows) {
        if (r.side != 'R') continue;
        thetas.insert(r.theta_i);
        if (std::find(f.categories.begin(), f.categories.end(), r.category) == f.categories.end())
            f.categories.push_back(r.category);
    }
    f.theta_i.assign(thetas.begin(), thetas.end());
    std::vector<std::string> production;
    for (const std::string& m : models)
        if (is_production(m)) production.push_back(m);
    if (production.empty()) return {};

    // Per (model, category): the supported BRDF rows.
    struct Acc {
        std::set<std::string> configs;
        double e_sum = 0;
        int e_n = 0;
        std::vector<double> a_sum, a_n;
    };
    std::map<std::pair<std::string, std::string>, Acc> acc;
    std::map<std::string, std::map<RowKey, const MetricRow*>> by_model;
    for (const MetricRow& r : rows) {
        if (r.side != 'R' || !r.supported) continue;
        by_model[r.model][{r.config, r.theta_i, r.phi_i, r.channel}] = &r;
        Acc& a = acc[{r.model, r.category}];
        if (a.a_sum.empty()) a.a_sum.assign(f.theta_i.size(), 0), a.a_n.assign(f.theta_i.size(), 0);
        a.configs.insert(r.config);
        if (std::isfinite(r.metrics.misplaced_floor)) {
            a.e_sum += r.metrics.misplaced_floor;
            ++a.e_n;
        }
        const auto k =
            std::lower_bound(f.theta_i.begin(), f.theta_i.end(), r.theta_i) - f.theta_i.begin();
        if (std::isfinite(r.metrics.albedo_error)) {
            a.a_sum[k] += r.metrics.albedo_error;
            a.a_n[k] += 1;
        }
    }
    auto mean_e = [&](const std::string& m, const std::string& c) {
        const auto it = acc.find({m, c});
        return it == acc.end() || it->second.e_n == 0 ? NAN : it->second.e_sum / it->second.e_n;
    };

    for (const std::string& c : f.categories) {
        for (const std::string& m : production) {
            EngineFindings::Cell cell{m, c, 0, NAN, std::vector<double>(f.theta_i.size(), NAN)};
            const auto it = acc.find({m, c});
            if (it != acc.end()) {
                cell.configurations = int(it->second.configs.size());
                cell.mean_misplaced = mean_e(m, c);
                for (std::size_t k = 0; k < f.theta_i.size(); ++k)
                    if (it->second.a_n[k] > 0)
                        cell.albedo_error[k] = it->second.a_sum[k] / it->second.a_n[k];
            }
            f.cells.push_back(cell);
            if (std::isfinite(cell.mean_misplaced) &&
                (!f.best_production.count(c) || cell.mean_misplaced < f.best_production_error[c])) {
                f.best_production[c] = m;
                f.best_production_error[c] = cell.mean_misplaced;
            }
        }
        for (const std::string& m : models) {
            const double e = mean_e(m, c);
            if (std::isfinite(e) && (!f.best_overall.count(c) || e < f.best_overall_error[c])) {
                f.best_overall[c] = m;
                f.best_overall_error[c] = e;
            }
        }
    }

    // Ablations: each variant "NAME:KEY=VALUE" of a production coat against NAME, row by row.
    for (const std::string& v : models) {
        const auto colon = v.find(':');
        if (colon == std::string::npos) continue;
        const std::string base = v.substr(0, colon);
        if (!is_production(base) || !by_model.count(base) || !by_model.count(v)) continue;
        std::map<std::string, EngineFindings::Ablation> per_category;
        for (const auto& [key, rv] : by_model[v]) {
            const auto it = by_model[base].find(key);
            if (it == by_model[base].end()) continue;
            const MetricRow& rb = *it->second;
            if (!std::isfinite(rv->metrics.misplaced_floor) ||
                !std::isfinite(rb.metrics.misplaced_floor))
                continue;
            EngineFindings::Ablation& a = per_category[rv->category];
            a.rows++;
            a.shipped += rb.metrics.misplaced_floor;
            a.switched += rv->metrics.misplaced_floor;
            if (std::isfinite(rv->metrics.albedo_error) && std::isfinite(rb.metrics.albedo_error)) {
                a.shipped_albedo += std::abs(rb.metrics.albedo_error);
                a.switched_albedo += std::abs(rv->metrics.albedo_error);
            }
        }
        for (const std::string& c : f.categories) {
            auto it = per_category.find(c);
            if (it == per_category.end() || it->second.rows == 0) continue;
            EngineFindings::Ablation a = it->second;
            a.variant = v;
            a.model = base;
            a.flag = v.substr(colon + 1);
            a.category = c;
            a.shipped /= a.rows;
            a.switched /= a.rows;
            a.shipped_albedo /= a.rows;
            a.switched_albedo /= a.rows;
            f.ablations.push_back(a);
        }
    }

    // Each specification beside each of its implementations, row by row.
    for (const std::string& m : production) {
        const ModelEntry* e = entry_of(m);
        if (e->specification.empty() || !by_model.count(m) || !by_model.count(e->specification) ||
            std::find(models.begin(), models.end(), e->specification) == models.end())
            continue;
        const auto& spec_rows = by_model[e->specification];
        std::map<std::string, EngineFindings::Implementation> per_category;
        std::map<std::string, int> albedo_rows;
        for (const auto& [key, row] : by_model[m]) {
            const auto s = spec_rows.find(key);
            if (s == spec_rows.end() || !std::isfinite(row->metrics.misplaced_floor) ||
                !std::isfinite(s->second->metrics.misplaced_floor))
                continue;
            const MetricRow& rs = *s->second;
            EngineFindings::Implementation& d = per_category[row->category];
            d.rows++;
            d.implementation_error += row->metrics.misplaced_floor;
            d.specification_error += rs.metrics.misplaced_floor;
            if (std::isfinite(row->metrics.albedo_error) &&
                std::isfinite(rs.metrics.albedo_error)) {
                d.implementation_albedo += std::abs(row->metrics.albedo_error);
                d.specification_albedo += std::abs(rs.metrics.albedo_error);
                d.albedo_difference +=
                    std::abs(row->metrics.albedo_model - rs.metrics.albedo_model) /
                    row->metrics.albedo_ref;
                albedo_rows[row->category]++;
            }
        }
        for (const std::string& c : f.categories) {
            auto it = per_category.find(c);
            if (it == per_category.end() || it->second.rows == 0) continue;
            EngineFindings::Implementation d = it->second;
            d.specification = e->specification;
            d.implementation = m;
            d.category = c;
            d.implementation_error /= d.rows;
            d.specification_error /= d.rows;
            const int n = albedo_rows[c];
            d.implementation_albedo = n ? d.implementation_albedo / n : NAN;
            d.specification_albedo = n ? d.specification_albedo / n : NAN;
            d.albedo_difference = n ? d.albedo_difference / n : NAN;
            f.implementations.push_back(d);
        }
    }

    // Each coat against its exact leaves and lamina-coat, on the rows lamina-coat also covers.
    if (by_model.count("lamina-coat")) {
        const auto& replacement = by_model["lamina-coat"];
        for (const std::string& m : production) {
            if (!by_model.count(m)) continue;
            const auto exact = by_model.find(m + ":leaves=exact");
            std::map<std::string, EngineFindings::Replacement> per_category;
            for (const auto& [key, row] : by_model[m]) {
                const auto lc = replacement.find(key);
                if (lc == replacement.end() || !std::isfinite(row->metrics.misplaced_floor) ||
                    !std::isfinite(lc->second->metrics.misplaced_floor))
                    continue;
                EngineFindings::Replacement& r = per_category[row->category];
                r.rows++;
                r.shipped += row->metrics.misplaced_floor;
                r.lamina_coat += lc->second->metrics.misplaced_floor;
                double e = NAN;
                if (exact != by_model.end()) {
                    const auto x = exact->second.find(key);
                    if (x != exact->second.end()) e = x->second->metrics.misplaced_floor;
                }
                r.exact_leaves += e;  // NaN as soon as one row lacks it
            }
            for (const std::string& c : f.categories) {
                auto it = per_category.find(c);
                if (it == per_category.end()) continue;
                EngineFindings::Replacement r = it->second;
                r.model = m;
                r.category = c;
                r.shipped /= r.rows;
                r.exact_leaves /= r.rows;
                r.lamina_coat /= r.rows;
                f.replacements.push_back(r);
            }
        }
    }
    return f;
}

namespace {

/// One sentence of advice for an engine shipping `r.model`, from the three errors.
std::string replacement_advice(const EngineFindings::Replacement& r) {
    const double best_of_coat =
        std::isfinite(r.exact_leaves) ? std::min(r.shipped, r.exact_leaves) : r.shipped;
    if (r.lamina_coat < 0.5 * r.shipped)
        return fmt::format("replace it: lamina-coat misplaces {:.0f}% of what it does",
                           100 * r.lamina_coat / r.shipped);
    if (r.lamina_coat < best_of_coat)
        return fmt::format("lamina-coat is better by {:.1f} points",
                           100 * (best_of_coat - r.lamina_coat));
    if (std::isfinite(r.exact_leaves) && r.exact_leaves < r.shipped - 0.001)
        return "keep its layering and take exact leaves";
    return "keep it here";
}

/// "too dark at every incidence (−3.1% at 0° to −9.0% at 80°)", "too bright at grazing incidence
/// (+12% at 80°), too dark at normal incidence (−2% at 0°)", "within ±1% at every incidence".
std::string albedo_words(const std::vector<double>& theta, const std::vector<double>& err) {
    double lo = INFINITY, hi = -INFINITY;
    std::size_t ilo = 0, ihi = 0;
    for (std::size_t k = 0; k < err.size(); ++k) {
        if (!std::isfinite(err[k])) continue;
        if (err[k] < lo) lo = err[k], ilo = k;
        if (err[k] > hi) hi = err[k], ihi = k;
    }
    if (!std::isfinite(lo)) return "no albedo error (no reference energy)";
    const double tol = 0.01;
    if (hi <= tol && lo >= -tol) return "its albedo is within ±1% at every incidence";
    auto at = [&](std::size_t k) { return fmt::format("{} at {}°", signed_pct(err[k]), theta[k]); };
    if (lo >= -tol) return fmt::format("too bright, most at {} (least {})", at(ihi), at(ilo));
    if (hi <= tol) return fmt::format("too dark, most at {} (least {})", at(ilo), at(ihi));
    return fmt::format("too bright at {}° ({}), too dark at {}° ({})", theta[ihi],
                       signed_pct(err[ihi]), theta[ilo], signed_pct(err[ilo]));
}

/// What an ablation says: switching a heuristic off (`=off`) that raises the error means the
/// heuristic helps; switching one on that lowers it means it would help; `leaves=exact` measures
/// the leaves' error; any other switch is reported as the change it makes.
std::string switch_effect(const EngineFindings::Ablation& a) {
    const double d = a.switched - a.shipped;
    const std::string points = fmt::format("{:.1f} points", 100 * std::abs(d));
    if (std::abs(d) < 0.001) return "no change (< 0.1 point)";
    const std::string value = a.flag.substr(a.flag.find('=') + 1);
    const std::string key = a.flag.substr(0, a.flag.find('='));
    if (key == "leaves")
        return d < 0 ? fmt::format("the shipped leaves cost {}", points)
                     : fmt::format("the shipped leaves gain {} (errors that cancel)", points);
    if (value == "off")
        return d > 0 ? fmt::format("**{} helps** ({} without it)", key, points)
                     : fmt::format("**{} hurts** ({} better without it)", key, points);
    if (value == "on" || value == "1")
        return d < 0 ? fmt::format("**{} would help** ({} better)", key, points)
                     : fmt::format("{} would hurt ({} worse)", key, points);
    return d < 0 ? fmt::format("`{}` is better by {}", a.flag, points)
                 : fmt::format("`{}` is worse by {}", a.flag, points);
}

/// The coats of the cost table: the production coats the study ran, then lamina-coat if it ran.
std::vector<std::string> costed_models(const EngineFindings& f) {
    std::vector<std::string> models;
    for (const auto& cell : f.cells)
        if (std::find(models.begin(), models.end(), cell.model) == models.end())
            models.push_back(cell.model);
    if (!f.replacements.empty()) models.push_back("lamina-coat");
    return models;
}

std::string ns_text(double ns) {
    return std::isfinite(ns) ? fmt::format("{:.0f}", ns) : "–";
}

constexpr const char* kCostStacks[] = {"plastic", "coated-gold"};

}  // namespace

std::string engine_findings_markdown(const EngineFindings& f) {
    if (f.empty()) return "";
    std::string md;
    auto out = [&]<typename... A>(fmt::format_string<A...> format, A&&... args) {
        fmt::format_to(std::back_inserter(md), format, std::forward<A>(args)...);
    };
    out("## For engine developers: the production coats\n\n");
    out("The coats engines ship (`docs/models.md`, \"Production coats\"), on the BRDF of each "
        "category: the mean signed albedo error (model − reference)/reference against θi "
        "(negative: "
        "the coat is too dark), the lobe error (mean misplaced energy with the 5% floor, the "
        "ranking metric), what each heuristic does "
        "(the model with one flag switched, `NAME:KEY=VALUE`, against the model as shipped on the "
        "same rows; `lamina study --ablations`), each specification beside the code that ships it, "
        "and the most accurate production coat.\n\n");
    for (const std::string& c : f.categories) {
        std::vector<const EngineFindings::Cell*> cells;
        for (const auto& cell : f.cells)
            if (cell.category == c && cell.configurations > 0) cells.push_back(&cell);
        out("### {}\n\n", c);
        if (cells.empty()) {
            out("No production coat supports this category (see \"Not supported\").\n\n");
            continue;
        }
        out("| model | misplaced energy (5% floor) |");
        for (double t : f.theta_i)
            out(" albedo error {}° |", t);
        out("\n|---|---|");
        for (std::size_t k = 0; k < f.theta_i.size(); ++k)
            out("---|");
        out("\n");
        for (const auto* cell : cells) {
            out("| {} | {} |", cell->model, percent_text(cell->mean_misplaced));
            for (double e : cell->albedo_error)
                out(" {} |", signed_pct(e));
            out("\n");
        }
        out("\n");
        for (const auto* cell : cells)
            out("- **{}**: {}; misplaces {} of the reflected energy.\n", cell->model,
                albedo_words(f.theta_i, cell->albedo_error), percent_text(cell->mean_misplaced));
        if (f.best_production.count(c))
            out("- Most accurate production coat here: **{}** ({}); best of every model run "
                "(ablations included): {} ({}).\n",
                f.best_production.at(c), percent_text(f.best_production_error.at(c)),
                f.best_overall.at(c), percent_text(f.best_overall_error.at(c)));
        // The rows of `items` in this category under `header`, nothing when there are none.
        const auto table = [&](const auto& items, const char* header, const auto& row) {
            bool started = false;
            for (const auto& item : items) {
                if (item.category != c) continue;
                if (!started) out("{}", header);
                started = true;
                row(item);
            }
            return started;
        };
        table(
            f.ablations,
            "\nHeuristics and leaves (mean misplaced energy, 5% floor; mean |albedo error|):\n\n"
            "| model | switched | as shipped | switched | what it says |\n|---|---|---|---|---|\n",
            [&](const EngineFindings::Ablation& a) {
                out("| {} | `{}` | {}; {} | {}; {} | {} |\n", a.model, a.flag,
                    percent_text(a.shipped), percent_text(a.shipped_albedo),
                    percent_text(a.switched), percent_text(a.switched_albedo), switch_effect(a));
            });
        out("\n");
        if (table(f.implementations,
                  "Specifications and the code that ships them (on the rows both support: mean "
                  "misplaced energy, 5% floor; mean |albedo error|; and how far apart the two "
                  "albedos are, mean |a_code − a_specification| / a_reference):\n\n"
                  "| specification | the code shipping it | the specification's errors | the "
                  "code's errors | albedos apart |\n|---|---|---|---|---|\n",
                  [&](const EngineFindings::Implementation& d) {
                      out("| {} | {} | {}; {} | {}; {} | {} |\n", d.specification, d.implementation,
                          percent_text(d.specification_error), percent_text(d.specification_albedo),
                          percent_text(d.implementation_error),
                          percent_text(d.implementation_albedo), percent_text(d.albedo_difference));
                  }))
            out("\n");
        if (table(f.replacements,
                  "What an engine could ship instead (mean misplaced energy, 5% floor, on the rows "
                  "lamina-coat covers; the cost per evaluation of each is below, and `make "
                  "bench`, BM_CoatEval):\n\n"
                  "| coat | as shipped | `leaves=exact` | lamina-coat | advice |\n"
                  "|---|---|---|---|---|\n",
                  [&](const EngineFindings::Replacement& r) {
                      out("| {} | {} | {} | {} | {} |\n", r.model, percent_text(r.shipped),
                          percent_text(r.exact_leaves), percent_text(r.lamina_coat),
                          replacement_advice(r));
                  }))
            out("\n");
    }
    const CoatCosts& costs = coat_costs();
    out("### Cost per evaluation\n\n"
        "Nanoseconds per evaluation f(wi, wo) through lamina's Model interface, each coat as "
        "shipped and with `leaves=exact`, on random direction pairs; measured side by side in one "
        "run on {}, {} (`{}`; data/coat_costs.json: a measurement, not part of this study's "
        "computation). The plastic is a rough clear coat over a Lambertian, the coated gold the "
        "same coat over rough gold.\n\n"
        "| coat | plastic, as shipped | plastic, `leaves=exact` | coated gold, as shipped | "
        "coated gold, `leaves=exact` |\n|---|---|---|---|---|\n",
        costs.machine, costs.date, costs.command);
    for (const std::string& m : costed_models(f)) {
        out("| {} |", m);
        for (const char* stack : kCostStacks)
            out(" {} | {} |", ns_text(costs.of(m, stack)),
                ns_text(costs.of(m + ":leaves=exact", stack)));
        out("\n");
    }
    out("\n");
    return md;
}

nlohmann::json engine_findings_json(const EngineFindings& f) {
    if (f.empty()) return nullptr;
    nlohmann::json j;
    j["theta_i"] = f.theta_i;
    for (const std::string& c : f.categories) {
        nlohmann::json jc;
        for (const auto& cell : f.cells) {
            if (cell.category != c || cell.configurations == 0) continue;
            nlohmann::json ae = nlohmann::json::array();
            for (double e : cell.albedo_error)
                ae.push_back(json_number(e));
            jc["models"][cell.model] = {{"configurations_supported", cell.configurations},
                                        {"mean_misplaced_floor", json_number(cell.mean_misplaced)},
                                        {"albedo_error_by_theta_i", ae}};
        }
        if (f.best_production.count(c)) {
            jc["most_accurate_production"] = f.best_production.at(c);
            jc["most_accurate_overall"] = f.best_overall.at(c);
        }
        for (const auto& a : f.ablations)
            if (a.category == c)
                jc["ablations"].push_back(
                    {{"variant", a.variant},
                     {"model", a.model},
                     {"flag", a.flag},
                     {"rows", a.rows},
                     {"shipped_misplaced_floor", json_number(a.shipped)},
                     {"switched_misplaced_floor", json_number(a.switched)},
                     {"shipped_mean_abs_albedo_error", json_number(a.shipped_albedo)},
                     {"switched_mean_abs_albedo_error", json_number(a.switched_albedo)}});
        for (const auto& d : f.implementations)
            if (d.category == c)
                jc["implementations"].push_back(
                    {{"specification", d.specification},
                     {"implementation", d.implementation},
                     {"rows", d.rows},
                     {"specification_misplaced_floor", json_number(d.specification_error)},
                     {"implementation_misplaced_floor", json_number(d.implementation_error)},
                     {"specification_mean_abs_albedo_error", json_number(d.specification_albedo)},
                     {"implementation_mean_abs_albedo_error", json_number(d.implementation_albedo)},
                     {"mean_albedo_difference", json_number(d.albedo_difference)}});
        for (const auto& r : f.replacements)
            if (r.category == c)
                jc["replacements"].push_back(
                    {{"model", r.model},
                     {"rows", r.rows},
                     {"shipped_misplaced_floor", json_number(r.shipped)},
                     {"exact_leaves_misplaced_floor", json_number(r.exact_leaves)},
                     {"lamina_coat_misplaced_floor", json_number(r.lamina_coat)},
                     {"advice", replacement_advice(r)}});
        j["categories"][c] = jc;
    }
    const CoatCosts& costs = coat_costs();
    nlohmann::json jc = {{"machine", costs.machine},
                         {"date", costs.date},
                         {"command", costs.command},
                         {"ns_per_evaluation", nlohmann::json::object()}};
    for (const std::string& m : costed_models(f))
        for (const std::string& spec : {m, m + ":leaves=exact"})
            for (const char* stack : kCostStacks)
                if (std::isfinite(costs.of(spec, stack)))
                    jc["ns_per_evaluation"][spec][stack] = costs.of(spec, stack);
    j["cost_per_evaluation"] = jc;
    return j;
}

}  // namespace lamina

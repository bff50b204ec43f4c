// The engine developers' section of the summary, on hand-made metric rows whose aggregates are
// known: a production coat too dark at grazing incidence, one of its ablations, a 2019 model
// that is better, a category no production coat supports.
#include "study/engine_findings.h"

#include "study/coat_costs.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

MetricRow row(const std::string& config, const std::string& category, const std::string& model,
              double theta, int channel, bool supported, double misplaced, double albedo_error) {
    MetricRow r;
    r.config = config;
    r.category = category;
    r.model = model;
    r.theta_i = theta;
    r.side = 'R';
    r.channel = channel;
    r.supported = supported;
    r.metrics.misplaced_energy = supported ? misplaced : NAN;
    r.metrics.misplaced_floor = r.metrics.misplaced_energy;  // the ranking metric (reference ≥ 5%)
    r.metrics.albedo_error = supported ? albedo_error : NAN;
    return r;
}

std::vector<MetricRow> rows() {
    std::vector<MetricRow> out;
    for (const char* cfg : {"p1", "p2"})
        for (double t : {0.0, 60.0})
            for (int c = 0; c < 3; ++c) {
                // openpbr: right at normal incidence, 10% too dark at 60°.
                out.push_back(row(cfg, "plastic", "openpbr", t, c, true, 0.2, t == 0 ? 0.0 : -0.1));
                out.push_back(row(cfg, "plastic", "openpbr:darkening=off", t, c, true, 0.3,
                                  t == 0 ? 0.05 : 0.0));
                out.push_back(row(cfg, "plastic", "filament", t, c, true, 0.25, 0.2));
                out.push_back(row(cfg, "plastic", "ww-prime", t, c, true, 0.05, 0.01));
                out.push_back(row("s1", "slab", "openpbr", t, c, false, 0, 0));
            }
    return out;
}

const std::vector<std::string> kModels = {"ww-prime", "openpbr", "filament",
                                          "openpbr:darkening=off"};

TEST(EngineFindings, AggregatesTheProductionCoats) {
    const EngineFindings f = compute_engine_findings(rows(), kModels);
    ASSERT_FALSE(f.empty());
    EXPECT_EQ(f.theta_i, (std::vector<double>{0, 60}));
    EXPECT_EQ(f.categories, (std::vector<std::string>{"plastic", "slab"}));
    const EngineFindings::Cell* openpbr = nullptr;
    for (const auto& c : f.cells)
        if (c.model == "openpbr" && c.category == "plastic") openpbr = &c;
    ASSERT_NE(openpbr, nullptr);
    EXPECT_EQ(openpbr->configurations, 2);
    EXPECT_NEAR(openpbr->mean_misplaced, 0.2, 1e-12);
    EXPECT_NEAR(openpbr->albedo_error[0], 0.0, 1e-12);
    EXPECT_NEAR(openpbr->albedo_error[1], -0.1, 1e-12);
    // Only production coats get cells (ww-prime is a 2019 model, the variant an ablation).
    for (const auto& c : f.cells)
        EXPECT_TRUE(c.model == "openpbr" || c.model == "filament") << c.model;
    EXPECT_EQ(f.best_production.at("plastic"), "openpbr");
    EXPECT_EQ(f.best_overall.at("plastic"), "ww-prime");
    EXPECT_FALSE(f.best_production.count("slab"));
    ASSERT_EQ(f.ablations.size(), 1u);
    const auto& a = f.ablations[0];
    EXPECT_EQ(a.model, "openpbr");
    EXPECT_EQ(a.flag, "darkening=off");
    EXPECT_EQ(a.rows, 12);
    EXPECT_NEAR(a.shipped, 0.2, 1e-12);
    EXPECT_NEAR(a.switched, 0.3, 1e-12);
    EXPECT_NEAR(a.shipped_albedo, 0.05, 1e-12);
    EXPECT_NEAR(a.switched_albedo, 0.025, 1e-12);
}

TEST(EngineFindings, MarkdownReadsAsFindings) {
    const std::string md = engine_findings_markdown(compute_engine_findings(rows(), kModels));
    EXPECT_NE(md.find("## For engine developers"), std::string::npos);
    EXPECT_NE(md.find("**openpbr**: too dark, most at -10.0% at 60°"), std::string::npos) << md;
    EXPECT_NE(md.find("**filament**: too bright, most at +20.0% at 0°"), std::string::npos) << md;
    EXPECT_NE(md.find("Most accurate production coat here: **openpbr** (20.0%); best of every "
                      "model run (ablations included): ww-prime (5.0%)"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("`darkening=off` | 20.0%; 5.0% | 30.0%; 2.5% | **darkening helps** (10.0 "
                      "points without it)"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("No production coat supports this category"), std::string::npos);
    const nlohmann::json j = engine_findings_json(compute_engine_findings(rows(), kModels));
    EXPECT_EQ(j["categories"]["plastic"]["most_accurate_production"], "openpbr");
    EXPECT_NEAR(
        j["categories"]["plastic"]["models"]["openpbr"]["albedo_error_by_theta_i"][1].get<double>(),
        -0.1, 1e-12);
}

// The section ranks by misplaced_floor, the summary's ranking metric, not by misplaced_energy:
// where the reference holds little light the two disagree (misplaced_energy explodes), and the
// ranking must follow the floored one.
TEST(EngineFindings, RanksByTheFlooredMetric) {
    std::vector<MetricRow> r;
    for (double t : {0.0, 80.0})
        for (int c = 0; c < 3; ++c) {
            // openpbr: small relative error everywhere, but at 80° on a dim reference the
            // floored metric is large (0.4) while misplaced_energy is small (0.05).
            MetricRow a = row("p1", "plastic", "openpbr", t, c, true, 0.05, 0.0);
            a.metrics.misplaced_floor = t == 0 ? 0.1 : 0.4;
            // filament: misplaced_energy explodes (3.0) on the dim reference, the floored
            // metric stays at 0.15.
            MetricRow b = row("p1", "plastic", "filament", t, c, true, t == 0 ? 0.1 : 3.0, 0.0);
            b.metrics.misplaced_floor = 0.15;
            r.push_back(a);
            r.push_back(b);
        }
    const EngineFindings f = compute_engine_findings(r, {"openpbr", "filament"});
    ASSERT_FALSE(f.empty());
    // Means: openpbr (0.1 + 0.4)/2 = 0.25 floored, 0.05 energy; filament 0.15 floored, 1.55.
    EXPECT_EQ(f.best_production.at("plastic"), "filament");
    EXPECT_EQ(f.best_overall.at("plastic"), "filament");
    for (const auto& c : f.cells) {
        if (c.model == "openpbr") {
            EXPECT_NEAR(c.mean_misplaced, 0.25, 1e-12);
        }
        if (c.model == "filament") {
            EXPECT_NEAR(c.mean_misplaced, 0.15, 1e-12);
        }
    }
}

TEST(EngineFindings, QuotesTheMeasuredCostOfEachCoat) {
    // The cost table lists the production coats the study ran, with the measurement's
    // provenance; its numbers are data/coat_costs.json's (study/coat_costs.h).
    const EngineFindings f = compute_engine_findings(rows(), kModels);
    const std::string md = engine_findings_markdown(f);
    const CoatCosts& costs = coat_costs();
    EXPECT_NE(md.find("### Cost per evaluation"), std::string::npos) << md;
    EXPECT_NE(md.find(costs.machine), std::string::npos) << md;
    EXPECT_NE(md.find(fmt::format(
                  "| openpbr | {:.0f} | {:.0f} | {:.0f} | {:.0f} |", costs.of("openpbr", "plastic"),
                  costs.of("openpbr:leaves=exact", "plastic"), costs.of("openpbr", "coated-gold"),
                  costs.of("openpbr:leaves=exact", "coated-gold"))),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| filament |"), std::string::npos) << md;
    EXPECT_EQ(md.find("| ww-prime |"), std::string::npos) << md;  // not a production coat
    const nlohmann::json j = engine_findings_json(f);
    EXPECT_EQ(
        j["cost_per_evaluation"]["ns_per_evaluation"]["filament"]["coated-gold"].get<double>(),
        costs.of("filament", "coated-gold"));
}

TEST(EngineFindings, EmptyWithoutProductionCoats) {
    std::vector<MetricRow> r = {row("p1", "plastic", "ww-prime", 0, 0, true, 0.1, 0.0)};
    const EngineFindings f = compute_engine_findings(r, {"ww-prime"});
    EXPECT_TRUE(f.empty());
    EXPECT_EQ(engine_findings_markdown(f), "");
    EXPECT_TRUE(engine_findings_json(f).is_null());
}

}  // namespace
}  // namespace lamina

namespace lamina {
namespace {

TEST(EngineFindings, SetsEachCoatBesideItsExactLeavesAndLaminaCoat) {
    std::vector<MetricRow> rs;
    for (double t : {0.0, 60.0})
        for (int c = 0; c < 3; ++c) {
            rs.push_back(row("p1", "plastic", "openpbr", t, c, true, t == 0 ? 0.1 : 0.3, 0));
            rs.push_back(row("p1", "plastic", "openpbr:leaves=exact", t, c, true, 0.15, 0));
            rs.push_back(row("p1", "plastic", "lamina-coat", t, c, true, 0.05, 0));
            rs.push_back(row("p1", "plastic", "filament", t, c, true, 0.06, 0));
        }
    const EngineFindings f =
        compute_engine_findings(rs, {"openpbr", "filament", "openpbr:leaves=exact", "lamina-coat"});
    ASSERT_EQ(f.replacements.size(), 2u);
    const auto& openpbr = f.replacements[0];
    EXPECT_EQ(openpbr.model, "openpbr");
    EXPECT_EQ(openpbr.rows, 6);
    EXPECT_NEAR(openpbr.shipped, 0.2, 1e-12);
    EXPECT_NEAR(openpbr.exact_leaves, 0.15, 1e-12);
    EXPECT_NEAR(openpbr.lamina_coat, 0.05, 1e-12);
    EXPECT_TRUE(std::isnan(f.replacements[1].exact_leaves));  // filament:leaves=exact not run
    const std::string md = engine_findings_markdown(f);
    EXPECT_NE(md.find("| openpbr | 20.0% | 15.0% | 5.0% | replace it: lamina-coat misplaces 25% "
                      "of what it does |"),
              std::string::npos)
        << md;
    EXPECT_NE(md.find("| filament | 6.0% | – | 5.0% | lamina-coat is better by 1.0 points |"),
              std::string::npos)
        << md;
}

// A specification beside the code that ships it (ModelEntry::specification: openpbr-adobe
// implements openpbr), on the rows both support: each one's errors and how far apart their
// albedos are, |a_code − a_spec| / a_ref averaged over the rows.
TEST(EngineFindings, SetsEachSpecificationBesideItsCode) {
    std::vector<MetricRow> r;
    for (double t : {0.0, 60.0})
        for (int c = 0; c < 3; ++c) {
            MetricRow spec = row("p1", "plastic", "openpbr", t, c, true, 0.2, -0.1);
            MetricRow code =
                row("p1", "plastic", "openpbr-adobe", t, c, true, 0.1, t == 0 ? 0.1 : 0.02);
            spec.metrics.albedo_ref = code.metrics.albedo_ref = 0.5;
            spec.metrics.albedo_model = 0.45;  // −10 %
            code.metrics.albedo_model = t == 0 ? 0.55 : 0.51;
            r.push_back(spec);
            r.push_back(code);
            // A row only the code supports does not enter the comparison.
            r.push_back(row("p2", "plastic", "openpbr", t, c, false, 0, 0));
            r.push_back(row("p2", "plastic", "openpbr-adobe", t, c, true, 0.9, 0.5));
        }
    const EngineFindings f = compute_engine_findings(r, {"openpbr", "openpbr-adobe"});
    ASSERT_EQ(f.implementations.size(), 1u);
    const auto& d = f.implementations[0];
    EXPECT_EQ(d.specification, "openpbr");
    EXPECT_EQ(d.implementation, "openpbr-adobe");
    EXPECT_EQ(d.rows, 6);
    EXPECT_NEAR(d.specification_error, 0.2, 1e-12);
    EXPECT_NEAR(d.implementation_error, 0.1, 1e-12);
    EXPECT_NEAR(d.specification_albedo, 0.1, 1e-12);
    EXPECT_NEAR(d.implementation_albedo, 0.06, 1e-12);
    EXPECT_NEAR(d.albedo_difference, (0.2 + 0.12) / 2, 1e-12);  // (0.10 + 0.06)/0.5, averaged
    const std::string md = engine_findings_markdown(f);
    EXPECT_NE(md.find("| openpbr | openpbr-adobe | 20.0%; 10.0% | 10.0%; 6.0% | 16.0% |"),
              std::string::npos)
        << md;
    const nlohmann::json j = engine_findings_json(f);
    EXPECT_EQ(j["categories"]["plastic"]["implementations"][0]["implementation"], "openpbr-adobe");
    // Without the specification in the study there is nothing to set it beside.
    EXPECT_TRUE(compute_engine_findings(r, {"openpbr-adobe"}).implementations.empty());
}

}  // namespace
}  // namespace lamina

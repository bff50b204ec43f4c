// The summary's aggregates on hand-made metric rows: rankings per group, over the configurations
// each model supports, and like for like over the configurations every model supports.
#include "study/summary.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

namespace lamina {
namespace {

const StudyConfiguration& builtin(const std::string& id) {
    static const std::vector<StudyConfiguration> all = builtin_configurations();
    const auto it = std::find_if(all.begin(), all.end(), [&](const auto& c) { return c.id == id; });
    if (it == all.end()) throw std::runtime_error("no built-in configuration " + id);
    return *it;
}

// Rows of one (configuration, model): every channel of one incidence with the same error.
// misplaced_floor: the same as misplaced_energy unless given (a reference above 5% of the light).
void add_rows(std::vector<MetricRow>& rows, const StudyConfiguration& c, const std::string& model,
              bool supported, double misplaced_energy, double misplaced_floor = NAN) {
    for (int channel = 0; channel < 3; ++channel) {
        MetricRow r;
        r.config = c.id;
        r.category = c.category;
        r.model = model;
        r.theta_i = 30;
        r.side = 'R';
        r.channel = channel;
        r.supported = supported;
        r.metrics.misplaced_energy = supported ? misplaced_energy : NAN;
        r.metrics.misplaced_floor =
            supported ? (std::isnan(misplaced_floor) ? misplaced_energy : misplaced_floor) : NAN;
        r.metrics.albedo_error = supported ? misplaced_energy : NAN;
        r.floor.misplaced_energy = 0.01;
        r.floor.misplaced_floor = 0.01;
        rows.push_back(r);
    }
}

// Writes the summary of `rows` (one incidence, θi = 30°) into a fresh folder and reads it back.
struct Written {
    nlohmann::json json;
    std::string md;
    StudyFindings findings;
};
Written summarize(const std::vector<StudyConfiguration>& configs,
                  const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                  const ReferenceLoss& lost = {}) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "lamina-summary-test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    StudySettings s;
    s.reference.theta_i_deg = {30};
    const StudyFindings findings = compute_findings(configs, s, models, rows, lost);
    EXPECT_EQ(write_summary(dir, findings), 2);
    EXPECT_EQ(write_summary(dir, findings), 0);  // unchanged: nothing rewritten
    Written w;
    w.findings = findings;
    std::ifstream in(dir / "summary.json");
    w.json = nlohmann::json::parse(in);
    std::ifstream md_in(dir / "summary.md");
    w.md.assign(std::istreambuf_iterator<char>(md_in), std::istreambuf_iterator<char>());
    std::filesystem::remove_all(dir);
    return w;
}

/// Model "a" on a plastic (50%) and a paint (10%), model "b" on the paint alone (20%).
std::vector<MetricRow> a_everywhere_b_on_the_paint(const StudyConfiguration& plastic,
                                                   const StudyConfiguration& paint) {
    std::vector<MetricRow> rows;
    add_rows(rows, plastic, "a", true, 0.5);
    add_rows(rows, plastic, "b", false, 0);
    add_rows(rows, paint, "a", true, 0.1);
    add_rows(rows, paint, "b", true, 0.2);
    return rows;
}

// Model "a" supports a plastic (where it misplaces 50%) and a paint (10%); model "b" supports
// only the paint (20%). Over what each supports, b (20%) ranks before a (30%); like for like, on
// the paint alone, a (10%) ranks before b (20%).
TEST(StudySummary, LikeForLikeRankingUsesOnlyConfigurationsEveryModelSupports) {
    const StudyConfiguration& plastic = builtin("plastic-P1-a0.05");
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    const std::vector<MetricRow> rows = a_everywhere_b_on_the_paint(plastic, paint);

    const Written w = summarize({plastic, paint}, {"a", "b"}, rows);
    const nlohmann::json& j = w.json;
    EXPECT_EQ(j["groups"]["all"]["ranking"], (nlohmann::json{"b", "a"}));
    EXPECT_NEAR(j["groups"]["all"]["models"]["a"]["mean_misplaced_energy"].get<double>(), 0.3,
                1e-12);
    EXPECT_EQ(j["common"]["configurations"], 1);
    EXPECT_EQ(j["common"]["ids"], (nlohmann::json{paint.id}));
    EXPECT_EQ(j["common"]["ranking"], (nlohmann::json{"a", "b"}));
    EXPECT_NEAR(j["common"]["models"]["a"]["mean_misplaced_energy"].get<double>(), 0.1, 1e-12);
    EXPECT_NEAR(j["common"]["models"]["b"]["mean_misplaced_energy"].get<double>(), 0.2, 1e-12);
    EXPECT_NE(w.md.find("**Like for like** (the BRDF of the 1 configuration every model "
                        "supports): a 10.0% < b 20.0%."),
              std::string::npos)
        << w.md;
}

// Three models and no configuration all of them support: "a" and "b" share the paint, "c"
// supports only the plastic, which "b" does not. The model with the fewest supported BRDFs ("b"
// and "c" one each: the later in the study's order on a tie) is left out; a and b are then
// compared on the paint, and the summary names c.
TEST(StudySummary, LikeForLikeLeavesOutTheModelsMadeForFewerConfigurations) {
    const StudyConfiguration& plastic = builtin("plastic-P1-a0.05");
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    std::vector<MetricRow> rows;
    add_rows(rows, plastic, "a", true, 0.5);
    add_rows(rows, plastic, "b", false, 0);
    add_rows(rows, plastic, "c", true, 0.05);
    add_rows(rows, paint, "a", true, 0.1);
    add_rows(rows, paint, "b", true, 0.2);
    add_rows(rows, paint, "c", false, 0);

    const Written w = summarize({plastic, paint}, {"a", "b", "c"}, rows);
    const nlohmann::json& j = w.json;
    EXPECT_EQ(j["common"]["left_out"], (nlohmann::json{"c"}));
    EXPECT_EQ(j["common"]["ids"], (nlohmann::json{paint.id}));
    EXPECT_EQ(j["common"]["ranking"], (nlohmann::json{"a", "b"}));
    EXPECT_NE(w.md.find("every model but c (made for fewer configurations) supports): a 10.0% < "
                        "b 20.0%."),
              std::string::npos)
        << w.md;
    // The overall ranking says how many configurations each model's mean covers.
    EXPECT_NE(w.md.find("c 5.0% (1 of 2)"), std::string::npos) << w.md;
}

// A category's best mean may cover only some of its configurations: the finding says on how
// many, and names the best model that supports them all. Over the plastic and the paint, "b"
// (paint only, 20%) has the lower mean; "a" (both, 30%) is the best over all of them.
TEST(StudySummary, FindingsSayWhatAMeanCovers) {
    StudyConfiguration plastic = builtin("plastic-P1-a0.05"), paint = builtin("paint-a0.05-a1.3");
    paint.category = plastic.category;
    const std::vector<MetricRow> rows = a_everywhere_b_on_the_paint(plastic, paint);
    const Written w = summarize({plastic, paint}, {"a", "b"}, rows);
    EXPECT_NE(w.md.find("use **b** (on the 1 of 2 configurations it supports) — mean misplaced "
                        "energy 20.0%"),
              std::string::npos)
        << w.md;
    EXPECT_NE(w.md.find("Of the models that support all 2: **a** (30.0%). Then a (30.0%)."),
              std::string::npos)
        << w.md;
}

// The reference's own microsurface loss, per category and overall: means over incidences and
// channels, and the worst with where it is.
TEST(StudySummary, ReportsTheReferencesMicrosurfaceLoss) {
    const StudyConfiguration& plastic = builtin("plastic-P1-a0.05");
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    std::vector<MetricRow> rows;
    add_rows(rows, plastic, "a", true, 0.5);
    add_rows(rows, paint, "a", true, 0.1);
    const ReferenceLoss lost = {{plastic.id, {Rgbd(0.1, 0.2, 0.3)}},
                                {paint.id, {Rgbd(0.0, 0.0, 0.9)}}};

    const Written w = summarize({plastic, paint}, {"a"}, rows, lost);
    const nlohmann::json& j = w.json["reference_lost_microsurface"];
    EXPECT_NEAR(j[plastic.category]["mean"].get<double>(), 0.2, 1e-12);
    EXPECT_NEAR(j[paint.category]["mean"].get<double>(), 0.3, 1e-12);
    EXPECT_NEAR(j["all"]["mean"].get<double>(), 0.25, 1e-12);
    EXPECT_NEAR(j["all"]["worst"].get<double>(), 0.9, 1e-12);
    EXPECT_EQ(j["all"]["worst_at"]["config"], paint.id);
    EXPECT_EQ(j["all"]["worst_at"]["channel"], "b");
    EXPECT_EQ(j[plastic.category]["worst_at"]["channel"], "b");
    EXPECT_NE(w.md.find("lose, on average over incidences and channels, plastic 20.0%, "
                        "metallic-paint 30.0% of the incident energy (worst 90.0%: " +
                        paint.id + ", θi 30°, b)"),
              std::string::npos)
        << w.md;
}

// The ranking is by misplaced_floor, not by the relative misplaced energy. Model "a" misplaces
// 300% of a lobe holding 1% of the light (3% of the light: misplaced_floor 0.03 / 0.05 = 60%);
// model "b" misplaces 80% of a lobe above 5% (both metrics 80%). Relative, a is worse; floored,
// a is better, and ranks first.
TEST(StudySummary, RanksByMisplacedFloorAndKeepsTheRelativeMetricBeside) {
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    std::vector<MetricRow> rows;
    add_rows(rows, paint, "a", true, 3.0, 0.6);
    add_rows(rows, paint, "b", true, 0.8, 0.8);
    const Written w = summarize({paint}, {"b", "a"}, rows);
    const nlohmann::json& g = w.json["groups"][paint.category];
    EXPECT_EQ(g["ranking"], (nlohmann::json{"a", "b"}));
    EXPECT_NEAR(g["models"]["a"]["mean_misplaced_floor"].get<double>(), 0.6, 1e-12);
    EXPECT_NEAR(g["models"]["a"]["mean_misplaced_energy"].get<double>(), 3.0, 1e-12);
    EXPECT_NEAR(g["models"]["a"]["mean_misplaced_floor_noise"].get<double>(), 0.01, 1e-12);
    EXPECT_EQ(w.json["ranking_metric"], "misplaced_floor");
    EXPECT_EQ(w.json["common"]["ranking"], (nlohmann::json{"a", "b"}));
    // Both are challenging (above 20% and twice the noise floor); the best is a, at 60%.
    ASSERT_EQ(w.json["challenging"].size(), 1u);
    EXPECT_EQ(w.json["challenging"][0]["best_model"], "a");
    EXPECT_NEAR(w.json["challenging"][0]["best_mean_misplaced_floor"].get<double>(), 0.6, 1e-12);
    EXPECT_NE(w.md.find("use **a** — mean misplaced energy 60.0% (noise floor 1.0%; relative "
                        "300.0%)"),
              std::string::npos)
        << w.md;
}

// What `lamina study` prints is the Findings section of summary.md, from the same findings.
TEST(StudySummary, HeadlineIsTheFindingsSectionOfTheMarkdown) {
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    std::vector<MetricRow> rows;
    add_rows(rows, paint, "a", true, 0.1);
    const Written w = summarize({paint}, {"a"}, rows);
    const std::string headline = findings_headline(w.findings);
    EXPECT_EQ(headline.rfind("## Findings\n", 0), 0u);
    EXPECT_NE(w.md.find(headline), std::string::npos);
    EXPECT_EQ(findings_markdown(w.findings), w.md);
}

}  // namespace
}  // namespace lamina

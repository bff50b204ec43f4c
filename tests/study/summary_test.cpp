// The summary's aggregates on hand-made metric rows: rankings per group, over the configurations
// each model supports, and like for like over the configurations every model supports.
#include "study/summary.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
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
void add_rows(std::vector<MetricRow>& rows, const StudyConfiguration& c, const std::string& model,
              bool supported, double misplaced_energy) {
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
        r.metrics.albedo_error = supported ? misplaced_energy : NAN;
        r.floor.misplaced_energy = 0.01;
        rows.push_back(r);
    }
}

// Writes the summary of `rows` (one incidence, θi = 30°) into a fresh folder and reads it back.
struct Written {
    nlohmann::json json;
    std::string md;
};
Written summarize(const std::vector<StudyConfiguration>& configs,
                  const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                  const ReferenceLoss& lost = {}) {
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "lamina-summary-test";
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    StudySettings s;
    s.theta_i_deg = {30};
    write_summary(dir, configs, s, models, rows, lost);
    Written w;
    std::ifstream in(dir / "summary.json");
    w.json = nlohmann::json::parse(in);
    std::ifstream md_in(dir / "summary.md");
    w.md.assign(std::istreambuf_iterator<char>(md_in), std::istreambuf_iterator<char>());
    std::filesystem::remove_all(dir);
    return w;
}

// Model "a" supports a plastic (where it misplaces 50%) and a paint (10%); model "b" supports
// only the paint (20%). Over what each supports, b (20%) ranks before a (30%); like for like, on
// the paint alone, a (10%) ranks before b (20%).
TEST(StudySummary, LikeForLikeRankingUsesOnlyConfigurationsEveryModelSupports) {
    const StudyConfiguration& plastic = builtin("plastic-P1-a0.05");
    const StudyConfiguration& paint = builtin("paint-a0.05-a1.3");
    std::vector<MetricRow> rows;
    add_rows(rows, plastic, "a", true, 0.5);
    add_rows(rows, plastic, "b", false, 0);
    add_rows(rows, paint, "a", true, 0.1);
    add_rows(rows, paint, "b", true, 0.2);

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

}  // namespace
}  // namespace lamina

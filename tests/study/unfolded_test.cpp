// The study on the unfolded grid: an anisotropic configuration's incidences, its grid, the
// metrics' solid angles there, the brushed category, and a tiny brushed study end to end.
#include "study/configurations.h"
#include "study/metrics.h"
#include "study/reference.h"
#include "study/study.h"
#include "support/stacks.h"

#include "models/numerics/binned.h"
#include "models/registry.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace lamina {
namespace {

Stack gold_under_coat() {
    return test::make_stack(
        {test::dielectric_layer(1.5, 0.1),
         test::conductor_layer(Rgbd(0.143, 0.374, 1.442), Rgbd(3.983, 2.385, 1.603), 0.2)});
}

// Every metric of a against b, relative to their size.
void expect_same_metrics(const LobeMetrics& a, const LobeMetrics& b, double rel) {
    auto near = [&](double x, double y, const char* what) {
        EXPECT_NEAR(x, y, rel * std::max(std::abs(x), std::abs(y)) + 1e-15) << what;
    };
    near(a.misplaced_energy, b.misplaced_energy, "misplaced_energy");
    near(a.misplaced_floor, b.misplaced_floor, "misplaced_floor");
    near(a.albedo_ref, b.albedo_ref, "albedo_ref");
    near(a.albedo_model, b.albedo_model, "albedo_model");
    near(a.albedo_error, b.albedo_error, "albedo_error");
    near(a.rmse, b.rmse, "rmse");
    near(a.log_rmse, b.log_rmse, "log_rmse");
}

// The unfolded grid holds each folded bin as two mirror patches of half its Ω⊥: for an isotropic
// stack lit from φi = 0 (mirror-symmetric about the plane of incidence) every metric — sums of
// f Ω⊥ and of Ω⊥-weighted squares — is the folded one. Two models against each other, so that the
// metrics are not zero; a wrong Ω⊥ (the folded one counted on each patch, or a patch's Ω⊥ with
// φ's span of the folded grid) doubles the albedos and leaves the rmse's weights unequal.
TEST(StudyUnfolded, MetricsOfAnIsotropicStackAreTheFoldedOnes) {
    const Stack stack = gold_under_coat();
    const auto a = make_model("openpbr", stack);
    const auto b = make_model("ww09", stack);
    const HemisphereGrid folded(9, 8), unfolded = folded.unfolded();
    ASSERT_TRUE(unfolded.is_unfolded());
    for (double theta_i : {0.0, 30.0, 70.0}) {
        const BinnedTable fa = bin_model(*a, folded, {theta_i});
        const BinnedTable fb = bin_model(*b, folded, {theta_i});
        const BinnedTable ua = bin_model(*a, unfolded, {theta_i}, 0.0);
        const BinnedTable ub = bin_model(*b, unfolded, {theta_i}, 0.0);
        for (int c = 0; c < 3; ++c) {
            const LobeMetrics mf = lobe_metrics(folded, fa.lobe(0, Side::Reflection).f,
                                                fb.lobe(0, Side::Reflection).f, c);
            const LobeMetrics mu = lobe_metrics(unfolded, ua.lobe(0, Side::Reflection).f,
                                                ub.lobe(0, Side::Reflection).f, c);
            ASSERT_GT(mf.misplaced_energy, 1e-3);  // the two models differ
            // Each patch's value is the folded bin's up to the quadrature's rounding.
            expect_same_metrics(mf, mu, 1e-9);
        }
    }
}

// Lit from φi = 90°, an isotropic stack's unfolded table is the φi = 0 one turned by a quarter
// turn (a quarter of the unfolded φ bins, 16 / 4): the metrics are the same.
TEST(StudyUnfolded, MetricsOfAnIsotropicStackDoNotDependOnTheAzimuth) {
    const Stack stack = gold_under_coat();
    const auto a = make_model("openpbr", stack);
    const auto b = make_model("ww09", stack);
    const HemisphereGrid unfolded = HemisphereGrid(9, 8).unfolded();
    for (int c = 0; c < 3; ++c) {
        LobeMetrics m[2];
        for (int k = 0; k < 2; ++k) {
            const double phi_i = k == 0 ? 0.0 : 90.0;
            const BinnedTable ta = bin_model(*a, unfolded, {45.0}, phi_i);
            const BinnedTable tb = bin_model(*b, unfolded, {45.0}, phi_i);
            m[k] = lobe_metrics(unfolded, ta.lobe(0, Side::Reflection).f,
                                tb.lobe(0, Side::Reflection).f, c);
        }
        expect_same_metrics(m[0], m[1], 1e-6);
    }
}

TEST(StudyUnfolded, IncidencesOfAnAnisotropicStackTurnTheLight) {
    SimulationSettings s;
    s.theta_i_deg = {0, 30, 60};
    const Stack iso = gold_under_coat();
    Stack aniso = iso;
    aniso.layers[1].interface = anisotropic(aniso.layers[1].interface, 0.05, 0.3, 45);
    const auto inc = study_incidences(iso, s);
    ASSERT_EQ(inc.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
        EXPECT_EQ(inc[i].theta_i, s.theta_i_deg[i]);
        EXPECT_EQ(inc[i].phi_i, 0.0);
    }
    EXPECT_FALSE(study_grid(iso, s).is_unfolded());
    // θi = 0 once (every azimuth is the same light), then each θi at 0°, 45° and 90°.
    const auto a = study_incidences(aniso, s);
    ASSERT_EQ(a.size(), 7u);
    EXPECT_EQ(a[0].theta_i, 0.0);
    EXPECT_EQ(a[0].phi_i, 0.0);
    for (std::size_t k = 0; k < 3; ++k) {
        EXPECT_EQ(a[1 + k].theta_i, 30.0);
        EXPECT_EQ(a[1 + k].phi_i, kAnisotropicPhiIDeg[k]);
        EXPECT_EQ(a[4 + k].theta_i, 60.0);
        EXPECT_EQ(a[4 + k].phi_i, kAnisotropicPhiIDeg[k]);
    }
    EXPECT_EQ(study_grid(aniso, s), s.grid.unfolded());
    // --phi-i ≠ 0 unfolds an isotropic configuration, lit from there.
    s.phi_i_deg = 20;
    EXPECT_TRUE(study_grid(iso, s).is_unfolded());
    for (const StudyIncidence& i : study_incidences(iso, s))
        EXPECT_EQ(i.phi_i, 20.0);
}

TEST(StudyUnfolded, ReferenceKeySaysTheAzimuthOnlyAwayFromZero) {
    SimulationSettings s;
    const Stack stack = gold_under_coat();
    const ReferenceKey k0 = reference_key("c", stack, 30, s);
    EXPECT_EQ(reference_key("c", stack, 30, s, 0.0).canonical(), k0.canonical());
    EXPECT_EQ(reference_key("c", stack, 30, s, 0.0).file_name(), k0.file_name());
    const ReferenceKey k45 = reference_key("c", stack, 30, s, 45.0);
    // The azimuth is said (and auto takes the SIMD kernel there too, which traces φi ≠ 0); at 0
    // it is not.
    EXPECT_NE(k45.canonical().find(" | phi_i 45"), std::string::npos) << k45.canonical();
    EXPECT_NE(k45.canonical().find(" | kernel " + kernel_description(Kernel::Simd)),
              std::string::npos)
        << k45.canonical();
    EXPECT_EQ(k0.canonical().find("phi_i"), std::string::npos) << k0.canonical();
    EXPECT_EQ(k45.file_name().rfind("theta30-phi45-n", 0), 0u) << k45.file_name();
    EXPECT_TRUE(k45.grid().is_unfolded());
    EXPECT_FALSE(k0.grid().is_unfolded());
}

// docs/study.md, "The brushed category": anisotropic metals under clear coats, stable ids, valid
// stacks, in the standard and paper presets only.
TEST(StudyConfigurations, BrushedInTheLargerPresetsOnly) {
    const auto brushed = brushed_configurations();
    ASSERT_EQ(brushed.size(), 8u);
    std::set<std::string> ids;
    std::set<double> turns;
    for (const auto& c : brushed) {
        EXPECT_TRUE(ids.insert(c.id).second) << c.id;
        EXPECT_EQ(c.category, "brushed");
        ASSERT_EQ(c.stack.layers.size(), 2u);
        EXPECT_EQ(c.stack.layers[0].interface.eta, 1.5);
        const InterfaceSpec& base = c.stack.layers[1].interface;
        EXPECT_EQ(base.type, InterfaceType::Conductor);
        EXPECT_TRUE(base.is_anisotropic()) << c.id;
        EXPECT_LT(base.alpha, base.alpha_b()) << c.id;  // brushed along the tangent
        if (c.stack.layers[0].interface.is_anisotropic())
            turns.insert(base.tangent_deg - c.stack.layers[0].interface.tangent_deg);
        EXPECT_EQ(stack_from_json(stack_to_json(c.stack), c.id), c.stack) << c.id;
        EXPECT_TRUE(c.parameters.at("alpha1").find("×") != std::string::npos) << c.id;
    }
    EXPECT_EQ(turns, (std::set<double>{0, 45, 90}));  // coat and metal aligned, at 45°, crossed
    for (const StudyConfiguration& c : preset_configurations("quick"))
        EXPECT_NE(c.category, "brushed") << c.id;
    for (const char* preset : {"standard", "paper"}) {
        const auto all = preset_configurations(preset);
        ASSERT_EQ(all.size(), 76u);  // and the dispersive category's two (metrics_test.cpp)
        EXPECT_EQ(all[73].id, brushed.back().id);
    }
}

std::string read_text(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// A tiny brushed study end to end (few particles: the metrics are not judged, their presence is):
// every incidence of the configuration is compared, a model that does not represent anisotropy
// is "not supported", the files record the unfolded grid and the incidences, and a re-run reads
// everything back.
TEST(StudyUnfolded, TinyBrushedStudyRunsEndToEnd) {
    const std::filesystem::path dir =
        std::filesystem::path(LAMINA_BINARY_DIR) / "test-output" / "brushed-study";
    std::filesystem::remove_all(dir);
    std::vector<StudyConfiguration> configs =
        filter_configurations(brushed_configurations(), "brushed-al-a0.05x.2-a1.05x.3-t90");
    ASSERT_EQ(configs.size(), 1u);
    StudySettings s;
    s.models = {"openpbr", "bel-prime"};  // bel-prime: no anisotropy
    s.reference.theta_i_deg = {0, 45};
    s.reference.particles = 20'000;
    s.reference.grid = HemisphereGrid(9, 6);
    s.quiet = true;
    const StudyResult r = run_study(configs, s, dir);
    // 2 models × 4 incidences ((0, 0), (45, 0), (45, 45), (45, 90)) × R × 3 channels.
    ASSERT_EQ(r.rows.size(), 24u);
    std::set<std::pair<double, double>> incidences;
    for (const MetricRow& row : r.rows) {
        incidences.insert({row.theta_i, row.phi_i});
        if (row.model == "bel-prime") {
            EXPECT_FALSE(row.supported);
        } else {
            EXPECT_TRUE(row.supported);
            EXPECT_TRUE(std::isfinite(row.metrics.misplaced_floor));
            EXPECT_GT(row.metrics.albedo_ref, 0.1);  // aluminium reflects most of the light
        }
    }
    EXPECT_EQ(incidences,
              (std::set<std::pair<double, double>>{{0, 0}, {45, 0}, {45, 45}, {45, 90}}));
    EXPECT_EQ(r.work.reference_pieces_computed, 4u);
    const std::string csv = read_text(dir / "metrics.csv");
    EXPECT_EQ(csv.rfind("config,category,model,theta_i,phi_i,side,channel,", 0), 0u);
    EXPECT_NE(csv.find("\nbrushed-al-a0.05x.2-a1.05x.3-t90,brushed,bel-prime,45,90,R,b,,,,,,,,,,"
                       "false\n"),
              std::string::npos);
    const nlohmann::json cj = nlohmann::json::parse(
        read_text(dir / "configs" / "brushed-al-a0.05x.2-a1.05x.3-t90" / "config.json"));
    EXPECT_EQ(cj.at("grid"), "9x6 unfolded");
    EXPECT_EQ(cj.at("theta_i"), nlohmann::json({0, 45, 45, 45}));
    EXPECT_EQ(cj.at("phi_i"), nlohmann::json({0, 0, 45, 90}));
    EXPECT_EQ(cj.at("tables").at("shape"), nlohmann::json({3, 4, 1, 9, 12, 3}));
    EXPECT_EQ(cj.at("supported").at("bel-prime").at("R"), false);
    const nlohmann::json sj = nlohmann::json::parse(read_text(dir / "study.json"));
    EXPECT_EQ(sj.at("configurations").at(0).at("grid"), "9x6 unfolded");
    EXPECT_EQ(sj.at("configurations").at(0).at("incidences").size(), 4u);
    // The summary ranks the category; bel-prime is not supported there, not failing.
    const GroupFindings* g = r.findings.group("brushed");
    ASSERT_NE(g, nullptr);
    EXPECT_EQ(g->ranking, std::vector<std::string>{"openpbr"});
    EXPECT_EQ(g->models.at("openpbr").rows, 12);
    EXPECT_EQ(r.findings.not_supported.at("bel-prime").at(configs[0].id), "R");
    const std::string summary = read_text(dir / "summary.md");
    EXPECT_NE(summary.find("**brushed**"), std::string::npos);

    const StudyResult again = run_study(configs, s, dir);
    EXPECT_EQ(again.work.reference_pieces_computed, 0u);
    EXPECT_EQ(again.work.model_tables_computed, 0u);
    EXPECT_EQ(again.work.configurations_unchanged, 1u);
    ASSERT_EQ(again.rows.size(), r.rows.size());
    for (std::size_t k = 0; k < r.rows.size(); ++k) {
        EXPECT_EQ(again.rows[k].phi_i, r.rows[k].phi_i);
        EXPECT_EQ(again.rows[k].theta_i, r.rows[k].theta_i);
    }
    EXPECT_EQ(read_text(dir / "metrics.csv"), csv);
    // A fresh model pass over the cached reference (recompute) gives the same metrics bit for bit.
    s.recompute = true;
    run_study(configs, s, dir);
    EXPECT_EQ(read_text(dir / "metrics.csv"), csv);
}

}  // namespace
}  // namespace lamina

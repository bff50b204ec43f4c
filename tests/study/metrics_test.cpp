// The study's metrics on hand-computed tables.
#include "study/metrics.h"
#include "study/configurations.h"
#include "study/reference.h"
#include "support/stacks.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace lamina {
namespace {

std::vector<Rgbd> constant(const HemisphereGrid& grid, double v) {
    return std::vector<Rgbd>(grid.size(), Rgbd(v));
}

TEST(StudyMetrics, IdenticalTablesHaveNoError) {
    const HemisphereGrid grid(9, 9);
    std::vector<Rgbd> f(grid.size());
    for (std::size_t j = 0; j < f.size(); ++j)
        f[j] = Rgbd(0.1 * (j % 7), 0.2, 0.01 * j);
    for (int c = 0; c < 3; ++c) {
        const LobeMetrics m = lobe_metrics(grid, f, f, c);
        EXPECT_EQ(m.misplaced_energy, 0.0);
        EXPECT_EQ(m.albedo_error, 0.0);
        EXPECT_EQ(m.rmse, 0.0);
        EXPECT_EQ(m.log_rmse, 0.0);
    }
}

TEST(StudyMetrics, DoubleTheEnergyMisplacesAllOfIt) {
    // f = 2 f̂ everywhere: Σ|f − f̂|Ω⊥ / Σ f̂Ω⊥ = 1 and the albedo error is +100%.
    const HemisphereGrid grid(9, 9);
    const auto ref = constant(grid, 1 / kPi<double>);  // a white Lambertian: albedo exactly 1
    const auto model = constant(grid, 2 / kPi<double>);
    const LobeMetrics m = lobe_metrics(grid, ref, model, 0);
    EXPECT_NEAR(m.misplaced_energy, 1.0, 1e-12);
    EXPECT_NEAR(m.albedo_ref, 1.0, 1e-12);  // Σ Ω⊥ over the hemisphere is π
    EXPECT_NEAR(m.albedo_error, 1.0, 1e-12);
    // Weighted RMSE of a constant offset 1/π is 1/π; log-RMSE of log(1+2/π) − log(1+1/π).
    EXPECT_NEAR(m.rmse, 1 / kPi<double>, 1e-12);
    EXPECT_NEAR(m.log_rmse, std::log1p(2 / kPi<double>) - std::log1p(1 / kPi<double>), 1e-12);
}

TEST(StudyMetrics, MovedEnergyIsMisplacedTwice) {
    // Moving a fraction q of the energy from one half of the bins to the other keeps the albedo
    // and misplaces 2q: what leaves one place and arrives elsewhere both count.
    const HemisphereGrid grid(2, 1);  // two θ bins with Ω⊥ = π/2 each (sin² 45° = 1/2)
    const std::vector<Rgbd> ref = {Rgbd(1.0), Rgbd(1.0)};
    const std::vector<Rgbd> model = {Rgbd(1.25), Rgbd(0.75)};
    const LobeMetrics m = lobe_metrics(grid, ref, model, 1);
    EXPECT_NEAR(m.albedo_error, 0.0, 1e-15);
    EXPECT_NEAR(m.misplaced_energy, 0.25, 1e-15);  // (0.25 + 0.25)·π/2 / (2·π/2)
}

TEST(StudyMetrics, EmptyReferenceHasNoRelativeError) {
    const HemisphereGrid grid(3, 3);
    const LobeMetrics m = lobe_metrics(grid, constant(grid, 0), constant(grid, 0.1), 0);
    EXPECT_TRUE(std::isnan(m.misplaced_energy));
    EXPECT_TRUE(std::isnan(m.albedo_error));
    EXPECT_GT(m.rmse, 0);
}

// misplaced_floor = Σ|f − f̂|Ω⊥ / max(Σ f̂Ω⊥, 0.05). Constant lobes on the whole hemisphere
// (Σ Ω⊥ = π): a lobe c/π has the albedo c.
TEST(StudyMetrics, MisplacedFloorIsRelativeAboveFivePercentOfTheLight) {
    const HemisphereGrid grid(9, 9);
    // Reference albedo 0.4, model 0.5: 0.1 misplaced, 25% of the reference's energy in both.
    const LobeMetrics m =
        lobe_metrics(grid, constant(grid, 0.4 / kPi<double>), constant(grid, 0.5 / kPi<double>), 2);
    EXPECT_NEAR(m.misplaced_energy, 0.25, 1e-12);
    EXPECT_NEAR(m.misplaced_floor, 0.25, 1e-12);
    // At exactly 5% the two agree too: 0.05 against 0.06 misplaces 0.01, 20%.
    const LobeMetrics e = lobe_metrics(grid, constant(grid, 0.05 / kPi<double>),
                                       constant(grid, 0.06 / kPi<double>), 0);
    EXPECT_NEAR(e.misplaced_energy, 0.2, 1e-12);
    EXPECT_NEAR(e.misplaced_floor, 0.2, 1e-12);
}

TEST(StudyMetrics, MisplacedFloorIsRelativeToFivePercentBelowIt) {
    const HemisphereGrid grid(9, 9);
    // Reference albedo 0.01, model 0.03: 0.02 misplaced, 200% of the reference's energy but 40%
    // of the 5% floor.
    const LobeMetrics m = lobe_metrics(grid, constant(grid, 0.01 / kPi<double>),
                                       constant(grid, 0.03 / kPi<double>), 1);
    EXPECT_NEAR(m.misplaced_energy, 2.0, 1e-12);
    EXPECT_NEAR(m.misplaced_floor, 0.4, 1e-12);
    // Moving energy within a faint lobe: two θ bins of Ω⊥ = π/2, reference 0.01 in each (albedo
    // 0.01π < 0.05), the model moves 0.005 from one to the other: Σ|Δ|Ω⊥ = 2 · 0.005 · π/2.
    const HemisphereGrid two(2, 1);
    const LobeMetrics moved =
        lobe_metrics(two, {Rgbd(0.01), Rgbd(0.01)}, {Rgbd(0.015), Rgbd(0.005)}, 0);
    EXPECT_NEAR(moved.misplaced_energy, 0.5, 1e-12);  // 0.005π / 0.01π
    EXPECT_NEAR(moved.misplaced_floor, 0.005 * kPi<double> / 0.05, 1e-12);
    // An empty reference: the relative metric has no value, the floored one is the model's
    // whole energy over 5%.
    const LobeMetrics empty =
        lobe_metrics(grid, constant(grid, 0), constant(grid, 0.02 / kPi<double>), 0);
    EXPECT_TRUE(std::isnan(empty.misplaced_energy));
    EXPECT_NEAR(empty.misplaced_floor, 0.4, 1e-12);
}

TEST(StudyMetrics, NoiseFloorOfMisplacedFloorIsHalfTheHalvesDifference) {
    const HemisphereGrid grid(9, 9);
    // Halves of albedo 0.01 and 0.02: 0.01 apart, 0.2 of the 5% floor; halved, 0.1.
    const LobeMetrics f = noise_floor(grid, constant(grid, 0.01 / kPi<double>),
                                      constant(grid, 0.02 / kPi<double>), 0);
    EXPECT_NEAR(f.misplaced_floor, 0.1, 1e-12);
    EXPECT_NEAR(f.misplaced_energy, 0.5, 1e-12);  // 0.01 / 0.01, halved
}

// A reference piece stored before misplaced_floor existed has none in its floor: it is derived
// from what the piece holds, and equals the one computed with the piece.
TEST(StudyMetrics, OldReferencePiecesGetTheirMisplacedFloorNoise) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(0.8, 0.3, 0.02))});
    SimulationSettings s;
    s.particles = 4000;
    s.seed = 3;
    s.grid = HemisphereGrid(6, 6);
    s.kernel = Kernel::Scalar;
    const ReferenceKey key = reference_key("old", stack, 30, s);
    std::string bytes = compute_reference_piece(key, 1, [](std::uint64_t) {});
    const std::size_t eol = bytes.find('\n', bytes.find('\n') + 1);
    std::string meta = bytes.substr(0, eol);
    std::size_t removed = 0;
    for (std::size_t at; (at = meta.find("\"misplaced_floor\":")) != std::string::npos; ++removed) {
        const std::size_t end = meta.find(',', at);
        meta.erase(at, end + 1 - at);
    }
    ASSERT_EQ(removed, 6u);  // 2 sides × 3 channels
    const std::filesystem::path dir =
        std::filesystem::temp_directory_path() / "lamina-old-piece-test";
    std::filesystem::remove_all(dir);
    const ReferencePiece now = store_reference_piece(dir, key, bytes);
    const ReferencePiece old = store_reference_piece(dir, key, meta + bytes.substr(eol));
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(now.floor[0][c].misplaced_floor, 0);
        EXPECT_NEAR(old.floor[0][c].misplaced_floor, now.floor[0][c].misplaced_floor,
                    1e-12 * now.floor[0][c].misplaced_floor);
    }
    std::filesystem::remove_all(dir);
}

// The noise floor shrinks as 1/√N, and matches its expected value. For a white-ish Lambertian each
// particle lands in bin j with probability p_j = Ω⊥_j/π carrying flux ρ, so a half-reference of n
// particles estimates f_j with relative standard deviation s_j = √((1 − p_j)/(n p_j)); the halves'
// relative difference D_j has √2 s_j. The floor Σ_j p_j |D_j| / 2 (normalizing by the reference
// energy, whose own noise is negligible) has mean Σ p_j √(2/π) √2 s_j / 2 and standard deviation
// √(Σ p_j² 2 s_j² (1 − 2/π)) / 2 (|Z| of a normal Z has mean √(2/π), variance 1 − 2/π).
TEST(StudyMetricsStat, NoiseFloorShrinksAsOneOverSqrtN) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(0.8))});
    const HemisphereGrid grid(9, 9);
    auto floor_at = [&](std::uint64_t n) {
        SimulationSettings s;
        s.theta_i_deg = {30};
        s.grid = grid;
        s.particles = n;
        s.seed = 11;
        const auto a = simulate(stack, s);
        s.seed = second_half_seed(11);
        const auto b = simulate(stack, s);
        return noise_floor(grid, a.table.lobe(0, Side::Reflection).f,
                           b.table.lobe(0, Side::Reflection).f, 0)
            .misplaced_energy;
    };
    auto expected = [&](double n, double* sd) {
        double mean = 0, var = 0;
        for (std::size_t j = 0; j < grid.size(); ++j) {
            const double p = grid.projected_solid_angle(j) / kPi<double>;
            const double s_d = std::sqrt(2 * (1 - p) / (n * p));  // of the halves' difference
            mean += p * std::sqrt(2 / kPi<double>) * s_d / 2;
            var += p * p * s_d * s_d * (1 - 2 / kPi<double>) / 4;
        }
        *sd = std::sqrt(var);
        return mean;
    };
    double sd1, sd4;
    const double e1 = expected(40'000, &sd1), e4 = expected(160'000, &sd4);
    const double f1 = floor_at(40'000), f4 = floor_at(160'000);
    EXPECT_NEAR(f1, e1, 4 * sd1);
    EXPECT_NEAR(f4, e4, 4 * sd4);
    // The ratio is 2 to within the propagated 4σ.
    const double ratio_sd = 2 * std::hypot(sd1 / e1, sd4 / e4);
    EXPECT_NEAR(f1 / f4, 2.0, 4 * ratio_sd) << f1 << " " << f4;
}

TEST(StudyConfigurations, SixtyWithStableUniqueIds) {
    const auto configs = builtin_configurations();
    ASSERT_EQ(configs.size(), 60u);
    std::set<std::string> ids;
    std::map<std::string, int> per_category;
    for (const auto& c : configs) {
        EXPECT_TRUE(ids.insert(c.id).second) << c.id;
        ++per_category[c.category];
        EXPECT_EQ(c.stack.layers.size(), 2u);
        EXPECT_EQ(c.stack.layers[0].interface.eta, 1.5);
    }
    EXPECT_EQ(per_category["plastic"], 20);
    EXPECT_EQ(per_category["metallic-paint"], 10);
    EXPECT_EQ(per_category["frosted-metal"], 10);
    EXPECT_EQ(per_category["slab"], 20);
    // docs/study.md's example ids.
    EXPECT_TRUE(ids.count("plastic-P1-a0.05"));
    EXPECT_TRUE(ids.count("paint-a0.001-a1.3"));
    const auto only = filter_configurations(configs, "slab-*-tinted");
    EXPECT_EQ(only.size(), 10u);
    EXPECT_THROW(filter_configurations(configs, "nothing*"), InputError);
}

// The parameters name the top coat and the base; a stack with more layers says how many, so that
// nothing reads it as one coat over a base (the explorer's live lamina-coat).
TEST(StudyConfigurations, ParametersCountTheLayersOfALongerStack) {
    const Layer base = test::lambertian_layer(Rgbd(0.8));
    const Stack two = test::make_stack({test::dielectric_layer(1.5, 0.1), base});
    const Stack three = test::make_stack(
        {test::dielectric_layer(1.5, 0.1), test::dielectric_layer(1.3, 0.2), base});
    EXPECT_EQ(describe_parameters(two).count("layers"), 0u);
    EXPECT_EQ(describe_parameters(three).at("layers"), "3");
    for (const StudyConfiguration& c : preset_configurations("paper"))
        EXPECT_EQ(c.parameters.count("layers"), 0u) << c.id;  // the study's stacks are coat + base
}

// docs/study.md, "The iridescent category": six clear coats over filmed metals, stable ids,
// valid stacks (the reader's ranges, through its JSON round trip), added by the larger presets;
// the quick one adds three of them, after the 60: the film on a rough metal, the interference
// pigment under a rough coat, the absorbing oxide.
TEST(StudyConfigurations, IridescentInEveryPresetThreeInTheQuickOne) {
    const auto irid = iridescent_configurations();
    ASSERT_EQ(irid.size(), 6u);
    for (const auto& c : irid) {
        EXPECT_EQ(c.category, "iridescent");
        ASSERT_EQ(c.stack.layers.size(), 2u);
        EXPECT_EQ(c.stack.layers[0].interface.eta, 1.5);
        EXPECT_TRUE(c.stack.layers[1].interface.has_film) << c.id;
        // A measured metal: the reference traces the stack's spectrum.
        EXPECT_FALSE(c.stack.layers[1].interface.material.empty()) << c.id;
        EXPECT_TRUE(c.stack.is_spectral()) << c.id;
        EXPECT_EQ(c.parameters.at("metal"), c.stack.layers[1].interface.material);
        EXPECT_EQ(c.parameters.at("eta1"), c.parameters.at("metal") + " (measured)");
        EXPECT_EQ(stack_from_json(stack_to_json(c.stack), c.id), c.stack) << c.id;
        EXPECT_TRUE(c.parameters.count("film_nm")) << c.id;
    }
    const auto quick = preset_configurations("quick");
    ASSERT_EQ(quick.size(), 63u);
    EXPECT_EQ(quick[59].category, "slab");
    EXPECT_EQ(quick[60].id, "irid-ti-oxide-a0.05-a1.3");
    EXPECT_EQ(quick[61].id, "irid-gold-film-a0.3-a1.05");
    EXPECT_EQ(quick[62].id, "irid-fe-temper-a0.05-a1.1");
    const auto quick_irid = iridescent_configurations(true);
    ASSERT_EQ(quick_irid.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i)
        EXPECT_EQ(stack_to_json(quick_irid[i].stack), stack_to_json(quick[60 + i].stack));
    for (const char* preset : {"standard", "paper"}) {
        const auto all = preset_configurations(preset);
        ASSERT_EQ(all.size(), 76u);  // the brushed category's eight (unfolded_test.cpp), the
                                     // dispersive category's two (below)
        EXPECT_EQ(all[65].id, irid.back().id);
    }
}

// docs/study.md, "The dispersive category": the slab's glass over air with a dense flint's index as
// a spectrum, smooth and rough, last in the larger presets. The index is the two-term Cauchy
// formula through n_d = 1.785 at the helium d line with V_d = 25.7 (ISO 7944), checked here
// against its own definition: (n_d − 1)/(n_F − n_C) at 587.56, 486.13 and 656.27 nm.
TEST(StudyConfigurations, DispersiveInTheLargerPresetsOnly) {
    const auto disp = dispersive_configurations();
    ASSERT_EQ(disp.size(), 2u);
    for (const auto& c : disp) {
        EXPECT_EQ(c.category, "dispersive");
        ASSERT_EQ(c.stack.layers.size(), 2u);
        const InterfaceSpec& glass = c.stack.layers[0].interface;
        ASSERT_TRUE(glass.eta_spectrum.has_value()) << c.id;
        EXPECT_TRUE(c.stack.is_spectral()) << c.id;
        const Spectrum& n = *glass.eta_spectrum;
        EXPECT_NEAR(n.at(587.56), 1.785, 1e-9) << c.id;
        EXPECT_NEAR((n.at(587.56) - 1) / (n.at(486.13) - n.at(656.27)), 25.7, 1e-6) << c.id;
        EXPECT_GT(n.at(400), n.at(700));
        // The slab's exit: back to air.
        EXPECT_EQ(c.stack.layers[1].interface.type, InterfaceType::Dielectric);
        EXPECT_EQ(c.stack.layers[1].interface.eta, 1.0);
        EXPECT_TRUE(c.stack.transmits());
        EXPECT_EQ(stack_from_json(stack_to_json(c.stack), c.id), c.stack) << c.id;
    }
    EXPECT_EQ(filter_configurations(preset_configurations("quick"), "*").size(), 63u);
    for (const StudyConfiguration& c : preset_configurations("quick"))
        EXPECT_NE(c.category, "dispersive") << c.id;
    for (const char* preset : {"standard", "paper"}) {
        const auto all = preset_configurations(preset);
        ASSERT_EQ(all.size(), 76u);
        EXPECT_EQ(all[74].id, disp.front().id);
        EXPECT_EQ(all.back().id, disp.back().id);
    }
}

TEST(StudyReference, CachedPieceIsReusedAndAMismatchIsRecomputed) {
    const std::filesystem::path dir =
        std::filesystem::path(LAMINA_BINARY_DIR) / "test-output" / "reference-cache";
    std::filesystem::remove_all(dir);
    SimulationSettings s;
    s.particles = 20'000;
    s.seed = 5;
    s.grid = HemisphereGrid(9, 9);
    ReferenceKey key =
        reference_key("lambertian", test::make_stack({test::lambertian_layer(Rgbd(0.5))}), 30, s);
    bool computed = false;
    const ReferencePiece first = reference_piece(dir, key, 0, {}, &computed);
    EXPECT_TRUE(computed);
    const ReferencePiece again = reference_piece(dir, key, 0, {}, &computed);
    EXPECT_FALSE(computed);
    EXPECT_EQ(first.f[0], again.f[0]);
    EXPECT_EQ(first.se[0], again.se[0]);
    // A truncated file is never trusted.
    const auto file = dir / key.config_id / key.file_name();
    std::filesystem::resize_file(file, std::filesystem::file_size(file) - 7);
    const ReferencePiece redone = reference_piece(dir, key, 0, {}, &computed);
    EXPECT_TRUE(computed);
    EXPECT_EQ(first.f[0], redone.f[0]);
    // Another seed is another piece.
    key.settings.seed = 6;
    reference_piece(dir, key, 0, {}, &computed);
    EXPECT_TRUE(computed);
}

}  // namespace
}  // namespace lamina

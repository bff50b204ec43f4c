// Unity HDRP's StackLit coat (models/production/unity_stacklit.h): against Unity's own code (values
// recorded by running StackLit.hlsl transliterated outside the repository, provenance in
// tests/models/production/data/unity-stacklit.json), HDRP's FGD texture against the estimator and
// the integral it stands for, and the model's own properties (energy, reciprocity, sampling).
#include "models/production/unity_stacklit.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/model_checks.h"
#include "models/model_sampling.h"
#include "models/numerics/binned.h"
#include "models/production/filament_dfg.h"
#include "models/production/ggx_albedo.h"
#include "models/registry.h"
#include "models/test_stacks.h"
#include "support/closed_forms.h"

#include "models/production/golden_data.h"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <iostream>

namespace lamina {
namespace {

using nlohmann::json;
using test::coated;
using test::dir;

Stack stacklit_stack(const json& s) {
    const InterfaceSpec base =
        s.at("base") == "lambertian"
            ? test::lambertian(test::golden_rgb(s.at("rho")))
            : test::conductor(test::golden_rgb(s.at("eta1")), test::golden_rgb(s.at("kappa1")),
                              s.at("alpha1").get<double>());
    Stack stack = coated(s.at("eta0").get<double>(), s.at("alpha0").get<double>(), base,
                         test::golden_rgb(s.at("tau")));
    if (s.contains("alpha1_xy")) {  // an anisotropic base: [α_x, α_y] at tangent1_deg
        InterfaceSpec& b = stack.layers[1].interface;
        b = anisotropic(b, s.at("alpha1_xy").at(0).get<double>(),
                        s.at("alpha1_xy").at(1).get<double>(), s.at("tangent1_deg").get<double>());
    }
    return stack;
}

// The recorded inputs are docs/models.md's mapping of each stack: coat IOR η0, coat perceptual
// roughness √α0, thickness 1 with extinction τ; a metal's base colour its F0 against air
// F(1; η1, κ1), metallic 1, perceptual roughness √α1; a diffuse base's colour ρ, metallic 0,
// dielectric IOR η0 and StackLit's default perceptual roughness 0.5.
void expect_inputs_follow_the_mapping(const std::string& file) {
    for (const json& record : test::load_golden(file).at("stacks")) {
        const json &s = record.at("stack"), &in = record.at("inputs");
        const std::string id = record.at("id");
        const double eta0 = s.at("eta0");
        EXPECT_EQ(in.at("coat_ior").get<double>(), eta0) << id;
        EXPECT_NEAR(in.at("coat_perceptual_roughness").get<double>(),
                    std::sqrt(s.at("alpha0").get<double>()), 1e-12)
            << id;
        EXPECT_EQ(in.at("coat_thickness").get<double>(), 1) << id;
        EXPECT_EQ(in.at("coat_mask").get<double>(), 1) << id;
        EXPECT_EQ(in.at("lobe_mix").get<double>(), 0) << id;
        const Rgbd tau = test::golden_rgb(s.at("tau")),
                   ext = test::golden_rgb(in.at("coat_extinction")),
                   color = test::golden_rgb(in.at("base_color"));
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(ext[c], tau[c]) << id;
        if (s.at("base") == "lambertian") {
            EXPECT_EQ(in.at("metallic").get<double>(), 0) << id;
            EXPECT_EQ(in.at("dielectric_ior").get<double>(), eta0) << id;
            EXPECT_EQ(in.at("perceptual_roughness_a").get<double>(), 0.5) << id;
            const Rgbd rho = test::golden_rgb(s.at("rho"));
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(color[c], rho[c]) << id;
        } else {
            EXPECT_EQ(in.at("metallic").get<double>(), 1) << id;
            EXPECT_NEAR(in.at("perceptual_roughness_a").get<double>(),
                        std::sqrt(s.at("alpha1").get<double>()), 1e-12)
                << id;
            const Rgbd eta1 = test::golden_rgb(s.at("eta1")), k1 = test::golden_rgb(s.at("kappa1"));
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(color[c], test::conductor_ref(1, eta1[c], k1[c]), 1e-12) << id;
            if (s.contains("alpha1_xy")) {
                const double ax = s.at("alpha1_xy").at(0), ay = s.at("alpha1_xy").at(1);
                EXPECT_NEAR(s.at("alpha1").get<double>(), 0.5 * (ax + ay), 1e-12) << id;
                EXPECT_NEAR(in.at("anisotropy_a").get<double>(), (ax - ay) / (ax + ay), 1e-12)
                    << id;
                EXPECT_EQ(in.at("tangent_deg").get<double>(), s.at("tangent1_deg").get<double>())
                    << id;
            }
        }
    }
}
TEST(UnityStackLitGolden, InputsFollowTheMapping) {
    expect_inputs_follow_the_mapping("unity-stacklit.json");
    expect_inputs_follow_the_mapping("unity-stacklit-anisotropic.json");
}

// `unity-stacklit` against StackLit's code: every recorded pair of every stack to 1e-3 relative,
// every channel.
void expect_matches_its_code(const std::string& file) {
    const json data = test::load_golden(file);
    const json& pairs = data.at("pairs");
    double worst = 0;
    std::string where;
    for (const json& record : data.at("stacks")) {
        const auto m = make_model("unity-stacklit", stacklit_stack(record.at("stack")));
        ASSERT_TRUE(m->support().brdf) << record.at("id");
        for (std::size_t i = 0; i < pairs.size(); ++i) {
            const json& p = pairs.at(i);
            const Vec3d wi = dir(p.at(0), p.at(1)), wo = dir(p.at(2), p.at(3));
            const Rgbd want = test::golden_rgb(record.at("values").at(i)), got = m->eval(wi, wo);
            for (int c = 0; c < 3; ++c) {
                const double rel = std::abs(got[c] - want[c]) / std::abs(want[c]);
                EXPECT_LE(rel, 1e-3) << record.at("id") << " pair " << i << " channel " << c;
                if (rel > worst)
                    worst = rel, where = fmt::format("{} pair {} channel {}: {} against {}",
                                                     record.at("id").get<std::string>(), p.dump(),
                                                     c, got[c], want[c]);
            }
        }
    }
    std::cout << fmt::format("unity-stacklit ({}): worst relative difference {:.2e} ({})\n", file,
                             worst, where);
}
TEST(UnityStackLitGolden, MatchesItsCode) {
    expect_matches_its_code("unity-stacklit.json");
}
// At anisotropic settings: brushed metals (StackLit's anisotropy a = (α_x − α_y)/(α_x + α_y) of
// the base at its tangent, α = (α_x + α_y)/2), tangents at 0°–100° from the light's plane.
TEST(UnityStackLitGolden, MatchesItsCodeWhenAnisotropic) {
    expect_matches_its_code("unity-stacklit-anisotropic.json");
}

// --- HDRP's FGD texture ----------------------------------------------------------------------

using Fgd = UnityFgdTexture;

// A texel is the estimator's value at its node rounded to 10 bits; between nodes the texture
// interpolates bilinearly in (√μ, r); outside, its edges are clamped.
TEST(UnityFgdTexture, TexelsAndInterpolation) {
    const Fgd& t = Fgd::get();
    for (const auto& [i, j] : {std::pair{5, 7}, std::pair{40, 20}, std::pair{63, 63}}) {
        const double s = i / 63.0, r = j / 63.0;
        const double e =
            FilamentDfgTexture::estimate(s * s, r * r, Fgd::kSamples, HammersleyAzimuth::Second);
        EXPECT_EQ(t.texel(i, j), std::nearbyint(std::min(e, 1.0) * 1023) / 1023) << i << " " << j;
        EXPECT_NEAR(t.albedo(s * s, r), t.texel(i, j), 1e-12);
    }
    const double s = 40.5 / 63, r = 20.5 / 63;
    EXPECT_NEAR(t.albedo(s * s, r),
                0.25 * (t.texel(40, 20) + t.texel(41, 20) + t.texel(40, 21) + t.texel(41, 21)),
                1e-12);
    EXPECT_EQ(t.albedo(1.0, 1.5), t.texel(63, 63));
}

// Unity's estimator (4096 Hammersley points, the coordinates the other way round from
// Filament's) converges to the integral it stands for: within 2e-5 at 2^20 points.
TEST(UnityFgdTexture, EstimatorConvergesToTheIntegral) {
    for (double alpha : {0.05, 0.2, 0.6})
        for (double mu : {0.1, 0.5, 0.95})
            EXPECT_NEAR(FilamentDfgTexture::estimate(mu, alpha, 1 << 20, HammersleyAzimuth::Second),
                        correlated_ggx_albedo_white(mu, alpha, 64, 256), 2e-5)
                << alpha << " " << mu;
}

// The texture against the integral at its nodes (docs/models.md, "HDRP's FGD texture"): the
// 4096-point estimator and the 10-bit rounding, measured over the texels at perceptual roughness
// ≥ 3/63 (α ≥ 2.3e-3) and, apart, over the smoothest rows.
TEST(UnityFgdTexture, TextureAgainstTheIntegral) {
    const Fgd& t = Fgd::get();
    double worst = 0, worst_smooth = 0, worst_grazing = 0;
    for (int j = 0; j < Fgd::kSize; ++j)
        for (int i = 0; i < Fgd::kSize; ++i) {
            const double s = i / 63.0, r = j / 63.0;
            const double d = std::abs(t.texel(i, j) - correlated_ggx_albedo_white(s * s, r * r));
            if (j < 3)
                worst_smooth = std::max(worst_smooth, d);
            else if (i < 8)
                worst_grazing = std::max(worst_grazing, d);
            else
                worst = std::max(worst, d);
        }
    std::cout << fmt::format(
        "HDRP FGD texture against the integral: {:.2e} (sqrt(mu) >= 8/63, r >= 3/63), {:.2e} "
        "(sqrt(mu) < 8/63), {:.2e} (r < 3/63)\n",
        worst, worst_grazing, worst_smooth);
    // Measured: 5.1e-3, 8.1e-3 and 7.6e-3 (the estimator alone 4.6e-3 on every third texel).
    EXPECT_GT(worst, 4e-3);
    EXPECT_LT(worst, 5.5e-3);
    EXPECT_LT(worst_grazing, 8.5e-3);
    EXPECT_LT(worst_smooth, 8e-3);
}

// --- The model's properties ----------------------------------------------------------------

const Rgbd kStackLitRho(0.8, 0.5, 0.2), kStackLitTau(0.1, 0.2, 0.3);

double max_albedo(bool per_view) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    double worst = 0;
    for (const auto& [what, stack] : test::energy_sweep(false)) {
        std::unique_ptr<Model> m = make_model("unity-stacklit", stack);
        if (!m->support().brdf) continue;
        for (double t : {0.0, 45.0, 80.0}) {
            const Vec3d w = incident_direction(deg_to_rad(t));
            const double a =
                per_view ? model_albedo(test::TransposedModel(*m), w, Side::Reflection, o).max()
                         : model_albedo(*m, w, Side::Reflection, o).max();
            worst = std::max(worst, a);
        }
    }
    return worst;
}

// StackLit does not conserve energy either way (docs/models.md, measured over the sweep at θ ≤
// 80°): per view (the light arriving at wo from every wi) up to 1.483 (η0 = 2, α0 = 0.5 over a
// near-mirror metal, view at 80°: the adding roughens the base lobe at grazing views and its
// compensation 1 + F0 (1/E − 1) multiplies it by up to 2.5); per incidence up to 1.418 (η0 = 2,
// smooth coat over gold α1 = 0.4, light at 80°; the model's own sampling gives 1.4180 ± 0.0005).
// The bounds hold the measured values within the quadrature's 1e-3.
TEST(UnityStackLit, EnergyAsMeasured) {
    const double per_view = max_albedo(true), forward = max_albedo(false);
    std::cout << fmt::format(
        "unity-stacklit: largest albedo per view {:.4f}, per incidence {:.4f}\n", per_view,
        forward);
    EXPECT_GT(per_view, 1.47);
    EXPECT_LT(per_view, 1.49);
    EXPECT_GT(forward, 1.41);
    EXPECT_LT(forward, 1.43);
}

// Not reciprocal: the statistics, the energies and the compensation follow the view alone
// (measured 0.555 on the plastic, 0.429 on the gold).
TEST(UnityStackLit, ReciprocityAsMeasured) {
    for (const Stack& s : {coated(1.5, 0.2, test::lambertian(kStackLitRho), kStackLitTau),
                           coated(1.5, 0.1, test::gold(0.25), kStackLitTau)}) {
        const auto m = make_model("unity-stacklit", s);
        double worst = 0;
        for (double ti : {10.0, 40.0, 70.0})
            for (double to : {20.0, 55.0, 80.0})
                for (double po : {30.0, 150.0}) {
                    const Rgbd fab = m->eval(dir(ti, 0), dir(to, po)),
                               fba = m->eval(dir(to, po), dir(ti, 0));
                    for (int c = 0; c < 3; ++c)
                        worst =
                            std::max(worst, std::abs(fab[c] - fba[c]) / std::max(fab[c], fba[c]));
                }
        EXPECT_GT(worst, 0.4);
    }
}

// The sampler: directions against pdf() (chi-square) and each sample's weight eval·μo/pdf, on a
// rough plastic, a nearly smooth coat over a rough metal and a rough coat over a smooth metal.
TEST(UnityStackLit, Sampling) {
    const std::vector<std::pair<std::string, Stack>> stacks = {
        {"plastic", coated(1.5, 0.2, test::lambertian(kStackLitRho), kStackLitTau)},
        {"paint", coated(1.5, 0.01, test::gold(0.3), kStackLitTau)},
        {"frosted", coated(1.5, 0.3, test::gold(0.02))},
        {"brushed",
         coated(1.5, 0.05, anisotropic(test::gold(0.3), 0.3, 0.05, 20.0), kStackLitTau)}};
    const int tests = int(stacks.size()) * 2;
    for (const auto& [what, s] : stacks) {
        const auto m = make_model("unity-stacklit", s);
        ASSERT_TRUE(m->has_sampling());
        for (double ti : {30.0, 75.0}) {
            const Vec3d wi = dir(ti, 0);
            const std::string name = fmt::format("unity-stacklit {} ti={}", what, ti);
            const auto r = test::model_sampling_chi2(*m, wi, name, tests);
            EXPECT_TRUE(r.passed) << r.message;
            ParticleRng rng(11, std::uint64_t(ti), 0);
            EXPECT_GT(test::expect_sample_weights(*m, wi, rng, 2000, name), 1000);
            test::expect_prepared_equals_eval(*m, wi);
        }
    }
}

TEST(UnityStackLit, NotSupported) {
    Stack s = coated(1.5, 0.1, test::gold(0.2), kStackLitTau);
    s.layers[0].interface = anisotropic(s.layers[0].interface, 0.2, 0.05, 0.0);
    const auto m = make_model("unity-stacklit", s);
    EXPECT_FALSE(m->support().brdf);
    EXPECT_NE(m->support().reason.find("anisotropic coat"), std::string::npos);
    const auto below_one =
        make_model("unity-stacklit", coated(0.8, 0.1, test::lambertian(kStackLitRho)));
    EXPECT_FALSE(below_one->support().brdf);
    EXPECT_NE(below_one->support().reason.find("at least 1"), std::string::npos);
}

}  // namespace
}  // namespace lamina

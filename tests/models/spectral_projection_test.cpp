// The spectral projection of a model (models/spectral_projection.h): a grey spectrum gives the
// RGB model's value, a spectral stack the D65-weighted sum over wavelengths computed here one
// wavelength at a time (for a non-dispersive and a dispersive stack), and its sampler the density
// it reports.
#include "models/spectral_projection.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "layers/colorimetry.h"
#include "model_sampling.h"
#include "models/registry.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace lamina {
namespace {

ModelFactory factory_of(const std::string& name) {
    return [name](const Stack& s) { return make_model(name, s); };
}

// A rough clear coat over gold, the gold's index measured (data/nk); `coat_eta` a number or a
// dispersion law.
Stack coated_gold(const std::string& coat_eta) {
    return parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": )" + coat_eta +
            R"(, "alpha": 0.2}}, {"interface": {"type": "conductor", "material": "Au", "alpha": 0.3}}]})",
        "test");
}

// ∫ S ȳ dλ over 360–830 nm by the midpoint rule on 0.01 nm cells (the normalization of XYZ, CIE
// 015:2018 §7), computed apart from d65_y_integral's 0.1 nm cells: the two differ by ~10⁻⁸
// relative, the tolerance of the comparisons below (1e-7).
double y_integral() {
    double y = 0;
    for (int i = 0; i < 47000; ++i)
        y += d65_xyz_weights(360 + (i + 0.5) * 0.01)[1] * 0.01;
    return y;
}

// The sRGB of the spectrum f(λ) that `name` gives one wavelength at a time (channel 0 of a model
// built on the stack at that wavelength alone), by the rule the header states: n intervals of
// 360–830 nm, f at their middles, each weighted by ∫ S (x̄, ȳ, z̄) over its interval (16 cells).
// With f = 1 (`name` empty) the projection of a constant spectrum.
Rgbd sum_over_wavelengths(const Stack& stack, const std::string& name, const Vec3d& wi,
                          const Vec3d& wo, int n) {
    const double step = 470.0 / n;
    Rgbd xyz(0.0);
    for (int j = 0; j < n; ++j) {
        Rgbd w(0.0);
        for (int cell = 0; cell < 16; ++cell)
            w += d65_xyz_weights(360 + (j + (cell + 0.5) / 16) * step) * (step / 16);
        const double lambda = 360 + (j + 0.5) * step;
        const double f =
            name.empty() ? 1.0
                         : make_model(name, stack.at_wavelengths(Rgbd(lambda), 1))->eval(wi, wo)[0];
        xyz += w * f;
    }
    return xyz_to_linear_srgb(xyz * (1 / y_integral()));
}

std::vector<std::pair<Vec3d, Vec3d>> some_directions() {
    std::vector<std::pair<Vec3d, Vec3d>> out;
    for (double ti : {0.0, 35.0, 70.0})
        for (double to : {5.0, 40.0, 80.0})
            for (double po : {30.0, 180.0})
                out.push_back(
                    {direction_from_angles(deg_to_rad(ti), 0.0, Side::Reflection),
                     direction_from_angles(deg_to_rad(to), deg_to_rad(po), Side::Reflection)});
    return out;
}

TEST(SpectralProjection, AGreySpectrumGivesTheRgbModelsValueInWhite) {
    // A flat albedo spectrum under a coat of one index: every wavelength's model is the RGB
    // model, so the projection is its value times the projection of a constant spectrum, D65's
    // white: sRGB (1, 1, 1) within 2·10⁻³ (the IEC matrix against the interpolated CIE tables,
    // the bound the spectral goniophotometer's white Lambertian is held to).
    const Stack stack = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}},
            {"interface": {"type": "lambertian", "albedo": {"spectrum": [[360, 0.6], [830, 0.6]]}}}]})",
        "test");
    ASSERT_TRUE(stack.is_spectral());
    const Rgbd white = sum_over_wavelengths(stack, "", Vec3d(0, 0, 1), Vec3d(0, 0, 1), 48);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(white[c], 1.0, 2e-3);
    for (const char* name : {"openpbr", "ww-prime", "lamina-1"}) {
        const auto rgb = make_model(name, stack);
        ASSERT_TRUE(rgb->support().brdf) << name;
        const auto projected = make_spectral_projection(factory_of(name), stack);
        for (const auto& [wi, wo] : some_directions()) {
            const Rgbd want = rgb->eval(wi, wo), got = projected->eval(wi, wo);
            ASSERT_GT(want[0], 0) << name;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(got[c], want[c] * white[c], 1e-7 * want[c]) << name << " channel " << c;
        }
    }
}

TEST(SpectralProjection, IsTheSumOverWavelengths) {
    // Gold's spectrum under a coat of one index: the models are built three wavelengths at once.
    const Stack stack = coated_gold("1.5");
    const auto projected = make_spectral_projection(factory_of("openpbr"), stack);
    for (const auto& [wi, wo] : some_directions()) {
        const Rgbd want = sum_over_wavelengths(stack, "openpbr", wi, wo, 48);
        const Rgbd got = projected->eval(wi, wo);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want[c], 1e-7 * std::abs(want[c]));
    }
    // Gold is yellow: red over blue, as its reflectance spectrum rises past 500 nm.
    const Rgbd head_on = projected->eval(Vec3d(0, 0, 1), Vec3d(0, 0, 1));
    EXPECT_GT(head_on[0], 1.5 * head_on[2]);
}

TEST(SpectralProjection, ADispersiveCoatGetsOneModelPerWavelength) {
    // The coat's index from its Abbe number: each wavelength refracts at its own index.
    const Stack stack = coated_gold(R"({"abbe": [1.5, 30]})");
    const auto projected = make_spectral_projection(factory_of("openpbr"), stack);
    for (const auto& [wi, wo] : some_directions()) {
        const Rgbd want = sum_over_wavelengths(stack, "openpbr", wi, wo, 48);
        const Rgbd got = projected->eval(wi, wo);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want[c], 1e-7 * std::abs(want[c]));
    }
}

// The binned tables evaluate a model through prepare(wi) (and an evaluator for one thread of
// it): the projection prepares its members, so that what depends on wi alone is computed once per
// member rather than at every node, and must give eval's values bit for bit — on a dispersive
// coat (one member per wavelength) and a filmed metal (three wavelengths per member), for models
// whose evaluators keep incident statistics (lamina-1, the production coats, the Belcour family).
TEST(SpectralProjection, PreparedEvaluatorsAreEvalBitForBit) {
    const Stack dispersive = coated_gold(R"({"abbe": [1.5, 30]})");
    const Stack filmed = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.05}},
            {"interface": {"type": "conductor", "material": "Ti", "alpha": 0.3,
                           "film": {"thickness_nm": 60, "eta": 2.5}}}]})",
        "test");
    struct Case {
        const Stack& stack;
        const char* model;
    };
    const Case cases[] = {{dispersive, "lamina-1"},
                          {dispersive, "bel-prime"},
                          {dispersive, "openpbr"},
                          {filmed, "openpbr"},
                          {filmed, "openpbr-adobe"}};
    for (const Case& c : cases) {
        const auto projected = make_spectral_projection(factory_of(c.model), c.stack);
        ASSERT_TRUE(projected->support().brdf) << c.model;
        for (const auto& [wi, wo] : some_directions()) {
            const auto prepared = projected->prepare(wi);
            const auto one_thread = prepared->for_one_thread();
            const Rgbd want = projected->eval(wi, wo);
            for (int c2 = 0; c2 < 3; ++c2) {
                EXPECT_EQ(prepared->eval(wo)[c2], want[c2]) << c.model;
                if (one_thread) {
                    EXPECT_EQ(one_thread->eval(wo)[c2], want[c2]) << c.model;
                }
            }
        }
    }
}

TEST(SpectralProjection, SamplesTheDensityItReports) {
    const Stack stack = coated_gold("1.5");
    const auto projected = make_spectral_projection(factory_of("openpbr"), stack);
    ASSERT_TRUE(projected->has_sampling());
    ParticleRng rng(7, 0, 0);
    const Vec3d wi = direction_from_angles(deg_to_rad(40.0), 0.0, Side::Reflection);
    EXPECT_GT(test::expect_sample_weights(*projected, wi, rng, 2000, "projection"), 1500);
    const auto r = test::model_sampling_chi2(*projected, wi, "projection", 1, 100'000);
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(SpectralProjection, AShippedFilmKeepsItsOwnColour) {
    // three.js's film as shipped integrates the film's spectrum itself: on a spectral stack it is
    // evaluated once, on the stack at its channels' wavelengths; its exact leaf is projected.
    const Stack stack = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.1}},
            {"interface": {"type": "conductor", "material": "Ti", "alpha": 0.1,
                           "film": {"thickness_nm": 60, "eta": 2.5}}}]})",
        "test");
    const auto shipped = make_model("threejs-clearcoat", stack);
    ASSERT_TRUE(shipped->support().brdf) << shipped->support().reason;
    EXPECT_TRUE(shipped->integrates_spectrum());
    const auto projected = make_spectral_projection(factory_of("threejs-clearcoat"), stack);
    const auto exact = make_model("threejs-clearcoat:leaves=exact", stack);
    EXPECT_FALSE(exact->integrates_spectrum());
    const auto exact_projected =
        make_spectral_projection(factory_of("threejs-clearcoat:leaves=exact"), stack);
    int differ = 0;
    for (const auto& [wi, wo] : some_directions()) {
        EXPECT_EQ(projected->eval(wi, wo), shipped->eval(wi, wo));
        differ += exact_projected->eval(wi, wo) != exact->eval(wi, wo);
    }
    EXPECT_GT(differ, 0);
}

}  // namespace
}  // namespace lamina

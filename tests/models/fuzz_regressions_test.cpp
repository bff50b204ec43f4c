// Stacks the longer fuzz runs (docs/robustness.md) found NaN in, each at the directions that
// showed it: every value finite and non-negative, and the value the physics gives there.
#include "core/math.h"
#include "layers/stack.h"
#include "models/registry.h"
#include "physics/smith_masking.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

Vec3d dir(double theta_deg, double phi_deg) {
    const double t = deg_to_rad(theta_deg), p = deg_to_rad(phi_deg);
    return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

void expect_good(const Rgbd& f, const std::string& what) {
    for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(f[c])) << what << " channel " << c;
        EXPECT_GE(f[c], 0.0) << what << " channel " << c;
    }
}

// Seed 4242, case 541: a coat less dense than the ambient medium (relative η 0.306) over a
// near-perfect smooth metal that OpenPBR's base roughening makes rough. Past the coat's critical
// angle (17.8°) its Fresnel factor K is 1 and the darkening (1 − K)/(1 − E_b K) was 0/0; the coat
// reflects everything there, so the base adds nothing.
TEST(FuzzRegressions, OpenPbrDarkeningUnderTotalReflection) {
    const Stack stack = parse_stack(
        R"({"ambient_eta": 3.2745424988597738, "layers": [{"interface": {"type": "dielectric",
        "eta": 1.0014198695512948, "alpha": 0.0001}}, {"interface": {"type": "conductor",
        "eta": 0.01, "k": 3.574162441956937, "alpha": 0}}]})",
        "fuzz-4242-541");
    const auto model = make_model("openpbr", stack);
    for (double theta_o : {10.0, 30.0, 60.0, 89.0, 90.0 - 1e-6})
        expect_good(model->eval(dir(0, 0), dir(theta_o, 161.45)), "openpbr");
    // Past the critical angle the coat's own lobe is all there is (a narrow lobe, far from it
    // at θo = 60° with θi = 0): nothing from the base.
    const auto no_darkening = make_model("openpbr", stack, {"darkening=off"});
    EXPECT_LE(model->eval(dir(0, 0), dir(60, 161.45)).max(),
              no_darkening->eval(dir(0, 0), dir(60, 161.45)).max());
}

// Seed 4242, case 230: a channel without absorption (τ = 0) along a path that does not exist
// (refracted past total reflection: 1/μ = ∞) gave exp(−0·∞) = NaN; Beer–Lambert is 1 for τ = 0.
TEST(FuzzRegressions, BeerLambertWithoutAbsorptionOnAnInfinitePath) {
    const Stack stack = parse_stack(
        R"({"ambient_eta": 5, "layers": [{"interface": {"type": "dielectric", "eta": 1.5278960857865616,
        "alpha": 0}, "medium": {"tau_a": [84.4, 0, 5e-324]}}, {"interface": {"type": "conductor",
        "eta": 10, "k": [1e-320, 3.03, 10], "alpha": 0.0001}}]})",
        "fuzz-4242-230");
    for (const char* name : {"openpbr", "openpbr-adobe", "ww-prime", "lamina-1"}) {
        const auto model = make_model(name, stack);
        for (double theta_o : {0.0, 45.0, 90.0 - 1e-6})
            expect_good(model->eval(dir(0, 0), dir(theta_o, 176.7)), name);
    }
}

// Seed 777, case 451: an index-matched smooth coat over a smooth dielectric, light exactly at
// grazing (cos θi = 6e-17): the coat's Fresnel factor is 1 and the bottom's too, and the delta
// series 1/(1 − F R_b) was 1/0 times a zero transmittance. Nothing enters: only the mirror lobe.
TEST(FuzzRegressions, Lamina1DeltaSeriesAtGrazingIncidence) {
    const Stack stack = parse_stack(
        R"({"ambient_eta": 1, "layers": [{"interface": {"type": "dielectric", "eta": 1,
        "alpha": 0}}, {"interface": {"type": "dielectric", "eta": 1.1720485292432317,
        "alpha": 0}}]})",
        "fuzz-777-451");
    const auto model = make_model("lamina-1", stack);
    const Vec3d wi(1, 0, 6.123233995736766e-17);
    for (const DeltaLobe& lobe : model->delta_lobes(wi))
        expect_good(lobe.energy, "lamina-1 delta");
}

// Seed 4242, case 1393 (and 703): an index-matched rough coat, light exactly at grazing, wo
// straight down through a slab: the refracted direction lies on the horizon (cos θi' = 0 by
// rounding) and the spread factor was 0/0. Nothing enters there.
TEST(FuzzRegressions, Lamina1GrazingIntoAnIndexMatchedCoat) {
    const Stack stack = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1, "alpha": 0.3877396462905696}},
        {"interface": {"type": "dielectric", "eta": 2.427874138908023, "alpha": 0.9999999999999999}}]})",
        "fuzz-4242-1393");
    for (const auto& options : std::vector<std::vector<std::string>>{
             {}, {"coat-transmittance=fresnel", "exit-transmittance=outside"}}) {
        const auto model = make_model("lamina-1", stack, options);
        const Vec3d wi(1, 0, 6.123233995736766e-17);
        expect_good(model->eval(wi, Vec3d(0, 0, -1)), "lamina-1 BTDF");
        expect_good(model->eval(wi, Vec3d(0, 0, 1)), "lamina-1 BRDF");
    }
}

// Seed 4242, case 977 (the scalar kernel's budget): the Smith refraction escape
// (1 + Λi) B(1 + Λi, 1 + Λo) is a fraction, but in float its Beta function rounded above 1 near
// Λ = 0 (an index-matched rough interface) and booked −1.8e-7 as lost to the microsurface.
TEST(FuzzRegressions, RefractionEscapeIsAFraction) {
    for (int i = 0; i <= 1000; ++i) {
        const float r_i = 1.0f + 1e-6f * float(i), r_o = 1.0f + 3e-7f * float(1000 - i);
        const float g = smith_refraction_escape(r_i, r_o);
        EXPECT_LE(g, 1.0f) << r_i << " " << r_o;
        EXPECT_GE(g, 0.0f);
    }
}

}  // namespace
}  // namespace lamina

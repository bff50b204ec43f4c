// The production coats that define anisotropic roughness (OpenPBR's parametrization: `openpbr`,
// `openpbr-adobe`; docs/models.md, "Anisotropic coats") on anisotropic stacks: they reduce to their
// isotropic form as α_y → α_x, they turn with their tangents, their energy is bounded as measured,
// and their samplers draw the density they claim. Their values against openpbr-bsdf's own code are
// in production_golden_test.cpp.
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "models/model_sampling.h"
#include "models/numerics/binned.h"
#include "models/production/production_coat.h"
#include "models/registry.h"
#include "models/test_stacks.h"

#include "models/model_checks.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

namespace lamina {
namespace {

using test::coated;
using test::dir;

const Rgbd kTau(0.1, 0.2, 0.3);
const char* const kAnisotropicCoats[] = {"openpbr", "openpbr-adobe"};

/// A brushed metal (α_x, α_y at tangent ψ1) under a coat (α_x, α_y at ψ0); equal α's leave that
/// interface isotropic.
Stack brushed(double c_x, double c_y, double psi0, double b_x, double b_y, double psi1) {
    Stack s = coated(1.5, c_x, test::gold(b_x), kTau);
    if (c_y != c_x) s.layers[0].interface = anisotropic(s.layers[0].interface, c_x, c_y, psi0);
    if (b_y != b_x) s.layers[1].interface = anisotropic(s.layers[1].interface, b_x, b_y, psi1);
    return s;
}

/// Directions in and off the plane φ = 0.
std::vector<Vec3d> directions() {
    std::vector<Vec3d> out;
    for (double t : {5.0, 30.0, 55.0, 80.0})
        for (double p : {0.0, 40.0, 130.0, 200.0, 310.0})
            out.push_back(dir(t, p));
    return out;
}

double relative_difference(const Rgbd& a, const Rgbd& b) {
    double worst = 0;
    for (int c = 0; c < 3; ++c)
        if (a[c] != b[c])
            worst =
                std::max(worst, std::abs(a[c] - b[c]) / std::max(std::abs(a[c]), std::abs(b[c])));
    return worst;
}

// OpenPBR's isotropic α of α_x, α_y is their root mean square; α itself for an isotropic one.
TEST(ProductionAnisotropy, IsotropicAlphaIsTheRootMeanSquare) {
    const InterfaceSpec iso = test::gold(0.3);
    EXPECT_EQ(openpbr_isotropic_alpha(iso), 0.3);
    // OpenPBR 1.1: a = 0.5 of α = 0.2 gives α_t = 0.2 √(2/1.25), α_b = α_t / 2.
    const double a_t = 0.2 * std::sqrt(2 / 1.25);
    EXPECT_NEAR(openpbr_isotropic_alpha(anisotropic(iso, a_t, 0.5 * a_t, 10)), 0.2, 1e-15);
}

// As α_y → α_x the anisotropic form is the isotropic one: α_y = α_x (1 + 1e-8) on coat and base
// moves no value by more than 1e-6 relative (the lobes' D and Λ are smooth in α_y; the energy
// terms read the root mean square, which moves by 5e-9 relative).
TEST(ProductionAnisotropy, ReducesToTheIsotropicForm) {
    for (const char* name : kAnisotropicCoats)
        for (const auto& [c, b] : {std::pair{0.2, 0.3}, std::pair{0.05, 0.5}}) {
            const auto iso = make_model(name, brushed(c, c, 0, b, b, 0));
            const auto aniso =
                make_model(name, brushed(c, c * (1 + 1e-8), 35, b, b * (1 + 1e-8), -60));
            ASSERT_TRUE(aniso->support().brdf) << name << ": " << aniso->support().reason;
            double worst = 0;
            for (const Vec3d& wi : directions())
                for (const Vec3d& wo : directions())
                    worst = std::max(worst,
                                     relative_difference(aniso->eval(wi, wo), iso->eval(wi, wo)));
            EXPECT_LT(worst, 1e-6) << name << " coat " << c << " base " << b;
        }
}

// Swapping α_x and α_y is turning the tangent by 90°, and turning both tangents and both
// directions by ψ leaves every value: the lobes are the anisotropic GGX of physics/microfacet.h in
// the interface's frame, and every other term depends on cosines to the normal alone.
TEST(ProductionAnisotropy, TurnsWithItsTangents) {
    const double psi = 37;
    const auto turn = [](const Vec3d& w, double deg) {
        const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
        return Vec3d(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
    };
    for (const char* name : kAnisotropicCoats) {
        const auto m = make_model(name, brushed(0.3, 0.08, 20, 0.1, 0.4, -50));
        const auto swapped = make_model(name, brushed(0.08, 0.3, 110, 0.4, 0.1, 40));
        const auto turned = make_model(name, brushed(0.3, 0.08, 20 + psi, 0.1, 0.4, -50 + psi));
        double worst_swap = 0, worst_turn = 0;
        for (const Vec3d& wi : directions())
            for (const Vec3d& wo : directions()) {
                const Rgbd f = m->eval(wi, wo);
                worst_swap = std::max(worst_swap, relative_difference(swapped->eval(wi, wo), f));
                worst_turn = std::max(
                    worst_turn, relative_difference(turned->eval(turn(wi, psi), turn(wo, psi)), f));
            }
        EXPECT_LT(worst_swap, 1e-10) << name;
        EXPECT_LT(worst_turn, 1e-10) << name;
    }
}

// Energy: the albedo ∫ f μo dωo over the whole hemisphere (no mirror symmetry: full azimuth), per
// incidence and, of the transposed BRDF, per view, at θ ∈ {0°, 45°, 80°} and azimuths across the
// tangents, over brushed metals and a brushed coat over a Lambertian. Per view it stays within
// energy conservation (the quadrature's 1e-3 and the FGD table's 6.3e-3 as in production_test);
// per incidence the albedo scaling exceeds 1 at grazing light, as the isotropic coats do
// (production_test, EnergyAsMeasured): bounded by the measured excess.
TEST(ProductionAnisotropy, EnergyIsBounded) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    o.full_azimuth = true;
    const std::vector<Stack> stacks = {
        brushed(0.3, 0.05, 30, 0.4, 0.02, -45), brushed(0.05, 0.05, 0, 0.6, 0.1, 90), [] {
            Stack s = coated(1.5, 0.4, test::lambertian(Rgbd(0.9)), Rgbd(0.0));
            s.layers[0].interface = anisotropic(s.layers[0].interface, 0.4, 0.05, 60);
            return s;
        }()};
    for (const char* name : kAnisotropicCoats) {
        double forward = 0, per_view = 0;
        for (const Stack& s : stacks) {
            const auto m = make_model(name, s);
            const test::TransposedModel transposed(*m);
            for (double t : {0.0, 45.0, 80.0})
                for (double p : {0.0, 75.0, 150.0}) {
                    const Vec3d w = dir(t, p);
                    forward = std::max(forward, model_albedo(*m, w, Side::Reflection, o).max());
                    per_view =
                        std::max(per_view, model_albedo(transposed, w, Side::Reflection, o).max());
                }
        }
        std::cout << fmt::format("{}: largest albedo per incidence {:.4f}, per view {:.4f}\n", name,
                                 forward, per_view);
        // Measured: per view 0.9934 (openpbr), 0.9991 (openpbr-adobe); per incidence 1.0511,
        // 1.0525 (the albedo scaling's excess at grazing wi, as for isotropic coats).
        EXPECT_LE(per_view, 1 + 1e-3 + 6.3e-3) << name;
        EXPECT_LE(forward, 1.06) << name;
    }
}

// The samplers draw the density pdf() claims (chi-square), and each sample's weight is
// eval·cos/pdf, on anisotropic coats and metals lit in and off the plane φ = 0.
TEST(ProductionAnisotropy, SamplingMatchesItsDensity) {
    const std::vector<std::pair<std::string, Stack>> stacks = {
        {"brushed-both", brushed(0.3, 0.05, 30, 0.4, 0.02, -45)},
        {"brushed-metal", brushed(0.1, 0.1, 0, 0.5, 0.08, 100)}};
    const int count = 2 * int(stacks.size()) * 2;
    for (const char* name : kAnisotropicCoats)
        for (const auto& [what, stack] : stacks) {
            const auto m = make_model(name, stack);
            ASSERT_TRUE(m->has_sampling()) << name;
            for (const Vec3d& wi : {dir(25, 0), dir(60, 130)}) {
                const auto r = test::model_sampling_chi2(
                    *m, wi, fmt::format("{}-{}-{:.0f}", name, what, wi.z * 100), count);
                EXPECT_TRUE(r.passed) << name << " " << what << ": " << r.message;
                ParticleRng rng(3, 0, 0);
                EXPECT_GT(test::expect_sample_weights(*m, wi, rng, 2000, name), 1000);
            }
        }
}

}  // namespace
}  // namespace lamina

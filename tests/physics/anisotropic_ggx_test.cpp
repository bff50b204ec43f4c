// The anisotropic GGX distribution (physics/microfacet.h): D against its closed form in the
// tangent frame and its normalization, Smith's Λ with the projected roughness α(φ) against the
// projected-area identity, the visible normals' normalization and chi-square tests of both
// samplers, the isotropic instance (α_x = α_y through the anisotropic code path) and the symmetry
// "swapping α_x and α_y is turning the tangent by 90°".
#include "physics/microfacet.h"

#include "core/math.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace lamina {
namespace {

using test::Chi2Draw;

struct Aniso {
    double alpha_x, alpha_y, psi;
};
// Strongly and mildly anisotropic, tangents along and across the axes and oblique.
const Aniso kCases[] = {{0.1, 0.4, 0.0}, {0.5, 0.15, 0.7}, {0.3, 0.6, 2.2}, {0.05, 0.3, -1.1}};

const Vec3d kAnisotropicViews[] = {Vec3d(0, 0, 1),
                                   test::direction_of(0.7, 0.3),
                                   test::direction_of(0.2, 2.0),
                                   test::direction_of(0.05, 4.0),
                                   test::direction_of(-0.5, 1.0),
                                   test::direction_of(-0.1, 5.5)};

// The closed forms, written from angles in the tangent frame (independent of the code's forms).
// D: Heitz 2014, the anisotropic GGX, 1/(π α_x α_y cos⁴θ (1 + tan²θ (cos²φ/α_x² + sin²φ/α_y²))²).
double D_closed_form(const Aniso& a, const Vec3d& wm) {
    if (wm.z <= 0) return 0;
    const double phi = std::atan2(wm.y, wm.x) - a.psi;
    const double cos2 = sqr(wm.z), tan2 = (1 - cos2) / cos2;
    const double e =
        tan2 * (sqr(std::cos(phi)) / sqr(a.alpha_x) + sqr(std::sin(phi)) / sqr(a.alpha_y));
    return 1 / (kPi<double> * a.alpha_x * a.alpha_y * sqr(cos2) * sqr(1 + e));
}
// Λ = (−1 + √(1 + α(φ)² tan²θ))/2, α(φ)² = cos²φ α_x² + sin²φ α_y².
double lambda_closed_form(const Aniso& a, const Vec3d& w) {
    const double phi = std::atan2(w.y, w.x) - a.psi;
    const double alpha2 = sqr(std::cos(phi) * a.alpha_x) + sqr(std::sin(phi) * a.alpha_y);
    const double cos2 = sqr(w.z), tan2 = (1 - cos2) / cos2;
    return (-1 + std::sqrt(1 + alpha2 * tan2)) / 2;
}

GGX<double> ggx_of(const Aniso& a) {
    return GGX<double>::anisotropic(a.alpha_x, a.alpha_y, a.psi);
}

TEST(AnisotropicGgx, DistributionMatchesClosedFormAndIsNormalized) {
    for (const Aniso& a : kCases) {
        const GGX<double> ggx = ggx_of(a);
        ASSERT_TRUE(ggx.anisotropy.on);
        for (double c : {1.0, 0.9, 0.5, 0.1})
            for (double phi : {0.0, 0.4, 1.3, 2.9, 4.0, 5.9}) {
                const Vec3d wm = test::direction_of(c, phi);
                EXPECT_NEAR(ggx.D(wm), D_closed_form(a, wm), 1e-12 * D_closed_form(a, wm))
                    << a.alpha_x << " " << a.alpha_y << " " << c << " " << phi;
            }
        // ∫ D(wm) cos θm dωm = 1 (the projected microfacet area is the macro area).
        const double total =
            test::integrate_hemisphere([&](const Vec3d& wm) { return ggx.D(wm) * wm.z; },
                                       std::min(a.alpha_x, a.alpha_y), 1e-10, 8);
        EXPECT_NEAR(total, 1, 1e-8) << a.alpha_x << " " << a.alpha_y;
    }
}

TEST(AnisotropicGgx, LambdaIsTheProjectedAreaOfTheDistribution) {
    // ∫ max(0, w·wm) D(wm) dωm = cos θ (1 + Λ(w)), i.e. ∫ G1 max(0, w·wm) D dωm = cos θ (Heitz
    // 2014, Eq. 25), for w below the surface with −w; Λ from the closed form with α(φ) (the
    // identity holds because the anisotropic GGX is a stretch of the α = 1 one), and Λ of the code
    // against it.
    for (const Aniso& a : kCases) {
        const GGX<double> ggx = ggx_of(a);
        for (const Vec3d& w : kAnisotropicViews) {
            const double sign = w.z < 0 ? -1 : 1, cos_theta = std::abs(w.z);
            const double lambda = lambda_closed_form(a, w);
            EXPECT_NEAR(ggx.lambda(w), lambda, 1e-12 * (1 + lambda));
            EXPECT_NEAR(ggx.smith_root(w), 1 + 2 * lambda, 1e-12 * (1 + lambda));
            const double masked = test::integrate_hemisphere(
                [&](const Vec3d& wm) {
                    return ggx.G1(w) * std::max(0.0, sign * dot(w, wm)) * ggx.D(wm);
                },
                std::min(a.alpha_x, a.alpha_y), 1e-10, 8);
            EXPECT_NEAR(masked, cos_theta, 1e-8) << a.alpha_x << " " << a.alpha_y << " " << w.z;
            const double complete = test::integrate_hemisphere(
                [&](const Vec3d& wm) { return ggx.D_visible_complete(w, wm); },
                std::min(a.alpha_x, a.alpha_y), 1e-10, 64);
            EXPECT_NEAR(complete, 1, 1e-8) << a.alpha_x << " " << a.alpha_y << " " << w.z;
        }
    }
}

TEST(AnisotropicGgx, EqualRoughnessIsTheIsotropicDistribution) {
    // The anisotropic code path forced on with α_x = α_y (and a turned tangent) gives the
    // isotropic distribution: D, Λ, and the same visible normals from the same numbers (the
    // stretch is then α I in any frame), to rounding.
    for (double alpha : {0.05, 0.3, 1.0}) {
        const GGX<double> iso{alpha};
        GGX<double> forced = GGX<double>::anisotropic(alpha, alpha, 0.9);
        ASSERT_FALSE(forced.anisotropy.on);
        forced.anisotropy.on = true;
        for (const Vec3d& w : kAnisotropicViews) {
            EXPECT_NEAR(forced.lambda(w), iso.lambda(w), 1e-13 * (1 + iso.lambda(w)));
            const Vec3d m = test::direction_of(std::abs(w.z) * 0.5 + 0.5, 1.7);
            EXPECT_NEAR(forced.D(m), iso.D(m), 1e-13 * iso.D(m));
            for (double u1 : {0.1, 0.6})
                for (double u2 : {0.3, 0.95}) {
                    const Vec3d a = forced.sample_visible_normal_complete(w, u1, u2);
                    const Vec3d b = iso.sample_visible_normal_complete(w, u1, u2);
                    EXPECT_NEAR(length(a - b), 0, 1e-12);
                    const Vec3d c = forced.sample_visible_normal(w, u1, u2);
                    const Vec3d d = iso.sample_visible_normal(w, u1, u2);
                    EXPECT_NEAR(length(c - d), 0, 1e-12);
                }
        }
    }
}

TEST(AnisotropicGgx, SwappingTheRoughnessesTurnsTheTangentBy90Degrees) {
    for (const Aniso& a : kCases) {
        const GGX<double> ggx = ggx_of(a);
        const GGX<double> swapped =
            GGX<double>::anisotropic(a.alpha_y, a.alpha_x, a.psi + kPi<double> / 2);
        for (const Vec3d& w : kAnisotropicViews) {
            EXPECT_NEAR(swapped.lambda(w), ggx.lambda(w), 1e-12 * (1 + ggx.lambda(w)));
            const Vec3d m = test::direction_of(std::abs(w.z) * 0.5 + 0.5, 2.3);
            EXPECT_NEAR(swapped.D(m), ggx.D(m), 1e-12 * ggx.D(m));
        }
        // And turning the tangent by 180° changes nothing (D is point-symmetric in the plane).
        const GGX<double> turned =
            GGX<double>::anisotropic(a.alpha_x, a.alpha_y, a.psi + kPi<double>);
        for (const Vec3d& w : kAnisotropicViews)
            EXPECT_NEAR(turned.lambda(w), ggx.lambda(w), 1e-12 * (1 + ggx.lambda(w)));
    }
}

// Chi-square tests in AnisotropicGgxStat (Šidák correction, 1 % for the suite).
constexpr int kChi2Tests = 8;

TEST(AnisotropicGgxStat, VisibleNormalSamplingChi2) {
    // Both samplers of visible normals against their densities: Heitz 2018's (sample_visible_normal
    // against D_visible, w below the surface through −w) and the spherical caps, complete, of the
    // particle kernels (sample_visible_normal_complete against D_visible_complete, from below the
    // horizon on the same side too).
    struct Case {
        Aniso a;
        Vec3d w;
    };
    const Case cases[] = {{kCases[0], test::direction_of(0.6, 0.2)},
                          {kCases[1], test::direction_of(-0.4, 1.3)},
                          {kCases[2], test::direction_of(0.15, 4.1)},
                          {kCases[3], Vec3d(0, 0, 1)}};
    static_assert(2 * std::size(cases) == kChi2Tests);
    for (const Case& c : cases) {
        const GGX<double> ggx = ggx_of(c.a);
        for (bool caps : {false, true}) {
            test::Chi2Options o;
            o.name = std::string(caps ? "aniso_caps" : "aniso_heitz") + "_ax" +
                     std::to_string(c.a.alpha_x) + "_ay" + std::to_string(c.a.alpha_y) + "_z" +
                     std::to_string(c.w.z);
            o.test_count = kChi2Tests;
            o.cos_theta_min = 0;
            const auto r = test::run_chi2(
                o,
                [&](const std::array<double, 3>& u) {
                    return Chi2Draw::direction(
                        caps ? ggx.sample_visible_normal_complete(c.w, u[0], u[1])
                             : ggx.sample_visible_normal(c.w, u[0], u[1]));
                },
                [&](const Vec3d& wm) {
                    return caps ? ggx.D_visible_complete(c.w, wm) : ggx.D_visible(c.w, wm);
                });
            EXPECT_TRUE(r.passed) << r.message;
            EXPECT_NEAR(r.pdf_integral, 1, 1e-5) << o.name;
        }
    }
}

}  // namespace
}  // namespace lamina

// The GGX distribution (physics/microfacet.h): normalization of D and of the visible normals,
// the projected-area identities that define Smith's Λ, the closed form of Λ, bounds of G2, and a
// chi-square test of the visible-normal sampler against its density.
#include "physics/microfacet.h"

#include "core/math.h"
#include "core/rng.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

namespace lamina {
namespace {

using test::Chi2Draw;

constexpr double kAlphas[] = {0.001, 0.05, 0.2, 0.5, 1.0};

TEST(Microfacet, NormalDistributionIsNormalized) {
    // ∫ D(wm) cos θm dωm = 1 (the projected microfacet area equals the macro area, Walter Eq. 4).
    // D depends on θm only; with u = sin²θm, dω = dφ d(cos θm) = dφ du/(2 cos θm), so
    // ∫ D cos θm dω = π ∫₀¹ D(u) du. The peak has width u ≈ α²: adaptive Simpson on graded
    // intervals [α²4^(k−4), α²4^(k−3)] resolves α = 0.001 (tolerance 1e-12 per interval, so the
    // total is good to ~1e-10; we ask for 1e-9).
    for (double alpha : kAlphas) {
        const GGX<double> ggx{alpha};
        const auto integrand = [&](double u) {
            return kPi<double> * ggx.D(Vec3d(std::sqrt(u), 0, std::sqrt(1 - u)));
        };
        std::vector<double> nodes = {0.0};
        for (double x = sqr(alpha) / 256; x < 1; x *= 4)
            nodes.push_back(x);
        nodes.push_back(std::nextafter(1.0, 0.0));  // D = 0 on the horizon; its limit is not
        double total = 0;
        for (std::size_t k = 0; k + 1 < nodes.size(); ++k)
            total += test::adaptive_simpson(integrand, nodes[k], nodes[k + 1], 1e-12);
        EXPECT_NEAR(total, 1, 1e-9) << "alpha = " << alpha;
        // The same through the 2-D hemisphere quadrature used below (a check of that helper).
        if (alpha >= 0.05) {
            EXPECT_NEAR(test::integrate_hemisphere(
                            [&](const Vec3d& wm) { return ggx.D(wm) * wm.z; }, alpha, 1e-10),
                        1, 1e-8)
                << "alpha = " << alpha;
        }
    }
    // Known values: D at the pole is 1/(π α²); D vanishes below the horizon.
    EXPECT_NEAR(GGX<double>{0.2}.D(Vec3d(0, 0, 1)), 1 / (kPi<double> * 0.04), 1e-12);
    EXPECT_EQ(GGX<double>{0.2}.D(Vec3d(0, 0.6, -0.8)), 0.0);
}

// Directions of w for the visible-normal tests: normal, oblique, grazing, and below the surface.
const Vec3d kViews[] = {Vec3d(0, 0, 1),
                        test::direction_of(0.7, 0.3),
                        test::direction_of(0.2, 2.0),
                        test::direction_of(0.01, 4.0),
                        test::direction_of(-0.5, 1.0),
                        test::direction_of(-0.02, 5.5)};

TEST(Microfacet, VisibleNormalsAreNormalized) {
    // ∫ D_w(wm) dωm = 1 for every w, including below the surface and grazing (Heitz 2014, Eq. 38
    // normalized by Eq. 25). Quadrature tolerance 1e-10; we ask for 1e-8.
    for (double alpha : {0.05, 0.2, 0.5, 1.0}) {
        const GGX<double> ggx{alpha};
        for (const Vec3d& w : kViews) {
            const double total = test::integrate_hemisphere(
                [&](const Vec3d& wm) { return ggx.D_visible(w, wm); }, alpha, 1e-10);
            EXPECT_NEAR(total, 1, 1e-8) << "alpha = " << alpha << ", w.z = " << w.z;
        }
    }
}

TEST(Microfacet, CompleteVisibleNormalsAreNormalized) {
    // The normals visible from any w on the *same* side of the microsurface (below the horizon: a
    // ray inside the microsurface, microsurface_walk.h): ∫ max(0, w·wm) D(wm) dωm is the projected
    // area, cos θ (1 + Λ) above and |cos θ| Λ below (the signed projected area ∫ (w·wm) D = cos θ
    // minus the back-facing part). Λ from the independent closed form below.
    for (double alpha : {0.05, 0.2, 0.5, 1.0}) {
        const GGX<double> ggx{alpha};
        for (const Vec3d& w : kViews) {
            const double total = test::integrate_hemisphere(
                [&](const Vec3d& wm) { return ggx.D_visible_complete(w, wm); }, alpha, 1e-10, 64);
            EXPECT_NEAR(total, 1, 1e-8) << "alpha = " << alpha << ", w.z = " << w.z;
        }
    }
}

// Λ written independently from θ: Heitz 2014, Eq. 72, Λ = (−1 + √(1 + α² tan²θ))/2.
double lambda_closed_form(double alpha, double cos_theta) {
    const double tan2 = (1 - sqr(cos_theta)) / sqr(cos_theta);
    return (-1 + std::sqrt(1 + sqr(alpha) * tan2)) / 2;
}

TEST(Microfacet, ProjectedAreas) {
    // Heitz 2014, §2 (projected areas): the signed projected area of the microsurface onto any w is
    // that of the macrosurface, ∫ (w·wm) D(wm) dωm = cos θ. Eq. 25 with Smith's G1 = 1/(1 + Λ):
    // the visible part projects to ∫ max(0, w·wm) D(wm) dωm = cos θ (1 + Λ(w)), i.e.
    // ∫ G1(w) max(0, w·wm) D(wm) dωm = cos θ. For w below the surface the same holds with −w.
    // Λ is taken from the independent closed form above, so this checks D against Λ.
    for (double alpha : {0.05, 0.2, 0.5, 1.0}) {
        const GGX<double> ggx{alpha};
        for (const Vec3d& w : kViews) {
            const double sign = w.z < 0 ? -1 : 1, cos_theta = std::abs(w.z);
            const double is = test::integrate_hemisphere(
                [&](const Vec3d& wm) { return sign * dot(w, wm) * ggx.D(wm); }, alpha, 1e-10);
            EXPECT_NEAR(is, cos_theta, 1e-8) << "alpha = " << alpha << ", w.z = " << w.z;
            const double visible = test::integrate_hemisphere(
                [&](const Vec3d& wm) { return std::max(0.0, sign * dot(w, wm)) * ggx.D(wm); },
                alpha, 1e-10);
            EXPECT_NEAR(visible, cos_theta * (1 + lambda_closed_form(alpha, cos_theta)), 1e-8)
                << "alpha = " << alpha << ", w.z = " << w.z;
            const double masked = test::integrate_hemisphere(
                [&](const Vec3d& wm) {
                    return ggx.G1(w) * std::max(0.0, sign * dot(w, wm)) * ggx.D(wm);
                },
                alpha, 1e-10);
            EXPECT_NEAR(masked, cos_theta, 1e-8) << "alpha = " << alpha << ", w.z = " << w.z;
        }
    }
}

TEST(Microfacet, LambdaMatchesClosedForm) {
    // The code uses the cancellation-free form x/(2(√(1+x)+1)), x = α² tan²θ. The naive closed
    // form loses about 1e-16/x relative precision to cancellation, so we compare to it at 1e-11
    // relative where x > 1e-3 and, below that, against the series of (√(1+x) − 1)/2,
    // x/4 − x²/16 + x³/32 − 5x⁴/256, whose first omitted term 7x⁵/512 is < 6e-14 relative.
    for (double alpha : kAlphas) {
        const GGX<double> ggx{alpha};
        for (int i = 1; i <= 200; ++i) {
            const double cos_theta = i / 200.0;
            for (double side : {1.0, -1.0}) {
                const Vec3d w = test::direction_of(side * cos_theta, 0.1 * i);
                const double x = sqr(alpha) * (1 - sqr(cos_theta)) / sqr(cos_theta);
                const double expected =
                    x > 1e-3 ? lambda_closed_form(alpha, cos_theta)
                             : x / 4 - sqr(x) / 16 + x * x * x / 32 - 5 * sqr(sqr(x)) / 256;
                EXPECT_NEAR(ggx.lambda(w), expected, 1e-11 * std::max(expected, 1e-300) + 1e-300)
                    << "alpha = " << alpha << ", cos = " << w.z;
                EXPECT_NEAR(ggx.G1(w), 1 / (1 + expected), 1e-12);
            }
        }
        // Normal incidence: Λ = 0, G1 = 1. Grazing: Λ = ∞, G1 = 0.
        EXPECT_EQ(ggx.lambda(Vec3d(0, 0, 1)), 0.0);
        EXPECT_EQ(ggx.G1(Vec3d(0, 0, -1)), 1.0);
        EXPECT_EQ(ggx.G1(Vec3d(1, 0, 0)), 0.0);
    }
}

TEST(Microfacet, MaskingShadowingBounds) {
    // G2 = 1/(1 + Λi + Λo): since Λ ≥ 0, 1 + Λi + Λo ≥ 1 + Λi gives G2 ≤ G1(wi) (and wo), and
    // (1 + Λi)(1 + Λo) = 1 + Λi + Λo + ΛiΛo ≥ 1 + Λi + Λo gives G2 ≥ G1(wi) G1(wo). Symmetric.
    ParticleRng rng(21, 0, 0);
    for (double alpha : kAlphas) {
        const GGX<double> ggx{alpha};
        for (int i = 0; i < 2000; ++i) {
            const Vec3d wi =
                test::direction_of(2 * rng.uniform_double() - 1, 7 * rng.uniform_double());
            const Vec3d wo =
                test::direction_of(2 * rng.uniform_double() - 1, 7 * rng.uniform_double());
            const double g2 = ggx.G2(wi, wo);
            EXPECT_LE(g2, std::min(ggx.G1(wi), ggx.G1(wo)) * (1 + 1e-15));
            EXPECT_GE(g2, ggx.G1(wi) * ggx.G1(wo) * (1 - 1e-15));
            EXPECT_DOUBLE_EQ(g2, ggx.G2(wo, wi));  // (1 + Λi) + Λo vs (1 + Λo) + Λi: ≤ 4 ulp
            EXPECT_EQ(ggx.G2_uncorrelated(wi, wo), ggx.G1(wi) * ggx.G1(wo));
        }
    }
}

// Chi-square tests in MicrofacetStat (Šidák correction, 1 % for the suite): 7 views below and 2
// zoomed sharp lobes.
constexpr int kVisibleNormalChi2Tests = 13;

TEST(MicrofacetStat, VisibleNormalSamplingChi2) {
    // sample_visible_normal against pdf_visible_normal (= D_w), for several α and views: normal,
    // oblique, near grazing, and below the surface (oblique and near grazing). Every draw must be
    // a unit normal in the upper hemisphere that w sees (D_w > 0), which the harness enforces.
    struct Case {
        double alpha;
        Vec3d w;
    };
    const Case cases[] = {
        {0.05, test::direction_of(0.7, 0.3)},  {0.2, Vec3d(0, 0, 1)},
        {0.2, test::direction_of(0.02, 2.0)},  {0.5, test::direction_of(-0.5, 1.0)},
        {0.5, test::direction_of(0.3, 5.0)},   {1.0, test::direction_of(-0.02, 5.5)},
        {0.05, test::direction_of(-0.05, 1.0)}};
    static_assert(std::size(cases) + 2 + 4 == kVisibleNormalChi2Tests);
    for (const Case& c : cases) {
        const GGX<double> ggx{c.alpha};
        test::Chi2Options o;
        o.name = "visible_normals_a" + std::to_string(c.alpha) + "_z" + std::to_string(c.w.z);
        o.test_count = kVisibleNormalChi2Tests;
        o.cos_theta_min = 0;
        const auto r = test::run_chi2(
            o,
            [&](const std::array<double, 3>& u) {
                return Chi2Draw::direction(ggx.sample_visible_normal(c.w, u[0], u[1]));
            },
            [&](const Vec3d& wm) { return ggx.pdf_visible_normal(c.w, wm); });
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdf_integral, 1, 1e-6) << o.name;
    }
}

TEST(MicrofacetStat, CompleteVisibleNormalSamplingChi2) {
    // sample_visible_normal_complete against D_visible_complete from views below the horizon on
    // the same side (where it differs from sample_visible_normal) and one above (where it is the
    // same construction).
    struct Case {
        double alpha;
        Vec3d w;
    };
    const Case cases[] = {{0.5, test::direction_of(-0.5, 1.0)},
                          {1.0, test::direction_of(-0.9, 2.0)},
                          {0.2, test::direction_of(-0.05, 4.0)},
                          {0.5, test::direction_of(0.4, 0.5)}};
    static_assert(std::size(cases) + 7 + 2 == kVisibleNormalChi2Tests);
    for (const Case& c : cases) {
        const GGX<double> ggx{c.alpha};
        test::Chi2Options o;
        o.name =
            "visible_normals_complete_a" + std::to_string(c.alpha) + "_z" + std::to_string(c.w.z);
        o.test_count = kVisibleNormalChi2Tests;
        o.cos_theta_min = 0;
        const auto r = test::run_chi2(
            o,
            [&](const std::array<double, 3>& u) {
                return Chi2Draw::direction(ggx.sample_visible_normal_complete(c.w, u[0], u[1]));
            },
            [&](const Vec3d& wm) { return ggx.D_visible_complete(c.w, wm); });
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdf_integral, 1, 1e-6) << o.name;
    }
}

TEST(MicrofacetStat, SharpVisibleNormalLobeChi2) {
    // α = 0.05 and 0.01 seen from the normal: the lobe has 1 − cos θm ≈ α²/2, inside one cell of
    // the full grid, so the grid is zoomed onto cos θm ∈ [1 − 8α², 1]. GGX puts
    // P(tan²θm > T) = α²/(α² + T) outside (T ≈ 16α², i.e. ≈ 6 %), which joins the absent bin.
    for (double alpha : {0.05, 0.01}) {
        const GGX<double> ggx{alpha};
        const Vec3d w = test::direction_of(0.999, 1.0);
        test::Chi2Options o;
        o.name = "visible_normals_zoomed_a" + std::to_string(alpha);
        o.test_count = kVisibleNormalChi2Tests;
        o.cos_theta_min = 1 - 8 * sqr(alpha);
        const auto r = test::run_chi2(
            o,
            [&](const std::array<double, 3>& u) {
                return Chi2Draw::direction(ggx.sample_visible_normal(w, u[0], u[1]));
            },
            [&](const Vec3d& wm) { return ggx.pdf_visible_normal(w, wm); });
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_GT(r.absent_fraction, 0.03);  // the zoom really cuts the tails
    }
}

}  // namespace
}  // namespace lamina

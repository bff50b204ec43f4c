// The split visible-normal rule (models/numerics/visible_normal_quadrature.h) against the
// closed-form distribution of GGX normals, and its root finder against a known root.
#include "models/numerics/visible_normal_quadrature.h"

#include "core/math.h"
#include "core/vec.h"
#include "models/numerics/quadrature.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

// GGX (Trowbridge–Reitz): the fraction of the projected normal distribution D(wm) cos θm with
// tan²θm < t is t/(α² + t) (integrate D cos θm dω = α² d(tan²θ)/(α² + tan²θ)²).
double ggx_cap_fraction(double alpha, double cos_theta) {
    const double t = (1 - sqr(cos_theta)) / sqr(cos_theta);
    return t / (sqr(alpha) + t);
}

// At normal incidence the visible normals are distributed as D(wm) cos θm: the share with
// cos θm above z0 is a step of the integrand, which the rule splits, so a few nodes per piece
// give it to the root finder's tolerance; two steps (a band of cosines) likewise.
TEST(VisibleNormalQuadrature, StepsAtCrossingsAreExact) {
    const Vec3d w(0, 0, 1);
    const QuadratureRule q = gauss_legendre(3);
    for (double alpha : {0.05, 0.3, 0.8})
        for (double z0 : {0.6, 0.9, 0.99}) {
            const GGX<double> ggx{alpha};
            auto height = [](const Vec3d& wm) { return wm.z; };
            const double cap = integrate_visible_split<double>(
                ggx, w, [&](const Vec3d& wm) { return wm.z > z0 ? 1.0 : 0.0; }, q, 4, 1e-10,
                Crossing{height, z0});
            EXPECT_NEAR(cap, ggx_cap_fraction(alpha, z0), 1e-8) << alpha << " " << z0;
            const double z1 = 0.5 * z0;
            const double band = integrate_visible_split<double>(
                ggx, w, [&](const Vec3d& wm) { return wm.z > z1 && wm.z < z0 ? 1.0 : 0.0; }, q, 4,
                1e-10, Crossing{height, z0}, Crossing{height, z1});
            EXPECT_NEAR(band, ggx_cap_fraction(alpha, z1) - ggx_cap_fraction(alpha, z0), 1e-8)
                << alpha << " " << z0;
        }
}

// A reflection off an oblique direction is not monotonic along the radius: on the φ lines of the
// half disk facing away from w the reflected direction's height rises and falls, so a cap of
// reflected directions can enter and leave one line with the same sign at both ends. The rule
// scans each line for sign changes: the share of visible normals that reflect w (θ = 46°, GGX
// α 0.27) into the cap z > 0.866, G2/G1-weighted, equals an independent solid-angle sum of the
// reflection lobe f μo = D G2/(4 μi) over that cap (midpoint cells; 500 × 1000 and 4000 × 8000
// agree to 1e-6). The rule's remaining error is its φ midpoints on the cap edge's kink, 1.2e-3
// at 32 nodes, 3e-4 at 64–128, 1e-5 at 256: with 256, 1e-4. Without the scan the same rule is
// 15 % low.
TEST(VisibleNormalQuadrature, ReflectedCapCrossingAPhiLineTwice) {
    const double alpha = 0.272, mu = 0.6939, z_cap = std::sqrt(0.75);
    const GGX<double> ggx{alpha};
    const Vec3d w(std::sqrt(1 - mu * mu), 0, mu);
    const double lambda_w = ggx.lambda(w);
    const QuadratureRule q = gauss_legendre(4);
    const double rule = integrate_visible_split<double>(
        ggx, w,
        [&](const Vec3d& wm) {
            const Vec3d wo = reflect(w, wm);
            return wo.z > z_cap ? (1 + lambda_w) / (1 + lambda_w + ggx.lambda(wo)) : 0.0;
        },
        q, 256, 1e-9, Crossing{[&](const Vec3d& wm) { return reflect(w, wm).z; }, z_cap});
    double sum = 0;
    const int n = 500;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < 2 * n; ++j) {
            const double z = (i + 0.5) / n, s = std::sqrt(1 - z * z);
            const double phi = 2 * kPi<double> * (j + 0.5) / (2 * n);
            if (z <= z_cap) continue;
            const Vec3d wo(s * std::cos(phi), s * std::sin(phi), z);
            const Vec3d h = normalize(w + wo);
            sum += ggx.D(h) * ggx.G2(w, wo) / (4 * w.z) * (1.0 / n) * (kPi<double> / n);
        }
    EXPECT_NEAR(rule, sum, 1e-4);
}

// The pieces cover the whole disk at any incidence: the visible normals' density integrates to
// one, split or not, but for the rim r > 1 − 1e-9 the rule leaves out (2e-9 of the disk).
TEST(VisibleNormalQuadrature, PiecesCoverTheDisk) {
    const QuadratureRule q = gauss_legendre(5);
    for (double alpha : {0.02, 0.4, 1.0})
        for (double theta : {0.0, 0.7, 1.4}) {
            const GGX<double> ggx{alpha};
            const Vec3d w(std::sin(theta), 0, std::cos(theta));
            const double total = integrate_visible_split<double>(
                ggx, w, [](const Vec3d&) { return 1.0; }, q, 6, 1e-8,
                Crossing{[&](const Vec3d& wm) { return dot(w, wm); }, 0.8});
            EXPECT_NEAR(total, 1.0 - 2e-9, 1e-12) << alpha << " " << theta;
        }
}

// A smooth integrand that varies in the normals' rim: the mean cosine of the visible normals at
// normal incidence, E[cos θm] = ∫ (1 + t)^(−1/2) α² dt/(α² + t)² over t = tan²θm, here by a fine
// independent rule in s = t/(α² + t) (t = α² s/(1 − s), α² dt/(α² + t)² = ds), against 5 × 6
// nodes of the rule. In u = √(1 − r) the rim layer where the slopes pass 1 (1 − r ~ α²/2 in r)
// is ~α wide: the rule's error is 3e-4 at α ≥ 0.3 but grows to 1.1e-3 at α = 0.1 and 7e-4 at
// 0.05 (measured; the reason docs/models.md gives the per-material curves' budget as it does).
TEST(VisibleNormalQuadrature, RimIsResolvedInU) {
    const Vec3d w(0, 0, 1);
    const QuadratureRule q = gauss_legendre(5);
    for (double alpha : {0.05, 0.1, 0.3, 0.6, 1.0}) {
        const int n = 200000;
        double mean = 0;
        for (int i = 0; i < n; ++i) {
            const double s = (i + 0.5) / n, t = sqr(alpha) * s / (1 - s);
            mean += 1 / std::sqrt(1 + t) / n;
        }
        const GGX<double> ggx{alpha};
        const double rule = integrate_visible_split<double>(
            ggx, w, [](const Vec3d& wm) { return wm.z; }, q, 6, 1e-8,
            Crossing{[](const Vec3d& wm) { return wm.z; }, -1.0});
        EXPECT_NEAR(rule, mean, alpha >= 0.3 ? 3e-4 : 1.5e-3) << alpha;
    }
}

// The root of a smooth monotone function within the tolerance, in fewer evaluations than
// bisection's log2(width/tol).
TEST(VisibleNormalQuadrature, BracketedRootIsFastOnSmoothFunctions) {
    int evaluations = 0;
    auto h = [&](double x) {
        ++evaluations;
        return x * x * x + x - 0.3;
    };
    const double root = bracketed_root(h, 0.0, 1.0, h(0.0), h(1.0), 1e-10);
    EXPECT_NEAR(root * root * root + root, 0.3, 1e-9);
    EXPECT_LT(evaluations, 2 + 20);  // bisection: 34
}

}  // namespace
}  // namespace lamina

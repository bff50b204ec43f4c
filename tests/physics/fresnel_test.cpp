// Fresnel reflectance, Snell refraction and mirror reflection (physics/fresnel.h).
#include "physics/fresnel.h"

#include "core/math.h"
#include "core/rng.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

// Closed forms below are evaluated in double; the code under test computes the same quantities
// through a different route (via cos θt, or through std::complex), so agreement to a few hundred
// ulp is expected: 1e-14 absolute on reflectances in [0, 1].
constexpr double kExact = 1e-14;

TEST(Fresnel, NormalIncidence) {
    // At θ = 0 both polarizations give r = (η − 1)/(η + 1) (Born & Wolf §1.5.2):
    // F = (0.5/2.5)² = 0.04 for η = 1.5, and the same from the dense side (η = 1/1.5).
    EXPECT_NEAR(fresnel_dielectric(1.0, 1.5), 0.04, 1e-16);
    EXPECT_NEAR(fresnel_dielectric(1.0, 1 / 1.5), 0.04, 1e-16);
    EXPECT_NEAR(fresnel_dielectric(-1.0, 1.5), 0.04, 1e-16);  // from below: relative index 1/η
    for (double eta : {1.0001, 1.33, 2.4, 0.5}) {
        EXPECT_NEAR(fresnel_dielectric(1.0, eta), sqr((eta - 1) / (eta + 1)), kExact);
        // The F0 the production models are parametrized by: the same number, and the same from
        // the dense side.
        EXPECT_NEAR(fresnel_dielectric_normal(eta), fresnel_dielectric(1.0, eta), kExact);
        EXPECT_NEAR(fresnel_dielectric_normal(1 / eta), fresnel_dielectric_normal(eta), kExact);
    }
    EXPECT_NEAR(fresnel_dielectric_normal(1.5), 0.04, 1e-16);
    EXPECT_EQ(fresnel_dielectric_normal(1.0), 0.0);
}

TEST(Fresnel, KnownValueAt45Degrees) {
    // η = 1.5, θi = 45°: cos θi = √2/2, sin²θt = (1/2)/2.25 = 2/9, so η cos θt = 1.5·√(7/9) = √7/2.
    // s: r_s = (cos θi − η cos θt)/(cos θi + η cos θt) = (√2 − √7)/(√2 + √7), R_s = 0.0920134
    // p: at 45° Abelès' identity gives R_p = R_s² (check: r_p = (η cos θi − cos θt)/(η cos θi +
    //    cos θt) = (1.06066 − 0.88192)/(1.06066 + 0.88192) = 0.092013 = R_s), R_p = 0.0084665.
    // F = (R_s + R_p)/2 = 0.0502399.
    const double rs = sqr((std::sqrt(2.0) - std::sqrt(7.0)) / (std::sqrt(2.0) + std::sqrt(7.0)));
    const double expected = (rs + rs * rs) / 2;
    EXPECT_NEAR(expected, 0.0502399110, 1e-10);  // the hand value above
    EXPECT_NEAR(fresnel_dielectric(std::sqrt(0.5), 1.5), expected, kExact);
}

TEST(Fresnel, GrazingIncidenceReflectsEverything) {
    // cos θi = 0: r_s = −η cos θt/(η cos θt) = −1 and r_p = −cos θt/cos θt = −1, so F = 1.
    for (double eta : {1.5, 1 / 1.5, 3.0}) {
        EXPECT_NEAR(fresnel_dielectric(0.0, eta), 1.0, kExact);
        EXPECT_NEAR(fresnel_conductor(0.0, eta, 0.0), 1.0, kExact);
        EXPECT_NEAR(fresnel_conductor(0.0, eta, 2.0), 1.0, kExact);
    }
}

TEST(Fresnel, SameEnergyFromBothSides) {
    // Stokes relations: reflectance is the same for the ray and its reversed refracted ray,
    // F(cos θi, η) = F(cos θt, 1/η) with η sin θt = sin θi; and light arriving from below
    // (negative cosine) sees the relative index 1/η, so F(−cos θt, η) is the same number again.
    for (double eta : {1.5, 1 / 1.5, 2.4, 1.01}) {
        for (int i = 0; i <= 100; ++i) {
            const double cos_i = i / 100.0;
            const double sin2_t = (1 - sqr(cos_i)) / sqr(eta);
            if (sin2_t >= 1) continue;  // TIR: no reversed ray
            const double cos_t = std::sqrt(1 - sin2_t);
            const double f = fresnel_dielectric(cos_i, eta);
            EXPECT_NEAR(fresnel_dielectric(cos_t, 1 / eta), f, 1e-13) << eta << ' ' << cos_i;
            EXPECT_NEAR(fresnel_dielectric(-cos_t, eta), f, 1e-13) << eta << ' ' << cos_i;
            EXPECT_GE(f, 0);
            EXPECT_LE(f, 1);
        }
    }
}

TEST(Fresnel, TotalInternalReflection) {
    // From the dense side (η = 1/1.5) the critical angle has sin θc = 1/1.5, cos θc = √(1 − 1/2.25)
    // = 0.745356. Every cos θi below it reflects exactly 1; just above, F is continuous at 1 (r_p
    // → 1 as cos θt → 0, 1 − F = O(cos θt) = O(√(cos θi − cos θc)), i.e. < 1e-2 at 1e-7 above) and
    // then drops to 0.04 at normal incidence.
    const double eta = 1 / 1.5, cos_c = std::sqrt(1 - 1 / 2.25);
    for (int i = 0; i < 1000; ++i) {
        const double cos_i = cos_c * i / 1000.0;
        EXPECT_EQ(fresnel_dielectric(cos_i, eta), 1.0) << cos_i;
        EXPECT_EQ(fresnel_dielectric(-cos_i, 1.5), 1.0) << cos_i;  // the same, seen from below
    }
    EXPECT_EQ(fresnel_dielectric(cos_c * (1 - 1e-12), eta), 1.0);
    EXPECT_LT(fresnel_dielectric(cos_c + 1e-7, eta), 1.0);
    EXPECT_GT(fresnel_dielectric(cos_c + 1e-7, eta), 0.99);
    EXPECT_LT(fresnel_dielectric(cos_c + 0.05, eta), 0.9);
}

TEST(Fresnel, ConductorWithoutAbsorptionIsADielectric) {
    // k = 0 makes the complex Fresnel equations the real ones, including TIR for η < 1 (there
    // cos θt is purely imaginary and |r| = 1).
    // At the critical angle (sin²θ = η²) R has an infinite slope: a rounding δ ≈ 1e-16 of
    // η² − sin²θ moves the real-arithmetic form by O(√δ) ≈ 1e-8, so there the tolerance is
    // 100·√ε; elsewhere both forms agree to rounding.
    for (double eta : {1.5, 1 / 1.5, 2.4, 0.8, 1.01}) {
        for (int i = 0; i <= 200; ++i) {
            const double cos_i = i / 200.0;
            const bool near_critical = std::abs((1 - cos_i * cos_i) - eta * eta) < 1e-12;
            EXPECT_NEAR(fresnel_conductor(cos_i, eta, 0.0), fresnel_dielectric(cos_i, eta),
                        near_critical ? 1.5e-6 : 1e-13)
                << eta << ' ' << cos_i;
        }
    }
}

TEST(Fresnel, ConductorAtNormalIncidence) {
    // θ = 0: r = (η + ik − 1)/(η + ik + 1), |r|² = ((η − 1)² + k²)/((η + 1)² + k²).
    for (const auto& [eta, k] : std::initializer_list<std::pair<double, double>>{
             {0.143, 3.983}, {0.374, 2.385}, {1.442, 1.603}, {2.9, 3.0}, {1.5, 0.0}, {0.2, 0.1}}) {
        EXPECT_NEAR(fresnel_conductor(1.0, eta, k),
                    (sqr(eta - 1) + sqr(k)) / (sqr(eta + 1) + sqr(k)), kExact);
    }
}

TEST(Fresnel, ConductorMatchesTheRealArithmeticForm) {
    // An independent form of the conductor Fresnel equations without complex numbers (Born & Wolf
    // §14.2; the form of pbrt-v3's FrConductor, after S. Lagarde, "Memo on Fresnel equations",
    // 2013): with
    // a² + b² = √((η² − k² − sin²θ)² + 4η²k²) and a = √((a² + b² + η² − k² − sin²θ)/2),
    //   R_s = (a² + b² − 2a cos θ + cos²θ)/(a² + b² + 2a cos θ + cos²θ),
    //   R_p = R_s (cos²θ (a² + b²) − 2a cos θ sin²θ + sin⁴θ)/(cos²θ (a² + b²) + 2a cos θ sin²θ
    //         + sin⁴θ),
    // F = (R_s + R_p)/2. Agreement to 1e-12 (both are a few dozen flops on O(1) numbers).
    const double etas[] = {0.143, 0.374, 1.442, 2.9, 0.2}, ks[] = {3.983, 2.385, 1.603, 3.0, 0.1};
    for (int m = 0; m < 5; ++m) {
        const double eta = etas[m], k = ks[m];
        for (int i = 0; i <= 100; ++i) {
            const double c = i / 100.0, s2 = 1 - c * c;
            const double t0 = sqr(eta) - sqr(k) - s2;
            const double a2b2 = std::sqrt(sqr(t0) + 4 * sqr(eta) * sqr(k));
            const double a = std::sqrt((a2b2 + t0) / 2);
            const double rs = (a2b2 - 2 * a * c + c * c) / (a2b2 + 2 * a * c + c * c);
            const double rp = rs * (c * c * a2b2 - 2 * a * c * s2 + s2 * s2) /
                              (c * c * a2b2 + 2 * a * c * s2 + s2 * s2);
            EXPECT_NEAR(fresnel_conductor(c, eta, k), (rs + rp) / 2, 1e-12)
                << eta << ' ' << k << ' ' << c;
        }
    }
}

TEST(Fresnel, GoldIsAReflectanceAtEveryAngle) {
    // Gold-like RGB (η, k) = (0.143, 3.983), (0.374, 2.385), (1.442, 1.603) (the usual rendering
    // values for gold at red, green, blue): F ∈ [0, 1] at every angle, and red reflects more than
    // blue at normal incidence (16.598/17.170 = 0.967 vs 2.765/8.533 = 0.324 by the closed form
    // above).
    const double eta[3] = {0.143, 0.374, 1.442}, k[3] = {3.983, 2.385, 1.603};
    for (int c = 0; c < 3; ++c) {
        for (int i = 0; i <= 1000; ++i) {
            const double f = fresnel_conductor(i / 1000.0, eta[c], k[c]);
            EXPECT_GE(f, 0);
            EXPECT_LE(f, 1);
        }
    }
    EXPECT_GT(fresnel_conductor(1.0, eta[0], k[0]), fresnel_conductor(1.0, eta[2], k[2]));
}

// Snell's law on random directions on both sides of a tilted normal.
TEST(Fresnel, RefractObeysSnellAndRoundTrips) {
    // With w on the side n points to, the relative index is η: sin θi = η sin θt; from the other
    // side it is 1/η. The refracted ray lies in the plane of w and n, on the other side, and
    // refracting it back through the same normal and η returns w (Helmholtz reversibility).
    // Tolerance 1e-12: a handful of flops on unit vectors, amplified near grazing by 1/cos θt.
    ParticleRng rng(11, 0, 0);
    const Vec3d n = normalize(Vec3d(0.2, -0.1, 0.9));
    int refracted = 0, tir = 0;
    for (double eta : {1.5, 1 / 1.5, 2.4}) {
        for (int i = 0; i < 2000; ++i) {
            const Vec3d w = test::uniform_sphere_direction(rng);
            const double cos_i = dot(w, n);
            const double rel = cos_i > 0 ? eta : 1 / eta;
            const double sin_i = length(cross(w, n));
            const auto wt = refract(w, n, eta);
            if (sin_i > rel * (1 + 1e-9)) {  // beyond the critical angle
                EXPECT_FALSE(wt.has_value());
                EXPECT_EQ(fresnel_dielectric(cos_i, eta), 1.0);
                ++tir;
                continue;
            }
            if (sin_i > rel * (1 - 1e-9)) continue;  // too close to call
            ASSERT_TRUE(wt.has_value()) << eta << ' ' << cos_i;
            ++refracted;
            EXPECT_NEAR(length(*wt), 1, 1e-12);
            EXPECT_LT(dot(*wt, n) * cos_i, 0);                       // other side
            EXPECT_NEAR(dot(*wt, cross(w, n)), 0, 1e-12);            // plane of incidence
            EXPECT_NEAR(rel * length(cross(*wt, n)), sin_i, 1e-12);  // Snell
            EXPECT_LE(dot(*wt, w), 1e-12);  // bends towards −w's side, never reflected back
            const auto back = refract(*wt, n, eta);
            ASSERT_TRUE(back.has_value());
            EXPECT_NEAR(back->x, w.x, 1e-10);
            EXPECT_NEAR(back->y, w.y, 1e-10);
            EXPECT_NEAR(back->z, w.z, 1e-10);
        }
    }
    EXPECT_GT(refracted, 1000);  // both branches were exercised
    EXPECT_GT(tir, 100);
}

TEST(Fresnel, RefractAtNormalIncidenceGoesStraightThrough) {
    const auto wt = refract(Vec3d(0, 0, 1), Vec3d(0, 0, 1), 1.5);
    ASSERT_TRUE(wt.has_value());
    EXPECT_NEAR(wt->z, -1, 1e-15);
    EXPECT_NEAR(wt->x, 0, 1e-15);
    const auto up = refract(Vec3d(0, 0, -1), Vec3d(0, 0, 1), 1.5);
    ASSERT_TRUE(up.has_value());
    EXPECT_NEAR(up->z, 1, 1e-15);
}

TEST(Fresnel, ReflectIsAnInvolutionAboutTheNormal) {
    ParticleRng rng(12, 0, 0);
    for (int i = 0; i < 1000; ++i) {
        const Vec3d w = test::uniform_sphere_direction(rng),
                    n = test::uniform_sphere_direction(rng);
        const Vec3d r = reflect(w, n);
        EXPECT_NEAR(length(r), 1, 1e-14);
        EXPECT_NEAR(dot(r, n), dot(w, n), 1e-14);  // same angle to the normal, same side
        const Vec3d back = reflect(r, n);
        EXPECT_NEAR(back.x, w.x, 1e-14);
        EXPECT_NEAR(back.y, w.y, 1e-14);
        EXPECT_NEAR(back.z, w.z, 1e-14);
    }
    // About +z: the mirror direction of docs/physics.md §1 (φ → φ + 180°).
    const Vec3d m = reflect(Vec3d(0.6, 0.0, 0.8), Vec3d(0, 0, 1));
    EXPECT_NEAR(m.x, -0.6, 1e-15);
    EXPECT_NEAR(m.y, 0.0, 1e-15);
    EXPECT_NEAR(m.z, 0.8, 1e-15);
}

}  // namespace
}  // namespace lamina

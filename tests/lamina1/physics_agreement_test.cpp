// The header library's scalar physics (include/lamina1/physics.h: what a renderer gets with
// lamina-1, which includes nothing of lamina) against lamina's own (physics/: lane templates the
// kernels evaluate), two writings of the same published formulas kept from drifting apart:
// Fresnel of dielectrics (Born & Wolf; R_s and R_p apart too) and conductors (also against the
// std::complex form), GGX's D and Smith Λ (isotropic and anisotropic, with the visible normals),
// Henyey–Greenstein and Snell's refraction, at 2000 random arguments each.
#include "core/math.h"
#include "core/rng.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/phase.h"
#include "physics/polarization.h"

#include "lamina1/physics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

void expect_rel(double a, double b, double rel, const char* what) {
    EXPECT_LE(std::abs(a - b), rel * std::max(std::abs(a), std::abs(b)) + 1e-300)
        << what << ": " << a << " vs " << b;
}

TEST(Lamina1Physics, AgreesWithLaminasPhysics) {
    ParticleRng rng(3, 0, 0);
    auto u = [&] { return rng.uniform_double(); };
    for (int n = 0; n < 2000; ++n) {
        const double c = 2 * u() - 1, eta = 0.2 + 3 * u(), k = 5 * u() * u();
        expect_rel(lamina1::fresnel_dielectric(c, eta), fresnel_dielectric(c, eta), 1e-12,
                   "fresnel_dielectric");
        // R_s and R_p apart (lamina-1's slab under polarization) against the reflection Mueller
        // matrix of lamina's polarized kernels: a = (R_s + R_p)/2, b = (R_s − R_p)/2, to 1e-12 of
        // a (a − b cancels near Brewster's angle, where R_p → 0).
        const lamina1::FresnelSp sp = lamina1::fresnel_dielectric_sp(c, eta);
        const InterfaceMueller<double> m =
            fresnel_dielectric_mueller<double>(c, eta, 1 / eta).reflection;
        EXPECT_LE(std::abs(sp.s - (m.a + m.b)), 1e-12 * m.a) << c << " " << eta;
        EXPECT_LE(std::abs(sp.p - (m.a - m.b)), 1e-12 * m.a) << c << " " << eta;
        const double cp = u();
        expect_rel(lamina1::fresnel_complex(cp, eta, k), fresnel_conductor(cp, eta, k), 1e-12,
                   "fresnel_complex");
        expect_rel(lamina1::fresnel_complex(cp, eta, k), fresnel_conductor_complex(cp, eta, k),
                   1e-9, "fresnel_complex against the complex form");
        const lamina1::Rgb rgb = lamina1::fresnel_complex_rgb(cp, lamina1::Rgb(eta, 1.1 * eta, 0.9),
                                                              lamina1::Rgb(k, 0.5 * k, 0.0));
        expect_rel(rgb[1], fresnel_conductor(cp, 1.1 * eta, 0.5 * k), 1e-12, "fresnel rgb");

        const double alpha = 0.001 + u();
        const double theta = 1.5 * u(), phi = 6.28 * u();
        const Vec3d w(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                      std::cos(theta));
        const lamina1::Vec3 w1{w.x, w.y, w.z};
        expect_rel(lamina1::GGX{alpha}.D(w1), GGX<double>{alpha}.D(w), 1e-12, "GGX D");
        expect_rel(lamina1::GGX{alpha}.lambda(w1), GGX<double>{alpha}.lambda(w), 1e-12,
                   "Smith lambda");

        const double g = 1.98 * u() - 0.99;
        expect_rel(lamina1::hg_phase(c, g), hg_phase(c, g), 1e-12, "hg_phase");

        const auto r1 = lamina1::refract(w1, lamina1::Vec3{0, 0, 1}, eta);
        const auto r = refract(w, Vec3d(0, 0, 1), eta);
        ASSERT_EQ(bool(r1), bool(r));
        if (r) {
            expect_rel(r1->z, r->z, 1e-12, "refract z");
            expect_rel(r1->x, r->x, 1e-12, "refract x");
        }
    }
}

// The anisotropic GGX (lamina1::GGX of a SlopeCovariance, written with the covariance Σ in the
// surface's frame) against lamina's (physics/microfacet.h: α_x, α_y and the tangent, written as
// the isotropic formula plus the terms in α_y − α_x): D, Λ, the visible-normal density and the
// visible normal drawn from the same uniforms (both Heitz 2018's disk, in the same frame); and
// the covariance of α² I taken as anisotropic against the isotropic distribution.
TEST(Lamina1Physics, AnisotropicGgxAgreesWithLaminasPhysics) {
    ParticleRng rng(5, 0, 0);
    auto u = [&] { return rng.uniform_double(); };
    auto to1 = [](const Vec3d& w) { return lamina1::Vec3{w.x, w.y, w.z}; };
    for (int n = 0; n < 2000; ++n) {
        const double alpha_x = 0.002 + u(), alpha_y = 0.002 + u(), psi = 12.6 * u() - 6.3;
        const lamina1::GGX a1 =
            lamina1::GGX::anisotropic_of(lamina1::SlopeCovariance::of_axes(alpha_x, alpha_y, psi));
        const GGX<double> a = GGX<double>::anisotropic(alpha_x, alpha_y, psi);
        auto direction = [&] {
            const double theta = 1.5 * u(), phi = 6.28 * u();
            return Vec3d(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                         std::cos(theta));
        };
        const Vec3d w = direction(), wm = direction();
        // The covariance form reads Σ's entries, each rounded to a few ulps, through det Σ and
        // the quadratic forms, whose cancellations amplify them by up to the condition number
        // κ = (α_max/α_min)² (up to 2.5e5 here): 1e-12 plus 1e-15 κ.
        const double kappa = sqr(std::max(alpha_x, alpha_y) / std::min(alpha_x, alpha_y));
        const double tol = 1e-12 + 1e-15 * kappa;
        expect_rel(a1.D(to1(wm)), a.D(wm), tol, "anisotropic D");
        expect_rel(a1.lambda(to1(w)), a.lambda(w), tol, "anisotropic lambda");
        expect_rel(a1.D_visible(to1(w), to1(wm)), a.D_visible(w, wm), tol, "anisotropic D_w");
        const double u1 = u(), u2 = u();
        const lamina1::Vec3 m1 = a1.sample_visible_normal(to1(w), u1, u2);
        const Vec3d m = a.sample_visible_normal(w, u1, u2);
        EXPECT_NEAR(m1.x, m.x, tol);
        EXPECT_NEAR(m1.y, m.y, tol);
        EXPECT_NEAR(m1.z, m.z, tol);

        // Σ = α² I through the anisotropic formulas is the isotropic distribution.
        const lamina1::GGX iso{alpha_x};
        const lamina1::GGX as_aniso =
            lamina1::GGX::anisotropic_of(lamina1::SlopeCovariance::isotropic(alpha_x));
        expect_rel(as_aniso.D(to1(wm)), iso.D(to1(wm)), 1e-12, "isotropic D");
        expect_rel(as_aniso.lambda(to1(w)), iso.lambda(to1(w)), 1e-12, "isotropic lambda");
        const lamina1::Vec3 n1 = as_aniso.sample_visible_normal(to1(w), u1, u2),
                            n0 = iso.sample_visible_normal(to1(w), u1, u2);
        EXPECT_NEAR(n1.x, n0.x, 1e-12);
        EXPECT_NEAR(n1.y, n0.y, 1e-12);
        EXPECT_NEAR(n1.z, n0.z, 1e-12);
    }
}

}  // namespace
}  // namespace lamina

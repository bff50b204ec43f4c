// The header library's scalar physics (include/lamina1/physics.h: what a renderer gets with
// lamina-1, which includes nothing of lamina) against lamina's own (physics/: lane templates the
// kernels evaluate), two writings of the same published formulas kept from drifting apart:
// Fresnel of dielectrics (Born & Wolf) and conductors (also against the std::complex form), GGX's
// D and Smith Λ, Henyey–Greenstein and Snell's refraction, at 2000 random arguments each.
#include "core/rng.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/phase.h"

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

}  // namespace
}  // namespace lamina

// lamina-coat (models/lamina_coat/lamina_coat.h): its tables against independent integrals, its
// reciprocity and energy conservation, its smooth limits.
#include "models/lamina_coat/lamina_coat.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/production/ggx_albedo.h"
#include "models/registry.h"
#include "models/tables/fgd_table.h"
#include "models/test_stacks.h"
#include "physics/fresnel.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test::dir;

// A 16-bit table holds each value to 1/131070; the integrals behind it (a 128 × 128 Gauss rule
// over the visible normals, scripts/lamina_coat_fit.py) agree with lamina's own to 3e-4, but for
// the white lobe at small α and steep incidence, where the facets that reflect below the horizon
// cut the domain and the rule converges slowly (6e-4 at r = 8/31, μ = 1): 1e-3 there.
constexpr double kTableTolerance = 3e-4, kWhiteTableTolerance = 1e-3;

TEST(LaminaCoatTable, CoatAlbedoIsTheDielectricLobesIntegralAtTheNodes) {
    for (double eta : {1.1, 1.5, 2.0, 2.6})
        for (int j : {1, 8, 16, 31})
            for (int i : {1, 4, 16, 31}) {
                const double mu = i / 31.0, r = j / 31.0;
                EXPECT_NEAR(lamina_coat_albedo(mu, r, eta),
                            FgdTable::direct(mu, r * r, eta, 0.0, 192, 256), kTableTolerance)
                    << "eta " << eta << " r " << r << " mu " << mu;
            }
}

TEST(LaminaCoatTable, WhiteAlbedoIsTheWhiteLobesIntegralAtTheNodes) {
    for (int j : {1, 8, 16, 31})
        for (int i : {1, 4, 16, 31}) {
            const double mu = i / 31.0, r = j / 31.0;
            EXPECT_NEAR(lamina_coat_white_albedo(mu, r),
                        correlated_ggx_albedo_white(mu, r * r, 192, 256), kWhiteTableTolerance)
                << "r " << r << " mu " << mu;
        }
}

TEST(LaminaCoatTable, InternalReflectanceUnderAbsorption) {
    // K_τ = ∫ F(μ; 1/η) e^(−2τ/μ) 2μ dμ / ∫ F(μ; 1/η) 2μ dμ, here by a 20 000-point midpoint rule
    // with lamina's Fresnel, at nodes τ = u/(1 − u), u = i/31.
    for (double eta : {1.2, 1.5, 2.5})
        for (int i : {0, 3, 10, 20}) {
            const double u = i / 31.0, tau = u / (1 - u);
            double with = 0, without = 0;
            const int n = 20000;
            for (int k = 0; k < n; ++k) {
                const double mu = (k + 0.5) / n, F = fresnel_dielectric(mu, 1 / eta);
                with += F * std::exp(-2 * tau / mu) * 2 * mu / n;
                without += F * 2 * mu / n;
            }
            EXPECT_NEAR(lamina_coat_internal_absorption(tau, eta), with / without, 2e-5)
                << "eta " << eta << " tau " << tau;
        }
}

TEST(LaminaCoatTable, AveragesAreTheAlbedosHemisphericalMeans) {
    // Ē = 2 ∫ E μ dμ: the trapezoids on the 32 nodes against a fine rule on the interpolated E.
    for (double r : {0.2, 0.5, 0.9}) {
        double mean = 0, white = 0;
        const int n = 4000;
        for (int k = 0; k < n; ++k) {
            const double mu = (k + 0.5) / n;
            mean += 2 * mu * lamina_coat_albedo(mu, r, 1.5) / n;
            white += 2 * mu * lamina_coat_white_albedo(mu, r) / n;
        }
        EXPECT_NEAR(lamina_coat_average_albedo(r, 1.5), mean, 2e-4);
        EXPECT_NEAR(lamina_coat_white_average_albedo(r), white, 2e-4);
    }
}

std::vector<Stack> stacks() {
    return {test::coated(1.5, 0.1, test::lambertian(Rgbd(0.8, 0.4, 0.1)), Rgbd(0.1, 0.0, 0.9)),
            test::coated(1.3, 0.5, test::lambertian(Rgbd(1.0))),
            test::coated(1.5, 0.05, test::gold(0.3), Rgbd(0.1)),
            test::coated(2.2, 0.3, test::gold(0.05)),
            test::coated(1.5, 0.0, test::lambertian(Rgbd(0.5)), Rgbd(0.3))};
}

TEST(LaminaCoat, IsReciprocal) {
    ParticleRng rng(7, 0, 0);
    for (const Stack& s : stacks()) {
        const auto model = make_model("lamina-coat", s);
        ASSERT_TRUE(model->support().brdf) << model->support().reason;
        for (int k = 0; k < 200; ++k) {
            const Vec3d wi = dir(89 * rng.uniform_double(), 360 * rng.uniform_double());
            const Vec3d wo = dir(89 * rng.uniform_double(), 360 * rng.uniform_double());
            const Rgbd a = model->eval(wi, wo), b = model->eval(wo, wi);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(a[c], b[c], 1e-12 * std::max(1.0, std::abs(a[c])));
        }
    }
}

/// ∫ f cos θo dωo (midpoint rule in θo, φo, finer near the mirror) plus the delta lobes.
Rgbd albedo_by_midpoints(const Model& m, const Vec3d& wi) {
    Rgbd sum(0.0);
    const int nt = 400, np = 400;
    for (int t = 0; t < nt; ++t) {
        const double theta = (t + 0.5) / nt * kPi<double> / 2;
        for (int p = 0; p < np; ++p) {
            const double phi = (p + 0.5) / np * 2 * kPi<double>;
            const Vec3d wo{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                           std::cos(theta)};
            sum += m.eval(wi, wo) *
                   (wo.z * std::sin(theta) * (kPi<double> / 2 / nt) * (2 * kPi<double> / np));
        }
    }
    for (const DeltaLobe& d : m.delta_lobes(wi))
        sum += d.energy;
    return sum;
}

TEST(LaminaCoat, ConservesEnergyAndAWhiteFurnaceReturnsEverything) {
    // A clear coat over a white Lambertian loses nothing: what it does not reflect it transmits,
    // and ρ (1 − K)/(1 − ρ K) = 1 returns all of it (to the tables' interpolation and this
    // quadrature, 3e-3).
    for (double alpha : {0.05, 0.3}) {
        const auto white =
            make_model("lamina-coat", test::coated(1.5, alpha, test::lambertian(Rgbd(1.0))));
        for (double theta : {0.0, 45.0, 75.0}) {
            const Rgbd a = albedo_by_midpoints(*white, dir(theta, 0));
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(a[c], 1.0, 3e-3) << alpha << " " << theta;
        }
    }
    // A bright conductor, rough coats: never above 1.
    for (const Stack& s : {test::coated(1.5, 0.3, test::conductor(Rgbd(0.05), Rgbd(8.0), 0.3)),
                           test::coated(2.0, 0.5, test::conductor(Rgbd(0.05), Rgbd(8.0), 0.1))}) {
        const auto m = make_model("lamina-coat", s);
        for (double theta : {0.0, 45.0, 75.0}) {
            const Rgbd a = albedo_by_midpoints(*m, dir(theta, 0));
            for (int c = 0; c < 3; ++c)
                EXPECT_LE(a[c], 1.0 + 1e-3) << theta;
        }
    }
}

TEST(LaminaCoat, SmoothCoatOverLambertianIsTheClassicalPlastic) {
    // α0 = 0, τ = 0: f = (1 − F(μi))(1 − F(μo)) ρ / (π η² (1 − ρ K)) with K = 1 − (1 − Ē_F)/η²
    // (e.g. Weidlich & Wilkie 2007's Lambertian under a smooth coat), Ē_F = 2∫F μ dμ.
    const double eta = 1.5, rho = 0.7;
    const auto m = make_model("lamina-coat", test::coated(eta, 0.0, test::lambertian(Rgbd(rho))));
    double average = 0;
    const int n = 20000;
    for (int k = 0; k < n; ++k) {
        const double mu = (k + 0.5) / n;
        average += 2 * mu * fresnel_dielectric(mu, eta) / n;
    }
    const double K = 1 - (1 - average) / (eta * eta);
    for (auto [ti, to] : {std::pair{0.0, 30.0}, {40.0, 70.0}, {60.0, 10.0}}) {
        const Vec3d wi = dir(ti, 0), wo = dir(to, 135);
        const double expected = (1 - fresnel_dielectric(wi.z, eta)) *
                                (1 - fresnel_dielectric(wo.z, eta)) * rho /
                                (kPi<double> * eta * eta * (1 - rho * K));
        EXPECT_NEAR(m->eval(wi, wo)[0], expected, 2e-3 * expected) << ti << " " << to;
    }
    const auto lobes = m->delta_lobes(dir(30, 0));
    ASSERT_EQ(lobes.size(), 1u);
    EXPECT_NEAR(lobes[0].energy[0], fresnel_dielectric(std::cos(30.0 * kPi<double> / 180), eta),
                1e-12);
}

TEST(LaminaCoat, SaysWhatItDoesNotSupport) {
    EXPECT_FALSE(make_model("lamina-coat", test::coated(3.0, 0.1, test::lambertian(Rgbd(0.5))))
                     ->support()
                     .brdf);
    EXPECT_FALSE(make_model("lamina-coat", test::coated(1.5, 0.1, test::dielectric(1.2, 0.1)))
                     ->support()
                     .brdf);
}

}  // namespace
}  // namespace lamina

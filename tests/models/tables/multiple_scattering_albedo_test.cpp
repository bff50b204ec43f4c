// The multiple-scattering albedo table (models/tables/multiple_scattering_albedo.h) against
// independent computations: a dielectric walk loses nothing, so its orders ≥ 2 carry exactly what
// the single- scattering interface loses, 1 − R_ss − T_ss, both computed here by quadrature over
// the visible normals (not by a walk); a white conductor's orders ≥ 2 carry 1 − E_ss. Tolerances:
// four standard errors of the walk's binomial estimate plus the quadrature's and the
// interpolation's error where stated.
#include "models/tables/multiple_scattering_albedo.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/tables/coat_transmittance.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

/// Single-scattering albedos over the visible normals of wi (Heitz 2018): reflection with the
/// height-correlated G2/G1 (Heitz 2014, Eq. 99), times a Fresnel factor (white: 1).
double reflection_ss(double mu, double alpha, double eta, bool white) {
    const Vec3d wi(std::sqrt(1 - mu * mu), 0, mu);
    const GGX<double> ggx{alpha};
    const double lambda_i = ggx.lambda(wi);
    const QuadratureRule q = gauss_legendre(96);
    const int n_phi = 192;
    double sum = 0;
    for (int a = 0; a < 96; ++a)
        for (int b = 0; b < n_phi; ++b) {
            const double r = q.x[a];
            const Vec3d wm = ggx.sample_visible_normal(wi, r * r, (b + 0.5) / n_phi);
            const Vec3d wo = reflect(wi, wm);
            if (wo.z <= 0) continue;
            const double F = white ? 1.0 : fresnel_dielectric(dot(wi, wm), eta);
            sum += q.w[a] * 2 * r / n_phi * F * (1 + lambda_i) / (1 + lambda_i + ggx.lambda(wo));
        }
    return sum;
}

double binomial_se(double p, int n) {
    return std::sqrt(std::max(p * (1 - p), 1.0 / n) / n);
}

struct Case {
    double mu, alpha, eta;
};

TEST(MultipleScatteringAlbedo, DielectricOrdersCarryWhatSingleScatteringLoses) {
    constexpr int kWalks = 1 << 15;
    unsigned stream = 900;
    for (const Case c : {Case{0.9, 0.3, 1.5}, Case{0.2, 0.6, 1.5}, Case{0.05, 1.0, 1.5},
                         Case{0.5, 0.5, 1 / 1.5}, Case{0.1, 0.8, 1 / 1.33}, Case{0.3, 0.4, 2.5}}) {
        const double lost = 1 - reflection_ss(c.mu, c.alpha, c.eta, false) -
                            CoatTransmittanceTable::direct(c.mu, c.alpha, c.eta,
                                                           TransmissionMasking::Smith, 96, 192);
        const auto d =
            MultipleScatteringAlbedo::walk_dielectric(c.mu, c.alpha, c.eta, kWalks, stream++);
        const double sum = d.reflected + d.transmitted;
        EXPECT_NEAR(sum, lost, 4 * binomial_se(sum, kWalks) + 1e-3)
            << "mu " << c.mu << " alpha " << c.alpha << " eta " << c.eta;
        EXPECT_GE(d.reflected, 0);
        EXPECT_GE(d.transmitted, 0);
    }
}

TEST(MultipleScatteringAlbedo, WhiteConductorOrdersAreOneMinusSingleScattering) {
    constexpr int kWalks = 1 << 15;
    unsigned stream = 950;
    for (const Case c : {Case{0.9, 0.2, 1}, Case{0.3, 0.6, 1}, Case{0.05, 1.0, 1}}) {
        const double expected = 1 - reflection_ss(c.mu, c.alpha, 1, true);
        const double got =
            MultipleScatteringAlbedo::walk_conductor(c.mu, c.alpha, kWalks, stream++);
        EXPECT_NEAR(got, expected, 4 * binomial_se(got, kWalks) + 1e-3)
            << "mu " << c.mu << " alpha " << c.alpha;
    }
}

TEST(MultipleScatteringAlbedo, TableInterpolatesTheWalk) {
    const auto& table = MultipleScatteringAlbedo::get();
    // Smooth interfaces have a single order.
    EXPECT_EQ(table.dielectric(0.5, 0.0, 1.5).reflected, 0);
    EXPECT_EQ(table.conductor(0.5, 0.0), 0);
    // Between nodes: the walk there, within its and the nodes' noise plus the linear
    // interpolation's error (the orders ≥ 2 vary slowly: ≤ 0.01 between nodes measured).
    constexpr int kWalks = 1 << 15;
    unsigned stream = 990;
    for (const Case c : {Case{0.37, 0.45, 1.5}, Case{0.12, 0.7, 1 / 1.5}, Case{0.8, 0.25, 1.8},
                         Case{0.2, 0.7, 1 / 1.2}, Case{0.5, 0.7, 1 / 1.2}}) {
        const auto t = table.dielectric(c.mu, c.alpha, c.eta);
        const auto w =
            MultipleScatteringAlbedo::walk_dielectric(c.mu, c.alpha, c.eta, kWalks, stream++);
        const double tol_r = 4 * binomial_se(w.reflected, kWalks) +
                             4 * binomial_se(w.reflected, MultipleScatteringAlbedo::kWalksSplit) +
                             0.01;
        const double tol_t = 4 * binomial_se(w.transmitted, kWalks) +
                             4 * binomial_se(w.transmitted, MultipleScatteringAlbedo::kWalksSplit) +
                             0.01;
        EXPECT_NEAR(t.reflected, w.reflected, tol_r) << c.mu << " " << c.alpha << " " << c.eta;
        EXPECT_NEAR(t.transmitted, w.transmitted, tol_t) << c.mu << " " << c.alpha << " " << c.eta;
        const double tc = table.conductor(c.mu, c.alpha);
        const double wc = MultipleScatteringAlbedo::walk_conductor(c.mu, c.alpha, kWalks, stream++);
        EXPECT_NEAR(tc, wc,
                    4 * binomial_se(wc, kWalks) +
                        4 * binomial_se(wc, MultipleScatteringAlbedo::kWalksConductor) + 0.01);
    }
}

}  // namespace
}  // namespace lamina

// The GGX albedos engines tabulate (models/production/ggx_albedo.h) against independent integrals
// over the outgoing solid angle, their limits, and the readings of Cycles' tables
// (cycles_albedo.h) and three.js's DFG texture (threejs_dfg.h) at their nodes.
#include "models/production/ggx_albedo.h"
#include "models/production/cycles_albedo.h"
#include "models/production/threejs_dfg.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/production/solid_angle_albedo.h"
#include "support/closed_forms.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace lamina {
namespace {

using test::conductor_ref;
using test::fresnel_ref;

/// ∫ g(wi·h) D(h) G(wi, wo) / (4 μi) dωo over the outgoing hemisphere with D in Walter et al.
/// 2007's form (Eq. 33) and Λ in Heitz 2014's (Eq. 72): `white` the height-correlated G2 and
/// g = 1 (the white albedo), else G = G1(wi) and g = ŝ, the integrand of s (whose reflected
/// direction wo is the variable: D_wi(h) dh = D G1(wi) (wi·h)/μi dh and dh = dωo/(4 wi·h)).
/// Gauss–Legendre in μo (n_mu) × midpoint in φo over [0, π], doubled.
double by_solid_angle(double mu, double alpha, double eta, bool white, int n_mu = 400,
                      int n_phi = 400) {
    const double f0 = sqr((eta - 1) / (eta + 1));
    return test::reflected_hemisphere_integral(
        mu, alpha, n_mu, n_phi, [&](const test::ReflectedPair& p) {
            return white ? p.D / (1 + p.lambda_i + p.lambda_o) / (4 * mu)
                         : (fresnel_ref(p.cos_i_h, eta) - f0) / (1 - f0) * p.D / (1 + p.lambda_i) /
                               (4 * mu);
        });
}

// The visible-normal integrals against the solid-angle ones at moderate roughness (where a
// 400 × 400 rule resolves the lobe): within 2e-5.
TEST(GgxAlbedo, AgreesWithTheSolidAngleIntegral) {
    for (double alpha : {0.1, 0.3, 0.7})
        for (double mu : {0.15, 0.5, 0.95}) {
            EXPECT_NEAR(correlated_ggx_albedo_white(mu, alpha),
                        by_solid_angle(mu, alpha, 1.5, true), 2e-5)
                << alpha << " " << mu;
            for (double eta : {1.2, 1.5, 2.3})
                EXPECT_NEAR(cycles_fresnel_factor(mu, alpha, eta),
                            by_solid_angle(mu, alpha, eta, false), 2e-5)
                    << alpha << " " << mu << " " << eta;
        }
}

// Limits: a smooth lobe reflects all its light and its factor is ŝ(μ) itself; ŝ runs from 0 at
// normal incidence to 1 at grazing.
TEST(GgxAlbedo, Limits) {
    for (double mu : {0.05, 0.4, 1.0}) {
        EXPECT_EQ(correlated_ggx_albedo_white(mu, 0), 1);
        const double f0 = 0.04;
        EXPECT_NEAR(cycles_fresnel_factor(mu, 0, 1.5), (fresnel_ref(mu, 1.5) - f0) / (1 - f0),
                    1e-15);
    }
    EXPECT_NEAR(cycles_fresnel_factor(1, 0, 1.5), 0, 1e-15);
    EXPECT_NEAR(cycles_fresnel_factor(0, 0, 1.5), 1, 1e-15);
}

// The reading: at Cycles' node coordinates the grids return the node values (the integrals at
// r = i/31 or m/15, μ likewise, η of z = k/15 with F0 = z⁴); between nodes, linear in each index.
TEST(CyclesAlbedo, ReadsItsNodesAsCyclesDoes) {
    const int i = 9, k = 20;  // r = 9/31, μ = 20/31
    const double r = i / 31.0, mu = k / 31.0;
    const CyclesWhiteAlbedo white(r);
    EXPECT_NEAR(white.albedo(mu), correlated_ggx_albedo_white(mu, r * r), 1e-14);
    const double mu_mid = (k + 0.25) / 31.0;
    EXPECT_NEAR(white.albedo(mu_mid),
                0.75 * correlated_ggx_albedo_white(mu, r * r) +
                    0.25 * correlated_ggx_albedo_white((k + 1) / 31.0, r * r),
                1e-14);
    // The η of node k: z = k/15, √F0 = z², η = (1 + √F0)/(1 − √F0).
    const double z = 6 / 15.0, eta = (1 + z * z) / (1 - z * z);
    EXPECT_NEAR(CyclesFresnelFactor::eta_node(6), eta, 1e-14);
    const double r16 = 4 / 15.0, mu16 = 11 / 15.0;
    const CyclesFresnelFactor factor(r16, eta);
    EXPECT_NEAR(factor.factor(mu16), cycles_fresnel_factor(mu16, r16 * r16, eta), 1e-12);
}

// The Schlick split adds up to the white albedo; at α = 0 it is 1 − w and w of μ itself.
TEST(GgxAlbedo, SchlickSplitAddsUpToTheAlbedo) {
    for (double alpha : {0.05, 0.4})
        for (double mu : {0.1, 0.6}) {
            const SchlickSplit s = correlated_ggx_schlick_split(mu, alpha);
            EXPECT_NEAR(s.scale + s.bias, correlated_ggx_albedo_white(mu, alpha), 1e-13);
            EXPECT_GT(s.bias, 0);
        }
    const SchlickSplit smooth = correlated_ggx_schlick_split(0.3, 0);
    EXPECT_NEAR(smooth.bias, std::pow(0.7, 5), 1e-15);
    EXPECT_NEAR(smooth.scale + smooth.bias, 1, 1e-15);
}

// three.js's texture as shipped (data/production) against the integral it stands for, E = scale
// + bias of the correlated lobe at each texel centre: a Monte Carlo estimate (4096 samples a
// texel), near it everywhere — a texture read transposed or shifted by a texel is off by far
// more — and worst at grazing view. The bounds are its measured distances (docs/models.md),
// rounded up: 1.474e-2 in the first row (μ = 1/32), 5.812e-3 in the second, 2.811e-3 elsewhere.
TEST(ThreeJsDfg, ShippedTexelsStandForTheIntegral) {
    double worst[3] = {0, 0, 0};
    for (int x = 0; x < ThreeJsDfgTexture::kSize; ++x) {
        const double r = ThreeJsDfgTexture::texel_centre(x);
        const ThreeJsDfgTexture texture(r);
        for (int y = 0; y < ThreeJsDfgTexture::kSize; ++y) {
            const double mu = ThreeJsDfgTexture::texel_centre(y);
            const SchlickSplit s = correlated_ggx_schlick_split(mu, r * r);
            double& w = worst[std::min(y, 2)];
            w = std::max(w, std::abs(texture.albedo(mu) - (s.scale + s.bias)));
        }
    }
    EXPECT_LE(worst[0], 1.48e-2);
    EXPECT_LE(worst[1], 5.82e-3);
    EXPECT_LE(worst[2], 2.82e-3);
    EXPECT_GT(worst[2], 1e-4);  // not the integral: the estimate's noise is there
}

// The reading: at a texel centre, that texel; half-way between two centres, their mean (in μ and
// in r); past the last centre, the edge texel.
TEST(ThreeJsDfg, ReadsItsTexelsAsTheGpuDoes) {
    const int x = 5, y = 9;
    const double r = ThreeJsDfgTexture::texel_centre(x), mu = ThreeJsDfgTexture::texel_centre(y);
    const ThreeJsDfgTexture texture(r), right(ThreeJsDfgTexture::texel_centre(x + 1)),
        between((r + ThreeJsDfgTexture::texel_centre(x + 1)) / 2);
    const double next = ThreeJsDfgTexture::texel_centre(y + 1);
    EXPECT_NEAR(texture.albedo((mu + next) / 2), (texture.albedo(mu) + texture.albedo(next)) / 2,
                1e-15);
    EXPECT_NEAR(between.albedo(mu), (texture.albedo(mu) + right.albedo(mu)) / 2, 1e-15);
    EXPECT_EQ(texture.albedo(1.0), texture.albedo(ThreeJsDfgTexture::texel_centre(15)));
    EXPECT_EQ(texture.albedo(0.0), texture.albedo(ThreeJsDfgTexture::texel_centre(0)));
    EXPECT_EQ(ThreeJsDfgTexture(1.0).albedo(mu),
              ThreeJsDfgTexture(ThreeJsDfgTexture::texel_centre(15)).albedo(mu));
}

}  // namespace
}  // namespace lamina

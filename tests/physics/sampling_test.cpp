// Warps of physics/sampling.h and the Henyey–Greenstein phase function of physics/phase.h, each
// tested as a triple (docs/style.md §4): round trip sample → invert, density integrating to one,
// and a chi-square goodness-of-fit test of the samples against the density (support/chi2.h).
#include "physics/sampling.h"
#include "core/math.h"
#include "core/rng.h"
#include "physics/phase.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test::Chi2Draw;
using test::Chi2Options;

// Round trips: the warps are bijections, so invert(sample(u)) = u up to rounding. The maps are
// built from sqrt, sin/cos and atan2 (each good to a few ulp) with derivatives of order one, except
// the polar singularities (a sample at the pole has no azimuth): 1e-12 leaves room for that
// amplification and is still nine orders below any plausible logic error.
constexpr double kRoundTrip = 1e-12;
constexpr int kRoundTripCount = 10000;

TEST(Sampling, ConcentricDiskRoundTrips) {
    ParticleRng rng(1, 0, 0);
    for (int i = 0; i < kRoundTripCount; ++i) {
        const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
        const auto d = sample_concentric_disk(u1, u2);
        ASSERT_LE(sqr(d[0]) + sqr(d[1]), 1 + 1e-15);
        const auto u = invert_concentric_disk(d[0], d[1]);
        EXPECT_NEAR(u[0], u1, kRoundTrip) << u1 << ' ' << u2;
        EXPECT_NEAR(u[1], u2, kRoundTrip) << u1 << ' ' << u2;
    }
    // Each of the four wedges and their boundaries (|a| = |b|) explicitly.
    for (const auto& [u1, u2] : std::initializer_list<std::pair<double, double>>{{0.9, 0.6},
                                                                                 {0.6, 0.9},
                                                                                 {0.1, 0.4},
                                                                                 {0.4, 0.1},
                                                                                 {0.9, 0.9},
                                                                                 {0.1, 0.1},
                                                                                 {0.9, 0.1},
                                                                                 {0.1, 0.9},
                                                                                 {0.75, 0.5},
                                                                                 {0.5, 0.25}}) {
        const auto d = sample_concentric_disk(u1, u2);
        const auto u = invert_concentric_disk(d[0], d[1]);
        EXPECT_NEAR(u[0], u1, kRoundTrip) << u1 << ' ' << u2;
        EXPECT_NEAR(u[1], u2, kRoundTrip) << u1 << ' ' << u2;
    }
}

TEST(Sampling, CosineHemisphereRoundTrips) {
    ParticleRng rng(2, 0, 0);
    for (int i = 0; i < kRoundTripCount; ++i) {
        const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
        const Vec3d w = sample_cosine_hemisphere(u1, u2);
        ASSERT_NEAR(length(w), 1, 1e-14);
        ASSERT_GE(w.z, 0);
        const auto u = invert_cosine_hemisphere(w);
        EXPECT_NEAR(u[0], u1, kRoundTrip);
        EXPECT_NEAR(u[1], u2, kRoundTrip);
    }
}

TEST(Sampling, UniformSphereRoundTrips) {
    ParticleRng rng(3, 0, 0);
    for (int i = 0; i < kRoundTripCount; ++i) {
        const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
        const Vec3d w = sample_uniform_sphere(u1, u2);
        ASSERT_NEAR(length(w), 1, 1e-14);
        const auto u = invert_uniform_sphere(w);
        EXPECT_NEAR(u[0], u1, kRoundTrip);
        EXPECT_NEAR(u[1], u2, kRoundTrip);
    }
}

TEST(Sampling, HenyeyGreensteinCosThetaRoundTrips) {
    // The inverse CDF divides by 2g: rounding errors of order 1e-16 grow like 1/|g|, so the
    // tolerance is 1e-13/|g| (1e-10 at g = 0.002, still far below a logic error).
    ParticleRng rng(4, 0, 0);
    for (double g : {-0.9, -0.3, -0.002, 0.0005, 0.002, 0.3, 0.9, 0.99}) {
        for (int i = 0; i < kRoundTripCount; ++i) {
            const double u = rng.uniform_double();
            const double c = sample_hg_cos_theta(g, u);
            ASSERT_GE(c, -1);
            ASSERT_LE(c, 1);
            EXPECT_NEAR(invert_hg_cos_theta(g, c), u, std::max(kRoundTrip, 1e-13 / std::abs(g)))
                << "g = " << g;
        }
    }
}

TEST(Sampling, HenyeyGreensteinSampleFollowsCosTheta) {
    // sample_hg puts cos θ = sample_hg_cos_theta(g, u1) between d_in and d_out, for any d_in
    // (including d_in = −z, the other branch of the Duff et al. frame).
    for (const Vec3d d_in : {Vec3d(0, 0, 1), Vec3d(0, 0, -1), normalize(Vec3d(0.4, -0.3, 0.5))}) {
        for (double u1 : {0.1, 0.5, 0.93}) {
            const Vec3d d = sample_hg(d_in, 0.6, u1, 0.37);
            EXPECT_NEAR(length(d), 1, 1e-14);
            EXPECT_NEAR(dot(d, d_in), sample_hg_cos_theta(0.6, u1), 1e-14);
        }
    }
}

TEST(Sampling, DensitiesIntegrateToOne) {
    // ∫ pdf dω over the sphere by the harness's own cell quadrature (tolerance 1e-12).
    const double cosine = test::integrate_cell(
        [](const Vec3d& w) { return pdf_cosine_hemisphere(w); }, -1, 1, 0, 2 * kPi<double>, 1e-12);
    EXPECT_NEAR(cosine, 1, 1e-10);
    const double sphere =
        test::integrate_cell([](const Vec3d&) { return pdf_uniform_sphere<double>(); }, -1, 1, 0,
                             2 * kPi<double>, 1e-12);
    EXPECT_NEAR(sphere, 1, 1e-12);
    // HG depends on cos θ only: ∫ p dω = 2π ∫_{-1}^{1} p(c) dc = 1, and its mean cosine
    // 2π ∫ c p(c) dc is g by definition of the parameter (Henyey & Greenstein 1941).
    for (double g : {-0.9, -0.3, 0.0, 0.002, 0.5, 0.95}) {
        const double norm =
            2 * kPi<double> *
            test::adaptive_simpson([&](double c) { return hg_phase(c, g); }, -1, 1, 1e-13, 6);
        EXPECT_NEAR(norm, 1, 1e-10) << "g = " << g;
        const double mean =
            2 * kPi<double> *
            test::adaptive_simpson([&](double c) { return c * hg_phase(c, g); }, -1, 1, 1e-13, 6);
        EXPECT_NEAR(mean, g, 1e-10) << "g = " << g;
    }
}

// --- Chi-square tests -------------------------------------------------------------------------

// Number of chi-square tests in SamplingStat (Šidák correction: 1 % false alarms for the suite):
// cosine hemisphere, uniform sphere, and HG at 7 values of g.
constexpr int kSamplingChi2Tests = 9;

Chi2Options sampling_options(const std::string& name) {
    Chi2Options o;
    o.name = name;
    o.test_count = kSamplingChi2Tests;
    return o;
}

TEST(SamplingStat, CosineHemisphereChi2) {
    const auto r = test::run_chi2(
        sampling_options("cosine_hemisphere"),
        [](const std::array<double, 3>& u) {
            return Chi2Draw::direction(sample_cosine_hemisphere(u[0], u[1]));
        },
        [](const Vec3d& w) { return pdf_cosine_hemisphere(w); });
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(SamplingStat, UniformSphereChi2) {
    const auto r = test::run_chi2(
        sampling_options("uniform_sphere"),
        [](const std::array<double, 3>& u) {
            return Chi2Draw::direction(sample_uniform_sphere(u[0], u[1]));
        },
        [](const Vec3d&) { return pdf_uniform_sphere<double>(); });
    EXPECT_TRUE(r.passed) << r.message;
}

TEST(SamplingStat, HenyeyGreensteinChi2) {
    // Against the analytic phase function: the density of d_out is hg_phase(d_in·d_out, g).
    // g near 0 on both sides of the uniform branch (|g| < 1e-3) and of the sign.
    int i = 0;
    for (double g : {-0.8, -0.3, -0.002, 0.0005, 0.002, 0.3, 0.9}) {
        const Vec3d d_in = i++ % 2 ? normalize(Vec3d(0.4, -0.3, 0.5)) : Vec3d(0, 0, -1);
        const auto r = test::run_chi2(
            sampling_options("hg_g" + std::to_string(g)),
            [&](const std::array<double, 3>& u) {
                return Chi2Draw::direction(sample_hg(d_in, g, u[0], u[1]));
            },
            [&](const Vec3d& w) { return hg_phase(dot(d_in, w), g); });
        EXPECT_TRUE(r.passed) << r.message;
        EXPECT_NEAR(r.pdf_integral, 1, 1e-6) << "g = " << g;
    }
}

}  // namespace
}  // namespace lamina

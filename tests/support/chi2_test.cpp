// Tests of the chi-square harness itself: a harness that cannot fail would make every sampler
// test below meaningless, so each failure path is exercised on a deliberately wrong sampler.
#include "support/chi2.h"

#include "core/math.h"
#include "physics/sampling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace lamina::test {
namespace {

TEST(Chi2Harness, IncompleteGammaKnownValues) {
    // Q(1, x) = e^{−x}; Q(1/2, x) = erfc(√x); Q(a, 0) = 1. Q(5, 3) = e^{−3} Σ_{k<5} 3^k/k!
    // (Q(n, x) is the Poisson probability of fewer than n events of mean x) = e^{−3}·(1 + 3 + 4.5
    // + 4.5 + 3.375) = 16.375 e^{−3}.
    for (double x : {0.01, 0.5, 1.0, 2.0, 7.5, 40.0}) {
        EXPECT_NEAR(gamma_q(1, x), std::exp(-x), 1e-14 * std::max(1.0, std::exp(-x) * 10));
        EXPECT_NEAR(gamma_q(0.5, x), std::erfc(std::sqrt(x)), 1e-13);
    }
    EXPECT_EQ(gamma_q(3.0, 0.0), 1.0);
    EXPECT_NEAR(gamma_q(5, 3), 16.375 * std::exp(-3.0), 1e-14);
    // Large dof, as in the sampler tests: Q(k/2, k/2) → 1/2 as k → ∞ (the chi-square median
    // approaches its mean); for k = 8000 the Wilson–Hilferty approximation gives 0.4979.
    EXPECT_NEAR(gamma_q(4000, 4000), 0.4979, 2e-4);
}

TEST(Chi2Harness, CellQuadratureIsExact) {
    // ∫ cos θ dω over [c0, c1] × [p0, p1] = (c1² − c0²)/2 · (p1 − p0).
    const double v = integrate_cell([](const Vec3d& w) { return w.z; }, 0.2, 0.7, 0.1, 1.3, 1e-12);
    EXPECT_NEAR(v, (0.49 - 0.04) / 2 * 1.2, 1e-12);
    // A narrow peak between the first nodes: a GGX-like lobe of width a² = 1e-3 in cos θ near 1,
    // ∫_{0.9}^{1} 2π · a²/(π (1 − c + a²)²) dc = 2a² [1/(1 − c + a²)]_{0.9}^{1}
    //                                          = 2a² (1/a² − 1/(0.1 + a²)).
    const double a2 = 1e-3;
    const double peak =
        integrate_cell([&](const Vec3d& w) { return a2 / (kPi<double> * sqr(1 - w.z + a2)); }, 0.9,
                       1.0, 0, 2 * kPi<double>, 1e-10);
    EXPECT_NEAR(peak, 2 * a2 * (1 / a2 - 1 / (0.1 + a2)), 1e-8);
}

Chi2Options small(const std::string& name) {
    Chi2Options o;
    o.name = name;
    o.sample_count = 100'000;
    o.cos_theta_bins = 16;
    o.phi_bins = 32;
    return o;
}

Chi2Draw cosine_draw(const std::array<double, 3>& u) {
    return Chi2Draw::direction(sample_cosine_hemisphere(u[0], u[1]));
}

TEST(Chi2Harness, PassesACorrectSampler) {
    const auto r = run_chi2(small("harness_correct"), cosine_draw,
                            [](const Vec3d& w) { return pdf_cosine_hemisphere(w); });
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 1, 1e-8);
}

TEST(Chi2Harness, ZoomedDomain) {
    // Cosine draws on cos θ ∈ [0.5, 1]: 2π ∫_{0.5}^{1} c/π dc = 1 − 0.25 = 0.75, so a quarter
    // of the draws fall outside and join the absent bin. A wrong density is still rejected.
    auto o = small("harness_zoomed");
    o.cos_theta_min = 0.5;
    const auto r =
        run_chi2(o, cosine_draw, [](const Vec3d& w) { return pdf_cosine_hemisphere(w); });
    EXPECT_TRUE(r.passed) << r.message;
    EXPECT_NEAR(r.pdf_integral, 0.75, 1e-9);
    EXPECT_NEAR(r.absent_fraction, 0.25, 5 * std::sqrt(0.25 * 0.75 / 1e5));  // 5 binomial SEs
    o.name = "harness_zoomed_wrong";
    const auto wrong = run_chi2(
        o, cosine_draw, [](const Vec3d& w) { return w.z > 0 ? 1 / (2 * kPi<double>) : 0.0; });
    EXPECT_FALSE(wrong.passed);
}

TEST(Chi2Harness, RejectsAWrongDensity) {
    // Cosine-distributed draws against the uniform-hemisphere density 1/(2π): the cell counts
    // differ by up to a factor 2, far beyond the noise of 10⁵ draws.
    const auto r = run_chi2(small("harness_wrong_pdf"), cosine_draw,
                            [](const Vec3d& w) { return w.z > 0 ? 1 / (2 * kPi<double>) : 0.0; });
    EXPECT_FALSE(r.passed);
    EXPECT_LT(r.p_value, 1e-10);
    // The failure message names the dumped histograms, which exist.
    const auto at = r.message.find(" and ");
    ASSERT_NE(at, std::string::npos) << r.message;
    const std::string pgm = r.message.substr(at + 5);
    EXPECT_TRUE(std::filesystem::exists(pgm)) << pgm;
    EXPECT_NE(pgm.find(".pgm"), std::string::npos);
}

TEST(Chi2Harness, RejectsDrawsOutsideTheSupport) {
    // One draw in 10⁴ is mirrored below the horizon, where the density is zero.
    const auto r = run_chi2(
        small("harness_outside"),
        [](const std::array<double, 3>& u) {
            Vec3d w = sample_cosine_hemisphere(u[0], u[1]);
            if (u[2] < 1e-4) w.z = -w.z;
            return Chi2Draw::direction(w);
        },
        [](const Vec3d& w) { return pdf_cosine_hemisphere(w); });
    EXPECT_FALSE(r.passed);
    EXPECT_NE(r.message.find("pdf is zero"), std::string::npos) << r.message;
}

TEST(Chi2Harness, AccountsForAbsentMass) {
    // A sampler that fails with probability 0.3 has the sub-probability density 0.7 cos θ/π: it
    // passes against it, and fails against the full density (the absent bin then expects 0) and
    // against 0.6 cos θ/π (the absent bin expects 4·10⁴ and sees 3·10⁴).
    const auto draw = [](const std::array<double, 3>& u) {
        return u[2] < 0.3 ? Chi2Draw::none() : cosine_draw(u);
    };
    const auto right = run_chi2(small("harness_absent_right"), draw,
                                [](const Vec3d& w) { return 0.7 * pdf_cosine_hemisphere(w); });
    EXPECT_TRUE(right.passed) << right.message;
    const auto full = run_chi2(small("harness_absent_full"), draw,
                               [](const Vec3d& w) { return pdf_cosine_hemisphere(w); });
    EXPECT_FALSE(full.passed);
    const auto low = run_chi2(small("harness_absent_low"), draw,
                              [](const Vec3d& w) { return 0.6 * pdf_cosine_hemisphere(w); });
    EXPECT_FALSE(low.passed);
}

}  // namespace
}  // namespace lamina::test

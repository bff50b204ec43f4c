// The density of a sum of GGX slopes (models/tables/slope_sum_table.h): its closed-form limits, its
// normalization, and an independent Monte Carlo of summed GGX slope samples.
#include "models/tables/slope_sum_table.h"
#include "core/math.h"
#include "core/rng.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <vector>

namespace lamina {
namespace {

double ggx_slope_density(double r, double a) {
    return sqr(a) * kInvPi<double> / sqr(sqr(a) + r * r);
}

// One scale holding all the variance is a GGX slope itself: R = 1 at every radius.
TEST(SlopeSumTable, OneScaleIsGgx) {
    const SlopeSumTable& t = SlopeSumTable::get();
    for (double r : {0.0, 0.01, 0.1, 0.3, 1.0, 3.0, 30.0}) {
        EXPECT_NEAR(t.density(r, 0.3, 0, 0), ggx_slope_density(r, 0.3),
                    1e-6 * ggx_slope_density(r, 0.3));
        EXPECT_NEAR(t.density(r, 0, 0.3, 0), ggx_slope_density(r, 0.3),
                    1e-6 * ggx_slope_density(r, 0.3));
        EXPECT_NEAR(t.density(r, 0, 0, 0.3), ggx_slope_density(r, 0.3),
                    1e-6 * ggx_slope_density(r, 0.3));
    }
}

// Two equal scales at the centre: (1/2π)∫(q K₁(q))² q dq = (1/2π)(2/3) against the GGX of the
// summed variance's 1/(2π): R(0) = 2/3 exactly (∫₀^∞ x³ K₁(x)² dx = 2/3). The node (x = 0,
// y = 1/2, ρ = 0) is a table node: no interpolation.
TEST(SlopeSumTable, TwoEqualScalesHaveTwoThirdsOfThePeak) {
    const SlopeSumTable& t = SlopeSumTable::get();
    EXPECT_NEAR(t.ratio(0, 0, 0.5), 2.0 / 3.0, 1e-6);
    EXPECT_NEAR(SlopeSumTable::direct(0, 0.2, 0.2, 0) / ggx_slope_density(0, 0.2 * std::sqrt(2.0)),
                2.0 / 3.0, 1e-9);
    // Symmetric in the three scales, and in y ↔ 1 − y.
    EXPECT_NEAR(t.density(0.1, 0.2, 0.1, 0.05), t.density(0.1, 0.2, 0.05, 0.1), 1e-12);
    EXPECT_NEAR(SlopeSumTable::direct(0.1, 0.2, 0.1, 0.05),
                SlopeSumTable::direct(0.1, 0.05, 0.1, 0.2),
                1e-9 * SlopeSumTable::direct(0.1, 0.2, 0.1, 0.05));
}

// The table's interpolation against the Hankel integral computed directly, between the nodes.
TEST(SlopeSumTable, TableEqualsDirectIntegral) {
    const SlopeSumTable& t = SlopeSumTable::get();
    const std::array<std::array<double, 3>, 4> cases = {
        {{0.05, 0.1, 0.1}, {0.3, 0.02, 0.07}, {0.0, 0.13, 0.29}, {0.11, 0.11, 0.11}}};
    for (const auto& a : cases) {
        const double sigma = std::sqrt(sqr(a[0]) + sqr(a[1]) + sqr(a[2]));
        for (double rho : {0.0, 0.07, 0.4, 1.3, 2.9, 7.0, 25.0}) {
            const double want = SlopeSumTable::direct(rho * sigma, a[0], a[1], a[2]);
            // Trilinear interpolation on 17 × 9 × 33 nodes: within 1 % of the density.
            EXPECT_NEAR(t.density(rho * sigma, a[0], a[1], a[2]), want, 0.01 * want)
                << a[0] << " " << a[1] << " " << a[2] << " rho " << rho;
        }
    }
}

// ∫ P 2πr dr = 1 through the table (the radius on r = σ u/(1 − u), midpoint rule).
TEST(SlopeSumTable, DensityIsNormalized) {
    const SlopeSumTable& t = SlopeSumTable::get();
    for (const auto& a : std::vector<std::array<double, 3>>{
             {0.1, 0.1, 0.1}, {0.0, 0.2, 0.2}, {0.3, 0.01, 0.1}, {0.05, 0.0, 0.4}}) {
        const double sigma = std::sqrt(sqr(a[0]) + sqr(a[1]) + sqr(a[2]));
        const int n = 200000;
        double sum = 0;
        for (int i = 0; i < n; ++i) {
            const double u = (i + 0.5) / n, r = sigma * u / (1 - u);
            const double dr = sigma / sqr(1 - u) / n;
            sum += t.density(r, a[0], a[1], a[2]) * 2 * kPi<double> * r * dr;
        }
        EXPECT_NEAR(sum, 1.0, 2e-3) << a[0] << " " << a[1] << " " << a[2];
    }
}

// An independent computation: sums of GGX slopes drawn by inverting the GGX slope distribution
// (|s| = a √(u/(1 − u)), uniform azimuth), histogrammed in rings of ρ = |S|/σ. Each ring's count
// is binomial: the table's ring probability (its density integrated over the ring) must lie
// within 5 standard errors plus the table's 1 % interpolation budget.
TEST(SlopeSumTable, EqualsSummedSlopeSamples) {
    const SlopeSumTable& t = SlopeSumTable::get();
    const std::array<double, 3> a = {0.04, 0.1, 0.07};
    const double sigma = std::sqrt(sqr(a[0]) + sqr(a[1]) + sqr(a[2]));
    const std::vector<double> edges = {0, 0.1, 0.25, 0.5, 0.75, 1, 1.5, 2, 3, 5, 10};
    std::vector<double> count(edges.size() - 1, 0);
    const int n = 1000000;
    ParticleRng rng(20261202, 0, 0);
    for (int i = 0; i < n; ++i) {
        double sx = 0, sy = 0;
        for (double aj : a) {
            const double u = rng.uniform_double(), phi = 2 * kPi<double> * rng.uniform_double();
            const double r = aj * std::sqrt(u / (1 - u));
            sx += r * std::cos(phi);
            sy += r * std::sin(phi);
        }
        const double rho = std::hypot(sx, sy) / sigma;
        for (std::size_t b = 0; b + 1 < edges.size(); ++b)
            if (rho >= edges[b] && rho < edges[b + 1]) count[b] += 1;
    }
    for (std::size_t b = 0; b + 1 < edges.size(); ++b) {
        const int m = 2000;
        double p = 0;
        for (int i = 0; i < m; ++i) {
            const double rho = edges[b] + (edges[b + 1] - edges[b]) * (i + 0.5) / m;
            p += t.density(rho * sigma, a[0], a[1], a[2]) * 2 * kPi<double> * rho * sigma * sigma *
                 (edges[b + 1] - edges[b]) / m;
        }
        const double observed = count[b] / n;
        const double se = std::sqrt(p * (1 - p) / n);
        EXPECT_NEAR(observed, p, 5 * se + 0.01 * p) << "ring " << edges[b] << "-" << edges[b + 1];
    }
}

}  // namespace
}  // namespace lamina

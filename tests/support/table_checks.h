#pragma once
// Statistical comparison of a simulated table with expected values, with tolerances from the
// table's own standard errors.

#include "core/table.h"
#include "simulator/goniophotometer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

namespace lamina::test {

/// Two-sided normal quantile for a tail probability p (Acklam's rational approximation refined by
/// one Newton step with std::erfc; accurate to ~1e-9).
inline double normal_quantile_upper(double p) {
    // Bisection on erfc: simple and exact enough for test thresholds.
    double lo = 0, hi = 40;
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

struct TableComparison {
    int bins = 0;          ///< bins compared (expected > 0 or observed > 0)
    double chi2 = 0;       ///< Σ z²
    double max_abs_z = 0;  ///< largest |z|
    std::string worst;     ///< where
};

/// Compares lobe (incidence i, side) channel by channel with expected(j) in bins whose standard
/// error is positive. A bin no particle reached (se = 0) is checked by its expected count: with
/// particle fluxes ≤ 1, at least λ = f Ω⊥ N particles were expected there, and an empty bin has
/// probability e^{−λ}; λ > 12 (p < 6·10⁻⁶) fails.
inline TableComparison compare_lobe(const BinnedTable& table, std::size_t i, Side side,
                                    const std::function<Rgbd(std::size_t)>& expected,
                                    double particles) {
    TableComparison r;
    const BinnedLobe& lobe = table.lobe(i, side);
    for (std::size_t j = 0; j < table.grid.size(); ++j) {
        const Rgbd e = expected(j);
        for (int c = 0; c < 3; ++c) {
            const double f = lobe.f[j][c], se = lobe.se[j][c];
            if (se == 0) {
                const double lambda = e[c] * table.grid.projected_solid_angle(j) * particles;
                if (f != 0 || lambda > 12) {
                    r.max_abs_z = 1e9;
                    r.worst = "bin " + std::to_string(j) + " channel " + std::to_string(c) +
                              ": no spread (f = " + std::to_string(f) + ") where " +
                              std::to_string(lambda) + " particles were expected";
                }
                continue;
            }
            const double z = (f - e[c]) / se;
            ++r.bins;
            r.chi2 += z * z;
            if (std::abs(z) > r.max_abs_z) {
                r.max_abs_z = std::abs(z);
                r.worst = "bin " + std::to_string(j) + " channel " + std::to_string(c) +
                          ": observed " + std::to_string(f) + " ± " + std::to_string(se) +
                          ", expected " + std::to_string(e[c]);
            }
        }
    }
    return r;
}

/// The agreement criterion used by the goniophotometer tests: the largest |z| below the Šidák
/// threshold for the number of bins at family-wise significance `alpha`, and Σz² within
/// 5 standard deviations of its χ²(k) mean k (√(2k)).
inline void expect_agreement(const TableComparison& r, double alpha = 1e-3) {
    ASSERT_GT(r.bins, 0);
    const double per_bin = 1 - std::pow(1 - alpha, 1.0 / r.bins);
    const double z_max = normal_quantile_upper(per_bin / 2);
    EXPECT_LT(r.max_abs_z, z_max) << "worst: " << r.worst;
    EXPECT_LT(std::abs(r.chi2 - r.bins) / std::sqrt(2.0 * r.bins), 5.0)
        << "chi2 = " << r.chi2 << " over " << r.bins << " bins; worst: " << r.worst;
}

/// |estimate − exact| < 5 se + floor: probability 1 − 6e-7 for an exact closed form (the floor
/// covers the closed form's own rounding).
inline void expect_within_se(double estimate, double exact, double se, const std::string& what,
                             double floor = 1e-12) {
    EXPECT_LT(std::abs(estimate - exact), 5 * se + floor)
        << what << ": estimate " << estimate << " ± " << se << ", exact " << exact;
}

/// A kernel-parameterized test's name suffix: the kernel's name (scalar, simd, auto).
inline std::string kernel_test_name(const ::testing::TestParamInfo<Kernel>& info) {
    return enum_text(info.param);
}

/// Every incidence's energy budget sums to 1 to `tolerance` (docs/physics.md §5).
inline void expect_budget_closes(const SimulationResult& r, double tolerance = 1e-6) {
    for (const IncidenceStats& st : r.incidences)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(st.budget.sum()[c], 1.0, tolerance);
}

}  // namespace lamina::test

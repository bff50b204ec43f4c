#pragma once
// A generic chi-square goodness-of-fit harness for direction samplers (docs/style.md §9), after
// Mitsuba 3 `src/python/python/chi2.py` and pbrt-v4 `src/pbrt/bsdfs_test.cpp`.
//
// Domain: the sphere of directions, parameterized by (cos θ, φ) ∈ [c_min, c_max] × [0, 2π) and cut
// into a regular grid. Because dω = d(cos θ) dφ, every cell of the grid has the same solid angle.
//
// Inputs: a sample function (three uniforms → an outcome) and the density the sampler claims, with
// respect to solid angle. Expected cell counts are N·∫_cell pdf dω by nested adaptive Simpson
// quadrature (Lyness 1969; error estimate |S₂ − S₁|/15 with Richardson extrapolation).
//
// Sub-probability densities. A BSDF sampler may return no direction (a failed sample), a direction
// carrying zero weight (energy lost to the single-scattering microsurface, `shadowing == 0`) or a
// delta direction; its pdf only describes the rest, so ∫ pdf dω = P ≤ 1. The harness treats the
// experiment as a multinomial over the grid cells *plus one "absent" outcome*: each sample either
// lands in a cell (expected N·∫_cell pdf) or is absent (expected N·(1 − P), P computed by the same
// quadrature). The absent outcome is one more bin of the Pearson statistic, so both the shape of
// the density and the missing mass are tested, and the expected total equals N exactly.
// Zoomed domains: with cos θ restricted to [c_min, c_max] (to resolve a sharp lobe), draws outside
// it join the absent bin, whose expected count is then N·(1 − ∫_domain pdf dω) by the same rule.
//
// Support: a sample in a cell whose expected count is numerically zero (≤ 1e-9, so the chance of a
// legitimate hit there is < 1e-9 per cell) fails the test outright, as does a non-finite or
// non-unit direction, or an absent sample when the pdf integrates to 1 over the domain (same
// rule, absent bin).
//
// Pooling: cells with expected count < 5 are pooled (in increasing order of expected count) until
// the pool reaches 5, as in Mitsuba's chi2.py; degrees of freedom = bins after pooling − 1.
// p-value: the chi-square survival function Q(dof/2, χ²/2), the regularized upper incomplete gamma
// function (Numerical Recipes in C, 2nd ed., §6.2, `gammq`: series for x < a + 1, Lentz's continued
// fraction otherwise). The test passes when p ≥ the Šidák-corrected level
// 1 − (1 − 0.01)^(1/test_count) (Šidák 1967), so that a suite of test_count independent chi-square
// tests has an overall false-alarm rate of 1 %.
//
// Estimated densities (run_chi2_estimated). A sampler whose density is known only through an
// unbiased stochastic estimate (the random walk's pdf) gives, per cell, an independent unbiased
// estimate m̂_j of its mass with the variance v_j of that estimate (e.g. the mean of a pdf
// estimate at uniformly jittered directions of the cell, times its solid angle). The expected
// counts Ê_j = N m̂_j are then noisy themselves, independent of the draws, and the Pearson terms
// become (O_j − Ê_j)²/(Ê_j + N² v_j): Var(O_j − Ê_j) = E_j + N² v_j for the Poisson limit of a
// cell (the multinomial covariance −N q_j q_k and the absent bin's coupling to the cells are
// neglected, as Pearson's approximation already does for small cells). The absent bin's mass is
// 1 − Σ m̂_j with variance Σ v_j; pooled bins add masses and variances. With v_j ≪ E_j/N² (many
// more estimate walks than draws per cell) this is the plain test.
//
// On failure both histograms (observed, expected) are written, as text and as one PGM image (left:
// observed, right: expected, same scale), to <build>/chi2/<name>.{txt,pgm}; the path is printed.

#include "core/math.h"
#include "core/rng.h"
#include "core/vec.h"

#include <array>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

namespace lamina::test {

/// One draw of a sampler, as the chi-square test sees it.
struct Chi2Draw {
    /// The sampled direction (unit), or nothing for a failed sample.
    std::optional<Vec3d> w;
    /// The draw carries no mass described by the pdf: a delta lobe, or a direction of zero weight
    /// (lost to the microsurface). Counted in the absent bin, like a failed sample.
    bool absent = false;

    static Chi2Draw direction(const Vec3d& w) { return {w, false}; }
    static Chi2Draw none() { return {std::nullopt, true}; }
};

using Chi2SampleFn = std::function<Chi2Draw(const std::array<double, 3>& u)>;
using Chi2PdfFn = std::function<double(const Vec3d& w)>;

struct Chi2Options {
    /// Used in messages and for the dump files <build>/chi2/<name>.{txt,pgm}.
    std::string name;
    std::size_t sample_count = 1'000'000;
    int cos_theta_bins = 64;
    int phi_bins = 128;
    double cos_theta_min = -1, cos_theta_max = 1;
    /// Number of chi-square tests in the suite (Šidák correction).
    int test_count = 1;
    double significance = 0.01;
    /// 0: derived from `name` (FNV-1a), so that the tests of a suite draw independent numbers, as
    /// the Šidák correction assumes, and each test is reproducible on its own. The environment
    /// variable LAMINA_CHI2_SEED (an integer) is mixed in, to rerun a suite on other numbers.
    std::uint64_t seed = 0;
    /// Absolute tolerance of the quadrature of the density over one cell (in probability).
    double cell_tolerance = 1e-10;
};

struct Chi2Result {
    bool passed = false;
    double chi2 = 0, p_value = 0, level = 0;
    int dof = 0;
    double pdf_integral = 0;     ///< P = ∫ pdf over the domain, by quadrature
    double pdf_integral_se = 0;  ///< its standard error (run_chi2_estimated; 0 otherwise)
    double absent_fraction = 0;  ///< fraction of absent draws
    std::string message;         ///< why it failed, and where the histograms were dumped
};

/// Runs the test. Use as `const auto r = run_chi2(...); EXPECT_TRUE(r.passed) << r.message;`.
Chi2Result run_chi2(const Chi2Options& options, const Chi2SampleFn& sample, const Chi2PdfFn& pdf);

/// An unbiased estimate of one cell's probability mass ∫_cell pdf dω, and its variance.
struct Chi2CellMass {
    double mass = 0;
    double variance = 0;
};

/// Estimates the mass of cell (row, col) = [c0, c1] × [p0, p1] of (cos θ, φ); called once per
/// cell, from several threads (it must be thread-safe and should key its random numbers by cell).
using Chi2CellMassFn =
    std::function<Chi2CellMass(int row, int col, double c0, double c1, double p0, double p1)>;

/// run_chi2 for a density known through per-cell mass estimates (see "Estimated densities").
Chi2Result run_chi2_estimated(const Chi2Options& options, const Chi2SampleFn& sample,
                              const Chi2CellMassFn& cell_mass);

/// Regularized upper incomplete gamma Q(a, x) = Γ(a, x)/Γ(a) (Numerical Recipes §6.2, gammq).
double gamma_q(double a, double x);

/// Adaptive Simpson quadrature of f over [a, b] to absolute tolerance eps (Lyness 1969), after
/// `min_depth` forced bisections (so narrow peaks between the first nodes are not missed).
double adaptive_simpson(const std::function<double(double)>& f, double a, double b, double eps,
                        int min_depth = 2, int max_depth = 24);

/// ∫ pdf dω over the cell [c0, c1] × [p0, p1] of (cos θ, φ), by nested adaptive Simpson.
double integrate_cell(const Chi2PdfFn& pdf, double c0, double c1, double p0, double p1, double eps);

/// ∫ f(wm) dωm over the upper hemisphere, resolving a GGX peak of width α at the pole: the polar
/// range is cut at 1 − cos θm = α²·4^k (graded nodes, the peak's scale is sin²θm ≈ α²), and each
/// band is integrated by integrate_cell to tolerance eps. `phi_pieces` splits the azimuth too, for
/// integrands that vanish on most of a band (normals visible from below the horizon) or that are
/// anisotropic, where Simpson's first nodes could all miss the support.
double integrate_hemisphere(const Chi2PdfFn& f, double alpha, double eps, int phi_pieces = 1);

/// Direction of (cos θ, φ).
inline Vec3d direction_of(double cos_theta, double phi) {
    const double s = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
    return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

/// A direction uniform on the whole sphere (two of rng's draws).
inline Vec3d uniform_sphere_direction(ParticleRng& rng) {
    const double cos_theta = 1 - 2 * rng.uniform_double();
    return direction_of(cos_theta, 2 * kPi<double> * rng.uniform_double());
}

}  // namespace lamina::test

#pragma once
// The azimuth-averaged (Fourier order 0) transfer of flux through a plane-parallel slab of a
// homogeneous Henyey–Greenstein medium, by discrete ordinates and the doubling method (van de
// Hulst 1963, "A new look at multiple scattering", NASA GISS report; Hansen & Travis 1974, "Light
// scattering in planetary atmospheres", Space Sci. Rev. 16, 527–610, its section on the adding
// and doubling methods: two identical layers combine as R₂ = R + T R (I − R R)⁻¹ T,
// T₂ = T (I − R R)⁻¹ T). lamina-1 uses it for the energy of the light a scattering coat
// medium sends back over all scattering orders (docs/models.md, lamina-1, "Scattering media").
//
// Directions are discretized on n cosines μ_j ∈ (0, 1) per hemisphere with weights w_j
// (Σ w_j = 1, a rule for ∫₀¹ dμ). A vector holds the *flux* through a horizontal plane carried in
// each node's cone of directions; a matrix maps the flux entering at node k (column) to the flux
// leaving at node j (row). Energy is therefore a column sum. Only the azimuthal average of the
// phase function enters: exact for energy (the flux through a plane does not depend on azimuth
// once averaged), not for the angular detail, which the callers do not take from here.
//
// Units: optical depths τ along the normal (dimensionless); ϖ = τs/τt the single-scattering
// albedo in [0, 1]; g ∈ (−1, 1). Nothing here throws; τt = 0 gives R = 0, T = I.

#include <vector>

namespace lamina {

/// A dense n × n matrix, row-major (small: the adding's n ≤ 32).
struct FluxMatrix {
    int n = 0;
    std::vector<double> a;
    FluxMatrix() = default;
    explicit FluxMatrix(int size) : n(size), a(std::size_t(size) * size, 0.0) {}
    static FluxMatrix identity(int size);
    static FluxMatrix diagonal(const std::vector<double>& d);
    double& operator()(int row, int col) { return a[std::size_t(row) * n + col]; }
    double operator()(int row, int col) const { return a[std::size_t(row) * n + col]; }
};

FluxMatrix operator*(const FluxMatrix& x, const FluxMatrix& y);
FluxMatrix operator+(const FluxMatrix& x, const FluxMatrix& y);
FluxMatrix operator-(const FluxMatrix& x, const FluxMatrix& y);
/// x⁻¹ by Gauss–Jordan elimination with partial pivoting; a singular matrix (a zero pivot) gives
/// the zero matrix (the callers invert I − (a loss-free product of reflectances < 1)).
FluxMatrix inverse(const FluxMatrix& x);
/// Row vector vᵀ x.
std::vector<double> row_times(const std::vector<double>& v, const FluxMatrix& x);

/// The discrete cosines of one hemisphere and their weights (Σ w = 1).
struct CosineNodes {
    std::vector<double> mu, w;
    int size() const { return int(mu.size()); }
};

/// Gauss–Legendre nodes on [0, split] and on [split, 1], n_each each (split ∈ (0, 1)); split ≤ 0
/// or ≥ 1: 2 n_each nodes on [0, 1]. The split puts a step of the integrand (a coat's critical
/// cosine) between nodes.
CosineNodes split_cosine_nodes(int n_each, double split);

/// The Fourier-0 HG phase functions between the nodes, 1/sr: same(j, k) = (1/2π)∫ p(μjμk +
/// sj sk cos φ) dφ (both directions in the same hemisphere: transmission), opposite(j, k) the same
/// with −μjμk (reflection), by Gauss–Legendre in t over φ = π t² (dense where the forward peak is).
struct AzimuthalPhase {
    FluxMatrix same, opposite;
};
AzimuthalPhase azimuthal_hg(const CosineNodes& nodes, double g);

/// The slab's reflection R and transmission T (flux matrices, the same from above and from
/// below: a homogeneous slab is symmetric), all scattering orders, the unscattered light on T's
/// diagonal (e^{−τt/μ}). Doubling from a layer of τ0 ≤ 2^−8 whose matrices are its exact single
/// scattering with the scattered flux scaled to ϖ(1 − e^{−τ0/μk}) per column (so that ϖ = 1 is
/// conservative to rounding: R + T has unit column sums).
struct SlabMatrices {
    FluxMatrix R, T;
};
SlabMatrices hg_slab(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
                     double omega);

/// The exact single-scattering reflection of the slab alone (first order in τs, no
/// renormalization): S(j, k) = 2π w_j μ_j ϖ p_opposite(j, k) (1 − e^{−τ(1/μj + 1/μk)})/(μj + μk).
FluxMatrix hg_single_reflection(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
                                double omega);

/// The exact once-scattered light of the slab over a mirror base of reflectance E(μ) (E at the
/// nodes): scattered on the way down then mirrored, or mirrored then scattered on the way up,
/// S(j, k) = 2π w_j μ_j ϖ p_same(j, k) (a_j − a_k)/(μj − μk) (E_j a_j + E_k a_k), a = e^{−τ/μ}
/// (the limit τ a/μ² at μj = μk).
FluxMatrix hg_single_mirror_paths(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                  double tau_t, double omega, const std::vector<double>& E);

/// (a(μ1) − a(μ2))/(μ1 − μ2) for a(μ) = e^{−τ/μ} given a1 = a(μ1), a2 = a(μ2): by expm1 where the
/// cosines are close, τ a/μ² where they are equal. μ1, μ2 > 0.
double attenuation_slope(double mu1, double mu2, double a1, double a2, double tau);

}  // namespace lamina

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

#include "lamina1/math.h"
#include "lamina1/physics.h"
#include "lamina1/quadrature.h"

#include <cmath>
#include <utility>
#include <vector>

namespace lamina1 {

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

inline FluxMatrix operator*(const FluxMatrix& x, const FluxMatrix& y);
inline FluxMatrix operator+(const FluxMatrix& x, const FluxMatrix& y);
inline FluxMatrix operator-(const FluxMatrix& x, const FluxMatrix& y);
/// x⁻¹ by Gauss–Jordan elimination with partial pivoting; a singular matrix (a zero pivot) gives
/// the zero matrix (the callers invert I − (a loss-free product of reflectances < 1)).
inline FluxMatrix inverse(const FluxMatrix& x);
/// Row vector vᵀ x.
inline std::vector<double> row_times(const std::vector<double>& v, const FluxMatrix& x);

/// The discrete cosines of one hemisphere and their weights (Σ w = 1).
struct CosineNodes {
    std::vector<double> mu, w;
    int size() const { return int(mu.size()); }
};

/// Gauss–Legendre nodes on [0, split] and on [split, 1], n_each each (split ∈ (0, 1)); split ≤ 0
/// or ≥ 1: 2 n_each nodes on [0, 1]. The split puts a step of the integrand (a coat's critical
/// cosine) between nodes.
inline CosineNodes split_cosine_nodes(int n_each, double split);

/// The Fourier-0 HG phase functions between the nodes, 1/sr: same(j, k) = (1/2π)∫ p(μjμk +
/// sj sk cos φ) dφ (both directions in the same hemisphere: transmission), opposite(j, k) the same
/// with −μjμk (reflection), by Gauss–Legendre in t over φ = π t² (dense where the forward peak is).
struct AzimuthalPhase {
    FluxMatrix same, opposite;
};
inline AzimuthalPhase azimuthal_hg(const CosineNodes& nodes, double g);

/// The slab's reflection R and transmission T (flux matrices, the same from above and from
/// below: a homogeneous slab is symmetric), all scattering orders, the unscattered light on T's
/// diagonal (e^{−τt/μ}). Doubling from a layer of τ0 ≤ 2^−8 whose matrices are its exact single
/// scattering with the scattered flux scaled to ϖ(1 − e^{−τ0/μk}) per column (so that ϖ = 1 is
/// conservative to rounding: R + T has unit column sums).
struct SlabMatrices {
    FluxMatrix R, T;
};
inline SlabMatrices hg_slab(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
                            double omega);

/// The exact single-scattering reflection of the slab alone (first order in τs, no
/// renormalization): S(j, k) = 2π w_j μ_j ϖ p_opposite(j, k) (1 − e^{−τ(1/μj + 1/μk)})/(μj + μk).
inline FluxMatrix hg_single_reflection(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                       double tau_t, double omega);

/// The exact once-scattered light of the slab over a mirror base of reflectance E(μ) (E at the
/// nodes): scattered on the way down then mirrored, or mirrored then scattered on the way up,
/// S(j, k) = 2π w_j μ_j ϖ p_same(j, k) (a_j − a_k)/(μj − μk) (E_j a_j + E_k a_k), a = e^{−τ/μ}
/// (the limit τ a/μ² at μj = μk).
inline FluxMatrix hg_single_mirror_paths(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                         double tau_t, double omega, const std::vector<double>& E);

/// (a(μ1) − a(μ2))/(μ1 − μ2) for a(μ) = e^{−τ/μ} given a1 = a(μ1), a2 = a(μ2): by expm1 where the
/// cosines are close, τ a/μ² where they are equal. μ1, μ2 > 0.
inline double attenuation_slope(double mu1, double mu2, double a1, double a2, double tau);

// Definitions.

inline FluxMatrix FluxMatrix::identity(int size) {
    FluxMatrix m(size);
    for (int i = 0; i < size; ++i)
        m(i, i) = 1;
    return m;
}

inline FluxMatrix FluxMatrix::diagonal(const std::vector<double>& d) {
    FluxMatrix m(int(d.size()));
    for (int i = 0; i < m.n; ++i)
        m(i, i) = d[i];
    return m;
}

inline FluxMatrix operator*(const FluxMatrix& x, const FluxMatrix& y) {
    FluxMatrix z(x.n);
    for (int i = 0; i < x.n; ++i)
        for (int k = 0; k < x.n; ++k) {
            const double xik = x(i, k);
            if (xik == 0) continue;
            for (int j = 0; j < x.n; ++j)
                z(i, j) += xik * y(k, j);
        }
    return z;
}

inline FluxMatrix operator+(const FluxMatrix& x, const FluxMatrix& y) {
    FluxMatrix z = x;
    for (std::size_t i = 0; i < z.a.size(); ++i)
        z.a[i] += y.a[i];
    return z;
}

inline FluxMatrix operator-(const FluxMatrix& x, const FluxMatrix& y) {
    FluxMatrix z = x;
    for (std::size_t i = 0; i < z.a.size(); ++i)
        z.a[i] -= y.a[i];
    return z;
}

inline FluxMatrix inverse(const FluxMatrix& x) {
    const int n = x.n;
    FluxMatrix a = x, inv = FluxMatrix::identity(n);
    for (int c = 0; c < n; ++c) {
        int pivot = c;
        for (int r = c + 1; r < n; ++r)
            if (std::abs(a(r, c)) > std::abs(a(pivot, c))) pivot = r;
        if (!(std::abs(a(pivot, c)) > 0)) return FluxMatrix(n);
        if (pivot != c)
            for (int j = 0; j < n; ++j) {
                std::swap(a(c, j), a(pivot, j));
                std::swap(inv(c, j), inv(pivot, j));
            }
        const double scale = 1 / a(c, c);
        for (int j = 0; j < n; ++j) {
            a(c, j) *= scale;
            inv(c, j) *= scale;
        }
        for (int r = 0; r < n; ++r) {
            if (r == c) continue;
            const double f = a(r, c);
            if (f == 0) continue;
            for (int j = 0; j < n; ++j) {
                a(r, j) -= f * a(c, j);
                inv(r, j) -= f * inv(c, j);
            }
        }
    }
    return inv;
}

inline std::vector<double> row_times(const std::vector<double>& v, const FluxMatrix& x) {
    std::vector<double> out(x.n, 0.0);
    for (int i = 0; i < x.n; ++i)
        for (int j = 0; j < x.n; ++j)
            out[j] += v[i] * x(i, j);
    return out;
}

inline CosineNodes split_cosine_nodes(int n_each, double split) {
    CosineNodes nodes;
    auto piece = [&](int n, double a, double b) {
        const QuadratureRule q = gauss_legendre(n);
        for (int i = 0; i < n; ++i) {
            nodes.mu.push_back(a + (b - a) * q.x[i]);
            nodes.w.push_back((b - a) * q.w[i]);
        }
    };
    if (split > 0 && split < 1) {
        piece(n_each, 0, split);
        piece(n_each, split, 1);
    } else {
        piece(2 * n_each, 0, 1);
    }
    return nodes;
}

inline AzimuthalPhase azimuthal_hg(const CosineNodes& nodes, double g) {
    static const QuadratureRule q = gauss_legendre(24);
    const int n = nodes.size();
    AzimuthalPhase p{FluxMatrix(n), FluxMatrix(n)};
    for (int j = 0; j < n; ++j)
        for (int k = 0; k <= j; ++k) {
            const double mm = nodes.mu[j] * nodes.mu[k];
            const double ss = safe_sqrt((1 - sqr(nodes.mu[j])) * (1 - sqr(nodes.mu[k])));
            double same = 0, opposite = 0;
            // (1/2π)∫₀^{2π} = (1/π)∫₀^π; φ = π t², dφ = 2π t dt.
            for (std::size_t i = 0; i < q.x.size(); ++i) {
                const double t = q.x[i], c = std::cos(kPi * t * t);
                const double wt = q.w[i] * 2 * t;
                same += wt * hg_phase(mm + ss * c, g);
                opposite += wt * hg_phase(-mm + ss * c, g);
            }
            p.same(j, k) = p.same(k, j) = same;
            p.opposite(j, k) = p.opposite(k, j) = opposite;
        }
    return p;
}

inline double attenuation_slope(double mu1, double mu2, double a1, double a2, double tau) {
    const double d = mu1 - mu2;
    const double x = tau * d / (mu1 * mu2);
    if (std::abs(x) < 0.5) {
        if (x == 0) return tau * a1 / (mu1 * mu1);
        return a2 * std::expm1(x) / d;
    }
    return (a1 - a2) / d;
}

/// The exact single scattering of a slab of optical depth tau (flux matrices), scattered parts
/// only (the unscattered e^{−τ/μ} is not included).
inline SlabMatrices slab_single_scattering(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                           double tau, double omega) {
    const int n = nodes.size();
    SlabMatrices s{FluxMatrix(n), FluxMatrix(n)};
    std::vector<double> a(n);
    for (int j = 0; j < n; ++j)
        a[j] = std::exp(-tau / nodes.mu[j]);
    for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
            const double bin = 2 * kPi * nodes.w[j] * nodes.mu[j] * omega;
            s.R(j, k) =
                bin * phase.opposite(j, k) * (1 - a[j] * a[k]) / (nodes.mu[j] + nodes.mu[k]);
            s.T(j, k) = bin * phase.same(j, k) *
                        attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau);
        }
    return s;
}

inline FluxMatrix hg_single_reflection(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                       double tau_t, double omega) {
    return slab_single_scattering(nodes, phase, tau_t, omega).R;
}

inline FluxMatrix hg_single_mirror_paths(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                         double tau_t, double omega, const std::vector<double>& E) {
    const int n = nodes.size();
    FluxMatrix S(n);
    std::vector<double> a(n);
    for (int j = 0; j < n; ++j)
        a[j] = std::exp(-tau_t / nodes.mu[j]);
    for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
            S(j, k) = 2 * kPi * nodes.w[j] * nodes.mu[j] * omega * phase.same(j, k) *
                      attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau_t) *
                      (E[j] * a[j] + E[k] * a[k]);
    return S;
}

inline SlabMatrices hg_slab(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
                            double omega) {
    const int n = nodes.size();
    if (!(tau_t > 0)) return {FluxMatrix(n), FluxMatrix::identity(n)};
    constexpr double kTau0 = 1.0 / 256;
    int doublings = 0;
    double tau0 = tau_t;
    while (tau0 > kTau0 && doublings < 60) {
        tau0 *= 0.5;
        ++doublings;
    }
    SlabMatrices s = slab_single_scattering(nodes, phase, tau0, omega);
    // Scale each column's scattered flux to ϖ(1 − e^{−τ0/μk}): the light that interacts in the
    // thin layer, less what it absorbs; the orders ≥ 2 the single scattering leaves out are
    // O(τ0²), and without the scaling a conservative medium would lose them at every doubling.
    for (int k = 0; k < n; ++k) {
        const double direct = std::exp(-tau0 / nodes.mu[k]);
        double sum = 0;
        for (int j = 0; j < n; ++j)
            sum += s.R(j, k) + s.T(j, k);
        const double scale = sum > 0 ? omega * (1 - direct) / sum : 0.0;
        for (int j = 0; j < n; ++j) {
            s.R(j, k) *= scale;
            s.T(j, k) *= scale;
        }
        s.T(k, k) += direct;
    }
    const FluxMatrix I = FluxMatrix::identity(n);
    for (int d = 0; d < doublings; ++d) {
        const FluxMatrix Q = inverse(I - s.R * s.R);
        const FluxMatrix TQ = s.T * Q;
        s.R = s.R + TQ * s.R * s.T;
        s.T = TQ * s.T;
    }
    return s;
}

}  // namespace lamina1

#include "models/numerics/medium_adding.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "physics/phase.h"

#include <cmath>
#include <utility>

namespace lamina {

FluxMatrix FluxMatrix::identity(int size) {
    FluxMatrix m(size);
    for (int i = 0; i < size; ++i)
        m(i, i) = 1;
    return m;
}

FluxMatrix FluxMatrix::diagonal(const std::vector<double>& d) {
    FluxMatrix m(int(d.size()));
    for (int i = 0; i < m.n; ++i)
        m(i, i) = d[i];
    return m;
}

FluxMatrix operator*(const FluxMatrix& x, const FluxMatrix& y) {
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

FluxMatrix operator+(const FluxMatrix& x, const FluxMatrix& y) {
    FluxMatrix z = x;
    for (std::size_t i = 0; i < z.a.size(); ++i)
        z.a[i] += y.a[i];
    return z;
}

FluxMatrix operator-(const FluxMatrix& x, const FluxMatrix& y) {
    FluxMatrix z = x;
    for (std::size_t i = 0; i < z.a.size(); ++i)
        z.a[i] -= y.a[i];
    return z;
}

FluxMatrix inverse(const FluxMatrix& x) {
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

std::vector<double> row_times(const std::vector<double>& v, const FluxMatrix& x) {
    std::vector<double> out(x.n, 0.0);
    for (int i = 0; i < x.n; ++i)
        for (int j = 0; j < x.n; ++j)
            out[j] += v[i] * x(i, j);
    return out;
}

CosineNodes split_cosine_nodes(int n_each, double split) {
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

AzimuthalPhase azimuthal_hg(const CosineNodes& nodes, double g) {
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
                const double t = q.x[i], c = std::cos(kPi<double> * t * t);
                const double wt = q.w[i] * 2 * t;
                same += wt * hg_phase(mm + ss * c, g);
                opposite += wt * hg_phase(-mm + ss * c, g);
            }
            p.same(j, k) = p.same(k, j) = same;
            p.opposite(j, k) = p.opposite(k, j) = opposite;
        }
    return p;
}

double attenuation_slope(double mu1, double mu2, double a1, double a2, double tau) {
    const double d = mu1 - mu2;
    const double x = tau * d / (mu1 * mu2);
    if (std::abs(x) < 0.5) {
        if (x == 0) return tau * a1 / (mu1 * mu1);
        return a2 * std::expm1(x) / d;
    }
    return (a1 - a2) / d;
}

namespace {

/// The exact single scattering of a slab of optical depth tau (flux matrices), scattered parts
/// only (the unscattered e^{−τ/μ} is not included).
SlabMatrices single_scattering(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau,
                               double omega) {
    const int n = nodes.size();
    SlabMatrices s{FluxMatrix(n), FluxMatrix(n)};
    std::vector<double> a(n);
    for (int j = 0; j < n; ++j)
        a[j] = std::exp(-tau / nodes.mu[j]);
    for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k) {
            const double bin = 2 * kPi<double> * nodes.w[j] * nodes.mu[j] * omega;
            s.R(j, k) =
                bin * phase.opposite(j, k) * (1 - a[j] * a[k]) / (nodes.mu[j] + nodes.mu[k]);
            s.T(j, k) = bin * phase.same(j, k) *
                        attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau);
        }
    return s;
}

}  // namespace

FluxMatrix hg_single_reflection(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
                                double omega) {
    return single_scattering(nodes, phase, tau_t, omega).R;
}

FluxMatrix hg_single_mirror_paths(const CosineNodes& nodes, const AzimuthalPhase& phase,
                                  double tau_t, double omega, const std::vector<double>& E) {
    const int n = nodes.size();
    FluxMatrix S(n);
    std::vector<double> a(n);
    for (int j = 0; j < n; ++j)
        a[j] = std::exp(-tau_t / nodes.mu[j]);
    for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
            S(j, k) = 2 * kPi<double> * nodes.w[j] * nodes.mu[j] * omega * phase.same(j, k) *
                      attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau_t) *
                      (E[j] * a[j] + E[k] * a[k]);
    return S;
}

SlabMatrices hg_slab(const CosineNodes& nodes, const AzimuthalPhase& phase, double tau_t,
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
    SlabMatrices s = single_scattering(nodes, phase, tau0, omega);
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

}  // namespace lamina

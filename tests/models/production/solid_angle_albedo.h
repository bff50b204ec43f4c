#pragma once
// The albedo integrals of a GGX reflection lobe over the outgoing solid angle, independent of the
// visible-normal integrals models/production tabulates: the tests of those tables compare the two.

#include "core/math.h"
#include "models/numerics/quadrature.h"

#include <cmath>

namespace lamina::test {

/// One lobe's facet quantities at a pair (μi, ωo) of the rule below.
struct ReflectedPair {
    double mu_o;      ///< cos θo
    double cos_i_h;   ///< wi·h
    double D;         ///< GGX D(h) (Walter et al. 2007, Eq. 33)
    double lambda_i;  ///< Smith Λ(wi) (Heitz 2014, Eq. 72)
    double lambda_o;  ///< Smith Λ(wo)
};

/// ∫ value(pair) dωo over the reflected hemisphere of incidence μ = cos θi (φi = 0) for GGX α:
/// Gauss–Legendre in μo (n_mu) × midpoint in φo (n_phi, over [0, π], doubled: every integrand
/// here is even in φo).
template <typename Value>
double reflected_hemisphere_integral(double mu, double alpha, int n_mu, int n_phi,
                                     const Value& value) {
    const double a2 = alpha * alpha;
    auto lambda = [&](double z) { return (-1 + std::sqrt(1 + a2 * (1 - z * z) / (z * z))) / 2; };
    const double s_i = std::sqrt(1 - mu * mu), lambda_i = lambda(mu);
    const QuadratureRule q = gauss_legendre(n_mu);
    double sum = 0;
    for (std::size_t i = 0; i < q.x.size(); ++i) {
        const double mu_o = q.x[i], s_o = std::sqrt(1 - mu_o * mu_o), lambda_o = lambda(mu_o);
        for (int j = 0; j < n_phi; ++j) {
            const double phi = kPi<double> * (j + 0.5) / n_phi;
            const double hx = s_i + s_o * std::cos(phi), hy = s_o * std::sin(phi), hz = mu + mu_o;
            const double len = std::sqrt(hx * hx + hy * hy + hz * hz);
            const double cz = hz / len, c_ih = (s_i * hx + mu * hz) / len;
            const double D = a2 / (kPi<double> * sqr(cz * cz * (a2 - 1) + 1));
            sum += q.w[i] * (kPi<double> / n_phi) * 2 *
                   value(ReflectedPair{mu_o, c_ih, D, lambda_i, lambda_o});
        }
    }
    return sum;
}

}  // namespace lamina::test

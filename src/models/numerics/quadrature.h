#pragma once
// Gauss–Legendre rules (Golub & Welsch 1969 give the theory; nodes here by Newton iteration on
// the Legendre recurrence, Press et al., Numerical Recipes 3rd ed., §4.6.1, `gauleg`).

#include "core/math.h"

#include <cmath>
#include <vector>

namespace lamina {

struct QuadratureRule {
    std::vector<double> x;  ///< nodes in [0, 1]
    std::vector<double> w;  ///< weights, summing to 1
};

/// n-point Gauss–Legendre rule mapped to [0, 1]; exact for polynomials of degree 2n − 1.
inline QuadratureRule gauss_legendre(int n) {
    QuadratureRule q{std::vector<double>(n), std::vector<double>(n)};
    for (int i = 0; i < (n + 1) / 2; ++i) {
        double z = std::cos(kPi<double> * (i + 0.75) / (n + 0.5));
        double dp = 0;
        for (int iter = 0; iter < 100; ++iter) {
            double p1 = 1, p2 = 0;
            for (int j = 0; j < n; ++j) {
                const double p3 = p2;
                p2 = p1;
                p1 = ((2 * j + 1) * z * p2 - j * p3) / (j + 1);
            }
            dp = n * (z * p1 - p2) / (z * z - 1);
            const double dz = p1 / dp;
            z -= dz;
            if (std::abs(dz) < 1e-15) break;
        }
        const double w = 2 / ((1 - z * z) * dp * dp);
        q.x[i] = 0.5 * (1 - z);
        q.x[n - 1 - i] = 0.5 * (1 + z);
        q.w[i] = q.w[n - 1 - i] = 0.5 * w;
    }
    return q;
}

/// ∫₀¹ f(μ) dμ by kNodes-point Gauss–Legendre in two pieces split at `split` (a critical cosine,
/// where f has a square-root edge: Fresnel beyond total reflection, a coat's smooth-limit
/// transmittance). The upper piece is integrated in t with μ = split + (1 − split) t², which makes
/// that edge smooth. The lower piece is skipped when split = 0, the upper when split = 1.
template <int kNodes, typename V, typename F>
V integrate_split01(F&& f, double split) {
    static const QuadratureRule q = gauss_legendre(kNodes);
    V sum{};
    split = clamp(split, 0.0, 1.0);
    for (int i = 0; i < kNodes; ++i) {
        if (split > 0) sum += f(split * q.x[i]) * (q.w[i] * split);
        const double t = q.x[i], d = 1 - split;
        if (d > 0) sum += f(split + d * t * t) * (q.w[i] * 2 * d * t);
    }
    return sum;
}

}  // namespace lamina

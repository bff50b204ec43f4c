#pragma once
// Gauss–Legendre quadrature for reference values in tests (independent of lamina's own
// integration code).

#include "core/grid.h"
#include "core/math.h"
#include "core/rgb.h"
#include "core/spherical.h"
#include "core/vec.h"

#include <cmath>
#include <functional>
#include <utility>
#include <vector>

namespace lamina::test {

/// Nodes and weights of n-point Gauss–Legendre on [−1, 1] (Newton on P_n; Golub–Welsch not
/// needed at these orders). Abramowitz & Stegun 25.4.29.
inline std::vector<std::pair<double, double>> gauss_legendre(int n) {
    std::vector<std::pair<double, double>> nodes;
    for (int i = 1; i <= n; ++i) {
        double x = std::cos(kPi<double> * (i - 0.25) / (n + 0.5));
        double dp = 0;
        for (int iter = 0; iter < 100; ++iter) {
            double p0 = 1, p1 = x;
            for (int k = 2; k <= n; ++k) {
                const double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
                p0 = p1;
                p1 = p2;
            }
            dp = n * (x * p1 - p0) / (x * x - 1);
            const double dx = p1 / dp;
            x -= dx;
            if (std::abs(dx) < 1e-15) break;
        }
        nodes.emplace_back(x, 2 / ((1 - x * x) * dp * dp));
    }
    return nodes;
}

/// ∫_a^b f with n-point Gauss–Legendre on each of `pieces` equal sub-intervals.
inline double integrate(const std::function<double(double)>& f, double a, double b, int n = 16,
                        int pieces = 1) {
    static thread_local std::vector<std::pair<double, double>> cache;
    static thread_local int cached_n = 0;
    if (cached_n != n) {
        cache = gauss_legendre(n);
        cached_n = n;
    }
    double sum = 0;
    const double h = (b - a) / pieces;
    for (int p = 0; p < pieces; ++p) {
        const double lo = a + p * h, mid = lo + h / 2;
        for (const auto& [x, w] : cache)
            sum += w * f(mid + x * h / 2);
    }
    return sum * h / 2;
}

/// Cos-weighted average of f(wo) over grid bin j on one side: ∫ f |cos| dω / Ω⊥. The measure
/// |cos θ| dω = ½ d(sin²θ) dφ is uniform in (u = sin²θ, φ); both folded halves are averaged.
/// n Gauss–Legendre nodes per axis on each of pieces × pieces sub-rectangles (composite rule: a
/// lobe that ends inside the bin, where one Gauss rule converges slowly, needs pieces > 1).
inline Rgbd bin_average(const HemisphereGrid& grid, std::size_t j, Side side,
                        const std::function<Rgbd(const Vec3d&)>& f, int n = 8, int pieces = 1) {
    const int t = int(j) / grid.n_phi(), p = int(j) % grid.n_phi();
    const double u_lo = sqr(std::sin(grid.theta_lo(t))), u_hi = sqr(std::sin(grid.theta_hi(t)));
    const double phi_lo = grid.phi_lo(p), phi_hi = grid.phi_hi(p);
    const auto nodes = gauss_legendre(n);
    Rgbd sum(0.0);
    double weight = 0;
    for (int iu = 0; iu < pieces; ++iu)
        for (int ip = 0; ip < pieces; ++ip) {
            const double u0 = u_lo + (u_hi - u_lo) * iu / pieces;
            const double u1 = u_lo + (u_hi - u_lo) * (iu + 1) / pieces;
            const double phi0 = phi_lo + (phi_hi - phi_lo) * ip / pieces;
            const double phi1 = phi_lo + (phi_hi - phi_lo) * (ip + 1) / pieces;
            for (const auto& [xu, wu] : nodes) {
                const double u = 0.5 * (u0 + u1) + 0.5 * (u1 - u0) * xu;
                const double theta = std::asin(std::sqrt(u));
                for (const auto& [xp, wp] : nodes) {
                    const double phi = 0.5 * (phi0 + phi1) + 0.5 * (phi1 - phi0) * xp;
                    const Vec3d a = direction_from_angles(theta, phi, side);
                    const Vec3d b = direction_from_angles(theta, -phi, side);
                    sum += (f(a) + f(b)) * (0.5 * wu * wp);
                    weight += wu * wp;
                }
            }
        }
    return sum / weight;
}

}  // namespace lamina::test

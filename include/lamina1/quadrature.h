#pragma once
// Quadrature rules of lamina-1's per-material precomputation (and of lamina's tables, which use
// these very functions): Gauss–Legendre rules, hemispherical integrals split at a critical
// cosine, and integrals over the normals visible from a direction whose integrand steps.

#include "lamina1/math.h"

#include <array>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

namespace lamina1 {

struct QuadratureRule {
    std::vector<double> x;  ///< nodes in [0, 1]
    std::vector<double> w;  ///< weights, summing to 1
};

/// n-point Gauss–Legendre rule mapped to [0, 1]; exact for polynomials of degree 2n − 1 (Golub &
/// Welsch 1969 give the theory; nodes by Newton iteration on the Legendre recurrence, Press et
/// al., Numerical Recipes 3rd ed., §4.6.1, `gauleg`).
inline QuadratureRule gauss_legendre(int n) {
    QuadratureRule q{std::vector<double>(n), std::vector<double>(n)};
    for (int i = 0; i < (n + 1) / 2; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (n + 0.5));
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

/// The crossing x ∈ (x0, x1) of a continuous h with h(x0) = h0 and h(x1) = h1 of opposite
/// signs, to within tol: Chandrupatla's hybrid of inverse quadratic interpolation and bisection
/// (T. R. Chandrupatla 1997, "A new hybrid quadratic/bisection algorithm for finding the zero of
/// a nonlinear function without using derivatives", Advances in Engineering Software 28(3)): the
/// interpolation is taken only where the last three points admit a monotone quadratic, else a
/// bisection step, so it never needs many more evaluations than bisection and, on the smooth
/// crossings of the visible-normal rules, far fewer. A NaN of h counts as h ≤ 0 and its step
/// falls back to bisection; at most 100 evaluations (bisection reaches 2^−100 of the bracket).
template <typename H>
double bracketed_root(H&& h, double x0, double x1, double h0, double h1, double tol) {
    // a: the newest point; a and b bracket the root; c: the point before.
    double b = x0, a = x1, c = x1, fb = h0, fa = h1, fc = h1;
    double t = 0.5;
    for (int evaluation = 0; evaluation < 100; ++evaluation) {
        const double xt = a + t * (b - a), ft = h(xt);
        if ((ft > 0) == (fa > 0)) {
            c = a, fc = fa;
        } else {
            c = b, b = a, fc = fb, fb = fa;
        }
        a = xt, fa = ft;
        const double xm = std::abs(fa) < std::abs(fb) ? a : b;
        if (ft == 0) return xt;
        const double t_lim = 0.5 * tol / std::abs(b - c);
        if (t_lim > 0.5) return xm;
        const double xi = (a - b) / (c - b), phi = (fa - fb) / (fc - fb);
        t = sqr(phi) < xi && sqr(1 - phi) < 1 - xi
                ? fa / (fb - fa) * fc / (fb - fc) +
                      (c - a) / (b - a) * fa / (fc - fa) * fb / (fc - fb)
                : 0.5;
        t = t == t ? clamp(t, t_lim, 1 - t_lim) : 0.5;
    }
    return std::abs(fa) < std::abs(fb) ? a : b;
}

/// A step of an integrand over the visible normals: where outgoing_z(wm) crosses z_split.
template <typename Out>
struct Crossing {
    Out outgoing_z;
    double z_split;
};
template <typename Out>
Crossing(Out, double) -> Crossing<Out>;

/// ∫ f(wm) over the normals wm visible from a direction, given the prepared visible-normal
/// sampler `frame` of that direction (Heitz 2018, "Sampling the GGX distribution of visible
/// normals", JCGT 7(4): u1 = r², u2 over the half disk, its mirror image giving the same integrand
/// for a direction in the xz plane), for an integrand that steps at the crossings given. `frame`
/// is any type with normal(r, cos φ, sin φ) (GGX::VisibleNormalFrame, or lamina's own). The
/// radius is integrated in u = √(1 − r) (r = 1 − u², the weight 2r dr = 4ur du): the normal's
/// height √(1 − r²) ≈ u √2 is smooth in u at the rim, where in r it has a square-root edge that a
/// few Gauss–Legendre nodes in r integrate poorly (4 × 8 nodes in r were up to 1e-2 high on the
/// transmittance of an α = 0.6 coat at normal incidence; in u, 6e-4). Per φ node (n_phi,
/// midpoint) the u axis is split at each crossing and each piece gets the Gauss–Legendre rule
/// q_r. The crossings are found by scanning each outgoing_z over kCrossingScan intervals of u for
/// sign changes, each then solved by bracketed_root to r_tol/2 in u: a reflection off an oblique
/// direction is not monotonic along r (towards the rim of the half disk facing away from w the
/// reflected direction rises and falls), so one crossing may enter and leave the same φ line,
/// where the ends' signs agree. Without the scan such a gap went unsplit: the slab's mirrored
/// transmission lobe's energy came out 24 % low (η0 2, θ' = 46°, β 0.27).
template <typename V, typename Frame, typename F, typename... Out>
V integrate_visible_split_frame(const Frame& frame, F&& f, const QuadratureRule& q_r, int n_phi,
                                double r_tol, const Crossing<Out>&... crossings) {
    constexpr double kUMin = 3.1622776601683795e-5;  // r ≤ 1 − 1e-9
    constexpr int kCrossings = sizeof...(Out);
    constexpr int kCrossingScan = 8;
    // r = 0 (u = 1) is the same normal for every φ.
    const auto normal_0 = frame.normal(0, 1, 0);
    const std::array<double, kCrossings> h_0 = {
        (crossings.outgoing_z(normal_0) - crossings.z_split)...};
    V sum{};
    for (int b = 0; b < n_phi; ++b) {
        const double phi = 2 * kPi * (0.5 * (b + 0.5) / n_phi - 0.25);
        const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
        auto normal = [&](double u) { return frame.normal(1 - u * u, cos_phi, sin_phi); };
        // The pieces' ends: kUMin, the crossings found (in increasing u), 1.
        std::array<double, kCrossings * kCrossingScan + 2> ends{};
        int n_ends = 0;
        ends[n_ends++] = kUMin;
        int k = 0;
        (
            [&](const auto& crossing) {
                auto h_u = [&](double u) {
                    return crossing.outgoing_z(normal(u)) - crossing.z_split;
                };
                double u_prev = kUMin, h_prev = h_u(kUMin);
                for (int j = 1; j <= kCrossingScan; ++j) {
                    const double u_j =
                        j == kCrossingScan ? 1.0 : kUMin + (1 - kUMin) * j / kCrossingScan;
                    const double h_j = j == kCrossingScan ? h_0[k] : h_u(u_j);
                    if ((h_prev > 0) != (h_j > 0))
                        ends[n_ends++] = bracketed_root(h_u, u_prev, u_j, h_prev, h_j, 0.5 * r_tol);
                    u_prev = u_j;
                    h_prev = h_j;
                }
                ++k;
            }(crossings),
            ...);
        for (int i = 2; i < n_ends; ++i)  // the crossings in increasing u (insertion)
            for (int j = i; j > 1 && ends[j] < ends[j - 1]; --j)
                std::swap(ends[j], ends[j - 1]);
        ends[n_ends++] = 1;
        for (int piece = 0; piece + 1 < n_ends; ++piece) {
            const double start = ends[piece], length = ends[piece + 1] - start;
            if (length <= 0) continue;
            for (std::size_t i = 0; i < q_r.x.size(); ++i) {
                const double u = start + length * q_r.x[i];
                sum += f(normal(u)) * (q_r.w[i] * length * 4 * u * (1 - u * u) / n_phi);
            }
        }
    }
    return sum;
}

/// The same over the normals of `ggx` visible from w.
template <typename V, typename Distribution, typename Direction, typename F, typename... Out>
V integrate_visible_split(const Distribution& ggx, const Direction& w, F&& f,
                          const QuadratureRule& q_r, int n_phi, double r_tol,
                          const Crossing<Out>&... crossings) {
    return integrate_visible_split_frame<V>(ggx.visible_normal_frame(w), f, q_r, n_phi, r_tol,
                                            crossings...);
}

/// The same with one crossing, where outgoing_z(wm) crosses z_split.
template <typename V, typename Distribution, typename Direction, typename Out, typename F>
V integrate_visible_split(const Distribution& ggx, const Direction& w, double z_split,
                          Out&& outgoing_z, F&& f, const QuadratureRule& q_r, int n_phi,
                          double r_tol) {
    return integrate_visible_split<V>(ggx, w, f, q_r, n_phi, r_tol,
                                      Crossing{std::ref(outgoing_z), z_split});
}

/// The same with kNr Gauss–Legendre nodes per piece, kNphi φ nodes and the crossing to
/// 2^−kBisections (as many bisections would give).
template <typename V, int kNr, int kNphi, int kBisections, typename Distribution,
          typename Direction, typename Out, typename F>
V integrate_visible_split(const Distribution& ggx, const Direction& w, double z_split,
                          Out&& outgoing_z, F&& f) {
    static const QuadratureRule q = gauss_legendre(kNr);
    return integrate_visible_split<V>(ggx, w, z_split, outgoing_z, f, q, kNphi,
                                      1.0 / double(1 << kBisections));
}

}  // namespace lamina1

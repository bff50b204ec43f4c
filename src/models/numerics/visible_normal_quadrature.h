#pragma once
// Quadrature over the normals visible from a direction (Heitz 2018, "Sampling the GGX distribution
// of visible normals", JCGT 7(4)) for integrands that step where the facet's outgoing direction
// crosses a cosine (total internal reflection, the edge of a coat's exit cone): the radius of
// Heitz's sampling disk is split at the steps per φ node, each piece integrated by Gauss–Legendre
// in u = √(1 − r). Used by the per-material curves of lamina-1 and the coat transmittance table.

#include "core/math.h"
#include "core/vec.h"
#include "models/numerics/quadrature.h"
#include "physics/microfacet.h"

#include <array>
#include <cmath>
#include <functional>
#include <utility>

namespace lamina {

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

/// ∫ f(wm) over the visible normals wm of w (Heitz 2018, "Sampling the GGX distribution of
/// visible normals", JCGT 7(4): u1 = r², u2 over the half disk, its mirror image giving the
/// same integrand for w in the xz plane), an integrand that steps at the crossings given. The
/// radius is integrated in u = √(1 − r) (r = 1 − u², the weight 2r dr = 4ur du): the normal's
/// height √(1 − r²) ≈ u √2 is smooth in u at the rim, where in r it has a square-root edge that a
/// few Gauss–Legendre nodes in r integrate poorly (4 × 8 nodes in r were up to 1e-2 high on the
/// transmittance of an α = 0.6 coat at normal incidence; in u, 6e-4). Per φ node (n_phi,
/// midpoint) the u axis is split at each crossing (bracketed_root to r_tol/2 in u; each
/// outgoing_z is monotonic along r for the reflections and refractions used here) and each piece
/// gets the Gauss–Legendre rule q_r.
template <typename V, typename F, typename... Out>
V integrate_visible_split(const GGX<double>& ggx, const Vec3d& w, F&& f, const QuadratureRule& q_r,
                          int n_phi, double r_tol, const Crossing<Out>&... crossings) {
    constexpr double kUMin = 3.1622776601683795e-5;  // r ≤ 1 − 1e-9
    constexpr int kCrossings = sizeof...(Out);
    const auto frame = ggx.visible_normal_frame(w);
    // r = 0 (u = 1) is the same normal for every φ.
    const Vec3d normal_0 = frame.normal(0, 1, 0);
    const std::array<double, kCrossings> h_0 = {
        (crossings.outgoing_z(normal_0) - crossings.z_split)...};
    V sum{};
    for (int b = 0; b < n_phi; ++b) {
        const double phi = 2 * kPi<double> * (0.5 * (b + 0.5) / n_phi - 0.25);
        const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
        auto normal = [&](double u) { return frame.normal(1 - u * u, cos_phi, sin_phi); };
        // The pieces' ends: kUMin, the crossings found (in increasing u), 1.
        std::array<double, kCrossings + 2> ends{};
        int n_ends = 0;
        ends[n_ends++] = kUMin;
        int k = 0;
        (
            [&](const auto& crossing) {
                auto h_u = [&](double u) {
                    return crossing.outgoing_z(normal(u)) - crossing.z_split;
                };
                const double h_rim = h_u(kUMin);
                if ((h_0[k] > 0) != (h_rim > 0))
                    ends[n_ends++] = bracketed_root(h_u, kUMin, 1.0, h_rim, h_0[k], 0.5 * r_tol);
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

/// The same with one crossing, where outgoing_z(wm) crosses z_split.
template <typename V, typename Out, typename F>
V integrate_visible_split(const GGX<double>& ggx, const Vec3d& w, double z_split, Out&& outgoing_z,
                          F&& f, const QuadratureRule& q_r, int n_phi, double r_tol) {
    return integrate_visible_split<V>(ggx, w, f, q_r, n_phi, r_tol,
                                      Crossing{std::ref(outgoing_z), z_split});
}

/// The same with kNr Gauss–Legendre nodes per piece, kNphi φ nodes and the crossing to
/// 2^−kBisections (as many bisections would give).
template <typename V, int kNr, int kNphi, int kBisections, typename Out, typename F>
V integrate_visible_split(const GGX<double>& ggx, const Vec3d& w, double z_split, Out&& outgoing_z,
                          F&& f) {
    static const QuadratureRule q = gauss_legendre(kNr);
    return integrate_visible_split<V>(ggx, w, z_split, outgoing_z, f, q, kNphi,
                                      1.0 / double(1 << kBisections));
}

}  // namespace lamina

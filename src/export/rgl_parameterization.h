#pragma once
// The coordinates of the RGL .bsdf format (Dupuy & Jakob 2018, "An adaptive parameterization for
// efficient material acquisition and rendering", ACM TOG 37(6)) and its node tables, shared by the
// writer (rgl_bsdf.h) and the reader (rgl_reader.h).
//
// A direction ω = (θ, φ) of the upper hemisphere is the point u = (√(θ/(π/2)), (φ + π)/(2π)) of
// [0, 1]²: the square root puts the nodes of a uniform u grid closer together near the normal,
// where the half vectors of glossy lobes gather. The solid angle is dω = J(u) du_x du_y with
// J(u) = 2π² u_x sin θ (dθ = π u_x du_x, dφ = 2π du_y). Every table of the format is a float32
// grid of nx × ny nodes over [0, 1]², node (i, j) at (i/(nx−1), j/(ny−1)), x fastest in memory,
// read by bilinear interpolation (clamped to the square).

#include "core/math.h"
#include "core/spherical.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace lamina::rgl {

inline double u_to_theta(double u) {
    return u * u * (kPi<double> / 2);
}
inline double u_to_phi(double u) {
    return (2 * u - 1) * kPi<double>;
}
inline double theta_to_u(double theta) {
    return std::sqrt(std::max(0.0, theta) / (kPi<double> / 2));
}
inline double phi_to_u(double phi) {
    return (phi + kPi<double>) / (2 * kPi<double>);
}

/// The direction at u (its azimuth u_to_phi(u_y), relative to whatever the table's φ is).
inline Vec3d direction_at(double ux, double uy) {
    return direction_from_angles(u_to_theta(ux), u_to_phi(uy));
}

/// dω/du: the solid angle per unit area of u, 2π² u_x sin θ.
inline double solid_angle_jacobian(double ux) {
    return 2 * kPi<double> * kPi<double> * ux * std::sin(u_to_theta(ux));
}

/// Bilinear interpolation of an nx × ny node grid (x fastest) at x ∈ [0, 1]², clamped.
template <typename T>
double bilinear(const T* nodes, std::size_t nx, std::size_t ny, double x, double y) {
    const double gx = std::clamp(x, 0.0, 1.0) * double(nx - 1),
                 gy = std::clamp(y, 0.0, 1.0) * double(ny - 1);
    const std::size_t i = std::min(std::size_t(gx), nx - 2), j = std::min(std::size_t(gy), ny - 2);
    const double s = gx - double(i), t = gy - double(j);
    auto at = [&](std::size_t a, std::size_t b) { return double(nodes[b * nx + a]); };
    return (1 - t) * ((1 - s) * at(i, j) + s * at(i + 1, j)) +
           t * ((1 - s) * at(i, j + 1) + s * at(i + 1, j + 1));
}

/// Linear interpolation of n ≥ 2 nodes over [0, 1] (node i at i/(n−1)) at x, clamped: one row of
/// a table that does not depend on y.
template <typename T>
double linear(const T* nodes, std::size_t n, double x) {
    const double g = std::clamp(x, 0.0, 1.0) * double(n - 1);
    const std::size_t i = std::min(std::size_t(g), n - 2);
    const double s = g - double(i);
    return (1 - s) * double(nodes[i]) + s * double(nodes[i + 1]);
}

/// The interpolation between incidence nodes the readers use: the node k below θ (clamped to
/// the first and last intervals) and the weight of node k + 1, clamped to [0, 1] (so θ past the
/// last node reads the last one). One node: (0, 0).
struct IncidenceWeight {
    std::size_t k;
    double w;
};
inline IncidenceWeight incidence_weight(const std::vector<double>& theta_nodes, double theta) {
    if (theta_nodes.size() < 2) return {0, 0.0};
    const auto it = std::upper_bound(theta_nodes.begin(), theta_nodes.end(), theta);
    const std::size_t k = std::size_t(std::clamp<std::ptrdiff_t>(
        it - theta_nodes.begin() - 1, 0, std::ptrdiff_t(theta_nodes.size()) - 2));
    const double w = (theta - theta_nodes[k]) / (theta_nodes[k + 1] - theta_nodes[k]);
    return {k, std::clamp(w, 0.0, 1.0)};
}

}  // namespace lamina::rgl

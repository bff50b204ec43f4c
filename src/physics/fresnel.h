#pragma once
// Fresnel reflectance, Snell refraction and mirror reflection.
//
// Relative index convention: `eta` is η_t / η_i, the index of the medium the light refracts *into*
// over the index of the medium it arrives from, for light arriving on the side the normal points
// to. At an interface of a stack (normal +z pointing up) eta = η_below / η_above.

#include "core/math.h"
#include "core/vec.h"

#include <cmath>
#include <complex>
#include <optional>

namespace lamina {

/// Exact unpolarized Fresnel reflectance of a dielectric interface (the mean of the s and p
/// reflectances; Born & Wolf, Principles of Optics, §1.5.2, Eqs. 21a–b).
/// cos_theta_i: cosine between the arriving direction and the normal, in [−1, 1]; a negative value
/// means the light arrives from the other side, where the relative index is 1/eta.
/// eta > 0. Returns 1 under total internal reflection (sin θt ≥ 1).
template <typename T>
inline T fresnel_dielectric(T cos_theta_i, T eta) {
    cos_theta_i = clamp(cos_theta_i, T(-1), T(1));
    if (cos_theta_i < 0) {
        eta = T(1) / eta;
        cos_theta_i = -cos_theta_i;
    }
    const T sin2_theta_t = (T(1) - sqr(cos_theta_i)) / sqr(eta);
    if (sin2_theta_t >= T(1)) return T(1);  // total internal reflection
    const T cos_theta_t = safe_sqrt(T(1) - sin2_theta_t);
    const T r_parallel = (eta * cos_theta_i - cos_theta_t) / (eta * cos_theta_i + cos_theta_t);
    const T r_perpendicular = (cos_theta_i - eta * cos_theta_t) / (cos_theta_i + eta * cos_theta_t);
    return (sqr(r_parallel) + sqr(r_perpendicular)) / T(2);
}

/// Exact unpolarized Fresnel reflectance of a conductor with relative complex index
/// eta + i·k (k ≥ 0), light arriving from the dielectric side with cos_theta_i in [0, 1].
/// The same Fresnel equations as the dielectric case with a complex index (Born & Wolf §14.2);
/// with k = 0 it equals fresnel_dielectric, including total internal reflection when eta < 1.
template <typename T>
inline T fresnel_conductor(T cos_theta_i, T eta, T k) {
    using C = std::complex<T>;
    cos_theta_i = clamp(cos_theta_i, T(0), T(1));
    const C eta_c(eta, k);
    const T sin2_theta_i = T(1) - sqr(cos_theta_i);
    const C sin2_theta_t = sin2_theta_i / (eta_c * eta_c);
    const C cos_theta_t = std::sqrt(C(1) - sin2_theta_t);  // principal root: Im ≥ 0 (decaying)
    const C r_parallel = (eta_c * cos_theta_i - cos_theta_t) / (eta_c * cos_theta_i + cos_theta_t);
    const C r_perpendicular =
        (C(cos_theta_i) - eta_c * cos_theta_t) / (C(cos_theta_i) + eta_c * cos_theta_t);
    return (std::norm(r_parallel) + std::norm(r_perpendicular)) / T(2);
}

/// Mirror reflection of w (pointing away from the surface) about the unit normal n.
template <typename T>
inline Vec3<T> reflect(const Vec3<T>& w, const Vec3<T>& n) {
    return n * (T(2) * dot(w, n)) - w;
}

/// Snell refraction of w (pointing away from the surface, on either side) through an interface
/// with unit normal n and relative index eta = η(side n points away from) / η(side n points to).
/// Returns the refracted direction, pointing away from the surface on the other side, or nothing
/// under total internal reflection.
template <typename T>
inline std::optional<Vec3<T>> refract(const Vec3<T>& w, Vec3<T> n, T eta) {
    T cos_theta_i = dot(n, w);
    if (cos_theta_i < 0) {  // arriving from the side n points away from
        eta = T(1) / eta;
        cos_theta_i = -cos_theta_i;
        n = -n;
    }
    const T sin2_theta_t = (T(1) - sqr(cos_theta_i)) / sqr(eta);
    if (sin2_theta_t >= T(1)) return std::nullopt;
    const T cos_theta_t = safe_sqrt(T(1) - sin2_theta_t);
    return -w / eta + n * (cos_theta_i / eta - cos_theta_t);
}

}  // namespace lamina

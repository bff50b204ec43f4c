#pragma once
// Spherical coordinates in lamina's conventions (docs/physics.md §1).
//
// θ is measured from +z for upper-hemisphere (reflected) directions and from −z for
// lower-hemisphere (transmitted) directions; φ is measured from +x. The light of an incidence θi
// sits at φ = 0: wi = (sin θi, 0, cos θi), so the mirror direction is at φo = 180° and the
// straight-through transmitted direction is also at φ = 180°.

#include "core/math.h"
#include "core/vec.h"

#include <cmath>

namespace lamina {

enum class Side { Reflection, Transmission };

/// Direction with polar angle theta (radians, in [0, π/2]) and azimuth phi (radians), on the given
/// side: upper hemisphere for Reflection, lower for Transmission (θ measured from −z).
template <typename T>
inline Vec3<T> direction_from_angles(T theta, T phi, Side side = Side::Reflection) {
    const T sin_theta = std::sin(theta);
    const T z = std::cos(theta);
    return {sin_theta * std::cos(phi), sin_theta * std::sin(phi),
            side == Side::Reflection ? z : -z};
}

/// The incident direction of incidence theta_i (radians): (sin θi, 0, cos θi).
template <typename T>
inline Vec3<T> incident_direction(T theta_i) {
    return direction_from_angles(theta_i, T(0), Side::Reflection);
}

/// Polar angle of w on its own side (radians, [0, π/2]): from +z if w.z ≥ 0, else from −z.
template <typename T>
inline T theta_of(const Vec3<T>& w) {
    return std::acos(clamp(std::abs(w.z), T(0), T(1)));
}

/// Azimuth of w in [0, 2π).
template <typename T>
inline T phi_of(const Vec3<T>& w) {
    T phi = std::atan2(w.y, w.x);
    return phi < 0 ? phi + 2 * kPi<T> : phi;
}

}  // namespace lamina

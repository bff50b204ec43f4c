#pragma once
// Orthonormal frames: local shading frames about any normal (e.g. a microfacet normal wm).

#include "core/vec.h"

#include <cmath>

namespace lamina {

/// An orthonormal basis (s, t, n). `to_local` expresses a world vector in it; `to_world` is its
/// inverse. n must be a unit vector.
template <typename T>
struct Frame {
    Vec3<T> s, t, n;

    /// Branchless construction from a unit normal: Duff et al. 2017, "Building an Orthonormal
    /// Basis, Revisited", JCGT 6(1), Listing 3.
    static Frame from_normal(const Vec3<T>& n) {
        const T sign = std::copysign(T(1), n.z);
        const T a = T(-1) / (sign + n.z);
        const T b = n.x * n.y * a;
        return {Vec3<T>(T(1) + sign * n.x * n.x * a, sign * b, -sign * n.x),
                Vec3<T>(b, sign + n.y * n.y * a, -n.y), n};
    }

    Vec3<T> to_local(const Vec3<T>& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
    Vec3<T> to_world(const Vec3<T>& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace lamina

#pragma once
// Orthonormal frames: local shading frames about any normal (e.g. a microfacet normal wm).

#include "core/lane_vec.h"
#include "core/vec.h"

#include <cmath>

namespace lamina {

/// An orthonormal basis (s, t, n). `to_local` expresses a world vector in it; `to_world` is its
/// inverse. n must be a unit vector.
template <typename T>
struct Frame {
    Vec3<T> s, t, n;

    /// Branchless construction from a unit normal: Duff et al. 2017, "Building an Orthonormal
    /// Basis, Revisited", JCGT 6(1), Listing 3 (the lane template lane_orthonormal_basis).
    static Frame from_normal(const Vec3<T>& n) {
        LaneVec3<T> s, t;
        lane_orthonormal_basis<T>({n.x, n.y, n.z}, s, t);
        return {Vec3<T>(s.x, s.y, s.z), Vec3<T>(t.x, t.y, t.z), n};
    }

    Vec3<T> to_local(const Vec3<T>& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
    Vec3<T> to_world(const Vec3<T>& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace lamina

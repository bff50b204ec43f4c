// LaneVec3, three lane values holding a direction, and its operations: the lane forms of
// core/vec.h's dot and normalize, and a lane-wise select. Lane templates: a lane header.

#include "core/lane.h"

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_CORE_LANE_VEC_H
#define LAMINA_CORE_LANE_VEC_H
#define LAMINA_CORE_LANE_VEC_BODY
#endif
#elif defined(LAMINA_CORE_LANE_VEC_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_CORE_LANE_VEC_TARGET
#undef LAMINA_CORE_LANE_VEC_TARGET
#else
#define LAMINA_CORE_LANE_VEC_TARGET
#endif
#define LAMINA_CORE_LANE_VEC_BODY
#endif

#ifdef LAMINA_CORE_LANE_VEC_BODY
#undef LAMINA_CORE_LANE_VEC_BODY

LAMINA_LANE_BEGIN

/// A direction (or any 3-vector) as three lane values: for T = float one Vec3. Defined once per
/// target, as its operations, so that argument-dependent lookup finds only that target's.
template <typename T>
struct LaneVec3 {
    T x, y, z;
};

/// a · b.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T lane_dot(const LaneVec3<T>& a, const LaneVec3<T>& b) {
    return L::mul_add(a.x, b.x, L::mul_add(a.y, b.y, a.z * b.z));
}
/// a times the reciprocal of its length (as core/vec.h normalize); a must be non-zero.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> lane_normalize(const LaneVec3<T>& a) {
    const T inv = L::inv_sqrt(lane_dot<T, L>(a, a));
    return {a.x * inv, a.y * inv, a.z * inv};
}
/// a × b.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> lane_cross(const LaneVec3<T>& a, const LaneVec3<T>& b) {
    return {L::mul_add(a.y, b.z, L::constant(0) - a.z * b.y),
            L::mul_add(a.z, b.x, L::constant(0) - a.x * b.z),
            L::mul_add(a.x, b.y, L::constant(0) - a.y * b.x)};
}
/// a where the mask m holds, else b.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> lane_select(typename L::Mask m, const LaneVec3<T>& a,
                                           const LaneVec3<T>& b) {
    return {L::select(m, a.x, b.x), L::select(m, a.y, b.y), L::select(m, a.z, b.z)};
}

/// The branchless orthonormal basis (s, t) completing the unit vector n to a right-handed frame
/// (s, t, n): Duff et al. 2017, "Building an Orthonormal Basis, Revisited", JCGT 6(1), Listing 3.
/// Frame::from_normal (core/frame.h) and the SIMD kernel evaluate these lines.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE void lane_orthonormal_basis(const LaneVec3<T>& n, LaneVec3<T>& s,
                                               LaneVec3<T>& t) {
    const T one = L::constant(1);
    const T sign = L::copysign(one, n.z);
    const T a = L::constant(-1) / (sign + n.z);
    const T b = n.x * n.y * a;
    s = {L::mul_add(sign * (n.x * n.x), a, one), sign * b, L::constant(0) - sign * n.x};
    t = {b, L::mul_add(n.y * n.y, a, sign), L::constant(0) - n.y};
}
/// s·v.x + t·v.y + n·v.z: a vector given in the frame (s, t, n) in world coordinates.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> lane_to_world(const LaneVec3<T>& s, const LaneVec3<T>& t,
                                             const LaneVec3<T>& n, const LaneVec3<T>& v) {
    return {L::mul_add(s.x, v.x, L::mul_add(t.x, v.y, n.x * v.z)),
            L::mul_add(s.y, v.x, L::mul_add(t.y, v.y, n.y * v.z)),
            L::mul_add(s.z, v.x, L::mul_add(t.z, v.y, n.z * v.z))};
}

LAMINA_LANE_END

#endif  // LAMINA_CORE_LANE_VEC_BODY

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
inline T lane_dot(const LaneVec3<T>& a, const LaneVec3<T>& b) {
    return L::mul_add(a.x, b.x, L::mul_add(a.y, b.y, a.z * b.z));
}
/// a times the reciprocal of its length (as core/vec.h normalize); a must be non-zero.
template <typename T, typename L = Lane<T>>
inline LaneVec3<T> lane_normalize(const LaneVec3<T>& a) {
    const T inv = L::inv_sqrt(lane_dot<T, L>(a, a));
    return {a.x * inv, a.y * inv, a.z * inv};
}
/// a where the mask m holds, else b.
template <typename T, typename L = Lane<T>>
inline LaneVec3<T> lane_select(typename L::Mask m, const LaneVec3<T>& a, const LaneVec3<T>& b) {
    return {L::select(m, a.x, b.x), L::select(m, a.y, b.y), L::select(m, a.z, b.z)};
}

LAMINA_LANE_END

#endif  // LAMINA_CORE_LANE_VEC_BODY

// The Henyey–Greenstein phase function (Henyey & Greenstein 1941, ApJ 93, Eq. 3).
//
// Directions here are *propagation* directions: `d_in` is where the particle travels before the
// scattering event, `d_out` after. cos_theta = d_in·d_out; g ∈ (−1, 1) is the mean cosine
// (g > 0 forward scattering). The phase function is normalized over the sphere (1/sr).

#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/math.h"
#include "core/vec.h"

#include <cmath>

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_PHASE_H
#define LAMINA_PHYSICS_PHASE_H
#define LAMINA_PHYSICS_PHASE_BODY
#endif
#elif defined(LAMINA_PHYSICS_PHASE_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_PHASE_TARGET
#undef LAMINA_PHYSICS_PHASE_TARGET
#else
#define LAMINA_PHYSICS_PHASE_TARGET
#endif
#define LAMINA_PHYSICS_PHASE_BODY
#endif

#ifdef LAMINA_PHYSICS_PHASE_BODY
#undef LAMINA_PHYSICS_PHASE_BODY

LAMINA_LANE_BEGIN

/// The phase function's value, 1/sr: (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}). A lane template
/// (core/lane.h), as sample_hg_cos_theta: the scalar and the SIMD kernels evaluate these lines.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T hg_phase(T cos_theta, T g) {
    const T one = L::constant(1), two = L::constant(2);
    // The dot product of two unit vectors in float can exceed 1 by rounding (1.00006 was seen);
    // with |g| near 1 the denominator (1 − g)² − 2g(cos θ − 1) then turns negative and the phase
    // infinite or NaN (found by the fuzz test): cos θ is clamped to [−1, 1].
    cos_theta = L::min(L::max(cos_theta, L::constant(-1)), one);
    const T denom = one + g * g - two * g * cos_theta;
    return (one - g * g) / (L::constant(4) * L::constant(kPi<double>) * denom *
                            L::sqrt(L::max(denom, L::constant(0))));
}

/// cos θ of a sample of HG from u in [0, 1) by inverting its CDF (e.g. Pharr, Jakob, Humphreys,
/// PBR 4th ed., §11.3.1); uniform when |g| is tiny (|g| < 1e-3). Branch-free.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T sample_hg_cos_theta(T g, T u) {
    const T zero = L::constant(0), one = L::constant(1), two = L::constant(2);
    // s = (1 − g²) / (1 + g − 2gu), both written without cancellation as |g| → 1 (1 − g² and
    // 1 + g − 2gu near 0 would be differences of numbers near 1 or 2, 50 to 200 ulps off at
    // g = 0.99): (1 − g)(1 + g), and (1 − |g|) + 2|g|(1 − u) for g > 0, (1 − |g|) + 2|g|u for
    // g < 0, sums of non-negative terms.
    const T a = L::max(g, zero - g);
    const T s =
        (one - g) * (one + g) / ((one - a) + two * a * L::select(L::less(zero, g), one - u, u));
    const T inverted = L::min(L::max((one + g * g - s * s) / (two * g), L::constant(-1)), one);
    const auto tiny = L::less(a, L::constant(1e-3));
    return L::select(tiny, one - two * u, inverted);
}

/// Propagation direction after scattering d_in (unit) with HG(g), from two uniforms in [0, 1):
/// cos θ by sample_hg_cos_theta, the azimuth 2πu2, about d_in in the frame of Duff et al. 2017
/// (core/lane_vec.h). A branch-free lane template (core/lane.h): sample_hg and the SIMD kernel
/// evaluate these lines.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> sample_hg_direction(const LaneVec3<T>& d_in, T g, T u1, T u2) {
    const T cos_theta = sample_hg_cos_theta<T, L>(g, u1);
    const T sin_theta =
        L::sqrt(L::max(L::neg_mul_add(cos_theta, cos_theta, L::constant(1)), L::constant(0)));
    T cos_phi, sin_phi;
    L::cos_sin_2pi(u2, cos_phi, sin_phi);
    LaneVec3<T> s, t;
    lane_orthonormal_basis<T, L>(d_in, s, t);
    return lane_to_world<T, L>(s, t, d_in, {sin_theta * cos_phi, sin_theta * sin_phi, cos_theta});
}

/// The same on one direction.
template <typename T>
LAMINA_LANE_INLINE Vec3<T> sample_hg(const Vec3<T>& d_in, T g, T u1, T u2) {
    const LaneVec3<T> d = sample_hg_direction<T>({d_in.x, d_in.y, d_in.z}, g, u1, u2);
    return {d.x, d.y, d.z};
}

/// Inverse of sample_hg_cos_theta: the u that produces cos_theta.
template <typename T>
LAMINA_LANE_INLINE T invert_hg_cos_theta(T g, T cos_theta) {
    if (std::abs(g) < T(1e-3)) return (T(1) - cos_theta) / T(2);
    const T s = std::sqrt(T(1) + sqr(g) - T(2) * g * cos_theta);
    return (T(1) + g - (T(1) - sqr(g)) / s) / (T(2) * g);
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_PHASE_BODY

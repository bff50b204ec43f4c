#pragma once
// Lane types. A formula written once as a branch-free template over a lane type T runs on one
// value (T = float or double, masks are bool) and on the lanes of a SIMD vector (the particle
// kernel instantiates it with Highway vectors through VecLane, core/lane_hwy.h, an operations
// struct of the same shape as Lane<T>). The template reads its arithmetic from the operators
// (+, −, ·, / are defined for both) and everything else from the operations struct L:
//
//   L::constant(x)   the double x as a lane value (rounded to T)
//   L::min/max/sqrt  lane-wise
//   L::log/log1p/exp lane-wise, the C library's (scalar) or Highway's (vectors: ≤ 4 ulp)
//   L::select(m,a,b) a where the mask m holds, else b
//   L::less(a, b)    the mask a < b
//   L::abs(x)        |x|
//   L::copysign(a, b)  |a| with the sign of b (of −0 too)
//   L::mul_add(a, b, c), L::neg_mul_add(a, b, c)   a·b + c and c − a·b (vectors: fused)
//   L::inv_sqrt(x)   1/√x (a square root and a division, correctly rounded)
//   L::cos_sin_2pi(u, c, s)   cos and sin of 2πu, u ∈ [0, 1) (an azimuth)
//   L::cos_sin(x, c, s)       cos and sin of x (a phase; double lanes only)
//   L::both(m, n), L::either(m, n), L::negate(m), L::none(m)   mask logic; none: no lane holds
//
// LaneVec3<T> (core/lane_vec.h) holds a direction as three lane values.
//
// Lane headers. Vector code must be compiled once per instruction set, inside Highway's target
// regions, so a header of lane templates (core/beta_function.h, physics/smith_masking.h) is
// included twice over: once as an ordinary header (its templates in namespace lamina, for scalar
// code), and once per instruction set with LAMINA_LANE_TARGET defined, after core/lane_hwy.h has
// pointed LAMINA_LANE_BEGIN/END at that target's namespace (core/lane_hwy.h shows how a unit of
// vector code does it). Such a header holds nothing but lane templates between LAMINA_LANE_BEGIN
// and LAMINA_LANE_END, and opens with this guard (NAME its path, as LAMINA_CORE_LANE_VEC):
//
//   #ifndef LAMINA_LANE_TARGET          // ordinary: once
//   #ifndef NAME_H
//   #define NAME_H
//   #define NAME_BODY
//   #endif
//   #elif defined(NAME_TARGET) == defined(HWY_TARGET_TOGGLE)   // per target: Highway's toggle
//   #ifdef NAME_TARGET
//   #undef NAME_TARGET
//   #else
//   #define NAME_TARGET
//   #endif
//   #define NAME_BODY
//   #endif
//
//   #ifdef NAME_BODY
//   #undef NAME_BODY
//   …
//   #endif
//
// Scalar instantiations are the readable reference; the lane tests check the vector
// instantiations against them (tests/simulator/kernel_simd_test.cpp, tests/physics/lanes_test.cpp,
// through tests/support/simd_probes.h).

#include <cmath>
#include <concepts>

/// Lane templates are always inlined: on vectors a call that is not inlined passes its vector
/// arguments and results (LaneVec3, masks) through memory, which costs the SIMD kernel more than
/// the arithmetic (measured: 25 % on a rough dielectric's event).
#ifndef LAMINA_LANE_INLINE
#define LAMINA_LANE_INLINE inline __attribute__((always_inline))
#endif

#ifndef LAMINA_LANE_BEGIN
#define LAMINA_LANE_BEGIN namespace lamina {
#define LAMINA_LANE_END }
#endif

namespace lamina {

template <typename T>
struct Lane;

template <std::floating_point T>
struct Lane<T> {
    using Value = T;
    using Mask = bool;
    static T constant(double x) { return T(x); }
    static T min(T a, T b) { return a < b ? a : b; }
    static T max(T a, T b) { return a > b ? a : b; }
    static T sqrt(T x) { return std::sqrt(x); }
    static T log(T x) { return std::log(x); }
    static T log1p(T x) { return std::log1p(x); }
    static T exp(T x) { return std::exp(x); }
    static T select(bool m, T a, T b) { return m ? a : b; }
    static bool less(T a, T b) { return a < b; }
    static T abs(T x) { return std::abs(x); }
    static T copysign(T a, T b) { return std::copysign(a, b); }
    static T mul_add(T a, T b, T c) { return a * b + c; }
    static T neg_mul_add(T a, T b, T c) { return c - a * b; }
    static T inv_sqrt(T x) { return T(1) / std::sqrt(x); }
    static void cos_sin(T x, T& c, T& s) {
        c = std::cos(x);
        s = std::sin(x);
    }
    static void cos_sin_2pi(T u, T& c, T& s) {
        const T phi = T(2) * T(3.14159265358979323846) * u;
        c = std::cos(phi);
        s = std::sin(phi);
    }
    static bool both(bool m, bool n) { return m && n; }
    static bool either(bool m, bool n) { return m || n; }
    static bool negate(bool m) { return !m; }
    static bool none(bool m) { return !m; }
    /// The largest argument the lane's special functions take without overflow in their
    /// intermediate products (core/beta_function.h).
    static constexpr double kBetaArgumentMax = sizeof(T) == 4 ? 1e7 : 1e15;
    /// Whether the lane holds floats (the special functions choose their method by it).
    static constexpr bool kSinglePrecision = sizeof(T) == 4;
};

}  // namespace lamina

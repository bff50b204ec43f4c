#pragma once
// Small numeric helpers and constants shared by every layer of lamina.

#include <algorithm>
#include <cmath>
#include <numbers>

/// Forces inlining of small hot-path functions the compiler's heuristics would keep out of line
/// (the particle tracer's interface samplers).
#define LAMINA_FORCE_INLINE inline __attribute__((always_inline))

namespace lamina {

template <typename T>
inline constexpr T kPi = std::numbers::pi_v<T>;
template <typename T>
inline constexpr T kInvPi = std::numbers::inv_pi_v<T>;

template <typename T>
constexpr T sqr(T x) {
    return x * x;
}

/// max(x, 0) written so that compilers emit one branch-free max instruction (std::max returns a
/// reference and is often compiled to a branch, which mispredicts in the particle tracer).
template <typename T>
constexpr T max0(T x) {
    return x > T(0) ? x : T(0);
}

/// sqrt clamped at zero: guards against tiny negative arguments produced by rounding.
template <typename T>
inline T safe_sqrt(T x) {
    return std::sqrt(max0(x));
}

/// x limited to [lo, hi] (branch-free min/max, as max0).
template <typename T>
constexpr T clamp(T x, T lo, T hi) {
    x = x < lo ? lo : x;
    return x > hi ? hi : x;
}

/// Linear interpolation a + t (b − a) for t ∈ [0, 1], as the tables of the production models
/// interpolate (their shaders' mix). std::lerp gives the same to the rounding, but its care for
/// t outside [0, 1] and for a, b of opposite signs (exactness at t = 1, monotonicity) keeps it out
/// of line, at several times the cost, in the models' per-evaluation table lookups.
template <typename T>
constexpr T mix(T a, T b, T t) {
    return a + t * (b - a);
}

constexpr double deg_to_rad(double deg) {
    return deg * std::numbers::pi / 180.0;
}
constexpr double rad_to_deg(double rad) {
    return rad * 180.0 / std::numbers::pi;
}

}  // namespace lamina

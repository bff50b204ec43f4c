#pragma once
// Warps from the unit square to directions, each as a triple sample / pdf / invert (docs/style.md
// §4).

#include "core/math.h"
#include "core/vec.h"

#include <array>
#include <cmath>

namespace lamina {

/// Concentric map of the unit square to the unit disk: Shirley & Chiu 1997, "A low distortion map
/// between disk and square", JGT 2(3).
template <typename T>
inline std::array<T, 2> sample_concentric_disk(T u1, T u2) {
    const T a = T(2) * u1 - T(1), b = T(2) * u2 - T(1);
    if (a == 0 && b == 0) return {T(0), T(0)};
    T r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi<T> / T(4)) * (b / a);
    } else {
        r = b;
        phi = kPi<T> / T(2) - (kPi<T> / T(4)) * (a / b);
    }
    return {r * std::cos(phi), r * std::sin(phi)};
}

/// Inverse of sample_concentric_disk for a point of the unit disk.
template <typename T>
inline std::array<T, 2> invert_concentric_disk(T x, T y) {
    const T r = std::sqrt(sqr(x) + sqr(y));
    T phi = std::atan2(y, x);  // (−π, π]
    T a, b;
    // Quadrants of the square: |a| > |b| maps to phi within ±π/4 of the x axis.
    if (phi < -kPi<T> / T(4)) phi += T(2) * kPi<T>;
    if (phi < kPi<T> / T(4)) {  // right wedge: a = r, b = a·phi/(π/4)
        a = r;
        b = phi * a / (kPi<T> / T(4));
    } else if (phi < T(3) * kPi<T> / T(4)) {  // top wedge: b = r
        b = r;
        a = -(phi - kPi<T> / T(2)) * b / (kPi<T> / T(4));
    } else if (phi < T(5) * kPi<T> / T(4)) {  // left wedge: a = −r
        a = -r;
        b = (phi - kPi<T>)*a / (kPi<T> / T(4));
    } else {  // bottom wedge: b = −r
        b = -r;
        a = -(phi - T(3) * kPi<T> / T(2)) * b / (kPi<T> / T(4));
    }
    return {(a + T(1)) / T(2), (b + T(1)) / T(2)};
}

/// Cosine-weighted upper hemisphere by Malley's method (project the concentric disk up).
template <typename T>
inline Vec3<T> sample_cosine_hemisphere(T u1, T u2) {
    const auto d = sample_concentric_disk(u1, u2);
    return {d[0], d[1], safe_sqrt(T(1) - sqr(d[0]) - sqr(d[1]))};
}

/// Density of sample_cosine_hemisphere: cos θ / π on the upper hemisphere, 0 below.
template <typename T>
inline T pdf_cosine_hemisphere(const Vec3<T>& w) {
    return w.z > 0 ? w.z * kInvPi<T> : T(0);
}

template <typename T>
inline std::array<T, 2> invert_cosine_hemisphere(const Vec3<T>& w) {
    return invert_concentric_disk(w.x, w.y);
}

/// Uniform direction on the unit sphere; density 1/(4π).
template <typename T>
inline Vec3<T> sample_uniform_sphere(T u1, T u2) {
    const T z = T(1) - T(2) * u1;
    const T r = safe_sqrt(T(1) - sqr(z));
    const T phi = T(2) * kPi<T> * u2;
    return {r * std::cos(phi), r * std::sin(phi), z};
}

template <typename T>
inline T pdf_uniform_sphere() {
    return T(1) / (T(4) * kPi<T>);
}

template <typename T>
inline std::array<T, 2> invert_uniform_sphere(const Vec3<T>& w) {
    T phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += T(2) * kPi<T>;
    return {(T(1) - w.z) / T(2), phi / (T(2) * kPi<T>)};
}

}  // namespace lamina

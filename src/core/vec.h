#pragma once
// Three-component vectors for directions in lamina's local frame.
//
// Conventions (docs/physics.md §1): z is the geometric normal, pointing into the ambient medium
// above the stack. Directions are unit vectors pointing *away* from the surface. Templated on the
// scalar so the particle tracer can run in float while models and tests use double.

#include <cmath>

namespace lamina {

template <typename T>
struct Vec3 {
    T x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(T x_, T y_, T z_) : x(x_), y(y_), z(z_) {}
    template <typename U>
    constexpr explicit Vec3(const Vec3<U>& v) : x(T(v.x)), y(T(v.y)), z(T(v.z)) {}

    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator*(T s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(T s) const { return {x / s, y / s, z / s}; }
    constexpr Vec3& operator+=(const Vec3& o) { return *this = *this + o; }
    constexpr Vec3& operator*=(T s) { return *this = *this * s; }
    constexpr bool operator==(const Vec3&) const = default;
};

template <typename T>
constexpr Vec3<T> operator*(T s, const Vec3<T>& v) {
    return v * s;
}

template <typename T>
constexpr T dot(const Vec3<T>& a, const Vec3<T>& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

template <typename T>
constexpr Vec3<T> cross(const Vec3<T>& a, const Vec3<T>& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <typename T>
inline T length(const Vec3<T>& v) {
    return std::sqrt(dot(v, v));
}

/// Unit vector along v. v must be non-zero. (One division: v times the reciprocal length.)
template <typename T>
inline Vec3<T> normalize(const Vec3<T>& v) {
    return v * (T(1) / length(v));
}

/// Mirror of w about z = 0 (used for transmitted lobes drawn as mirrored reflection lobes).
template <typename T>
constexpr Vec3<T> flip_z(const Vec3<T>& v) {
    return {v.x, v.y, -v.z};
}

using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

}  // namespace lamina

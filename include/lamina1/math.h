#pragma once
// lamina-1's header library: scalars, directions and RGB triples (C++17, the standard library
// only). Conventions (lamina's docs/notation.md): z is the macro-surface normal, pointing into the
// ambient medium above the stack; directions are unit vectors pointing away from the surface.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

/// Keeps a rarely taken branch out of the caller's hot path.
#if defined(__GNUC__) || defined(__clang__)
#define LAMINA1_NOINLINE __attribute__((noinline))
#else
#define LAMINA1_NOINLINE
#endif

namespace lamina1 {

constexpr double kPi = 3.141592653589793238462643383279502884;
constexpr double kInvPi = 0.318309886183790671537767526745028724;

constexpr double sqr(double x) {
    return x * x;
}

/// max(x, 0) as one branch-free max.
constexpr double max0(double x) {
    return x > 0.0 ? x : 0.0;
}

/// sqrt clamped at zero: guards against tiny negative arguments produced by rounding.
inline double safe_sqrt(double x) {
    return std::sqrt(max0(x));
}

/// x limited to [lo, hi] (NaN stays NaN).
constexpr double clamp(double x, double lo, double hi) {
    x = x < lo ? lo : x;
    return x > hi ? hi : x;
}

struct Vec3 {
    double x = 0, y = 0, z = 0;

    constexpr Vec3() = default;
    constexpr Vec3(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}

    constexpr Vec3 operator-() const { return {-x, -y, -z}; }
    constexpr Vec3 operator+(const Vec3& o) const { return {x + o.x, y + o.y, z + o.z}; }
    constexpr Vec3 operator-(const Vec3& o) const { return {x - o.x, y - o.y, z - o.z}; }
    constexpr Vec3 operator*(double s) const { return {x * s, y * s, z * s}; }
    constexpr Vec3 operator/(double s) const { return {x / s, y / s, z / s}; }
};

constexpr double dot(const Vec3& a, const Vec3& b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

inline double length(const Vec3& v) {
    return std::sqrt(dot(v, v));
}

/// Unit vector along v (non-zero): v times the reciprocal length.
inline Vec3 normalize(const Vec3& v) {
    return v * (1.0 / length(v));
}

/// Mirror reflection of w (pointing away from the surface) about the unit normal n.
inline Vec3 reflect(const Vec3& w, const Vec3& n) {
    return n * (2.0 * dot(w, n)) - w;
}

/// The mirror direction of wi about the macro normal.
constexpr Vec3 mirror_direction(const Vec3& wi) {
    return {-wi.x, -wi.y, wi.z};
}

/// Three independent spectral channels (red, green, blue).
struct Rgb {
    std::array<double, 3> c{};

    constexpr Rgb() = default;
    constexpr explicit Rgb(double v) : c{v, v, v} {}
    constexpr Rgb(double r, double g, double b) : c{r, g, b} {}

    constexpr double& operator[](std::size_t i) { return c[i]; }
    constexpr const double& operator[](std::size_t i) const { return c[i]; }
    constexpr Rgb operator+(const Rgb& o) const { return {c[0] + o[0], c[1] + o[1], c[2] + o[2]}; }
    constexpr Rgb operator-(const Rgb& o) const { return {c[0] - o[0], c[1] - o[1], c[2] - o[2]}; }
    constexpr Rgb operator*(const Rgb& o) const { return {c[0] * o[0], c[1] * o[1], c[2] * o[2]}; }
    constexpr Rgb operator*(double s) const { return {c[0] * s, c[1] * s, c[2] * s}; }
    Rgb& operator+=(const Rgb& o) { return *this = *this + o; }
    Rgb& operator*=(const Rgb& o) { return *this = *this * o; }
    Rgb& operator*=(double s) { return *this = *this * s; }
    constexpr bool operator==(const Rgb& o) const {
        return c[0] == o[0] && c[1] == o[1] && c[2] == o[2];
    }
    constexpr double mean() const { return (c[0] + c[1] + c[2]) / 3.0; }
    double max() const { return std::max({c[0], c[1], c[2]}); }
};

/// Each channel clamped at zero (interpolated energies, never negative).
inline Rgb nonnegative(Rgb v) {
    for (int c = 0; c < 3; ++c)
        v[c] = std::max(v[c], 0.0);
    return v;
}

}  // namespace lamina1

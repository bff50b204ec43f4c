#pragma once
// RGB triples: three independent spectral channels (docs/physics.md §1).

#include <algorithm>
#include <array>
#include <cstddef>

namespace lamina {

template <typename T>
struct Rgb {
    std::array<T, 3> c{};

    constexpr Rgb() = default;
    constexpr explicit Rgb(T v) : c{v, v, v} {}
    constexpr Rgb(T r, T g, T b) : c{r, g, b} {}
    template <typename U>
    constexpr explicit Rgb(const Rgb<U>& o) : c{T(o[0]), T(o[1]), T(o[2])} {}

    constexpr T& operator[](std::size_t i) { return c[i]; }
    constexpr const T& operator[](std::size_t i) const { return c[i]; }

    constexpr Rgb operator+(const Rgb& o) const { return {c[0] + o[0], c[1] + o[1], c[2] + o[2]}; }
    constexpr Rgb operator-(const Rgb& o) const { return {c[0] - o[0], c[1] - o[1], c[2] - o[2]}; }
    constexpr Rgb operator*(const Rgb& o) const { return {c[0] * o[0], c[1] * o[1], c[2] * o[2]}; }
    constexpr Rgb operator/(const Rgb& o) const { return {c[0] / o[0], c[1] / o[1], c[2] / o[2]}; }
    constexpr Rgb operator*(T s) const { return {c[0] * s, c[1] * s, c[2] * s}; }
    constexpr Rgb operator/(T s) const { return {c[0] / s, c[1] / s, c[2] / s}; }
    constexpr Rgb& operator+=(const Rgb& o) { return *this = *this + o; }
    constexpr Rgb& operator*=(const Rgb& o) { return *this = *this * o; }
    constexpr Rgb& operator*=(T s) { return *this = *this * s; }
    constexpr bool operator==(const Rgb&) const = default;

    constexpr T mean() const { return (c[0] + c[1] + c[2]) / T(3); }
    constexpr T max() const { return std::max({c[0], c[1], c[2]}); }
    constexpr T min() const { return std::min({c[0], c[1], c[2]}); }
};

template <typename T>
constexpr Rgb<T> operator*(T s, const Rgb<T>& v) {
    return v * s;
}

using Rgbf = Rgb<float>;
using Rgbd = Rgb<double>;

}  // namespace lamina

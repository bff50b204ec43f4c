#pragma once
// Complex arithmetic for the hot paths of the wave optics (Fresnel amplitudes, thin films' Airy
// sums, Mueller matrices), written out where the standard library's versions do more than these
// finite values need: libstdc++'s std::norm is |z|² through hypot (overflow-safe, several times
// the cost of two products), a complex quotient rescales its operands (C99 Annex G), and the C
// library's csqrt and cexp sort out every special value (and csqrt takes |z| by hypot) before
// the few operations a finite, moderate argument needs.

#include <cmath>
#include <complex>
#include <limits>

namespace lamina {

/// |z|² = Re² + Im² (std::norm without its hypot: exact to an ulp for finite z of moderate size;
/// a non-finite z gives a non-finite result, as std::norm does).
template <typename T>
inline T squared_modulus(std::complex<T> z) {
    return z.real() * z.real() + z.imag() * z.imag();
}

/// 1/z as z̄/|z|², for denominators of moderate size (|z| within 1e±150): z = 0 gives a non-finite
/// result, as 1/0 does. A denominator shared by several quotients is inverted once.
template <typename T>
inline std::complex<T> reciprocal(std::complex<T> z) {
    const T inv = T(1) / squared_modulus(z);
    return {z.real() * inv, -z.imag() * inv};
}

/// The principal square root (Re ≥ 0; on the negative real axis the sign of Im z, zero included,
/// picks the side, as std::sqrt's). The stable form of Press, Teukolsky, Vetterling & Flannery,
/// "Numerical Recipes in C", 2nd ed., §5.4, eqs. 5.4.6–5.4.7: w = √((|z| + |Re z|)/2), then
/// (w, Im z/2w) for Re z ≥ 0 and (|Im z|/2w, ±w) otherwise, with no cancellation on either side.
/// |z|² is taken as Re² + Im²; where it would lose precision to underflow or overflow (in double,
/// |z| below about 1e-146 or above about 1e154), at zero and for non-finite z, std::sqrt's result.
template <typename T>
inline std::complex<T> principal_sqrt(std::complex<T> z) {
    const T x = z.real(), y = z.imag();
    const T r2 = squared_modulus(z);
    constexpr T kSmallest = std::numeric_limits<T>::min() / std::numeric_limits<T>::epsilon();
    if (!(r2 >= kSmallest && r2 <= std::numeric_limits<T>::max())) return std::sqrt(z);
    const T w = std::sqrt((std::sqrt(r2) + std::abs(x)) / T(2));
    if (x >= T(0)) return {w, y / (T(2) * w)};
    return {std::abs(y) / (T(2) * w), std::copysign(w, y)};
}

/// e^{iθ} for a complex θ: e^{−Im θ} (cos Re θ + i sin Re θ), the phasor of a wave that has
/// advanced by Re θ and decayed by Im θ (std::exp(i θ) without cexp's special-value checks;
/// finite θ).
template <typename T>
inline std::complex<T> exp_i(std::complex<T> theta) {
    const T decay = std::exp(-theta.imag());
    return {decay * std::cos(theta.real()), decay * std::sin(theta.real())};
}

}  // namespace lamina

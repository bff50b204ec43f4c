#pragma once
// Complex arithmetic for the hot paths of the wave optics (Fresnel amplitudes, thin films' Airy
// sums, Mueller matrices), written out where the standard library's versions do more than these
// finite values need: libstdc++'s std::norm is |z|² through hypot (overflow-safe, several times
// the cost of two products), and a complex quotient rescales its operands (C99 Annex G).

#include <complex>

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

}  // namespace lamina

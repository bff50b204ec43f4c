#pragma once
// Complex arithmetic for the hot paths of the wave optics (Fresnel amplitudes, thin films' Airy
// sums, Mueller matrices), written out where the standard library's versions do more than these
// finite values need: libstdc++'s std::norm is |z|² through hypot (overflow-safe, several times
// the cost of two products), a complex quotient rescales its operands (C99 Annex G), and the C
// library's csqrt and cexp sort out every special value (and csqrt takes |z| by hypot) before
// the few operations a finite, moderate argument needs. Each is the lane template of
// core/lane_complex.h at one lane.

#include "core/lane.h"
#include "core/lane_complex.h"

#include <cmath>
#include <complex>
#include <limits>

namespace lamina {

template <typename T>
inline LaneComplex<T> lane_complex(std::complex<T> z) {
    return {z.real(), z.imag()};
}
template <typename T>
inline std::complex<T> std_complex(LaneComplex<T> z) {
    return {z.re, z.im};
}

/// |z|² = Re² + Im² (std::norm without its hypot: exact to an ulp for finite z of moderate size;
/// a non-finite z gives a non-finite result, as std::norm does).
template <typename T>
inline T squared_modulus(std::complex<T> z) {
    return squared_modulus(lane_complex(z));
}

/// 1/z as z̄/|z|², for denominators of moderate size (|z| within 1e±150): z = 0 gives a non-finite
/// result, as 1/0 does. A denominator shared by several quotients is inverted once.
template <typename T>
inline std::complex<T> reciprocal(std::complex<T> z) {
    return std_complex(reciprocal<T, Lane<T>>(lane_complex(z)));
}

/// The principal square root (Re ≥ 0; on the negative real axis the sign of Im z, zero included,
/// picks the side, as std::sqrt's): core/lane_complex.h's stable form. |z|² is taken as Re² +
/// Im²; where it would lose precision to underflow or overflow (in double, |z| below about
/// 1e-146 or above about 1e154), at zero and for non-finite z, std::sqrt's result.
template <typename T>
inline std::complex<T> principal_sqrt(std::complex<T> z) {
    const T r2 = squared_modulus(z);
    constexpr T kSmallest = std::numeric_limits<T>::min() / std::numeric_limits<T>::epsilon();
    if (!(r2 >= kSmallest && r2 <= std::numeric_limits<T>::max())) return std::sqrt(z);
    return std_complex(principal_sqrt<T, Lane<T>>(lane_complex(z)));
}

/// e^{iθ} for a complex θ: e^{−Im θ} (cos Re θ + i sin Re θ), the phasor of a wave that has
/// advanced by Re θ and decayed by Im θ (std::exp(i θ) without cexp's special-value checks;
/// finite θ).
template <typename T>
inline std::complex<T> exp_i(std::complex<T> theta) {
    return std_complex(exp_i<T, Lane<T>>(lane_complex(theta)));
}

}  // namespace lamina

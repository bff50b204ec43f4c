// Complex numbers as lane values: a real and an imaginary part, each a lane value of core/lane.h
// (one double, or the lanes of a SIMD vector of doubles), with the arithmetic the wave optics
// need (the Fresnel amplitudes of physics/fresnel.h, a thin film's Airy sums of
// physics/thin_film_airy.h). The functions of core/complex_math.h on std::complex are these
// templates instantiated at one lane.
//
// The forms are those of core/complex_math.h: |z|² = Re² + Im², 1/z = z̄/|z|², the principal
// square root of Press, Teukolsky, Vetterling & Flannery ("Numerical Recipes in C", 2nd ed., §5.4,
// eqs. 5.4.6–5.4.7), e^{iθ} = e^{−Im θ}(cos Re θ + i sin Re θ), for finite values of moderate size:
// the callers on one lane sort out the rest (complex_math.h's principal_sqrt), the callers on
// vectors pass the lanes whose results are not finite to them.

#include "core/lane.h"

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_CORE_LANE_COMPLEX_H
#define LAMINA_CORE_LANE_COMPLEX_H
#define LAMINA_CORE_LANE_COMPLEX_BODY
#endif
#elif defined(LAMINA_CORE_LANE_COMPLEX_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_CORE_LANE_COMPLEX_TARGET
#undef LAMINA_CORE_LANE_COMPLEX_TARGET
#else
#define LAMINA_CORE_LANE_COMPLEX_TARGET
#endif
#define LAMINA_CORE_LANE_COMPLEX_BODY
#endif

#ifdef LAMINA_CORE_LANE_COMPLEX_BODY
#undef LAMINA_CORE_LANE_COMPLEX_BODY

LAMINA_LANE_BEGIN

template <typename T>
struct LaneComplex {
    T re, im;
};

template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> operator+(LaneComplex<T> a, LaneComplex<T> b) {
    return {a.re + b.re, a.im + b.im};
}
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> operator-(LaneComplex<T> a, LaneComplex<T> b) {
    return {a.re - b.re, a.im - b.im};
}
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> operator*(LaneComplex<T> a, LaneComplex<T> b) {
    return {a.re * b.re - a.im * b.im, a.re * b.im + a.im * b.re};
}
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> operator*(LaneComplex<T> a, T x) {
    return {a.re * x, a.im * x};
}
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> operator*(T x, LaneComplex<T> a) {
    return {x * a.re, x * a.im};
}

/// a + x for a real x.
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> add_real(LaneComplex<T> a, T x) {
    return {a.re + x, a.im};
}

/// |z|².
template <typename T>
LAMINA_LANE_INLINE T squared_modulus(LaneComplex<T> z) {
    return z.re * z.re + z.im * z.im;
}

/// a b̄.
template <typename T>
LAMINA_LANE_INLINE LaneComplex<T> times_conj(LaneComplex<T> a, LaneComplex<T> b) {
    return {a.re * b.re + a.im * b.im, a.im * b.re - a.re * b.im};
}

/// 1/z as z̄/|z|² (z = 0: not finite; the imaginary part of 1/x for a real x is +0).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneComplex<T> reciprocal(LaneComplex<T> z) {
    const T inv = L::constant(1) / squared_modulus(z);
    return {z.re * inv, (L::constant(0) - z.im) * inv};
}

/// The principal square root (Re ≥ 0; on the negative real axis the sign of Im z, zero included,
/// picks the side): w = √((|z| + |Re z|)/2), then (w, Im z/2w) for Re z ≥ 0 and (|Im z|/2w, ±w)
/// otherwise. z = 0 gives a root that is not finite (0/0), as does a non-finite z.
template <typename T, typename L>
LAMINA_LANE_INLINE LaneComplex<T> principal_sqrt(LaneComplex<T> z) {
    const T zero = L::constant(0), two = L::constant(2);
    const T w = L::sqrt((L::sqrt(squared_modulus(z)) + L::abs(z.re)) / two);
    const T y_over_2w = z.im / (two * w);
    const auto negative = L::less(z.re, zero);
    return {L::select(negative, L::abs(y_over_2w), w),
            L::select(negative, L::copysign(w, z.im), y_over_2w)};
}

/// e^{iθ} = e^{−Im θ}(cos Re θ + i sin Re θ): the phasor of a wave that has advanced by Re θ and
/// decayed by Im θ (finite θ).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneComplex<T> exp_i(LaneComplex<T> theta) {
    const T decay = L::exp(L::constant(0) - theta.im);
    T c, s;
    L::cos_sin(theta.re, c, s);
    return {decay * c, decay * s};
}

LAMINA_LANE_END

#endif  // LAMINA_CORE_LANE_COMPLEX_BODY

// Euler's Beta function B(a, b) = Γ(a) Γ(b) / Γ(a + b) for a, b ≥ 1, written once as a branch-free
// template over a lane type (core/lane.h), so that the scalar and the vectorized particle kernels
// evaluate the same formula (the Smith masking of rough refraction, physics/microfacet.h).
//
// Method. The recurrence Γ(x + 1) = x Γ(x) (Abramowitz & Stegun 1964, "Handbook of Mathematical
// Functions", Eq. 6.1.15) shifts the arguments to A = a + 4, B = b + 4 (≥ 5):
//     B(a, b) = B(A, B) · ∏_{k=0}^{3} (s + 2k)(s + 2k + 1) / ((a + k)(b + k)),   s = a + b,
// and Stirling's series (A & S Eq. 6.1.41), ln Γ(x) = (x − ½) ln x − x + ½ ln 2π + ω(x) with
// ω(x) = 1/(12x) − 1/(360x³) + 1/(1260x⁵) − 1/(1680x⁷) + 1/(1188x⁹) − 691/(360360x¹¹)
// (truncation below 6e-12 for x ≥ 5), gives the shifted Beta function without the cancellation of
// ln Γ(A) + ln Γ(B) − ln Γ(A + B):
//     ln B(A, B) = −A ln(1 + B/A) − B ln(1 + A/B) + ½ ln(S/(A B)) + ½ ln 2π + ω(A) + ω(B) − ω(S).
// Accuracy: 5e-11 relative in double. In float the exponent is a sum of terms up to ~50 in size
// that cancel, so the rounding error of scale·B is about 1e-5 of it at worst, absolute for the
// masking's scale·B ≤ 1 (tests/core/beta_function_test.cpp measures both against std::beta).
//
// Near one, in single precision. For a, b ≤ 3 (Λ ≤ 2 in the masking, every direction but the
// grazing ones of a rough interface) a float lane type (L::kSinglePrecision) takes the Gamma
// functions themselves, B(a, b) = Γ(a) Γ(b) / Γ(a + b): each shifted by the recurrence into
// [1, 2] and there A & S Eq. 6.1.36's polynomial, Γ(1 + x) = 1 + Σ_{k=1}^{8} b_k x^k,
// |error| ≤ 3e-7 for 0 ≤ x ≤ 1. No logarithm, no exponential, one division: this is the particle
// kernels' common case (the single-scattering rough dielectric's every refraction), and it is
// also more accurate in float than the series, about 1e-6 relative (the same test). A vector with
// any lane beyond 3 evaluates the series as well and takes it there.
//
// Arguments above L::kBetaArgumentMax (1e7 in float, 1e15 in double; infinity included) are taken
// at that bound, which keeps every intermediate product finite. For the Smith masking this is a
// direction within 1e-7 (float) of grazing, whose weight is then zero or one to that precision.

#include "core/lane.h"

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_CORE_BETA_FUNCTION_H
#define LAMINA_CORE_BETA_FUNCTION_H
#define LAMINA_CORE_BETA_FUNCTION_BODY
#endif
#elif defined(LAMINA_CORE_BETA_FUNCTION_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_CORE_BETA_FUNCTION_TARGET
#undef LAMINA_CORE_BETA_FUNCTION_TARGET
#else
#define LAMINA_CORE_BETA_FUNCTION_TARGET
#endif
#define LAMINA_CORE_BETA_FUNCTION_BODY
#endif

#ifdef LAMINA_CORE_BETA_FUNCTION_BODY
#undef LAMINA_CORE_BETA_FUNCTION_BODY

LAMINA_LANE_BEGIN

/// Γ(x) for x ∈ [1, 2 + kShifts]: kShifts branch-free steps of Γ(x) = (x − 1) Γ(x − 1) (A & S
/// Eq. 6.1.15) bring x into [1, 2], where A & S Eq. 6.1.36's polynomial gives Γ to 3e-7 absolute.
/// For single precision (core/beta_function.h, the series is used otherwise).
template <int kShifts, typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T gamma_function_near_one(T x) {
    const T one = L::constant(1), two = L::constant(2);
    T factor = one;
    for (int k = 0; k < kShifts; ++k) {
        const auto above = L::less(two, x);
        const T x_minus_one = x - one;
        factor = factor * L::select(above, x_minus_one, one);
        x = L::select(above, x_minus_one, x);
    }
    const T t = x - one;
    T p = L::mul_add(L::constant(0.035868343), t, L::constant(-0.193527818));
    p = L::mul_add(p, t, L::constant(0.482199394));
    p = L::mul_add(p, t, L::constant(-0.756704078));
    p = L::mul_add(p, t, L::constant(0.918206857));
    p = L::mul_add(p, t, L::constant(-0.897056937));
    p = L::mul_add(p, t, L::constant(0.988205891));
    p = L::mul_add(p, t, L::constant(-0.577191652));
    p = L::mul_add(p, t, one);
    return factor * p;
}

/// scale · B(a, b) by Stirling's series (the method above), for a, b ≥ 1.
template <typename T, typename L = Lane<T>>
inline T beta_function_scaled_series(T a, T b, T scale) {
    const T cap = L::constant(L::kBetaArgumentMax);
    a = L::min(a, cap);
    b = L::min(b, cap);
    const T one = L::constant(1), two = L::constant(2), three = L::constant(3);
    const T s = a + b;
    // The shift's eight factors in two groups of four (each product stays below 2e29 in float).
    const T low = (s * (s + one)) * ((s + two) * (s + three)) / ((a * (a + one)) * (b * (b + one)));
    const T s4 = s + L::constant(4);
    const T high = (s4 * (s4 + one)) * ((s4 + two) * (s4 + three)) /
                   (((a + two) * (a + three)) * ((b + two) * (b + three)));
    const T A = a + L::constant(4), B = b + L::constant(4), S = s + L::constant(8);
    // ω(x) by Horner's rule in 1/x².
    auto omega = [&](T x) {
        const T y = one / x, y2 = y * y;
        T p = L::constant(1.0 / 1188.0) - y2 * L::constant(691.0 / 360360.0);
        p = L::constant(1.0 / 1680.0) - y2 * p;
        p = L::constant(1.0 / 1260.0) - y2 * p;
        p = L::constant(1.0 / 360.0) - y2 * p;
        p = L::constant(1.0 / 12.0) - y2 * p;
        return y * p;
    };
    const T ratio = B / A;
    const T stirling = (omega(A) + omega(B) - omega(S) + L::constant(0.91893853320467274178)) -
                       (A * L::log1p(ratio) + B * L::log1p(one / ratio));
    return L::exp(stirling + L::log(scale * (low * high) * L::sqrt(S / (A * B))));
}

/// scale · B(a, b) for a, b ≥ 1 and scale ∈ (0, L::kBetaArgumentMax]: the factor is folded into
/// the logarithm (scale = a gives a B(a, b) ≤ 1 without overflow or underflow of B alone). Single
/// precision takes the Gamma functions for a, b ≤ 3 (the method above).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T beta_function_scaled(T a, T b, T scale) {
    if constexpr (!L::kSinglePrecision) {
        return beta_function_scaled_series<T, L>(a, b, scale);
    } else {
        const T three = L::constant(3);
        const auto beyond = L::either(L::less(three, a), L::less(three, b));
        const T a3 = L::min(a, three), b3 = L::min(b, three);
        const T near_one =
            scale * (gamma_function_near_one<1, T, L>(a3) * gamma_function_near_one<1, T, L>(b3)) /
            gamma_function_near_one<4, T, L>(a3 + b3);
        if (L::none(beyond)) return near_one;
        return L::select(beyond, beta_function_scaled_series<T, L>(a, b, scale), near_one);
    }
}

LAMINA_LANE_END

#endif  // LAMINA_CORE_BETA_FUNCTION_BODY

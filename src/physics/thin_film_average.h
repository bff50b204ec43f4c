#pragma once
// The reflectance of a thin film averaged over a uniform range of thickness, in closed form.
//
// A film whose thickness varies over the surface (uniformly over [d_min, d_max]) reflects, seen
// over many pixels, the mean of its Airy reflectance over the range. For a transparent film (real
// index) crossed by a propagating wave (η_f > sin θ1, so that the film's normal wave number u_f is
// real), the amplitude r12 of the incident | film boundary is real, the round-trip phase
// x = 4π d u_f η_1/λ grows linearly with d, and with c = r12 r23 (r23 the film | exit amplitude,
// complex over a conductor) the Airy reflectance of physics/thin_film.h is, for each polarization,
//
//     R(x) = |r12 + r23 e^{ix}|² / |1 + c e^{ix}|² = 1 − (1 − r12²)(1 − |r23|²) / D(x),
//     D(x) = 1 + |c|² + 2|c| cos(x + arg c)
//
// (the two squared moduli differ by the x-independent (1 − r12²)(1 − |r23|²): Born & Wolf,
// "Principles of Optics", 7th ed., §1.6.4, and Stokes' relations). Its mean over a uniform x is the
// mean of 1/(A + B cos y), A = 1 + |c|², B = 2|c| < A, whose antiderivative
//
//     F(y) = 2/√(A² − B²) · [atan(√((A − B)/(A + B)) tan(y/2)) + π ⌊(y + π)/(2π)⌋]
//
// (Gradshteyn & Ryzhik, "Table of Integrals, Series, and Products", 7th ed., 2.553.3, made
// continuous across the poles of tan(y/2) by the floor term) is exact. Over whole periods the
// mean is 1/(1 − |c|²) and R the incoherent sum (R12 + R23 − 2 R12 R23)/(1 − R12 R23): the film's
// period average is the incoherent slab, as docs/physics.md §9 states.
//
// An absorbing film (k_f > 0) or one beyond its critical angle (the wave evanescent inside, where
// the phase is not periodic in d) has no such form: thin_film_reflectance_mean returns nothing and
// the caller averages numerically.

#include "physics/fresnel.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <optional>

namespace lamina {

/// The mean over a uniform y ∈ [y0, y1] (y1 > y0) of 1/(A + B cos y) for A > |B|, given as
/// A − B and A + B (both > 0; formed by the caller without cancellation).
template <typename T>
T mean_inverse_cosine_sum(T a_minus_b, T a_plus_b, T y0, T y1) {
    const T pi = std::numbers::pi_v<T>;
    const T s = std::sqrt(a_minus_b * a_plus_b), k = std::sqrt(a_minus_b / a_plus_b);
    const auto F = [&](T y) {
        // y = 2πn + r with r ∈ [−π, π]: tan(r/2) keeps the sign the floor term expects.
        const T n = std::floor((y + pi) / (2 * pi));
        const T r = std::clamp(y - 2 * pi * n, -pi, pi);
        return (std::atan(k * std::tan(r / 2)) + pi * n) * (2 / s);
    };
    return (F(y1) - F(y0)) / (y1 - y0);
}

/// The mean reflectances (R_s, R_p) of the film of thin_film_amplitudes (light from the incident
/// medium at cos_theta_i ∈ [0, 1] on a film of index eta_film over an exit medium of index
/// eta_exit, both relative to the incident medium) over its thickness uniformly distributed in
/// [waves_min, waves_max] (thickness_waves as thin_film_amplitudes takes it), in closed form.
/// Nothing when the film absorbs, when its wave is evanescent or within 1e-6 (in u_f²) of its
/// critical angle, or when the range is narrower than 1e-3 radians of round-trip phase (where the
/// closed form's difference of antiderivatives loses its digits): average numerically there.
template <typename T>
std::optional<std::pair<T, T>> thin_film_reflectance_mean(T cos_theta_i, std::complex<T> eta_film,
                                                          std::complex<T> eta_exit, T waves_min,
                                                          T waves_max) {
    using C = std::complex<T>;
    const T mu = std::min(std::max(cos_theta_i, T(0)), T(1));
    const T sin2 = T(1) - mu * mu;
    const T u2_squared = eta_film.real() * eta_film.real() - sin2;
    if (eta_film.imag() != T(0) || !(u2_squared > T(1e-6))) return std::nullopt;
    const T u2 = std::sqrt(u2_squared);
    const T x0 = 4 * std::numbers::pi_v<T> * waves_min * u2,
            x1 = 4 * std::numbers::pi_v<T> * waves_max * u2;
    if (!(x1 - x0 > T(1e-3))) return std::nullopt;
    const FresnelAmplitudes<T> b12 = fresnel_amplitudes<T>(C(1), C(mu), eta_film, C(u2));
    const FresnelAmplitudes<T> b23 =
        fresnel_amplitudes<T>(eta_film, C(u2), eta_exit, normal_wave_number(eta_exit, sin2));
    const auto mean = [&](C r12, C r23) {
        const C c = r12 * r23;
        const T abs_c = std::abs(c);
        // |c| < 1: |r12| < 1 for a propagating wave in a distinct film, |r23| ≤ 1.
        if (!(abs_c < T(1))) return T(1);
        const T phase = std::arg(c);
        // A ∓ B = (1 ∓ |c|)², positive even where |c| is within rounding of 1.
        const T m =
            mean_inverse_cosine_sum((T(1) - abs_c) * (T(1) - abs_c),
                                    (T(1) + abs_c) * (T(1) + abs_c), x0 + phase, x1 + phase);
        // In [0, 1] exactly; clamped against rounding near resonance (|c| → 1, where m is large).
        return std::clamp(T(1) - (T(1) - squared_modulus(r12)) * (T(1) - squared_modulus(r23)) * m,
                          T(0), T(1));
    };
    return std::pair<T, T>{mean(b12.r_s, b23.r_s), mean(b12.r_p, b23.r_p)};
}

}  // namespace lamina

// The Airy sums of a thin film (physics/thin_film.h, docs/physics.md §9) as lane templates: the
// film's reflection and transmission amplitudes for one channel from the amplitudes of its two
// boundaries, and, for one channel, the film's reflection Mueller matrix from its indices away
// from the special cases thin_film.h sorts out. The scalar functions of thin_film.h instantiate
// them at one lane; the SIMD particle kernel on the lanes of a vector of doubles
// (simulator/lane_film.h FilmReflection).

#include "core/lane.h"
#include "core/lane_complex.h"
#include "physics/fresnel.h"
#include "physics/polarization.h"

#include <numbers>

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_THIN_FILM_AIRY_H
#define LAMINA_PHYSICS_THIN_FILM_AIRY_H
#define LAMINA_PHYSICS_THIN_FILM_AIRY_BODY
#endif
#elif defined(LAMINA_PHYSICS_THIN_FILM_AIRY_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_THIN_FILM_AIRY_TARGET
#undef LAMINA_PHYSICS_THIN_FILM_AIRY_TARGET
#else
#define LAMINA_PHYSICS_THIN_FILM_AIRY_TARGET
#endif
#define LAMINA_PHYSICS_THIN_FILM_AIRY_BODY
#endif

#ifdef LAMINA_PHYSICS_THIN_FILM_AIRY_BODY
#undef LAMINA_PHYSICS_THIN_FILM_AIRY_BODY

LAMINA_LANE_BEGIN

/// The Airy sums (Born & Wolf, "Principles of Optics", 7th ed., §1.6.4; physics/thin_film.h's
/// header) of a film whose boundaries incident | film and film | exit have the amplitudes b12 and
/// b23, its normal wave number u2 (Im u2 ≥ 0) and its thickness in waves (thickness_waves: the
/// phase of one crossing is δ = 2π thickness_waves u2), for s and p:
///     r = (r12 + r23 e^{2iδ}) / (1 + r12 r23 e^{2iδ}),
///     t = t12 t23 e^{iδ} / (1 + r12 r23 e^{2iδ}).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneFresnelAmplitudes<T> airy_sums(const LaneFresnelAmplitudes<T>& b12,
                                                      const LaneFresnelAmplitudes<T>& b23,
                                                      LaneComplex<T> u2, T thickness_waves) {
    const T one = L::constant(1);
    // e^{iδ}: |e^{iδ}| = e^{−Im δ} ≤ 1 since Im u2 ≥ 0.
    const LaneComplex<T> phase =
        exp_i<T, L>((L::constant(2 * std::numbers::pi) * thickness_waves) * u2);
    const LaneComplex<T> phase2 = phase * phase;
    const LaneComplex<T> inv_den_s = reciprocal<T, L>(add_real(b12.r_s * b23.r_s * phase2, one));
    const LaneComplex<T> inv_den_p = reciprocal<T, L>(add_real(b12.r_p * b23.r_p * phase2, one));
    return {(b12.r_s + b23.r_s * phase2) * inv_den_s, (b12.r_p + b23.r_p * phase2) * inv_den_p,
            b12.t_s * b23.t_s * phase * inv_den_s, b12.t_p * b23.t_p * phase * inv_den_p};
}

/// The sums are even functions of u2, analytic in u2² = η_f² − sin²θ1, but at the film's critical
/// angle (u2 → 0: r12 → 1, r23 → −1, e^{2iδ} → 1) they are 0/0, and evaluated at |u2| they lose
/// ε/|u2| of their precision. Within h = kFilmNearCritical of it in u2² thin_film.h takes them as
/// the mean of their values at u2² ± h (the error of the mean is O(h²), of each value O(ε/√h)).
inline constexpr double kFilmNearCritical = 1e-6;

/// Where u2² = η_f² − sin²θ1 lies within `band` (kFilmNearCritical: thin_film.h's) of 0. The
/// SIMD kernel takes a wider band and leaves those lanes to thin_film.h, which decides: its sin²θ1
/// may round otherwise, and at the band's edge the two ways differ by more than a rounding.
template <typename T, typename L>
LAMINA_LANE_INLINE typename L::Mask near_film_critical(LaneComplex<T> eta_film, T sin2,
                                                       double band = kFilmNearCritical) {
    return L::less(squared_modulus(normal_wave_number_square<T, L>(eta_film, sin2)),
                   L::constant(band * band));
}

/// The upper boundary of a film seen from its incident medium (index 1) at the incidence cosine
/// mu ∈ [0, 1] (sin²θ = sin2): the film's normal wave number u2 and the boundary's amplitudes.
template <typename T>
struct LaneFilmTop {
    LaneComplex<T> u2;
    LaneFresnelAmplitudes<T> upper;
};

template <typename T, typename L>
LAMINA_LANE_INLINE LaneFilmTop<T> film_top(T mu, T sin2, LaneComplex<T> eta_film) {
    const T zero = L::constant(0);
    const LaneComplex<T> u2 = normal_wave_number<T, L>(eta_film, sin2);
    return {u2, fresnel_amplitudes<T, L>({L::constant(1), zero}, {mu, zero}, eta_film, u2)};
}

/// The film's reflection Mueller matrix for light arriving from the incident medium, over an exit
/// medium of relative index eta_exit (its normal wave number u3 = normal_wave_number(eta_exit,
/// sin2)), from the film's top: the Airy sums' r_s, r_p with flux 1. Away from the film's critical
/// angle (thin_film.h averages two sums there) and where the results are finite (thin_film.h's
/// grazing limit otherwise): the callers on vectors check both.
template <typename T, typename L>
LAMINA_LANE_INLINE InterfaceMueller<T> film_reflection_mueller(const LaneFilmTop<T>& top,
                                                               LaneComplex<T> eta_film, T sin2,
                                                               LaneComplex<T> eta_exit,
                                                               T thickness_waves) {
    const LaneComplex<T> u3 = normal_wave_number<T, L>(eta_exit, sin2);
    const LaneFresnelAmplitudes<T> lower = fresnel_amplitudes<T, L>(eta_film, top.u2, eta_exit, u3);
    const LaneFresnelAmplitudes<T> film =
        airy_sums<T, L>(top.upper, lower, top.u2, thickness_waves);
    return mueller_of_amplitudes<T, L>(film.r_s, film.r_p, L::constant(1));
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_THIN_FILM_AIRY_BODY

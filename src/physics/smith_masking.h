// The Smith masking-shadowing of one facet event as escape fractions G2/G1, from the Smith roots
// r = √(1 + α² tan²θ) = 1 + 2Λ of the two directions (GGX::smith_root, Heitz 2014, Eq. 72): the
// weight a particle keeps after a facet of a single-scattering rough interface (dielectric.h,
// conductor.h) sent it from wi to wo. Lane templates (core/lane.h): the scalar and the SIMD
// particle kernels evaluate these very lines.

#include "core/beta_function.h"
#include "core/lane.h"

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_SMITH_MASKING_H
#define LAMINA_PHYSICS_SMITH_MASKING_H
#define LAMINA_PHYSICS_SMITH_MASKING_BODY
#endif
#elif defined(LAMINA_PHYSICS_SMITH_MASKING_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_SMITH_MASKING_TARGET
#undef LAMINA_PHYSICS_SMITH_MASKING_TARGET
#else
#define LAMINA_PHYSICS_SMITH_MASKING_TARGET
#endif
#define LAMINA_PHYSICS_SMITH_MASKING_BODY
#endif

#ifdef LAMINA_PHYSICS_SMITH_MASKING_BODY
#undef LAMINA_PHYSICS_SMITH_MASKING_BODY

LAMINA_LANE_BEGIN

/// The escape fraction G2/G1 of a particle that one facet *reflects* from wi to wo, from the
/// Smith roots scaled by the directions' cosines, s = |cos θ| r (GGX's ggx_smith_root_times_cos,
/// no division per root): G2/G1 = (1 + Λi)/(1 + Λi + Λo) = (1 + r_i)/(r_i + r_o) (Heitz 2014, Eqs.
/// 43 and 99), multiplied through by |cos θi| |cos θo|: (|z_i| + s_i)|z_o| / (s_i|z_o| + s_o|z_i|).
/// z_i, z_o: the cosines' magnitudes. Zero for a grazing wo (z_o = 0). The ratio is ≤ 1 (Λ ≥ 0);
/// float rounding can give 1 + 1 ulp, which booked a flux of −1e-8 as lost to the microsurface
/// (found by the fuzz test): clamped at 1. Also the refraction escape under
/// TransmissionMasking::Pbrt. Any lane type (core/lane.h).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T smith_reflection_escape_scaled(T z_i, T s_i, T z_o, T s_o) {
    return L::min((z_i + s_i) * z_o / L::mul_add(s_i, z_o, s_o * z_i), L::constant(1));
}

/// The same from the Smith roots r = √(1 + α² tan²θ) = 1 + 2Λ (GGX::smith_root) themselves:
/// (1 + r_i)/(r_i + r_o).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T smith_reflection_escape(T r_i, T r_o) {
    return smith_reflection_escape_scaled<T, L>(L::constant(1), r_i, L::constant(1), r_o);
}

/// The escape fraction G2/G1 of a particle that one facet *refracts* from wi (one side) to wo
/// (the other), on the Smith microsurface with its height-correlated masking (Heitz 2014, §6: the
/// height-correlated masking-shadowing, whose Eq. 99 is the reflection case, taken here for a pair
/// on opposite sides of the surface, with the height-dependent masking G1(w, h) = C1(h)^Λ(w) of the
/// Smith model): the particle meets the microsurface at a height h whose C1(h) = c has density
/// (1 + Λi) c^Λi (a ray from wi passes height h unmasked with probability c^Λi), and the
/// refracted ray leaves below, where the heights above it have C1 = 1 − c, with probability
/// (1 − c)^Λo. Hence G2 = ∫₀¹ (1 + Λi) c^Λi (1 − c)^Λo dc / (1 + Λi) = B(1 + Λi, 1 + Λo) (Euler's
/// Beta function; Heitz et al. 2016, "Multiple-scattering microfacet BSDFs with the Smith model",
/// use this form for the single scattering of their dielectric) and
///     G2/G1 = (1 + Λi) B(1 + Λi, 1 + Λo),  1 + Λ = (1 + r)/2.
/// From the Smith roots r = 1 + 2Λ (GGX::smith_root), any lane type with its operations L
/// (core/lane.h). Accuracy: core/beta_function.h. Zero for a grazing wo (r_o = ∞) to the
/// precision of T; one for r_o = 1 (wo along the normal: nothing masks it).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T smith_refraction_escape(T r_i, T r_o) {
    const T half = L::constant(0.5), one = L::constant(1);
    const T one_plus_lambda_i = L::min(half * (one + r_i), L::constant(L::kBetaArgumentMax));
    const T one_plus_lambda_o = half * (one + r_o);
    // ≤ 1 exactly (a fraction); the Beta function's rounding can exceed it by an ulp near
    // Λ = 0 (an index-matched rough interface), which booked a flux of −1.8e-7 as lost to the
    // microsurface (found by the fuzz test, seed 4242): clamped.
    return L::min(
        beta_function_scaled<T, L>(one_plus_lambda_i, one_plus_lambda_o, one_plus_lambda_i), one);
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_SMITH_MASKING_BODY

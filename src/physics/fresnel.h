// Fresnel reflectance, Snell refraction and mirror reflection.
//
// Relative index convention: `eta` is η_t / η_i, the index of the medium the light refracts *into*
// over the index of the medium it arrives from, for light arriving on the side the normal points
// to. At an interface of a stack (normal +z pointing up) eta = η_below / η_above.

#include "core/complex_math.h"
#include "core/lane.h"
#include "core/lane_complex.h"
#include "core/math.h"
#include "core/vec.h"

#include <cmath>
#include <complex>
#include <optional>
#include <utility>

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_FRESNEL_H
#define LAMINA_PHYSICS_FRESNEL_H
#define LAMINA_PHYSICS_FRESNEL_BODY
#endif
#elif defined(LAMINA_PHYSICS_FRESNEL_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_FRESNEL_TARGET
#undef LAMINA_PHYSICS_FRESNEL_TARGET
#else
#define LAMINA_PHYSICS_FRESNEL_TARGET
#endif
#define LAMINA_PHYSICS_FRESNEL_BODY
#endif

#ifdef LAMINA_PHYSICS_FRESNEL_BODY
#undef LAMINA_PHYSICS_FRESNEL_BODY

LAMINA_LANE_BEGIN

/// Fresnel reflectance of a dielectric interface together with the refracted cosine, for code that
/// refracts after choosing (sharing the square root). `eta` is the relative index actually crossed
/// (1/eta when the light arrives from the other side); cos_theta_t = 0 under total reflection.
template <typename T>
struct FresnelDielectric {
    T reflectance;
    T cos_theta_t;
    T eta;      ///< the relative index crossed
    T inv_eta;  ///< its reciprocal
};

template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE FresnelDielectric<T> fresnel_dielectric_full(T cos_theta_i, T eta, T inv_eta);

/// Exact unpolarized Fresnel reflectance of a dielectric interface (the mean of the s and p
/// reflectances; Born & Wolf, Principles of Optics, §1.5.2, Eqs. 21a–b), with the refracted cosine.
/// cos_theta_i: cosine between the arriving direction and the normal, in [−1, 1]; a negative value
/// means the light arrives from the other side, where the relative index is 1/eta.
/// eta > 0. The reflectance is 1 under total internal reflection (sin θt ≥ 1).
template <typename T>
LAMINA_LANE_INLINE FresnelDielectric<T> fresnel_dielectric_full(T cos_theta_i, T eta) {
    return fresnel_dielectric_full(cos_theta_i, eta, T(1) / eta);
}

/// The same with 1/eta supplied (interfaces keep it, saving a division per event). A branch-free
/// lane template (core/lane.h): the scalar and the SIMD particle kernels evaluate these lines.
template <typename T, typename L>
LAMINA_LANE_INLINE FresnelDielectric<T> fresnel_dielectric_full(T cos_theta_i, T eta, T inv_eta) {
    const T zero = L::constant(0), one = L::constant(1);
    cos_theta_i = L::min(L::max(cos_theta_i, zero - one), one);
    // From the other side the relative index crossed is 1/η.
    const auto below = L::less(cos_theta_i, zero);
    const T eta_crossed = L::select(below, inv_eta, eta);
    const T inv_eta_crossed = L::select(below, eta, inv_eta);
    cos_theta_i = L::select(below, zero - cos_theta_i, cos_theta_i);
    const T sin2_theta_t = (one - cos_theta_i * cos_theta_i) * (inv_eta_crossed * inv_eta_crossed);
    const auto refracts = L::less(sin2_theta_t, one);  // otherwise total internal reflection
    const T cos_theta_t = L::sqrt(L::max(one - sin2_theta_t, zero));
    // r_parallel = a/b, r_perpendicular = c/d; (a²d² + c²b²) / (b²d²) needs a single division.
    const T a = eta_crossed * cos_theta_i - cos_theta_t,
            b = eta_crossed * cos_theta_i + cos_theta_t;
    const T c = cos_theta_i - eta_crossed * cos_theta_t,
            d = cos_theta_i + eta_crossed * cos_theta_t;
    const T bd = b * d, ad = a * d, cb = c * b;
    const T b2d2 = bd * bd;
    const T reflectance = L::select(L::less(zero, b2d2), (ad * ad + cb * cb) / (b2d2 + b2d2), one);
    return {L::select(refracts, reflectance, one), cos_theta_t, eta_crossed, inv_eta_crossed};
}

/// Exact unpolarized Fresnel reflectance of a dielectric interface; see fresnel_dielectric_full.
/// Returns 1 under total internal reflection.
template <typename T>
LAMINA_LANE_INLINE T fresnel_dielectric(T cos_theta_i, T eta) {
    return fresnel_dielectric_full(cos_theta_i, eta).reflectance;
}

/// The unpolarized reflectance of a dielectric interface of relative index eta at normal
/// incidence, F0 = ((η − 1)/(η + 1))² (Born & Wolf, "Principles of Optics", §1.5.2): where
/// r_s = −r_p, both polarizations alike. fresnel_dielectric at cos θ = 1 is the same number up to
/// rounding; this is the form the production models' F0 parametrizations are written in.
template <typename T>
constexpr T fresnel_dielectric_normal(T eta) {
    const T r = (eta - T(1)) / (eta + T(1));
    return r * r;
}

/// Exact unpolarized Fresnel reflectance of a conductor with relative complex index
/// eta + i·k (k ≥ 0), light arriving from the dielectric side with cos_theta_i in [0, 1].
/// The Fresnel equations with a complex index (Born & Wolf §14.2) written in real arithmetic:
/// with a² + b² = √((η² − k² − sin²θ)² + 4η²k²) and a = √((a² + b² + η² − k² − sin²θ)/2),
///   R_s = (a² + b² + cos²θ − 2a cos θ) / (a² + b² + cos²θ + 2a cos θ),
///   R_p = R_s (cos²θ (a² + b²) + sin⁴θ − 2a cos θ sin²θ) / (cos²θ (a² + b²) + sin⁴θ + 2a cos θ
///   sin²θ)
/// (e.g. Lagarde 2013, "Memo on Fresnel equations"; pbrt-v3 FrConductor). With k = 0 it equals
/// fresnel_dielectric, including total internal reflection (a = 0 gives R = 1) when eta < 1.
/// A branch-free lane template (core/lane.h): the scalar and the SIMD particle kernels evaluate
/// these lines.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T fresnel_conductor(T cos_theta_i, T eta, T k) {
    const T zero = L::constant(0), one = L::constant(1), two = L::constant(2);
    cos_theta_i = L::min(L::max(cos_theta_i, zero), one);
    const T cos2 = cos_theta_i * cos_theta_i;
    const T sin2 = one - cos2;
    const T eta2 = eta * eta, k2 = k * k;
    const T t0 = eta2 - k2 - sin2;
    const T a2_plus_b2 = L::sqrt(t0 * t0 + L::constant(4) * eta2 * k2);
    // a² = (a² + b² + t0)/2 cancels where t0 < 0 (a metal: η² − k² ≈ −16 for gold, so a² is a
    // small difference of numbers near 16, 14 float ulps off); there it is evaluated as the equal
    // 2η²k² / (a² + b² − t0), since (a² + b²)² − t0² = 4η²k².
    const T a2 = L::select(L::less(t0, zero), two * eta2 * k2 / (a2_plus_b2 - t0),
                           L::constant(0.5) * (a2_plus_b2 + t0));
    const T a = L::sqrt(L::max(a2, zero));
    const T t1 = a2_plus_b2 + cos2;
    const T t2 = two * cos_theta_i * a;
    // The numerators are sums of squares, t1 − t2 = (a − cos θ)² + b² and t3 − t4 =
    // (a cos θ − sin²θ)² + b² cos²θ, so never negative; near an index-matched interface (η ≈ 1,
    // k ≈ 0) rounding leaves them at −1e-17 or so: clamped at 0, or R would be negative.
    const T r_s = L::max(t1 - t2, zero) / (t1 + t2);
    const T t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    const T t4 = t2 * sin2;
    const T r_p = L::select(L::less(zero, t3 + t4), r_s * L::max(t3 - t4, zero) / (t3 + t4), r_s);
    return (r_s + r_p) / two;
}

/// The complex amplitude coefficients of one planar boundary for the s and p components of the
/// electric field (Born & Wolf §1.5.2, Eqs. 20–21, with the complex index of §14.2; time
/// dependence e^{−iωt}, an absorbing index n + ik with k > 0), in the frame convention of
/// docs/physics.md §8 (r_p = −r_s at normal incidence).
template <typename T>
struct FresnelAmplitudes {
    std::complex<T> r_s, r_p, t_s, t_p;
};

/// The same amplitudes as lane values (the lane template below).
template <typename T>
struct LaneFresnelAmplitudes {
    LaneComplex<T> r_s, r_p, t_s, t_p;
};

/// The amplitudes of the boundary from medium j into medium k, each given by its complex index
/// relative to one reference medium (eta_j, eta_k) and its normal wave number in units of the
/// reference's, u = η cos θ = √(η² − sin²θ_ref) (Snell's invariant η sin θ is the same in every
/// medium of a stack of parallel boundaries; Im u ≥ 0 for a wave that decays away from the
/// boundary, so the principal root). With ε = η²:
///     r_s = (u_j − u_k)/(u_j + u_k),       t_s = 2 u_j/(u_j + u_k),
///     r_p = (ε_k u_j − ε_j u_k)/(ε_k u_j + ε_j u_k),  t_p = 2 η_j η_k u_j/(ε_k u_j + ε_j u_k),
/// Born & Wolf's r_⊥, t_⊥, r_∥, t_∥ with n cos θ = u, cos θ = u/η. They obey Stokes' relations
/// r_kj = −r_jk and t_jk t_kj = 1 − r_jk² (both polarizations), which the Airy sums of a film rest
/// on (physics/thin_film.h). A boundary seen from the reference medium itself has η_j = 1,
/// u_j = cos θ. The denominators vanish only at an index-matched grazing boundary (u_j = u_k = 0).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneFresnelAmplitudes<T> fresnel_amplitudes(LaneComplex<T> eta_j,
                                                               LaneComplex<T> u_j,
                                                               LaneComplex<T> eta_k,
                                                               LaneComplex<T> u_k) {
    const LaneComplex<T> eps_j = eta_j * eta_j, eps_k = eta_k * eta_k;
    // Each denominator inverted once, for its r and t.
    const LaneComplex<T> inv_ds = reciprocal<T, L>(u_j + u_k),
                         inv_dp = reciprocal<T, L>(eps_k * u_j + eps_j * u_k);
    const T two = L::constant(2);
    return {(u_j - u_k) * inv_ds, (eps_k * u_j - eps_j * u_k) * inv_dp, (two * u_j) * inv_ds,
            (((two * eta_j) * eta_k) * u_j) * inv_dp};
}

/// The lane template above at one lane, on std::complex.
template <typename T>
FresnelAmplitudes<T> fresnel_amplitudes(std::complex<T> eta_j, std::complex<T> u_j,
                                        std::complex<T> eta_k, std::complex<T> u_k) {
    const LaneFresnelAmplitudes<T> a = fresnel_amplitudes<T, Lane<T>>(
        lane_complex(eta_j), lane_complex(u_j), lane_complex(eta_k), lane_complex(u_k));
    return {std_complex(a.r_s), std_complex(a.r_p), std_complex(a.t_s), std_complex(a.t_p)};
}

/// The square of the normal wave number below, η² − sin²θ, with an imaginary part of −0 made +0:
/// a −0 would put the root of a negative number on the decaying side's mirror image (the
/// principal root follows the sign of zero; x + 0 is +0 for x = ±0 and x otherwise).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneComplex<T> normal_wave_number_square(LaneComplex<T> eta, T sin2_theta) {
    const LaneComplex<T> e = eta * eta;
    return {e.re - sin2_theta, e.im + L::constant(0)};
}

/// The normal wave number u = √(η² − sin²θ) of a medium of complex index eta (relative to the
/// reference medium) for a wave whose Snell invariant is sin²θ = sin2_theta: the root with
/// Im u ≥ 0 (decaying into an absorbing medium, or evanescent under total internal reflection),
/// Re u ≥ 0. On lanes: not finite where η² − sin²θ = 0 (core/lane_complex.h's principal_sqrt).
template <typename T, typename L>
LAMINA_LANE_INLINE LaneComplex<T> normal_wave_number(LaneComplex<T> eta, T sin2_theta) {
    return principal_sqrt<T, L>(normal_wave_number_square<T, L>(eta, sin2_theta));
}

/// The normal wave number on one lane, on std::complex (complex_math.h's principal_sqrt, which
/// takes any value).
template <typename T>
std::complex<T> normal_wave_number(std::complex<T> eta, T sin2_theta) {
    return principal_sqrt(
        std_complex(normal_wave_number_square<T, Lane<T>>(lane_complex(eta), sin2_theta)));
}

/// The same reflectance as fresnel_conductor evaluated with std::complex, as written in Born &
/// Wolf (fresnel_amplitudes from the dielectric side, η_j = 1, u_j = cos θ): an independent form
/// for tests (slower: complex division and square root).
template <typename T>
LAMINA_LANE_INLINE T fresnel_conductor_complex(T cos_theta_i, T eta, T k) {
    using C = std::complex<T>;
    cos_theta_i = clamp(cos_theta_i, T(0), T(1));
    const C eta_c(eta, k);
    const FresnelAmplitudes<T> a = fresnel_amplitudes<T>(
        C(1), C(cos_theta_i), eta_c, normal_wave_number(eta_c, T(1) - sqr(cos_theta_i)));
    return (squared_modulus(a.r_p) + squared_modulus(a.r_s)) / T(2);
}

/// Mirror reflection of w (pointing away from the surface) about the unit normal n.
template <typename T>
LAMINA_LANE_INLINE Vec3<T> reflect(const Vec3<T>& w, const Vec3<T>& n) {
    return n * (T(2) * dot(w, n)) - w;
}

/// Snell refraction of w (pointing away from the surface, on either side) through an interface
/// with unit normal n and relative index eta = η(side n points away from) / η(side n points to).
/// Returns the refracted direction, pointing away from the surface on the other side, or nothing
/// under total internal reflection.
template <typename T>
LAMINA_LANE_INLINE std::optional<Vec3<T>> refract(const Vec3<T>& w, Vec3<T> n, T eta) {
    T cos_theta_i = dot(n, w);
    if (cos_theta_i < 0) {  // arriving from the side n points away from
        eta = T(1) / eta;
        cos_theta_i = -cos_theta_i;
        n = -n;
    }
    const T sin2_theta_t = (T(1) - sqr(cos_theta_i)) / sqr(eta);
    if (sin2_theta_t >= T(1)) return std::nullopt;
    const T cos_theta_t = safe_sqrt(T(1) - sin2_theta_t);
    return -w / eta + n * (cos_theta_i / eta - cos_theta_t);
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_FRESNEL_BODY

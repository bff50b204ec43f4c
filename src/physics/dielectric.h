// A dielectric interface between two non-absorbing media: smooth (α = 0, delta reflection and
// refraction) or rough (GGX, single-scattering microfacet BSDF of Walter et al. 2007, "Microfacet
// models for refraction through rough surfaces", EGSR). Conventions: physics/bsdf.h.
//
// eta = η_below / η_above > 0; eta = 1 is allowed: an index-matched interface is a delta pass-
// through, smooth or rough (for α > 0 the limit η → 1 of the rough BTDF, a refraction lobe of zero
// width; see dielectric_event). α ∈ [0, 1].

#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/math.h"
#include "physics/bsdf.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/polarization.h"

#include <algorithm>
#include <cmath>
#include <optional>

#ifndef LAMINA_PHYSICS_DIELECTRIC_SHAPE_H
#define LAMINA_PHYSICS_DIELECTRIC_SHAPE_H
namespace lamina {
/// What is the same on every lane of a dielectric event (dielectric_event): the interface's kind
/// and options (DielectricInterface). Defined once, outside the lane templates' namespaces.
struct DielectricEventShape {
    bool smooth;            ///< α = 0
    bool index_matched;     ///< η = 1
    bool uncorrelated;      ///< G1·G1 instead of the height-correlated G2
    bool smith_refraction;  ///< TransmissionMasking::Smith
};
}  // namespace lamina
#endif

// A lane header (core/lane.h): the particle event is a lane template, included once as an
// ordinary header and once per SIMD target; the interface type below it only once.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_DIELECTRIC_LANES_H
#define LAMINA_PHYSICS_DIELECTRIC_LANES_H
#define LAMINA_PHYSICS_DIELECTRIC_BODY
#endif
#elif defined(LAMINA_PHYSICS_DIELECTRIC_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_DIELECTRIC_TARGET
#undef LAMINA_PHYSICS_DIELECTRIC_TARGET
#else
#define LAMINA_PHYSICS_DIELECTRIC_TARGET
#endif
#define LAMINA_PHYSICS_DIELECTRIC_BODY
#endif

#ifdef LAMINA_PHYSICS_DIELECTRIC_BODY
#undef LAMINA_PHYSICS_DIELECTRIC_BODY

LAMINA_LANE_BEGIN

/// A particle event at an interface, per lane: the new direction wo (pointing away from the
/// surface), the fraction `shadowing` of the flux that escapes the microsurface (G2/G1; 1 on a
/// smooth interface), whether the lane reflected, and the lanes whose sample failed (`degenerate`:
/// a grazing arrival; nothing else holds for them).
template <typename T, typename M>
struct InterfaceEventLanes {
    LaneVec3<T> wo;
    T shadowing;
    M reflected;
    M degenerate;
};

/// The dielectric interface's particle event (DielectricInterface::sample) on the lanes of
/// `active`, each arriving from wi (away from the surface, either side): a visible microfacet
/// normal drawn from u1, u2 (Heitz 2018, by the spherical caps of Dupuy & Benyoub 2023; the macro
/// normal when smooth), the Fresnel reflectance at it (fresnel_dielectric_full), reflection if
/// uc < F and Snell refraction otherwise, both candidates formed and one selected (the Fresnel
/// choice is a coin flip no branch predictor learns), and the escape fraction G2/G1 of the pair
/// (ggx_escape_fraction; zero unless a reflection stays on wi's side and a refraction crosses,
/// the single-scattering microsurface losing the rest). The Fresnel branch probability cancels F
/// in the weight (Heitz 2018, §2; Walter et al. 2007, Eq. 41 with visible-normal sampling).
/// Index-matched (η = 1) and rough: F = 0 on every microfacet and Snell's law sends every refracted
/// ray straight on, so the BTDF of Walter et al. collapses onto a delta lobe at −wi, which eval and
/// pdf (densities) cannot represent; its weight is the η → 1 limit of the lobe's energy,
/// E[(1 − F) G2/G1] → G2(wi, −wi)/G1(wi) (every refracted direction tends to −wi; G2 of the
/// refraction lobe), so the interface is continuous in η; the single-scattering microsurface still
/// loses 1 − that. (The quotient is ≤ 1 exactly; rounded above it, it booked −6.6e-8 as lost to the
/// microsurface, found by the fuzz test with seed 99: the escape fractions are clamped at 1.)
/// Smooth and index-matched: straight through with weight 1. A grazing wi (wi.z = 0) is degenerate.
/// eta = η_below / η_above, inv_eta = 1/eta, ggx the GGX roughness (microfacet.h, anisotropic or
/// not).
/// Polarized (kPolarized, `pol` the state; physics/polarization.h): the particle's state is turned
/// into the facet's plane of incidence, the branch is chosen with the reflected flux fraction of
/// that state (polarized_dielectric_choice: the same uniform number uc, now against a + b q instead
/// of F), and the state leaves in the chosen branch's Mueller matrix, its frame the facet's s axis;
/// pol->factor returns the flux factors (1 unless the channels' states differ). An index-matched
/// interface leaves the state as it is (its Mueller matrix is the identity).
/// A branch-free lane template (core/lane.h): the scalar and the SIMD particle kernels evaluate
/// these lines.
template <typename T, typename L = Lane<T>, bool kPolarized = false, bool kA = false>
LAMINA_LANE_INLINE InterfaceEventLanes<T, typename L::Mask> dielectric_event(
    T eta, T inv_eta, const GgxLanes<T, kA>& ggx, DielectricEventShape shape, const LaneVec3<T>& wi,
    T uc, T u1, T u2, typename L::Mask active, PolarizationLanes<T>* pol = nullptr) {
    const T zero = L::constant(0), one = L::constant(1);
    InterfaceEventLanes<T, typename L::Mask> e;
    e.degenerate = L::both(active, L::negate(L::less(zero, L::abs(wi.z))));
    const auto ok = L::both(active, L::negate(e.degenerate));
    e.shadowing = one;
    if constexpr (kPolarized) pol->factor[0] = pol->factor[1] = pol->factor[2] = one;
    if (shape.index_matched) {
        e.wo = {zero - wi.x, zero - wi.y, zero - wi.z};
        e.reflected = L::both(ok, L::negate(ok));  // no lane
        if (!shape.smooth)
            e.shadowing = ggx_escape_fraction<T, L>(ggx, wi, e.wo, e.reflected, ok,
                                                    shape.uncorrelated, shape.smith_refraction);
        return e;
    }
    // The microfacet normal: drawn for a rough interface, the macro normal for a smooth one (then
    // the two candidates are the mirror direction and Snell's law, shadowing 1). From below, wi
    // sees the microsurface through −wi (microfacet.h).
    LaneVec3<T> wm = {zero, zero, one};
    if (!shape.smooth) {
        const T sign = L::select(L::less(wi.z, zero), zero - one, one);
        wm = ggx_sample_visible_normal_complete<T, L>(ggx, {sign * wi.x, sign * wi.y, sign * wi.z},
                                                      u1, u2);
    }
    const T cos_i_m = lane_dot<T, L>(wi, wm);  // < 0 when wi is below: seen from the other side
    [[maybe_unused]] DielectricMueller<T> fm;
    const FresnelDielectric<T> fr = [&] {
        if constexpr (kPolarized) {
            fm = fresnel_dielectric_mueller<T, L>(cos_i_m, eta, inv_eta);
            return FresnelDielectric<T>{zero, fm.cos_theta_t, fm.eta, fm.inv_eta};
        } else {
            return fresnel_dielectric_full<T, L>(cos_i_m, eta, inv_eta);
        }
    }();
    const T cos_i = L::min(L::abs(cos_i_m), one);
    // Mirror about wm (fresnel.h reflect), or Snell about wm (fresnel.h refract) reusing the
    // refracted cosine: with m = ±wm on wi's side, wt = −wi/η + m (cos θi/η − cos θt) (under total
    // reflection F = 1 and the refracted candidate is never selected).
    const T two_cos = cos_i_m + cos_i_m;
    const LaneVec3<T> reflected = {L::mul_add(two_cos, wm.x, zero - wi.x),
                                   L::mul_add(two_cos, wm.y, zero - wi.y),
                                   L::mul_add(two_cos, wm.z, zero - wi.z)};
    const T along = L::select(L::less(cos_i_m, zero), zero - one, one) *
                    L::mul_add(cos_i, fr.inv_eta, zero - fr.cos_theta_t);
    const T neg_inv_eta = zero - fr.inv_eta;
    const LaneVec3<T> refracted = {L::mul_add(wi.x, neg_inv_eta, wm.x * along),
                                   L::mul_add(wi.y, neg_inv_eta, wm.y * along),
                                   L::mul_add(wi.z, neg_inv_eta, wm.z * along)};
    if constexpr (kPolarized) {
        // The plane of incidence: its s axis ∝ wi × wm, ⊥ to the travel direction −wi.
        stokes_rotate_frame<T, L>(pol->stokes, {zero - wi.x, zero - wi.y, zero - wi.z},
                                  lane_cross<T, L>(wi, wm), pol->channels, ok);
        e.reflected = polarized_dielectric_choice<T, L>(*pol, fm, uc, ok, pol->flux);
    } else {
        e.reflected = L::less(uc, fr.reflectance);
    }
    e.wo = lane_select<T, L>(e.reflected, reflected, refracted);
    if (!shape.smooth) {
        // A reflection must stay on wi's side and a refraction cross, else G2 = 0.
        const auto same_side = L::less(zero, wi.z * e.wo.z);
        const auto crosses_right = L::either(L::both(same_side, e.reflected),
                                             L::both(L::negate(same_side), L::negate(e.reflected)));
        const auto escapes = L::both(L::less(zero, L::abs(e.wo.z)), crosses_right);
        const T escape = ggx_escape_fraction<T, L>(ggx, wi, e.wo, e.reflected, L::both(ok, escapes),
                                                   shape.uncorrelated, shape.smith_refraction);
        e.shadowing = L::select(escapes, escape, zero);
    }
    return e;
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_DIELECTRIC_BODY

#if !defined(LAMINA_LANE_TARGET) && !defined(LAMINA_PHYSICS_DIELECTRIC_H)
#define LAMINA_PHYSICS_DIELECTRIC_H

namespace lamina {

template <typename T>
struct DielectricInterface {
    T eta;
    T alpha;
    /// Use the uncorrelated G1·G1 instead of the height-correlated G2 (an option for ablations).
    bool uncorrelated_shadowing = false;
    /// The masking-shadowing of the refraction lobe (microfacet.h): the Smith microsurface's own
    /// B(1 + Λi, 1 + Λo) by default, or pbrt-v4's 1/(1 + Λi + Λo).
    TransmissionMasking transmission_masking = TransmissionMasking::Smith;
    GgxAnisotropy<T> anisotropy{};  ///< α_y and the tangent (microfacet.h); isotropic by default

    bool is_smooth() const { return alpha == 0; }
    T inv_eta() const { return T(1) / eta; }
    /// η = 1: no reflection (F = 0) and straight-through transmission, a delta lobe for any α.
    bool is_index_matched() const { return eta == T(1); }
    GGX<T> distribution() const { return {alpha, anisotropy}; }

    /// η(wo's side) / η(wi's side) — the ratio that appears in the refraction Jacobian.
    T eta_ratio(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (same_hemisphere(wi, wo)) return T(1);
        return wi.z > 0 ? eta : T(1) / eta;
    }

    /// G2(wi, wo): reflection 1/(1 + Λi + Λo); refraction as transmission_masking says.
    T masking_shadowing(const Vec3<T>& wi, const Vec3<T>& wo) const {
        const GGX<T> ggx = distribution();
        if (uncorrelated_shadowing) return ggx.G2_uncorrelated(wi, wo);
        if (transmission_masking == TransmissionMasking::Smith && !same_hemisphere(wi, wo))
            return ggx.G2_transmission(wi, wo);
        return ggx.G2(wi, wo);
    }

    /// Generalized half vector, in the upper hemisphere, or nothing for a degenerate pair.
    /// Reflection: wi + wo (Walter Eq. 13); transmission: −(η_i wi + η_o wo) (Walter Eq. 16).
    std::optional<Vec3<T>> half_vector(const Vec3<T>& wi, const Vec3<T>& wo) const {
        Vec3<T> wm = wi + wo * eta_ratio(wi, wo);
        const T len2 = dot(wm, wm);
        if (len2 == 0) return std::nullopt;
        wm = wm / std::sqrt(len2);
        if (wm.z < 0) wm = -wm;
        // Both directions must see the microfacet from their own side.
        if (dot(wm, wi) * wi.z <= 0 || dot(wm, wo) * wo.z <= 0) return std::nullopt;
        return wm;
    }

    /// Radiance BSDF, 1/sr, cosine excluded; zero for smooth and index-matched interfaces (delta
    /// lobes).
    T eval(const Vec3<T>& wi, const Vec3<T>& wo) const {
        const auto wm = rough_half_vector(wi, wo);
        if (!wm) return T(0);
        const GGX<T> ggx = distribution();
        const T F = fresnel_dielectric(dot(wi, *wm), eta);
        const T G = masking_shadowing(wi, wo);
        if (same_hemisphere(wi, wo)) {
            // Walter Eq. 20: f_r = F G D / (4 |cos θi| |cos θo|).
            return F * ggx.D(*wm) * G / std::abs(T(4) * wi.z * wo.z);
        }
        // Walter Eq. 21 (radiance, light from wi to wo):
        // f_t = |wi·wm| |wo·wm| η_o² (1 − F) G D / (|cos θi| |cos θo| (η_i wi·wm + η_o wo·wm)²).
        const T r = eta_ratio(wi, wo);  // η_o / η_i
        const T denom = sqr(dot(wi, *wm) + r * dot(wo, *wm));
        return (T(1) - F) * ggx.D(*wm) * G * sqr(r) * std::abs(dot(wi, *wm) * dot(wo, *wm)) /
               (std::abs(wi.z * wo.z) * denom);
    }

    /// Density of sample(wi, ·) at wo (solid angle); zero for smooth and index-matched interfaces.
    T pdf(const Vec3<T>& wi, const Vec3<T>& wo) const {
        const auto wm = rough_half_vector(wi, wo);
        if (!wm) return T(0);
        const GGX<T> ggx = distribution();
        const T F = fresnel_dielectric(dot(wi, *wm), eta);
        const T pdf_wm = ggx.pdf_visible_normal(wi, *wm);
        if (same_hemisphere(wi, wo)) {
            // Walter Eq. 14: dωm/dωo = 1 / (4 |wo·wm|).
            return F * pdf_wm / (T(4) * std::abs(dot(wo, *wm)));
        }
        // Walter Eq. 17: dωm/dωo = η_o² |wo·wm| / (η_i wi·wm + η_o wo·wm)².
        const T r = eta_ratio(wi, wo);
        const T jacobian = sqr(r) * std::abs(dot(wo, *wm)) / sqr(dot(wi, *wm) + r * dot(wo, *wm));
        return (T(1) - F) * pdf_wm * jacobian;
    }

    /// Follows a particle arriving from wi: dielectric_event (a visible microfacet normal drawn
    /// from u1, u2, reflection with probability F picked by uc, refraction otherwise) at one
    /// lane, keeping the fraction G2/G1 that escapes the microsurface (docs/physics.md §3), with
    /// the refraction lobe's G2 of transmission_masking. Smooth and index-matched interfaces give
    /// delta samples. Nothing for a grazing wi. kWithPdf = false skips the density (the particle
    /// tracer only needs the weight). kAnisotropic: the general (anisotropic) roughness, which an
    /// anisotropic interface needs; false takes the isotropic instance (GGX::lanes).
    template <bool kWithPdf = true, bool kAnisotropic = false>
    LAMINA_FORCE_INLINE std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T uc, T u1,
                                                            T u2) const {
        const DielectricEventShape shape = event_shape();
        const InterfaceEventLanes<T, bool> e =
            dielectric_event<T>(eta, inv_eta(), distribution().template lanes<kAnisotropic>(),
                                shape, {wi.x, wi.y, wi.z}, uc, u1, u2, true);
        if (e.degenerate) return std::nullopt;
        BsdfSample<T> s = event_sample(e, shape);
        s.weight = Rgb<T>(s.shadowing);
        if constexpr (kWithPdf)
            if (!s.is_delta) s.pdf = pdf(wi, s.wo);
        return s;
    }

    /// sample() following the particle's polarization (physics/polarization.h): dielectric_event's
    /// polarized branch choice, the state updated in `pol`; fresnel_weight holds the choice's flux
    /// factors (1 unless the channels' states differ). No density (the particle tracers').
    /// kAnisotropic as in sample().
    template <bool kAnisotropic = false>
    LAMINA_FORCE_INLINE std::optional<BsdfSample<T>> sample_polarized(
        const Vec3<T>& wi, T uc, T u1, T u2, PolarizationLanes<T>& pol) const {
        const DielectricEventShape shape = event_shape();
        const InterfaceEventLanes<T, bool> e = dielectric_event<T, Lane<T>, true>(
            eta, inv_eta(), distribution().template lanes<kAnisotropic>(), shape,
            {wi.x, wi.y, wi.z}, uc, u1, u2, true, &pol);
        if (e.degenerate) return std::nullopt;
        BsdfSample<T> s = event_sample(e, shape);
        s.fresnel_weight = {pol.factor[0], pol.factor[1], pol.factor[2]};
        s.weight = s.fresnel_weight * s.shadowing;
        return s;
    }

    /// The options of dielectric_event.
    DielectricEventShape event_shape() const {
        return {is_smooth(), is_index_matched(), uncorrelated_shadowing,
                transmission_masking == TransmissionMasking::Smith};
    }

  private:
    /// half_vector() for the rough lobes of eval and pdf: nothing for smooth and index-matched
    /// interfaces (delta lobes) and for grazing directions.
    std::optional<Vec3<T>> rough_half_vector(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (is_smooth() || is_index_matched() || wi.z == 0 || wo.z == 0) return std::nullopt;
        return half_vector(wi, wo);
    }

    /// The sample of dielectric_event's outcome `e` (its weight left to the caller).
    static BsdfSample<T> event_sample(const InterfaceEventLanes<T, bool>& e,
                                      const DielectricEventShape& shape) {
        BsdfSample<T> s;
        s.wo = {e.wo.x, e.wo.y, e.wo.z};
        s.is_delta = shape.smooth || shape.index_matched;
        s.is_transmission = !e.reflected;
        s.shadowing = e.shadowing;
        return s;
    }
};

}  // namespace lamina

#endif  // LAMINA_PHYSICS_DIELECTRIC_H

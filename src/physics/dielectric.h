#pragma once
// A dielectric interface between two non-absorbing media: smooth (α = 0, delta reflection and
// refraction) or rough (GGX, single-scattering microfacet BSDF of Walter et al. 2007, "Microfacet
// models for refraction through rough surfaces", EGSR). Conventions: physics/bsdf.h.
//
// eta = η_below / η_above > 0; eta = 1 is allowed: an index-matched interface is a delta pass-
// through, smooth or rough (for α > 0 the limit η → 1 of the rough BTDF, a refraction lobe of zero
// width; see sample_index_matched). α ∈ [0, 1].

#include "core/math.h"
#include "physics/bsdf.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <algorithm>
#include <cmath>
#include <optional>

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

    bool is_smooth() const { return alpha == 0; }
    T inv_eta() const { return T(1) / eta; }
    /// η = 1: no reflection (F = 0) and straight-through transmission, a delta lobe for any α.
    bool is_index_matched() const { return eta == T(1); }
    GGX<T> distribution() const { return {alpha}; }

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
        if (is_smooth() || is_index_matched() || wi.z == 0 || wo.z == 0) return T(0);
        const auto wm = half_vector(wi, wo);
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
        if (is_smooth() || is_index_matched() || wi.z == 0 || wo.z == 0) return T(0);
        const auto wm = half_vector(wi, wo);
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

    /// Follows a particle arriving from wi: picks a visible microfacet normal (Heitz 2018, drawn
    /// with the equivalent spherical-cap construction of Dupuy & Benyoub 2023), reflects with
    /// probability F and refracts otherwise, and keeps the fraction G2/G1 that escapes the
    /// microsurface (docs/physics.md §3), with the refraction lobe's G2 of transmission_masking. uc
    /// picks the Fresnel branch; u1, u2 the normal. kWithPdf = false skips the density (the
    /// particle tracer only needs the weight).
    template <bool kWithPdf = true>
    LAMINA_FORCE_INLINE std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T uc, T u1,
                                                            T u2) const {
        if (wi.z == 0) return std::nullopt;
        if (is_smooth()) return sample_smooth(wi, uc);
        if (is_index_matched()) return sample_index_matched(wi);
        const GGX<T> ggx = distribution();
        const Vec3<T> wm = ggx.sample_visible_normal_caps(wi, u1, u2);
        const T cos_i_m = dot(wi, wm);  // < 0 when wi is below: seen from the other side
        const FresnelDielectric<T> fr = fresnel_dielectric_full(cos_i_m, eta, inv_eta());
        // Both candidate directions are formed and one is selected: the Fresnel choice is a coin
        // flip no branch predictor can learn. Snell about wm (fresnel.h refract) reuses the
        // refracted cosine: with m = ±wm on wi's side, wt = −wi/η + m (cos θi/η − cos θt) (under
        // total reflection F = 1 and the refracted candidate is never selected).
        const T sign = cos_i_m < 0 ? T(-1) : T(1);
        const Vec3<T> reflected = reflect(wi, wm);
        const Vec3<T> refracted =
            wi * (-fr.inv_eta) + wm * (sign * (std::abs(cos_i_m) * fr.inv_eta - fr.cos_theta_t));
        const bool is_reflection = uc < fr.reflectance;
        BsdfSample<T> s;
        s.wo = is_reflection ? reflected : refracted;
        s.is_transmission = !is_reflection;
        // A reflection must stay on wi's side and a refraction cross: otherwise the single-
        // scattering microsurface loses the energy (G2 = 0 for the pair).
        const bool escapes = s.wo.z != 0 && (same_hemisphere(wi, s.wo) == is_reflection);
        // Weight f·|cos θo|/pdf = G2(wi, wo)/G1(wi): the Fresnel branch probability cancels F
        // (Heitz 2018, §2; Walter Eq. 41 with visible-normal sampling), in terms of the Smith
        // roots r = √(1 + α²tan²θ) = 1 + 2Λ (Heitz 2014, Eq. 72; microfacet.h).
        if (uncorrelated_shadowing) {
            s.shadowing = ggx.G1(s.wo);
        } else {
            const T r_i = ggx.smith_root(wi), r_o = ggx.smith_root(s.wo);
            s.shadowing = is_reflection || transmission_masking == TransmissionMasking::Pbrt
                              ? smith_reflection_escape(r_i, r_o)
                              : smith_refraction_escape(r_i, r_o);
        }
        if (!escapes) s.shadowing = 0;
        s.weight = Rgb<T>(s.shadowing);
        if constexpr (kWithPdf) s.pdf = pdf(wi, s.wo);
        return s;
    }

  private:
    /// Rough and η = 1: F = 0 on every microfacet and Snell's law sends every refracted ray
    /// straight on, so the BTDF of Walter et al. collapses onto a delta lobe at −wi, which eval
    /// and pdf (densities) cannot represent. Its weight is the η → 1 limit of the lobe's energy,
    /// E[(1 − F) G2/G1] → G2(wi, −wi)/G1(wi) (every refracted direction tends to −wi; G2 of the
    /// refraction lobe, transmission_masking's), so the interface is continuous in η; the
    /// single-scattering microsurface still loses 1 − that.
    std::optional<BsdfSample<T>> sample_index_matched(const Vec3<T>& wi) const {
        BsdfSample<T> s;
        s.wo = -wi;
        s.is_delta = true;
        s.is_transmission = true;
        // A fraction, ≤ 1 exactly; the float quotient can round an ulp above it (found by the
        // fuzz test, seed 99: −6.6e-8 booked as lost to the microsurface): clamped.
        s.shadowing = std::min(T(1), masking_shadowing(wi, s.wo) / distribution().G1(wi));
        s.weight = Rgb<T>(s.shadowing);
        return s;
    }

    std::optional<BsdfSample<T>> sample_smooth(const Vec3<T>& wi, T uc) const {
        const Vec3<T> n(0, 0, 1);
        const T F = fresnel_dielectric(wi.z, eta);
        BsdfSample<T> s;
        s.is_delta = true;
        s.weight = Rgb<T>(T(1));  // flux: the branch probability equals its Fresnel factor
        if (uc < F) {
            s.wo = Vec3<T>(-wi.x, -wi.y, wi.z);
        } else {
            const auto wt = refract(wi, n, eta);
            if (!wt) return std::nullopt;  // unreachable: F = 1 under TIR
            s.wo = *wt;
            s.is_transmission = true;
        }
        return s;
    }
};

}  // namespace lamina

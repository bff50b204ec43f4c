#pragma once
// A conductor (opaque) interface: smooth (delta mirror) or rough GGX reflection with the exact
// complex Fresnel factor per RGB channel (Walter et al. 2007, Eq. 20 with conductor Fresnel).
// Light arrives from above only (wi.z > 0). Relative complex index (eta + i k) per channel, taken
// against the medium above (docs/physics.md §2). Conventions: physics/bsdf.h.

#include "core/rgb.h"
#include "physics/bsdf.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/smith_masking.h"

#include <cmath>
#include <optional>

namespace lamina {

template <typename T>
struct ConductorInterface {
    Rgb<T> eta;
    Rgb<T> k;
    T alpha;
    bool uncorrelated_shadowing = false;

    bool is_smooth() const { return alpha == 0; }
    GGX<T> distribution() const { return {alpha}; }

    Rgb<T> fresnel(T cos_theta) const {
        return {fresnel_conductor(cos_theta, eta[0], k[0]),
                fresnel_conductor(cos_theta, eta[1], k[1]),
                fresnel_conductor(cos_theta, eta[2], k[2])};
    }

    T masking_shadowing(const Vec3<T>& wi, const Vec3<T>& wo) const {
        const GGX<T> ggx = distribution();
        return uncorrelated_shadowing ? ggx.G2_uncorrelated(wi, wo) : ggx.G2(wi, wo);
    }

    /// Walter Eq. 20: F(wi·wm) D(wm) G2 / (4 cos θi cos θo); zero unless both are above.
    Rgb<T> eval(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (is_smooth() || wi.z <= 0 || wo.z <= 0) return Rgb<T>(T(0));
        const Vec3<T> wm = normalize(wi + wo);
        const T scalar = distribution().D(wm) * masking_shadowing(wi, wo) / (T(4) * wi.z * wo.z);
        return fresnel(dot(wi, wm)) * scalar;
    }

    T pdf(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (is_smooth() || wi.z <= 0 || wo.z <= 0) return T(0);
        const Vec3<T> wm = normalize(wi + wo);
        return distribution().pdf_visible_normal(wi, wm) / (T(4) * dot(wo, wm));
    }

    /// Reflects a particle arriving from wi off a visible microfacet (Heitz 2018 density, drawn as
    /// in Dupuy & Benyoub 2023); weight
    /// F(wi·wm)·G2/G1. kWithPdf = false skips the density.
    template <bool kWithPdf = true>
    std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T u1, T u2) const {
        if (wi.z <= 0) return std::nullopt;
        BsdfSample<T> s;
        if (is_smooth()) {
            s.wo = Vec3<T>(-wi.x, -wi.y, wi.z);
            s.is_delta = true;
            s.fresnel_weight = fresnel(wi.z);
            s.weight = s.fresnel_weight;
            return s;
        }
        const GGX<T> ggx = distribution();
        const Vec3<T> wm = ggx.sample_visible_normal_caps(wi, u1, u2);
        s.wo = reflect(wi, wm);
        s.fresnel_weight = fresnel(dot(wi, wm));
        if (s.wo.z <= 0) {
            s.shadowing = 0;
        } else {
            // G2/G1 = (1 + r_i)/(r_i + r_o) with r = 1 + 2Λ (see dielectric.h).
            if (uncorrelated_shadowing) {
                s.shadowing = ggx.G1(s.wo);
            } else {
                const T r_i = ggx.smith_root(wi), r_o = ggx.smith_root(s.wo);
                s.shadowing = smith_reflection_escape(r_i, r_o);
            }
            if constexpr (kWithPdf) s.pdf = ggx.pdf_visible_normal(wi, wm) / (T(4) * dot(s.wo, wm));
        }
        s.weight = s.fresnel_weight * s.shadowing;
        return s;
    }
};

}  // namespace lamina

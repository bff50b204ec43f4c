// A conductor (opaque) interface: smooth (delta mirror) or rough GGX reflection with the exact
// complex Fresnel factor per RGB channel (Walter et al. 2007, Eq. 20 with conductor Fresnel).
// Light arrives from above only (wi.z > 0). Relative complex index (eta + i k) per channel, taken
// against the medium above (docs/physics.md §2). Conventions: physics/bsdf.h.

#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/rgb.h"
#include "physics/bsdf.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/polarization.h"
#include "physics/smith_masking.h"

#include <cmath>
#include <optional>
#include <type_traits>

// A lane header (core/lane.h): the particle event is a lane template, included once as an
// ordinary header and once per SIMD target; the interface type below it only once.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_CONDUCTOR_LANES_H
#define LAMINA_PHYSICS_CONDUCTOR_LANES_H
#define LAMINA_PHYSICS_CONDUCTOR_BODY
#endif
#elif defined(LAMINA_PHYSICS_CONDUCTOR_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_CONDUCTOR_TARGET
#undef LAMINA_PHYSICS_CONDUCTOR_TARGET
#else
#define LAMINA_PHYSICS_CONDUCTOR_TARGET
#endif
#define LAMINA_PHYSICS_CONDUCTOR_BODY
#endif

#ifdef LAMINA_PHYSICS_CONDUCTOR_BODY
#undef LAMINA_PHYSICS_CONDUCTOR_BODY

LAMINA_LANE_BEGIN

/// The conductor interface's particle event (ConductorInterface::sample) on the lanes of
/// `active`, light from above, GGX roughness `ggx` (microfacet.h, anisotropic or not): the mirror
/// direction about a visible microfacet normal drawn from
/// u1, u2 (Heitz 2018 density, by the spherical caps of Dupuy & Benyoub 2023; the macro normal
/// when `smooth`), its Fresnel factors `fresnel(cos θ, factors)` (three channels, at the facet
/// cosine; fresnel_conductor per channel) and, when rough, the escape fraction G2/G1
/// (ggx_escape_fraction; zero for a reflection below the horizon). A wi at or below the horizon
/// is degenerate.
/// Polarized (a `mueller` source given, `pol` the state; physics/polarization.h): the particle's
/// state is turned into the facet's plane of incidence and multiplied by the reflection Mueller
/// matrices that `mueller(cos θ, m)` fills per channel (fresnel_conductor_mueller; m[0] for all
/// channels when one state serves them, which needs the same index in every channel); the Fresnel
/// factors are then the reflected fractions a + b q of the state, returned in fresnel_factors and
/// pol->factor.
/// A branch-free lane template (core/lane.h): the scalar and the SIMD particle kernels evaluate
/// these lines.
template <typename T, typename L = Lane<T>, typename Fresnel, typename Mueller = NoMueller,
          bool kPolarized = !std::is_same_v<Mueller, NoMueller>, bool kA = false>
LAMINA_LANE_INLINE InterfaceEventLanes<T, typename L::Mask> conductor_event(
    const GgxLanes<T, kA>& ggx, bool smooth, bool uncorrelated, const LaneVec3<T>& wi, T u1, T u2,
    typename L::Mask active, const Fresnel& fresnel, T* fresnel_factors,
    PolarizationLanes<T>* pol = nullptr, const Mueller& mueller = {}) {
    const T zero = L::constant(0), one = L::constant(1);
    InterfaceEventLanes<T, typename L::Mask> e;
    e.degenerate = L::both(active, L::negate(L::less(zero, wi.z)));
    e.reflected = L::both(active, L::negate(e.degenerate));
    const LaneVec3<T> wm = smooth ? LaneVec3<T>{zero, zero, one}
                                  : ggx_sample_visible_normal_complete<T, L>(ggx, wi, u1, u2);
    const T cos_i_m = lane_dot<T, L>(wi, wm);
    const T two_cos = cos_i_m + cos_i_m;
    e.wo = {L::mul_add(two_cos, wm.x, zero - wi.x), L::mul_add(two_cos, wm.y, zero - wi.y),
            L::mul_add(two_cos, wm.z, zero - wi.z)};
    if constexpr (kPolarized) {
        stokes_rotate_frame<T, L>(pol->stokes, {zero - wi.x, zero - wi.y, zero - wi.z},
                                  lane_cross<T, L>(wi, wm), pol->channels, e.reflected);
        InterfaceMueller<T> m[3] = {};
        reflection_on_lanes(mueller, cos_i_m, m, e.reflected);
        StokesLanes<T>& st = pol->stokes;
        pol->factor[0] = stokes_apply<T, L>(m[0], st.q[0], st.u[0], st.v[0], e.reflected);
        pol->factor[1] = pol->factor[2] = pol->factor[0];
        for (int c = 1; c < pol->channels; ++c)
            pol->factor[c] = stokes_apply<T, L>(m[c], st.q[c], st.u[c], st.v[c], e.reflected);
        for (int c = 0; c < 3; ++c)
            fresnel_factors[c] = pol->factor[c];
    } else {
        reflection_on_lanes(fresnel, cos_i_m, fresnel_factors, e.reflected);
    }
    e.shadowing = one;
    if (!smooth)
        e.shadowing = L::select(
            L::less(zero, e.wo.z),
            ggx_escape_fraction<T, L>(ggx, wi, e.wo, e.reflected, e.reflected, uncorrelated, false),
            zero);
    return e;
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_CONDUCTOR_BODY

#if !defined(LAMINA_LANE_TARGET) && !defined(LAMINA_PHYSICS_CONDUCTOR_H)
#define LAMINA_PHYSICS_CONDUCTOR_H

namespace lamina {

template <typename T>
struct ConductorInterface {
    Rgb<T> eta;
    Rgb<T> k;
    T alpha;  ///< α_x (along the tangent) when anisotropic
    bool uncorrelated_shadowing = false;
    GgxAnisotropy<T> anisotropy{};  ///< α_y and the tangent (microfacet.h); isotropic by default

    bool is_smooth() const { return alpha == 0; }
    GGX<T> distribution() const { return {alpha, anisotropy}; }

    Rgb<T> fresnel(T cos_theta) const {
        return {fresnel_conductor(cos_theta, eta[0], k[0]),
                fresnel_conductor(cos_theta, eta[1], k[1]),
                fresnel_conductor(cos_theta, eta[2], k[2])};
    }

    /// Whether every channel has the same complex index (a grey conductor: one polarization
    /// state serves all channels).
    bool is_grey() const {
        return eta[0] == eta[1] && eta[1] == eta[2] && k[0] == k[1] && k[1] == k[2];
    }

    /// The reflection Mueller matrices (physics/polarization.h) of the three channels at the
    /// facet cosine cos_theta.
    void mueller(T cos_theta, InterfaceMueller<T>* m) const {
        for (int c = 0; c < 3; ++c)
            m[c] = fresnel_conductor_mueller(cos_theta, eta[c], k[c]);
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

    /// Reflects a particle arriving from wi: conductor_event at one lane (a visible microfacet
    /// normal, Heitz 2018 density drawn as in Dupuy & Benyoub 2023; weight F(wi·wm)·G2/G1).
    /// Nothing unless wi.z > 0. kWithPdf = false skips the density.
    /// kAnisotropic: the general (anisotropic) roughness, which an anisotropic interface needs;
    /// false takes the isotropic instance (GGX::lanes).
    template <bool kWithPdf = true, bool kAnisotropic = false>
    std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T u1, T u2) const {
        T factors[3];
        const auto channel_fresnel = [&](T cos_theta, T* out) {
            const Rgb<T> f = fresnel(cos_theta);
            out[0] = f[0], out[1] = f[1], out[2] = f[2];
        };
        const InterfaceEventLanes<T, bool> e = conductor_event<T>(
            distribution().template lanes<kAnisotropic>(), is_smooth(), uncorrelated_shadowing,
            {wi.x, wi.y, wi.z}, u1, u2, true, channel_fresnel, factors);
        if (e.degenerate) return std::nullopt;
        BsdfSample<T> s = reflection_sample(e, factors);
        if constexpr (kWithPdf)
            if (!s.is_delta && s.wo.z > 0) s.pdf = pdf(wi, s.wo);
        return s;
    }

    /// sample() following the particle's polarization (physics/polarization.h): conductor_event's
    /// Mueller matrices, the state updated in `pol`, the Fresnel weight the reflected fraction of
    /// the state. No density (the particle tracers'). kAnisotropic as in sample().
    template <bool kAnisotropic = false>
    std::optional<BsdfSample<T>> sample_polarized(const Vec3<T>& wi, T u1, T u2,
                                                  PolarizationLanes<T>& pol) const {
        T factors[3];
        const NoMueller unpolarized;
        const auto channel_mueller = [&](T cos_theta, InterfaceMueller<T>* m) {
            mueller(cos_theta, m);
        };
        const InterfaceEventLanes<T, bool> e = conductor_event<T>(
            distribution().template lanes<kAnisotropic>(), is_smooth(), uncorrelated_shadowing,
            {wi.x, wi.y, wi.z}, u1, u2, true, unpolarized, factors, &pol, channel_mueller);
        if (e.degenerate) return std::nullopt;
        return reflection_sample(e, factors);
    }

  private:
    /// The sample of conductor_event's outcome `e` with the channels' Fresnel `factors`.
    BsdfSample<T> reflection_sample(const InterfaceEventLanes<T, bool>& e,
                                    const T (&factors)[3]) const {
        BsdfSample<T> s;
        s.wo = {e.wo.x, e.wo.y, e.wo.z};
        s.is_delta = is_smooth();
        s.fresnel_weight = {factors[0], factors[1], factors[2]};
        s.shadowing = e.shadowing;
        s.weight = s.fresnel_weight * s.shadowing;
        return s;
    }
};

}  // namespace lamina

#endif  // LAMINA_PHYSICS_CONDUCTOR_H

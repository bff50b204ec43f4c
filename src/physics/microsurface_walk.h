#pragma once
// Multiple scattering on a rough GGX interface: the microsurface random walk of Heitz, Hanika,
// d'Eon & Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the Smith model", ACM TOG
// 35(4) (SIGGRAPH 2016), for dielectric and conductor microsurfaces.
//
// The single-scattering interfaces (dielectric.h, conductor.h) keep the fraction G2/G1 of a
// particle that escapes the microsurface after one facet and drop the rest (docs/physics.md §3:
// "lost to the microsurface"). The walk instead follows the particle from facet to facet until it
// leaves: a ray meets the microsurface at a height drawn from the Smith model's uncorrelated
// heights (uniform on [−1, 1]; the paper shows the BSDF does not depend on it), scatters off a
// facet drawn from the distribution of normals visible from its direction (which may point below
// the horizon after a first bounce), and so on. Nothing is lost but what a conductor's Fresnel
// factor absorbs. The first order of the walk is the single-scattering interface with the
// height-correlated Smith masking-shadowing (the tests check it bin by bin): with c = C1(h) of the
// first hit, c has density (1 + Λi) c^Λi; a reflected ray escapes with probability c^Λo, so
// G2/G1 = (1 + Λi)/(1 + Λi + Λo), the G2 of dielectric.h and conductor.h; a refracted ray leaves
// below, where the heights above it have C1 = 1 − c, so G2/G1 = ∫ (1 + Λi) c^Λi (1 − c)^Λo dc =
// (1 + Λi) B(1 + Λi, 1 + Λo) (B: Euler's Beta function), the single-scattering dielectric's
// default refraction masking (TransmissionMasking::Smith, physics/smith_masking.h); its `pbrt`
// option, 1/(1 + Λi + Λo) as pbrt-v4 uses for both lobes, differs by a few percent at grazing
// exits and by much more when both Λ are large.
//
// Conventions as in bsdf.h: `wi` points away from the surface towards where the light comes from
// (above: wi.z > 0; from below a dielectric: wi.z < 0). Directions of travel are written `wr`.
// Heights below the surface are seen from there with heights and directions negated (the
// microsurface is point-symmetric, microfacet.h).

#include "core/math.h"
#include "core/rgb.h"
#include "core/vec.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <cmath>
#include <limits>
#include <optional>

namespace lamina {

/// CDF C1 of the microsurface's heights, uniform on [−1, 1] (Heitz et al. 2016), and its
/// inverse on [0, 1].
template <typename T>
inline T microsurface_height_cdf(T h) {
    return clamp((h + T(1)) * T(0.5), T(0), T(1));
}
template <typename T>
inline T microsurface_height_cdf_inverse(T u) {
    return clamp(T(2) * u - T(1), T(-1), T(1));
}

/// Smith Λ for a direction of travel wr: GGX::lambda(wr) going up (wr.z > 0), −1 − Λ(−wr) going
/// down (Heitz et al. 2016: their GGX Λ evaluated with cot θ < 0).
template <typename T>
inline T smith_lambda_signed(const GGX<T>& ggx, const Vec3<T>& wr) {
    return wr.z >= 0 ? ggx.lambda(wr) : T(-1) - ggx.lambda(wr);
}

/// The height of the next intersection of a ray leaving height h along wr with the microsurface,
/// or +∞ when the ray escapes it (upwards only), from one uniform number u ∈ [0, 1).
/// Heitz et al. 2016 (the height-dependent masking G1(wr, h) = C1(h)^Λ(wr) and its inverse): a
/// ray going up escapes with probability C1(h)^Λ(wr); otherwise, and always going down, the next
/// height follows from C1(h') = C1(h) / (1 − u)^(1/Λ(wr)).
template <typename T>
inline T microsurface_next_height(const GGX<T>& ggx, const Vec3<T>& wr, T h, T u) {
    constexpr T kInfinity = std::numeric_limits<T>::infinity();
    if (wr.z > T(0.9999)) return kInfinity;  // straight up: nothing can mask it
    const T c = microsurface_height_cdf(h);
    if (wr.z < T(-0.9999)) return microsurface_height_cdf_inverse(u * c);  // Λ → −1
    if (std::abs(wr.z) < T(1e-4)) return h;  // horizontal: meets the surface where it is
    const T lambda = smith_lambda_signed(ggx, wr);
    if (wr.z > 0 && u >= T(1) - std::pow(c, lambda)) return kInfinity;
    return microsurface_height_cdf_inverse(c / std::pow(T(1) - u, T(1) / lambda));
}

/// Where a walk left the microsurface: direction (pointing away from it), the flux weight it
/// carries (RGB: a conductor's Fresnel factors; 1 for a dielectric) and the number of facets it
/// met (the scattering order, ≥ 1). `escaped` is false for a walk given up at its facet cap (it
/// would meet one more facet): its flux is lost to the microsurface and wo is meaningless.
template <typename T>
struct MicrosurfaceExit {
    Vec3<T> wo;
    Rgb<T> weight{T(1)};
    int order = 0;
    bool escaped = true;
};

/// The microsurface walk of a particle arriving from wi on a rough dielectric interface of
/// relative index eta (below / above) and roughness ggx.alpha > 0, light from either side. Each
/// facet reflects with its exact Fresnel probability and refracts otherwise (Heitz et al. 2016,
/// the random walk with their dielectric phase function). `uniform()` returns uniform
/// numbers in [0, 1). A walk that, after max_order facets, would meet one more is given up
/// (escaped = false: the caller books its flux as lost to the microsurface); a numerical
/// degeneracy returns nothing (the caller counts it).
template <typename T, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric(const GGX<T>& ggx, T eta,
                                                         const Vec3<T>& wi, Uniform&& uniform,
                                                         int max_order) {
    if (wi.z == 0) return std::nullopt;
    bool outside = wi.z > 0;       // on the side the interface's normal points to
    Vec3<T> wr = -wi;              // direction of travel
    T h = outside ? T(2) : T(-2);  // above every facet (C1 = 1) on its own side
    MicrosurfaceExit<T> exit;
    while (true) {
        // The next facet, in the frame of the side the particle is on.
        const T u = uniform();
        h = outside ? microsurface_next_height(ggx, wr, h, u)
                    : -microsurface_next_height(ggx, -wr, -h, u);
        if (!std::isfinite(h)) {
            exit.wo = wr;
            return exit;
        }
        if (exit.order == max_order) {
            exit.escaped = false;
            return exit;
        }
        ++exit.order;
        // A facet visible from the arriving direction (below the horizon after a first bounce).
        const Vec3<T> w = -wr;
        const T u1 = uniform(), u2 = uniform();
        const Vec3<T> wm = outside ? ggx.sample_visible_normal_complete(w, u1, u2)
                                   : -ggx.sample_visible_normal_complete(-w, u1, u2);
        const T cos_w_m = dot(w, wm);
        if (!(cos_w_m > 0)) return std::nullopt;  // degenerate facet (rounding at grazing)
        const T eta_crossed = outside ? eta : T(1) / eta;
        const T F = fresnel_dielectric(cos_w_m, eta_crossed);
        if (uniform() < F) {
            wr = reflect(w, wm);
        } else {
            const std::optional<Vec3<T>> wt = refract(w, wm, eta_crossed);
            if (!wt) return std::nullopt;  // unreachable: F = 1 under total reflection
            wr = normalize(*wt);
            outside = !outside;
        }
        if (!std::isfinite(wr.z)) return std::nullopt;
    }
}

/// The microsurface walk of a particle arriving from wi (wi.z > 0) on a rough conductor; each
/// facet multiplies the flux by its Fresnel factor (Heitz et al. 2016, the conductor phase
/// function). `fresnel(cos)` returns the RGB reflectance at a facet cosine. Given up past
/// max_order facets and empty on a degeneracy, as walk_rough_dielectric.
template <typename T, typename Fresnel, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor(const GGX<T>& ggx, const Fresnel& fresnel,
                                                        const Vec3<T>& wi, Uniform&& uniform,
                                                        int max_order) {
    if (wi.z <= 0) return std::nullopt;
    Vec3<T> wr = -wi;
    T h = T(2);
    MicrosurfaceExit<T> exit;
    while (true) {
        h = microsurface_next_height(ggx, wr, h, uniform());
        if (!std::isfinite(h)) {
            exit.wo = wr;
            return exit;
        }
        if (exit.order == max_order) {
            exit.escaped = false;
            return exit;
        }
        ++exit.order;
        const Vec3<T> w = -wr;
        const T u1 = uniform(), u2 = uniform();
        const Vec3<T> wm = ggx.sample_visible_normal_complete(w, u1, u2);
        const T cos_w_m = dot(w, wm);
        if (!(cos_w_m > 0)) return std::nullopt;
        exit.weight *= fresnel(cos_w_m);
        wr = reflect(w, wm);
    }
}

// ---- Evaluating the walk: phase functions, height masking and next-event estimation -------------
// The walk's BSDF has no closed form; Heitz et al. 2016 (§5, "stochastic evaluation") estimate it
// without bias by a walk that, at every facet it meets, connects towards the exit direction wo:
//
//     f(wi, wo)·|cos θo| = E[ Σ_facets  W_j · p_j(wo) · G1(wo, h_j) ],
//
// p_j the facet's phase function (the density of the walk's next direction at wo), G1(wo, h_j)
// the probability that a ray leaving the facet's height h_j along wo escapes the microsurface on
// the side wo points to (C1(h)^Λ(wo) above; C1(−h)^Λ(−wo) below, the heights seen from there), and
// W_j the flux weight the exit would carry (the conductor's Fresnel factors of the facets met so
// far and of this one; 1 for a dielectric, whose Fresnel factor is the branch probability inside
// p_j). The product p_j·G1 is the density of "the walk leaves along wo right after facet j", so the
// sum is the density of the walk's exit direction (weighted by its flux): the BSDF in the flux
// convention of the interfaces' eval()·|cos θo| (dielectric.h, conductor.h; no η² radiance
// factor: the flux leaving per solid angle of wo). docs/rendering.md §1.6 derives the first order.

/// The height-dependent masking G1(wo, h) = C1(h)^Λ(wo) of a ray leaving height h along wo on the
/// upper side (Heitz et al. 2016, from Smith's uncorrelated heights): the probability that it
/// escapes the microsurface; zero for wo.z ≤ 0 (it meets the microsurface again).
template <typename T>
inline T microsurface_escape(const GGX<T>& ggx, const Vec3<T>& wo, T h) {
    if (!(wo.z > 0)) return T(0);
    const T c = microsurface_height_cdf(h);
    const T lambda = ggx.lambda(wo);
    if (lambda == 0) return T(1);
    return std::pow(c, lambda);
}

/// The dielectric phase function of one facet met by a particle on the *upper* side coming from w
/// (w = −direction of travel; w may point below the horizon after a first bounce): the density
/// (1/sr) of the walk's next direction at wo, for the facets visible from w (D_visible_complete)
/// that reflect with probability F(w·wm) and refract into the lower side otherwise (Heitz et al.
/// 2016, their dielectric phase function). `refracted` selects the branch: wo on the lower side
/// (refraction, eta = η_lower / η_upper of this side's frame) or the upper side (reflection).
/// Reflection: F D_w(wm) / (4 w·wm), wm = (w + wo)/|w + wo| (Walter et al. 2007, Eq. 14);
/// refraction: (1 − F) D_w(wm) η² |wo·wm| / (w·wm + η wo·wm)², wm ∝ −(w + η wo) (Walter Eqs.
/// 16-17).
template <typename T>
inline T microsurface_dielectric_phase(const GGX<T>& ggx, T eta, const Vec3<T>& w,
                                       const Vec3<T>& wo, bool refracted) {
    Vec3<T> wm = refracted ? -(w + wo * eta) : w + wo;
    const T len2 = dot(wm, wm);
    if (!(len2 > 0)) return T(0);
    wm = wm / std::sqrt(len2);
    if (wm.z < 0) wm = -wm;
    const T cos_w_m = dot(w, wm), cos_o_m = dot(wo, wm);
    if (!(cos_w_m > 0)) return T(0);
    const T F = fresnel_dielectric(cos_w_m, eta);
    const T visible = ggx.D_visible_complete(w, wm);
    if (!refracted) return F * visible / (T(4) * cos_w_m);
    if (!(cos_o_m < 0)) return T(0);
    const T denom = sqr(cos_w_m + eta * cos_o_m);
    if (!(denom > 0)) return T(0);
    return (T(1) - F) * visible * sqr(eta) * -cos_o_m / denom;
}

/// The conductor's facet: the density of the reflected direction, D_w(wm) / (4 w·wm), and the
/// facet cosine w·wm at which its Fresnel factor is taken (0 when wo cannot be reached from w).
template <typename T>
inline T microsurface_reflection_density(const GGX<T>& ggx, const Vec3<T>& w, const Vec3<T>& wo,
                                         T& cos_w_m) {
    cos_w_m = T(0);
    const Vec3<T> sum = w + wo;
    const T len2 = dot(sum, sum);
    if (!(len2 > 0)) return T(0);
    const Vec3<T> wm = sum / std::sqrt(len2);
    const T c = dot(w, wm);
    if (!(c > 0) || !(wm.z > 0)) return T(0);
    cos_w_m = c;
    return ggx.D_visible_complete(w, wm) / (T(4) * c);
}

/// One facet a walk meets, as the visiting walks below report it before it scatters: its height
/// h (in the interface's frame), the direction w the particle comes from (−direction of travel),
/// whether the particle is on the upper side (`outside`), the flux weight it carries (a
/// conductor's Fresnel factors of the earlier facets; 1 for a dielectric) and the order (1 for
/// the first facet).
template <typename T>
struct MicrosurfaceFacet {
    T h;
    Vec3<T> w;
    bool outside;
    Rgb<T> weight;
    int order;
};

/// Next-event estimation from a dielectric facet towards wo (the interface's frame, either side,
/// wo.z ≠ 0): the facet's phase density at wo times G1(wo, h) on wo's side. A particle on the
/// lower side is seen from there (heights, directions negated, eta → 1/eta), so the branch is a
/// reflection when wo is on the particle's side and a refraction otherwise.
template <typename T>
inline T microsurface_dielectric_connect(const GGX<T>& ggx, T eta,
                                         const MicrosurfaceFacet<T>& facet, const Vec3<T>& wo) {
    if (wo.z == 0) return T(0);
    const bool wo_up = wo.z > 0;
    const bool refracted = facet.outside != wo_up;
    const T escape =
        wo_up ? microsurface_escape(ggx, wo, facet.h) : microsurface_escape(ggx, -wo, -facet.h);
    if (!(escape > 0)) return T(0);
    const T phase = facet.outside
                        ? microsurface_dielectric_phase(ggx, eta, facet.w, wo, refracted)
                        : microsurface_dielectric_phase(ggx, T(1) / eta, -facet.w, -wo, refracted);
    return phase * escape;
}

/// Next-event estimation from a conductor facet towards wo (wo.z > 0): `density` is the walk's
/// density of leaving along wo right after this facet, D_w(wm)/(4 w·wm)·G1(wo, h) (the walk draws
/// its directions without the Fresnel factor), and `weight` the flux that exit would carry,
/// facet.weight·F(w·wm).
template <typename T>
struct MicrosurfaceConnection {
    T density = 0;
    Rgb<T> weight{T(0)};
};
template <typename T, typename Fresnel>
inline MicrosurfaceConnection<T> microsurface_conductor_connect(const GGX<T>& ggx,
                                                                const Fresnel& fresnel,
                                                                const MicrosurfaceFacet<T>& facet,
                                                                const Vec3<T>& wo) {
    MicrosurfaceConnection<T> out;
    const T escape = microsurface_escape(ggx, wo, facet.h);
    if (!(escape > 0)) return out;
    T cos_w_m;
    const T density = microsurface_reflection_density(ggx, facet.w, wo, cos_w_m);
    if (!(density > 0)) return out;
    out.density = density * escape;
    out.weight = facet.weight * fresnel(cos_w_m);
    return out;
}

/// walk_rough_dielectric with a visitor: `visit(const MicrosurfaceFacet<T>&)` is called at every
/// facet before the particle scatters off it, with the same random numbers in the same order as
/// walk_rough_dielectric (one walk of either is the same walk). Returns the same exit.
template <typename T, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric_visiting(const GGX<T>& ggx, T eta,
                                                                  const Vec3<T>& wi,
                                                                  Uniform&& uniform, int max_order,
                                                                  Visit&& visit) {
    if (wi.z == 0) return std::nullopt;
    bool outside = wi.z > 0;
    Vec3<T> wr = -wi;
    T h = outside ? T(2) : T(-2);
    MicrosurfaceExit<T> exit;
    while (true) {
        const T u = uniform();
        h = outside ? microsurface_next_height(ggx, wr, h, u)
                    : -microsurface_next_height(ggx, -wr, -h, u);
        if (!std::isfinite(h)) {
            exit.wo = wr;
            return exit;
        }
        if (exit.order == max_order) {
            exit.escaped = false;
            return exit;
        }
        ++exit.order;
        const Vec3<T> w = -wr;
        visit(MicrosurfaceFacet<T>{h, w, outside, exit.weight, exit.order});
        const T u1 = uniform(), u2 = uniform();
        const Vec3<T> wm = outside ? ggx.sample_visible_normal_complete(w, u1, u2)
                                   : -ggx.sample_visible_normal_complete(-w, u1, u2);
        const T cos_w_m = dot(w, wm);
        if (!(cos_w_m > 0)) return std::nullopt;
        const T eta_crossed = outside ? eta : T(1) / eta;
        const T F = fresnel_dielectric(cos_w_m, eta_crossed);
        if (uniform() < F) {
            wr = reflect(w, wm);
        } else {
            const std::optional<Vec3<T>> wt = refract(w, wm, eta_crossed);
            if (!wt) return std::nullopt;
            wr = normalize(*wt);
            outside = !outside;
        }
        if (!std::isfinite(wr.z)) return std::nullopt;
    }
}

/// walk_rough_conductor with a visitor, as walk_rough_dielectric_visiting.
template <typename T, typename Fresnel, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor_visiting(const GGX<T>& ggx,
                                                                 const Fresnel& fresnel,
                                                                 const Vec3<T>& wi,
                                                                 Uniform&& uniform, int max_order,
                                                                 Visit&& visit) {
    if (wi.z <= 0) return std::nullopt;
    Vec3<T> wr = -wi;
    T h = T(2);
    MicrosurfaceExit<T> exit;
    while (true) {
        h = microsurface_next_height(ggx, wr, h, uniform());
        if (!std::isfinite(h)) {
            exit.wo = wr;
            return exit;
        }
        if (exit.order == max_order) {
            exit.escaped = false;
            return exit;
        }
        ++exit.order;
        const Vec3<T> w = -wr;
        visit(MicrosurfaceFacet<T>{h, w, true, exit.weight, exit.order});
        const T u1 = uniform(), u2 = uniform();
        const Vec3<T> wm = ggx.sample_visible_normal_complete(w, u1, u2);
        const T cos_w_m = dot(w, wm);
        if (!(cos_w_m > 0)) return std::nullopt;
        exit.weight *= fresnel(cos_w_m);
        wr = reflect(w, wm);
    }
}

/// One walk's unbiased estimate of the multiple-scattering rough dielectric's f(wi, wo)·|cos θo|
/// (flux convention, as DielectricInterface::eval·|cos θo|), orders 1..max_order (Heitz et al.
/// 2016, stochastic evaluation). Zero for wi.z = 0 or wo.z = 0.
template <typename T, typename Uniform>
T eval_rough_dielectric_multiple(const GGX<T>& ggx, T eta, const Vec3<T>& wi, const Vec3<T>& wo,
                                 Uniform&& uniform, int max_order) {
    if (wo.z == 0) return T(0);
    T sum(0);
    walk_rough_dielectric_visiting(ggx, eta, wi, uniform, max_order,
                                   [&](const MicrosurfaceFacet<T>& facet) {
                                       sum += microsurface_dielectric_connect(ggx, eta, facet, wo);
                                   });
    return std::isfinite(sum) ? sum : T(0);
}

/// One walk's unbiased estimate of the multiple-scattering rough conductor's f(wi, wo)·cos θo
/// (RGB), orders 1..max_order. Zero unless wi.z > 0 and wo.z > 0.
template <typename T, typename Fresnel, typename Uniform>
Rgb<T> eval_rough_conductor_multiple(const GGX<T>& ggx, const Fresnel& fresnel, const Vec3<T>& wi,
                                     const Vec3<T>& wo, Uniform&& uniform, int max_order) {
    Rgb<T> sum(T(0));
    if (!(wo.z > 0)) return sum;
    walk_rough_conductor_visiting(ggx, fresnel, wi, uniform, max_order,
                                  [&](const MicrosurfaceFacet<T>& facet) {
                                      const MicrosurfaceConnection<T> c =
                                          microsurface_conductor_connect(ggx, fresnel, facet, wo);
                                      sum += c.weight * c.density;
                                  });
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(sum[c])) return Rgb<T>(T(0));
    return sum;
}

}  // namespace lamina

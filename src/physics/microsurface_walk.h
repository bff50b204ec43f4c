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

}  // namespace lamina

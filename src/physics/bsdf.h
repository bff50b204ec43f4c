#pragma once
// Conventions shared by every BSDF in lamina (docs/physics.md §1; docs/style.md §3). Read this
// first.
//
// - Local frame: z is the macro-surface normal, pointing up (into the medium above).
// - `wi` points towards the light, `wo` towards the viewer; both point *away* from the surface and
//   may lie on either side of it (a direction below the surface is a transmitted one).
// - eval(wi, wo) is the radiance BSDF for light arriving from wi and leaving towards wo, in 1/sr,
//   *without* the cosine factor. For transmission between media of indices η_i (wi's side) and
//   η_o (wo's side) it obeys generalized reciprocity f(wi, wo)/η_o² = f(wo, wi)/η_i².
// - sample(wi, u…) follows light (a particle arriving from wi) and draws an outgoing wo. Its
//   `weight` is eval(wi, wo)·|cos θo| / pdf(wi, wo) (for delta lobes, the ratio of the limits): the
//   factor that multiplies a particle's flux. This is the direction a goniophotometer traces.
// - A failed sample is an empty std::optional. Nothing here throws or allocates.

#include "core/rgb.h"
#include "core/vec.h"

namespace lamina {

template <typename T>
struct BsdfSample {
    Vec3<T> wo;
    /// eval(wi, wo)·|cos θo| / pdf: multiplies the particle's flux (RGB).
    Rgb<T> weight;
    /// Density of wo with respect to solid angle (0 for delta lobes).
    T pdf = 0;
    /// Parts of the weight, for energy budgets: weight = fresnel_weight · shadowing, where
    /// fresnel_weight < 1 is energy absorbed by an opaque base (conductor Fresnel, Lambertian
    /// albedo) and shadowing = G2/G1 < 1 is energy lost to the single-scattering microsurface.
    Rgb<T> fresnel_weight{T(1)};
    T shadowing = 1;
    bool is_delta = false;
    bool is_transmission = false;
};

/// True when a and b are on the same side of the surface (a reflection pair).
template <typename T>
constexpr bool same_hemisphere(const Vec3<T>& a, const Vec3<T>& b) {
    return a.z * b.z > 0;
}

}  // namespace lamina

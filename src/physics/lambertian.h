// A Lambertian (ideal diffuse, opaque) interface: f = albedo / π on the side light arrives from.
// Conventions: physics/bsdf.h.

#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/math.h"
#include "core/rgb.h"
#include "physics/bsdf.h"
#include "physics/sampling.h"

#include <optional>

// A lane header (core/lane.h): the particle event is a lane template, included once as an
// ordinary header and once per SIMD target; the interface type below it only once.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_LAMBERTIAN_LANES_H
#define LAMINA_PHYSICS_LAMBERTIAN_LANES_H
#define LAMINA_PHYSICS_LAMBERTIAN_BODY
#endif
#elif defined(LAMINA_PHYSICS_LAMBERTIAN_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_LAMBERTIAN_TARGET
#undef LAMINA_PHYSICS_LAMBERTIAN_TARGET
#else
#define LAMINA_PHYSICS_LAMBERTIAN_TARGET
#endif
#define LAMINA_PHYSICS_LAMBERTIAN_BODY
#endif

#ifdef LAMINA_PHYSICS_LAMBERTIAN_BODY
#undef LAMINA_PHYSICS_LAMBERTIAN_BODY

LAMINA_LANE_BEGIN

/// The Lambertian interface's particle event (LambertianInterface::sample): a cosine-distributed
/// direction on wi's side by Malley's method (a uniform point of the unit disk projected up onto
/// the hemisphere; e.g. Pharr, Jakob & Humphreys, PBR 4th ed., §A.5.3) with the disk point drawn
/// by the polar map r = √u1, φ = 2πu2 (the same density as the concentric map of sampling.h,
/// fewer operations on vectors), from u1, u2 in [0, 1). wi_z: the arriving direction's cosine; a
/// lane with wi_z = 0 belongs to neither side (the caller treats it as degenerate). A branch-free
/// lane template (core/lane.h): the scalar and the SIMD particle kernels evaluate these lines.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> lambertian_event(T wi_z, T u1, T u2) {
    const T zero = L::constant(0);
    T cos_phi, sin_phi;
    L::cos_sin_2pi(u2, cos_phi, sin_phi);
    const T r = L::sqrt(u1);
    const T z = L::sqrt(L::max(L::constant(1) - u1, zero));
    return {r * cos_phi, r * sin_phi, L::select(L::less(wi_z, zero), zero - z, z)};
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_LAMBERTIAN_BODY

#if !defined(LAMINA_LANE_TARGET) && !defined(LAMINA_PHYSICS_LAMBERTIAN_H)
#define LAMINA_PHYSICS_LAMBERTIAN_H

namespace lamina {

template <typename T>
struct LambertianInterface {
    Rgb<T> albedo;

    Rgb<T> eval(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (!same_hemisphere(wi, wo)) return Rgb<T>(T(0));
        return albedo * kInvPi<T>;
    }

    T pdf(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (!same_hemisphere(wi, wo)) return T(0);
        return std::abs(wo.z) * kInvPi<T>;
    }

    /// Cosine-distributed reflection on wi's side (lambertian_event at one lane); weight =
    /// albedo. Nothing for wi.z = 0.
    std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T u1, T u2) const {
        if (wi.z == 0) return std::nullopt;
        BsdfSample<T> s;
        const LaneVec3<T> wo = lambertian_event<T>(wi.z, u1, u2);
        s.wo = {wo.x, wo.y, wo.z};
        s.pdf = std::abs(s.wo.z) * kInvPi<T>;
        s.fresnel_weight = albedo;
        s.weight = albedo;
        return s;
    }
};

}  // namespace lamina

#endif  // LAMINA_PHYSICS_LAMBERTIAN_H

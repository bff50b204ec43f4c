#pragma once
// A Lambertian (ideal diffuse, opaque) interface: f = albedo / π on the side light arrives from.
// Conventions: physics/bsdf.h.

#include "core/math.h"
#include "core/rgb.h"
#include "physics/bsdf.h"
#include "physics/sampling.h"

#include <optional>

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

    /// Cosine-distributed reflection on wi's side; weight = albedo.
    std::optional<BsdfSample<T>> sample(const Vec3<T>& wi, T u1, T u2) const {
        if (wi.z == 0) return std::nullopt;
        BsdfSample<T> s;
        s.wo = sample_cosine_hemisphere(u1, u2);
        if (wi.z < 0) s.wo.z = -s.wo.z;
        s.pdf = std::abs(s.wo.z) * kInvPi<T>;
        s.fresnel_weight = albedo;
        s.weight = albedo;
        return s;
    }
};

}  // namespace lamina

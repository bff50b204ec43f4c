#pragma once
// The proposal the production coats sample with: a mixture of their lobes. A coat model's BRDF is
// a coat lobe (GGX), a base lobe (GGX over a metal) and, over a dielectric base, a diffuse term;
// it samples a reflected direction from one of them, picked at random, and reports the density of
// the whole mixture (one-sample multiple importance sampling, Veach 1997, §9.2.4: the weight is
// f cos θo / pdf with the mixture's pdf, whichever lobe drew the direction). The GGX lobes are
// sampled through the normals visible from wi (Heitz 2018, "Sampling the GGX distribution of
// visible normals", JCGT 7(4)), reflected about them; the diffuse term by the cosine.

#include "core/vec.h"
#include "models/model.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <optional>

namespace lamina {

/// The mixture: the coat lobe with probability `coat`, the base lobe with `base`, and, when
/// `diffuse`, the cosine with the rest (1 − coat − base); without a diffuse term the base takes
/// the rest. A lobe of weight 0 is never sampled nor evaluated (a smooth lobe's density is a
/// delta, which a model reports apart).
struct ReflectionLobeMixture {
    double coat = 0, base = 0;
    GGX<double> coat_lobe{0.0}, base_lobe{0.0};
    bool diffuse = false;

    /// A reflected direction for light arriving along wi (wi.z > 0) from three uniform numbers;
    /// it may point below the horizon (the caller rejects it).
    Vec3d sample(const Vec3d& wi, const Vec3d& u) const {
        if (u.z < coat) return reflect(wi, coat_lobe.sample_visible_normal(wi, u.x, u.y));
        if (!diffuse || u.z < coat + base)
            return reflect(wi, base_lobe.sample_visible_normal(wi, u.x, u.y));
        return sample_cosine_hemisphere(u.x, u.y);
    }

    /// The mixture's density of wo (per solid angle), both directions above the horizon.
    double pdf(const Vec3d& wi, const Vec3d& wo) const {
        const Vec3d h = normalize(wi + wo);
        const double jacobian = 1 / (4 * dot(wo, h));  // dωh/dωo for reflection
        double p = 0;
        if (coat > 0) p += coat * coat_lobe.pdf_visible_normal(wi, h) * jacobian;
        const double base_weight = diffuse ? base : 1 - coat;
        if (base_weight > 0) p += base_weight * base_lobe.pdf_visible_normal(wi, h) * jacobian;
        if (diffuse && coat + base < 1) p += (1 - coat - base) * pdf_cosine_hemisphere(wo);
        return p;
    }
};

/// A model's sample from its mixture: the direction the mixture draws, weighted by the model's
/// f cos θo over its pdf (which the model takes from the same mixture); none below the horizon
/// or where the density vanishes.
inline std::optional<ModelSample> sample_lobe_mixture(const Model& model,
                                                      const ReflectionLobeMixture& mixture,
                                                      const Vec3d& wi, const Vec3d& u) {
    const Vec3d wo = mixture.sample(wi, u);
    if (wo.z <= 0) return std::nullopt;
    const double density = model.pdf(wi, wo);
    if (!(density > 0)) return std::nullopt;
    return ModelSample{wo, model.eval(wi, wo) * (wo.z / density), density};
}

/// The sampling of a model whose proposal is its lobe mixture (the production coats, StackLit,
/// the filmed plastic): Derived, a final Model, provides has_sampling() and
/// proposal(wi), the ReflectionLobeMixture for light arriving along wi; reflection only, light
/// from above. Derived befriends this class when proposal is private.
template <class Derived>
class LobeMixtureModel : public Model {
  public:
    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!self().has_sampling() || wi.z <= 0) return std::nullopt;
        return sample_lobe_mixture(*this, self().proposal(wi), wi, u);
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!self().has_sampling() || wi.z <= 0 || wo.z <= 0) return 0;
        return self().proposal(wi).pdf(wi, wo);
    }

  private:
    const Derived& self() const { return static_cast<const Derived&>(*this); }
};

}  // namespace lamina

#pragma once
// The worked integration of docs/lamina1.md: lamina-1 as a pbrt-v4 BxDF (shown there line for
// line; the test lamina1_header compiles and runs it against pbrt_stub.h).
#include "lamina1/lamina1.h"
#include "pbrt_stub.h"

namespace pbrt {

// pbrt's directions: local shading frame, wo towards the camera, wi towards the light, f
// without the cosine. lamina-1's: light arriving from wi (above), leaving towards wo.
class Lamina1BxDF {
  public:
    // A built lamina1::Bsdf (per material; it reads tables that outlive it).
    explicit Lamina1BxDF(const lamina1::Bsdf* bsdf) : bsdf_(bsdf) {
        const lamina1::Layers& l = bsdf->layers();
        eta_below_ = l.eta0 * l.base_eta[0];  // a slab: the medium below over the one above
    }
    BxDFFlags Flags() const {
        return BxDFFlags(Reflection | Glossy | (bsdf_->support().btdf ? Transmission : Unset));
    }
    SampledSpectrum f(Vector3f wo, Vector3f wi, TransportMode mode) const {
        // Radiance flows from the light towards the camera; importance the other way.
        return mode == TransportMode::Radiance ? radiance(wi, wo) : radiance(wo, wi);
    }
    std::optional<BSDFSample> Sample_f(Vector3f wo, Float uc, Point2f u, TransportMode mode) const {
        Vector3f wi;
        if (wo.z > 0) {  // lamina-1's sampler: its reflection is reciprocal, drawn from wo
            const auto s = bsdf_->sample(in(wo), {uc, u.x, u.y});
            if (!s) return std::nullopt;
            wi = out(s->wo);
        } else {  // under a slab: the light above, cosine-distributed
            const lamina1::Vec3 d = lamina1::sample_cosine_hemisphere(u.x, u.y);
            wi = out(d);
        }
        const Float pdf = PDF(wo, wi, mode);
        if (!(pdf > 0)) return std::nullopt;
        const BxDFFlags side = (wo.z > 0) == (wi.z > 0) ? Reflection : Transmission;
        return BSDFSample{f(wo, wi, mode), wi, pdf, BxDFFlags(side | Glossy)};
    }
    Float PDF(Vector3f wo, Vector3f wi, TransportMode) const {
        if (wo.z > 0) return Float(bsdf_->pdf(in(wo), in(wi)));
        return wi.z > 0 ? Float(wi.z * lamina1::kInvPi) : 0;
    }

  private:
    // The radiance BSDF for light arriving from l and leaving towards v. lamina-1 models light
    // arriving from above; light from below a slab is its reverse path by the reciprocity of
    // radiance BSDFs, f(l → v)/η_v² = f(v → l)/η_l² (Veach 1997, Eq. 5.14).
    SampledSpectrum radiance(Vector3f l, Vector3f v) const {
        lamina1::Rgb c(0.0);
        if (l.z > 0)
            c = bsdf_->eval(in(l), in(v));
        else if (v.z > 0)
            c = bsdf_->eval(in(v), in(l)) * (1 / (eta_below_ * eta_below_));
        // pbrt-v4 turns RGB into its wavelength samples here, e.g.
        // RGBUnboundedSpectrum(*colorSpace, RGB(c[0], c[1], c[2])).Sample(lambda).
        return SampledSpectrum{{Float(c[0]), Float(c[1]), Float(c[2])}};
    }
    static lamina1::Vec3 in(Vector3f w) { return {w.x, w.y, w.z}; }
    static Vector3f out(lamina1::Vec3 w) { return {Float(w.x), Float(w.y), Float(w.z)}; }

    const lamina1::Bsdf* bsdf_;
    double eta_below_ = 1;
};

}  // namespace pbrt

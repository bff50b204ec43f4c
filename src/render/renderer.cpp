#include "render/renderer.h"

#include "core/frame.h"
#include "core/math.h"
#include "core/progress.h"
#include "core/rng.h"
#include "models/random_walk_model.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <omp.h>

#include <chrono>
#include <cmath>

namespace lamina {

namespace {

// The light-sampling mixture of strategy A: cosine about n, a GGX lobe (visible normals seen from
// the view direction wo, reflected: the density of a rough mirror, Heitz 2018) and the cap lights
// (uniform in their cones, solid angle 2π(1 − cos_max)), with probabilities c_cos, c_lobe and
// c_cap each. `wi`, `wo` are local to the shading frame, `d_world` is wi in the world.
struct Mixture {
    const Environment& env;
    GGX<double> ggx;
    double c_cos, c_lobe, c_cap;

    Mixture(const Environment& e, double alpha) : env(e), ggx{std::max(alpha, 1e-3)} {
        const bool caps = !e.caps.empty(), lobe = alpha > 0;
        c_lobe = lobe ? (caps ? 0.3 : 0.5) : 0.0;
        c_cap = caps ? (lobe ? 0.4 : 0.5) / double(e.caps.size()) : 0.0;
        c_cos = 1 - c_lobe - c_cap * double(e.caps.size());
    }

    double pdf(const Vec3d& d_world, const Vec3d& wi, const Vec3d& wo) const {
        double p = wi.z > 0 ? c_cos * wi.z * kInvPi<double> : 0.0;
        if (c_lobe > 0 && wi.z > 0) {
            const Vec3d wm = normalize(wi + wo);
            const double c = dot(wo, wm);
            if (c > 0) p += c_lobe * ggx.pdf_visible_normal(wo, wm) / (4 * c);
        }
        for (const CapLight& cap : env.caps)
            if (dot(d_world, cap.direction) >= cap.cos_max)
                p += c_cap / (2 * kPi<double> * (1 - cap.cos_max));
        return p;
    }

    Vec3d sample(const Frame<double>& frame, const Vec3d& wo, ParticleRng& rng) const {
        const double us = rng.uniform_double(), u1 = rng.uniform_double(),
                     u2 = rng.uniform_double();
        if (us < c_cos) return frame.to_world(sample_cosine_hemisphere(u1, u2));
        if (us < c_cos + c_lobe)
            return frame.to_world(reflect(wo, ggx.sample_visible_normal_caps(wo, u1, u2)));
        const std::size_t k =
            std::min(env.caps.size() - 1, std::size_t((us - c_cos - c_lobe) / c_cap));
        const CapLight& c = env.caps[k];
        const double cos_t = 1 - u1 * (1 - c.cos_max);
        const double sin_t = safe_sqrt(1 - cos_t * cos_t);
        const double phi = 2 * kPi<double> * u2;
        return Frame<double>::from_normal(c.direction)
            .to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t});
    }
};

}  // namespace

Rendering render_sphere(const Model& model, const Environment& env, const RenderSettings& s) {
    const auto start = std::chrono::steady_clock::now();
    const auto* rw = dynamic_cast<const RandomWalkModel*>(&model);
    const RandomWalkStack* walker = rw ? &rw->walker() : nullptr;
    const int N = s.size;
    Rendering out;
    out.image = Image(N, N);
    out.mask.assign(std::size_t(N) * N, 0);
    const Mixture mix(env, s.lobe_alpha);
    const Vec3d view(0, 0, 1);
    const double px = 2 * s.extent / N;
    const int threads = s.threads > 0 ? s.threads : omp_get_max_threads();
    Progress progress("render " + model.name(), "rows", std::uint64_t(N));
    if (!s.progress) progress.finish();

    // Radiance towards the camera from the sphere point with normal n, one sample.
    auto shade = [&](const Vec3d& n, ParticleRng& rng) {
        const Frame<double> frame = Frame<double>::from_normal(n);
        const Vec3d wo = frame.to_local(view);
        if (wo.z <= 1e-9) return Rgbd(0.0);
        Rgbd L(0.0);
        auto f_at = [&](const Vec3d& wi) {
            return walker ? walker->eval_once(wi, wo, rng) : model.eval(wi, wo);
        };
        // (A) the light-sampling mixture.
        {
            const Vec3d d = mix.sample(frame, wo, rng);
            const Vec3d wi = frame.to_local(d);
            if (wi.z > 0) {
                const double p = mix.pdf(d, wi, wo);
                double w = 1;
                if (walker) w = p / (p + wi.z * kInvPi<double>);
                if (p > 0) L += f_at(wi) * env.radiance(d) * (wi.z * w / p);
            }
        }
        // (B) the random walk's own sample (reciprocity: a walk from wo exits towards wi).
        if (walker) {
            if (const auto smp = walker->sample(wo, rng); smp && !smp->is_delta && smp->wo.z > 0) {
                const Vec3d d = frame.to_world(smp->wo);
                const double q = smp->wo.z * kInvPi<double>;
                L += smp->weight * env.radiance(d) * (q / (mix.pdf(d, smp->wo, wo) + q));
            }
        }
        // Delta lobes, exactly (reciprocity: the lobes seen from wo).
        for (const DeltaLobe& lobe : model.delta_lobes(wo))
            if (lobe.direction.z > 0)
                L += lobe.energy * env.radiance(frame.to_world(lobe.direction));
        // The directional light.
        if (env.sun) {
            const Vec3d wi = frame.to_local(env.sun->direction);
            if (wi.z > 0) L += f_at(wi) * env.sun->irradiance * wi.z;
        }
        return L;
    };

#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int y = 0; y < N; ++y) {
        for (int x = 0; x < N; ++x) {
            const std::size_t pixel = std::size_t(y) * N + x;
            const double cx = -s.extent + (x + 0.5) * px, cy = s.extent - (y + 0.5) * px;
            out.mask[pixel] = std::hypot(std::abs(cx) + px / 2, std::abs(cy) + px / 2) < 1;
            Rgbd sum(0.0);
            for (int k = 0; k < s.spp; ++k) {
                ParticleRng rng(s.seed, pixel, std::uint64_t(k));
                const double sx = -s.extent + (x + rng.uniform_double()) * px;
                const double sy = s.extent - (y + rng.uniform_double()) * px;
                const double r2 = sx * sx + sy * sy;
                if (r2 >= 1) {
                    sum += Rgbd(s.background);
                    continue;
                }
                sum += shade(Vec3d(sx, sy, std::sqrt(1 - r2)), rng);
            }
            out.image.at(x, y) = Rgbf(sum / double(s.spp));
        }
        if (s.progress) progress.advance(1);
    }
    progress.finish();
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return out;
}

double lobe_alpha_for(const Stack& stack) {
    const InterfaceSpec& top = stack.layers.front().interface;
    if (top.type == InterfaceType::Lambertian) return 0;
    return std::clamp(top.alpha, 0.02, 1.0);
}

}  // namespace lamina

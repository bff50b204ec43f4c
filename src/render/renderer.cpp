#include "render/renderer.h"

#include "core/frame.h"
#include "core/math.h"
#include "core/progress.h"
#include "core/rng.h"
#include "models/random_walk/random_walk_model.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <omp.h>

#include <chrono>
#include <cmath>

namespace lamina {

namespace {

constexpr int kMaxChords = 10'000;  ///< safety cap on chords inside a transparent sphere

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
    // Transparent spheres (docs/rendering.md §2.1): the random walk of a transmitting stack, seen
    // from below inside the sphere.
    const RandomWalkStack* flipped = walker && s.transparent ? rw->flipped_walker() : nullptr;
    // Generalized reciprocity, f(wi, wo)/η_o² = f(wo, wi)/η_i² (bsdf.h; Veach 1997, §6.2):
    // a walk from the viewer estimates f(v → w); light from w on the other side needs
    // f(w → v) = f(v → w)·(η_v/η_w)².
    const double out_over_in =
        flipped ? sqr(walker->eta_top() / walker->eta_bottom()) : 1.0;  // (η_outside/η_inside)²
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

    // Radiance arriving at the sphere point x (|x| = 1) from inside, travelling against `d` (d
    // points from x into the sphere): the ray crosses the sphere's inside (homogeneous, index
    // η_inside, no medium) to the far side, whose stack is met from below — the flipped stack,
    // with its top towards the inside. A walk of the flipped stack from the direction back to x
    // either exits to the outside (the environment, through (η_inside/η_outside)²) or reflects
    // into the sphere (the next chord). The directional light is added by next-event estimation at
    // every inner vertex (a delta light cannot be hit). Russian roulette after 8 chords with
    // survival min(0.95, max throughput), divided out (unbiased; ends almost surely).
    auto inside = [&](Vec3d x, Vec3d d, ParticleRng& rng) {
        Rgbd L(0.0), throughput(1.0);
        for (int chord = 0; chord < kMaxChords; ++chord) {
            const double t = -2 * dot(x, d);  // |x + t d| = 1
            if (!(t > 0)) break;              // tangent: no far side
            x = normalize(x + d * t);
            // The far side seen from inside, normal −x. Brushed: the outside frame's tangent and
            // bitangent with the normal turned over, since flipped_stack keeps every azimuth
            // (z → −z, layers/stack.h); a left-handed frame, which to_local/to_world allow.
            const Frame<double> inner = [&] {
                if (!s.brushed) return Frame<double>::from_normal(-x);
                const Frame<double> outer = shading_frame(x, true);
                return Frame<double>{outer.s, outer.t, -x};
            }();
            const Vec3d v = inner.to_local(-d);
            if (v.z <= 0) break;
            if (env.sun) {
                const Vec3d sun = inner.to_local(env.sun->direction);
                if (sun.z < 0)
                    L += throughput * flipped->eval_once(v, sun, rng) * env.sun->irradiance *
                         (-sun.z / out_over_in);
            }
            const auto smp = flipped->sample(v, rng);
            if (!smp) break;
            throughput *= smp->weight;
            d = inner.to_world(smp->wo);
            if (smp->wo.z < 0) {
                L += throughput * env.radiance(d) / out_over_in;
                break;
            }
            if (chord >= 8) {
                const double q = std::min(0.95, throughput.max());
                if (!(rng.uniform_double() < q)) break;
                throughput = throughput / q;
            }
        }
        return L;
    };

    // Radiance towards the camera from the sphere point with normal n, one sample.
    auto shade = [&](const Vec3d& n, ParticleRng& rng) {
        const Frame<double> frame = shading_frame(n, s.brushed);
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
        // Exits below the surface carry light from inside the sphere (transparent spheres only;
        // delta exits too: no other strategy samples the inside).
        if (walker) {
            if (const auto smp = walker->sample(wo, rng); smp && smp->wo.z > 0) {
                if (!smp->is_delta) {
                    const Vec3d d = frame.to_world(smp->wo);
                    const double q = smp->wo.z * kInvPi<double>;
                    L += smp->weight * env.radiance(d) * (q / (mix.pdf(d, smp->wo, wo) + q));
                }
            } else if (smp && flipped) {
                L += smp->weight * inside(n, frame.to_world(smp->wo), rng) * out_over_in;
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

bool brushed_for(const Stack& stack) {
    return stack.is_anisotropic();
}

Frame<double> shading_frame(const Vec3d& n, bool brushed) {
    const double r = std::hypot(n.x, n.z);
    if (!brushed || r < 1e-9) return Frame<double>::from_normal(n);
    const Vec3d tangent(n.z / r, 0, -n.x / r);
    return {tangent, cross(n, tangent), n};
}

double lobe_alpha_for(const Stack& stack) {
    const InterfaceSpec& top = stack.layers.front().interface;
    if (top.type == InterfaceType::Lambertian) return 0;
    return std::clamp(top.alpha, 0.02, 1.0);
}

}  // namespace lamina

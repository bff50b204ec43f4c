#pragma once
// A sphere of a material under procedural lighting (docs/rendering.md §2).
//
// Orthographic camera along −z; the unit sphere fills the middle of a square image over a neutral
// background. At a visible point with normal n and view direction v the outgoing radiance
//   L(v) = ∫ f(wi, v) L_env(wi) cos θi dωi + Σ_delta lobes E_k L_env(w_k) + f(s, v) E_sun cos θs
// is estimated per sample by
//   (A) one direction from the mixture "cosine about n" + "a GGX lobe about the mirror direction of
//       v" (settings.lobe_alpha > 0) + "each cap light" (one-sample balance
//       heuristic over these strategies, so any BSDF works through eval alone), weighted by
//       f·L·cos/p_mix — for the random walk, f is one walk's unbiased estimate;
//   (B) random walk only: its own sample (a walk from v, reciprocity), weight·L;
//   A and B are combined with MIS weights p_mix/(p_mix + q) and q/(p_mix + q), q = cos θ/π a proxy
//   of the walk's exit density: the weights sum to one for every direction, so the combination is
//   unbiased whatever q is (Veach 1997, §9.2.2; why not the walk's own pdf estimate:
//   docs/rendering.md §2); delta exits of B are dropped because delta lobes
//   are added exactly (Model::delta_lobes) for every model, the random walk included.
// A transmitting stack (a slab) rendered by the random walk is a transparent sphere: the walk's
// exits below the surface continue inside the sphere, meet the far side's stack from below and
// leave to the environment (docs/rendering.md §2.1; `settings.transparent`). The analytic models,
// and the random walk with transparent = false, render the BRDF only (light from below the
// tangent plane is ignored).
//
// Reproducible: sample s of pixel p draws from ParticleRng(seed, p, s) (core/rng.h), whatever
// thread renders it. OpenMP over rows; progress on stderr.

#include "core/frame.h"
#include "layers/stack.h"
#include "models/model.h"
#include "render/environment.h"
#include "render/image.h"

#include <cstdint>

namespace lamina {

struct RenderSettings {
    int size = 512;  ///< image width = height, pixels
    int spp = 64;    ///< samples per pixel
    std::uint64_t seed = 1;
    int threads = 0;         ///< 0: all available
    Rgbf background{0.18f};  ///< neutral grey behind the sphere (linear)
    bool progress = true;
    double extent = 1.15;  ///< half-width of the view in sphere radii
    /// Roughness of a GGX reflection lobe about the view's mirror direction added to the
    /// light-sampling mixture (0: none). Only a proposal density — values always come from the
    /// model — so any value is unbiased; `lobe_alpha_for(stack)` picks the top interface's α.
    double lobe_alpha = 0;
    /// Render a transmitting stack as a transparent sphere (random walk only); false: the BRDF
    /// only, as the analytic models are rendered (comparison sheets use false).
    bool transparent = true;
    /// Shading frames whose tangent runs along the sphere's circles of latitude about the image's
    /// vertical axis (a sphere brushed on a lathe), so that an anisotropic interface's tangent
    /// (tangent_deg from it) is one smooth field over the sphere; false: any frame about the
    /// normal, which is all an isotropic stack needs. `brushed_for(stack)` picks it.
    bool brushed = false;
};

struct Rendering {
    Image image;
    /// Pixels entirely on the sphere (for error metrics): 1 inside, 0 elsewhere.
    std::vector<char> mask;
    double seconds = 0;
};

/// A proposal roughness for `stack`: its top interface's α clamped to [0.02, 1] (0 for a
/// Lambertian top).
double lobe_alpha_for(const Stack& stack);

/// Whether `stack` needs the brushed tangent field (RenderSettings::brushed): it is anisotropic.
bool brushed_for(const Stack& stack);

/// The shading frame at the sphere point with unit normal n: with `brushed`, its first axis is the
/// tangent of the circle of latitude about the vertical axis y, (n_z, 0, −n_x)/√(n_x² + n_z²),
/// turning counter-clockwise seen from above; at the poles, and without `brushed`, the branchless
/// frame of core/frame.h.
Frame<double> shading_frame(const Vec3d& n, bool brushed);

/// Renders `model` (analytic, or RandomWalkModel through its walker). The model's BRDF must be
/// supported (support().brdf).
Rendering render_sphere(const Model& model, const Environment& env, const RenderSettings& settings);

}  // namespace lamina

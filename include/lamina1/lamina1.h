#pragma once
// lamina-1, lamina's layered BSDF, as a header library: C++17 and its standard library, nothing
// else. Include this file; it includes the rest of lamina1/.
//
//   lamina1::Tables tables;                       // once: the generic tables (lamina1/tables.h)
//   tables.read("lamina1.tables");                // the data file `lamina export --lamina1-tables`
//   lamina1::Layers layers;                       // a material: coat over a base
//   layers.eta0 = 1.5; layers.alpha0 = 0.1;       //   (relative indices, GGX roughnesses)
//   layers.base = lamina1::Base::Conductor;
//   layers.base_eta = {0.14, 0.37, 1.44}; layers.base_k = {3.98, 2.39, 1.60}; layers.alpha1 = 0.2;
//   const lamina1::Bsdf bsdf(layers, tables);     // the per-material precomputation (≈ 1 ms)
//   lamina1::Rgb f = bsdf.eval(wi, wo);           // 1/sr, cosine excluded
//   auto s = bsdf.sample(wi, {u0, u1, u2});       // s->wo, s->weight = f |cos θo| / pdf, s->pdf
//
// Conventions: a local frame with z the macro normal pointing into the ambient medium above
// the coat; directions unit and pointing away from the surface; wi the direction light arrives
// from (wi.z > 0), wo the direction it leaves towards (wo.z > 0 reflection, wo.z < 0 a slab's
// transmission). The BSDF is a radiance BSDF (f(wi, wo) cos θi dωi dL = dL_o). Its reflection is
// reciprocal, f(wi, wo) = f(wo, wi), so a renderer that evaluates f(wo_camera, wi_light) may
// pass its directions in either order; lamina1/renderer.h has the adapter a path tracer uses
// (sampling the light direction from the camera's side, transmission both ways). Nothing here
// throws after construction; every function is const and thread-safe on a built Bsdf.
//
// lamina's docs/models.md ("lamina-1") derives the model, and docs/lamina1.md shows a
// pbrt-v4 BxDF and a Mitsuba 3 BSDF built on it.

#include "lamina1/bsdf.h"
#include "lamina1/coat.h"
#include "lamina1/eval.h"
#include "lamina1/gpu.h"
#include "lamina1/media.h"
#include "lamina1/sampling.h"
#include "lamina1/slab.h"

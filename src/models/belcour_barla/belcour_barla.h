#pragma once
// bb17: Belcour & Barla 2017, "A practical extension to microfacet theory for the modeling of
// varying iridescence" (ACM TOG 36(4)), as their supplemental BRDF Explorer shader evaluates it:
// one rough interface with a thin film on its base, the GGX microfacet BRDF
//
//   f(wi, wo) = D(h) G1(wi) G1(wo) F(h·wi) / (4 μi μo),    h = normalize(wi + wo),
//
// D the GGX distribution of roughness α, G1 Smith's masking (uncorrelated: the product), F the
// shader's iridescent Fresnel term (models/production/film_fresnel.h, belcour_barla_fresnel): the
// film's Airy sum to the third order, integrated against the CIE functions and returned in CIE 1931
// RGB. A lamina stack it represents: a conductor (α ≥ 0) under the ambient (alone, or under a
// smooth clear interface of the ambient's index, which is none), with or without a transparent
// film of index at least the ambient's, thickness one value or a range (averaged over).
// The shader's outside index is 1: lamina passes the indices relative to the ambient, and Dinc =
// 2 η_f d (the film's optical path at normal incidence, µm). docs/models.md, "Belcour & Barla
// 2017".

#include "models/model.h"
#include "models/model_options.h"

#include <memory>
#include <vector>

namespace lamina {

/// The options of bb17: `kappa3` (how a stack's conductor κ reaches the shader's κ3) and
/// `primaries` (the colour its Fresnel term returns: the shader's CIE 1931 RGB, or linear sRGB).
std::vector<OptionSpec> belcour_barla_options();

/// The model for `stack` (not supported, with the reason, for any other shape).
std::unique_ptr<Model> make_belcour_barla(const Stack& stack, const ModelOptions& options);

}  // namespace lamina

#pragma once
// The Weidlich–Wilkie family (docs/models.md, "The Weidlich–Wilkie family"): WW09, Ele10 and WW'
// are one formula with different choices, which are the flags below. Weidlich & Wilkie 2007,
// "Arbitrarily layered micro-facet surfaces" (GRAPHITE), §4:
//
//     f = f_top(wi, wo) + T01 · f_base(wi*, wo*) · a · t            (no inter-reflection)
//
// Each variant is a WWChoices value; its source file (ww09.cpp, ele10.cpp, ww_prime.cpp) holds
// its defaults and its entry point.

#include "models/model.h"

#include <string>
#include <vector>

namespace lamina {

struct WWChoices {
    /// Fresnel transmittances T01 (entering) and T10 (leaving) at the half vector h or at n.
    bool fresnel_at_h = false;
    /// Refracted directions (wi', wo') about h or about n.
    bool refract_about_h = false;
    /// f_base evaluated at the outside directions (WW09's code) or the refracted ones.
    bool base_at_outside = false;
    /// Exit factor: t = (1 − G) + T10·G with G = G2_α0(wi, wo) (WW07/09, Ele10), or T10 alone.
    bool exit_t_term = false;
    /// Multiply the base term by 1/η0² (solid-angle compression; Hanrahan & Krueger 1993, Eq. 8).
    bool eta2_factor = false;
    /// α1 ← max(α0, α1) (Elek 2010, Algorithm 1).
    bool max_roughness = false;
};

/// The flags of the family (defaults are each variant's own).
std::vector<OptionSpec> ww_option_specs(const WWChoices& defaults);
/// The choices named by validated options.
WWChoices ww_choices(const ModelOptions& options);

/// Builds one member of the family; `model_name` appears in support reasons.
std::unique_ptr<Model> make_ww_model(std::string model_name, const Stack& stack,
                                     const WWChoices& choices);

}  // namespace lamina

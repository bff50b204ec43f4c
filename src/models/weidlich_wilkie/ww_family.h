#pragma once
// The Weidlich–Wilkie family (docs/models.md, "The Weidlich–Wilkie family"): WW09, Ele10 and WW'
// are one formula with different choices, which are the flags below. Weidlich & Wilkie 2007,
// "Arbitrarily layered micro-facet surfaces" (GRAPHITE), §4:
//
//     f = f_top(wi, wo) + T01 · f_base(wi*, wo*) · a · t            (no inter-reflection)
//
// Each variant (ww09, ele10, ww-prime) is a WWChoices value, its defaults; the family's options
// (ww_option_table) can turn any of them into any other.

#include "models/model.h"
#include "models/model_options.h"

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

/// The flags of the family.
const ModelOptionTable<WWChoices>& ww_option_table();
/// The defaults of a variant: "ww09", "ele10" or "ww-prime" (a programming error otherwise).
WWChoices ww_variant(const std::string& variant);

/// A member of the family with `choices`; `name` appears in support reasons.
std::unique_ptr<Model> make_ww_model(const std::string& name, const Stack& stack,
                                     const WWChoices& choices);

}  // namespace lamina

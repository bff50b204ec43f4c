// WW09: Weidlich & Wilkie's layered model as implemented in their SIGGRAPH Asia 2009 course code
// (docs/models.md table, row WW09). T01 and the refractions use the half vector h; the base BRDF is
// evaluated at the *outside* directions (wi, wo) — this looks like a bug, but it is what the code
// did, so lamina implements it faithfully; t = (1 − G) + T10·G (Weidlich & Wilkie 2007, §4.2).
#include "models/factories.h"
#include "models/ww_family.h"

namespace lamina {

namespace {
WWChoices ww09_defaults() {
    WWChoices c;
    c.fresnel_at_h = true;
    c.refract_about_h = true;
    c.base_at_outside = true;
    c.exit_t_term = true;
    c.eta2_factor = false;
    c.max_roughness = false;
    return c;
}
}  // namespace

std::vector<OptionSpec> ww09_options() {
    return ww_option_specs(ww09_defaults());
}

std::unique_ptr<Model> make_ww09(const Stack& stack, const ModelOptions& options) {
    return make_ww_model("ww09", stack, ww_choices(options));
}

}  // namespace lamina

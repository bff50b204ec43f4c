// Ele10: Elek 2010, "Layered materials in real-time rendering", CESCG, Algorithm 1 (docs/models.md
// table, row Ele10). T01 and t at the half vector h; refraction about the macro normal n; the base
// BRDF at the refracted directions with α1 ← max(α0, α1); no 1/η0² factor.
#include "models/factories.h"
#include "models/ww_family.h"

namespace lamina {

namespace {
WWChoices ele10_defaults() {
    WWChoices c;
    c.fresnel_at_h = true;
    c.refract_about_h = false;
    c.base_at_outside = false;
    c.exit_t_term = true;
    c.eta2_factor = false;
    c.max_roughness = true;
    return c;
}
}  // namespace

std::vector<OptionSpec> ele10_options() {
    return ww_option_specs(ele10_defaults());
}

std::unique_ptr<Model> make_ele10(const Stack& stack, const ModelOptions& options) {
    return make_ww_model("ele10", stack, ww_choices(options));
}

}  // namespace lamina

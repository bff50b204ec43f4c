// WW': the study's correction of the Weidlich–Wilkie family (docs/models.md table, row WW'):
//     f = f_top + T01(μi) · f_base(wi', wo') · a / η0² · T10(μo)
// with Fresnel and refraction about the macro normal n, the exit transmission T10 instead of t,
// the solid-angle compression 1/η0² (Hanrahan & Krueger 1993, Eq. 8) and α1 ← max(α0, α1). For a
// smooth coat over a Lambertian base with τ = 0 it is the first term of the exact series
// (docs/physics.md §6.3).
#include "models/factories.h"
#include "models/ww_family.h"

namespace lamina {

namespace {
WWChoices ww_prime_defaults() {
    WWChoices c;
    c.fresnel_at_h = false;
    c.refract_about_h = false;
    c.base_at_outside = false;
    c.exit_t_term = false;
    c.eta2_factor = true;
    c.max_roughness = true;
    return c;
}
}  // namespace

std::vector<OptionSpec> ww_prime_options() {
    return ww_option_specs(ww_prime_defaults());
}

std::unique_ptr<Model> make_ww_prime(const Stack& stack, const ModelOptions& options) {
    return make_ww_model("ww-prime", stack, ww_choices(options));
}

}  // namespace lamina

// Bel18 forward: Belcour 2018 with the adding scheme fed the incident direction's own cosine
// c0 = μi (as in the author's renderer); the lobe statistics then depend only on wi, so the study
// computes them once per incidence (prepare). Not reciprocal. BRDF only; no Lambertian base.
#include "models/belcour.h"
#include "models/factories.h"

namespace lamina {

std::vector<OptionSpec> bel18_forward_options() {
    return belcour_option_specs({});
}

std::unique_ptr<Model> make_bel18_forward(const Stack& stack, const ModelOptions& options) {
    return make_belcour_model("bel18-forward", stack, belcour_choices(options, {}));
}

}  // namespace lamina

// Bel': the study's correction of Belcour 2018 (docs/models.md): Bel18 forward with lobe 0 replaced
// by the exact microfacet reflection of the top interface (Walter et al. 2007, Eq. 20), and the
// slab's BTDF as one transmitted GGX lobe of energy T0i, roughness α(sT0i) and the refracted mean
// direction, evaluated as the mirror image through z = 0 of a reflection lobe with those
// statistics.
#include "models/belcour.h"
#include "models/factories.h"

namespace lamina {

namespace {
BelcourChoices bel_prime_defaults() {
    BelcourChoices c;
    c.exact_top = true;
    c.btdf = true;
    return c;
}
}  // namespace

std::vector<OptionSpec> bel_prime_options() {
    return belcour_option_specs(bel_prime_defaults());
}

std::unique_ptr<Model> make_bel_prime(const Stack& stack, const ModelOptions& options) {
    return make_belcour_model("bel-prime", stack, belcour_choices(options, bel_prime_defaults()));
}

}  // namespace lamina

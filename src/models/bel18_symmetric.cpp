// Bel18 symmetric: Belcour 2018 with c0 = |wi·h| = |wo·h| (paper §7, "reciprocity"): the lobe
// statistics are recomputed for every pair (table lookups only) and the BRDF is reciprocal by
// construction. BRDF only; no Lambertian base.
#include "models/belcour.h"
#include "models/factories.h"

namespace lamina {

namespace {
BelcourChoices symmetric_defaults() {
    BelcourChoices c;
    c.symmetric = true;
    return c;
}
}  // namespace

std::vector<OptionSpec> bel18_symmetric_options() {
    return belcour_option_specs(symmetric_defaults());
}

std::unique_ptr<Model> make_bel18_symmetric(const Stack& stack, const ModelOptions& options) {
    return make_belcour_model("bel18-symmetric", stack,
                              belcour_choices(options, symmetric_defaults()));
}

}  // namespace lamina

// tm2: the transfer-matrix model of Randrianandrasana, Callet & Lucas 2021 over a conductor base
// (the released plugin tm2), with lobe 0 replaced by the exact top-interface reflection as the
// released code does. models/transfer_matrix.h has the scheme; docs/models.md the choices.
#include "models/factories.h"
#include "models/transfer_matrix.h"

namespace lamina {

namespace {
TmChoices tm2_defaults() {
    return TmChoices{};
}
TmChoices tm2_dielectric_defaults() {
    TmChoices c;
    c.exact_top = false;  // the released tm2_dielectric has no top correction
    c.slab = true;
    return c;
}
}  // namespace

std::vector<OptionSpec> tm2_options() {
    return tm_option_specs(tm2_defaults());
}

std::unique_ptr<Model> make_tm2(const Stack& stack, const ModelOptions& options) {
    return make_tm_model("tm2", stack, tm_choices(options, tm2_defaults()));
}

// tm2-dielectric: the slab variant (the released plugin tm2_dielectric): dielectric interfaces
// only, every lobe from the matrices, and the transmitted lobe.
std::vector<OptionSpec> tm2_dielectric_options() {
    return tm_option_specs(tm2_dielectric_defaults());
}

std::unique_ptr<Model> make_tm2_dielectric(const Stack& stack, const ModelOptions& options) {
    return make_tm_model("tm2-dielectric", stack, tm_choices(options, tm2_dielectric_defaults()));
}

}  // namespace lamina

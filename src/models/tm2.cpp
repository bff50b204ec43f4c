// tm2: the transfer-matrix model of Randrianandrasana, Callet & Lucas 2021 as released: over a
// conductor base the plugin tm2 (lobe 0 replaced by the exact top-interface reflection), over a
// dielectric base (a slab) the plugin tm2_dielectric (every lobe from the matrices, plus the
// transmitted lobe). models/transfer_matrix.h has the scheme; docs/models.md the choices.
#include "models/factories.h"
#include "models/transfer_matrix.h"

namespace lamina {

std::vector<OptionSpec> tm2_options() {
    return tm_option_specs();
}

std::unique_ptr<Model> make_tm2(const Stack& stack, const ModelOptions& options) {
    return make_tm_model("tm2", stack, tm_choices(options));
}

}  // namespace lamina

// tm6: the transfer-matrix model of Randrianandrasana, Callet & Lucas 2021 with Henyey–Greenstein
// media, as released (the plugin tm6): six fluxes (primary, forward- and back-scattered), three
// lobes per component, the exact top reflection, every other lobe normalized by its GGX albedo;
// over a conductor base. models/transfer_matrix.h has the scheme; docs/models.md the choices.
#include "models/factories.h"
#include "models/transfer_matrix.h"

namespace lamina {

std::vector<OptionSpec> tm6_options() {
    return tm6_option_specs();
}

std::unique_ptr<Model> make_tm6(const Stack& stack, const ModelOptions& options) {
    TmChoices choices = tm_choices(options);
    choices.scattering = true;
    return make_tm_model("tm6", stack, choices);
}

}  // namespace lamina

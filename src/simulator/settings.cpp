#include "simulator/goniophotometer.h"

namespace lamina {

// Apart from the kernels' translation unit (goniophotometer.cpp), so that what the settings
// instantiate (JSON) leaves the compiler's inlining of the particle code as it is.
void validate_settings(const SimulationSettings& s, const std::string& where) {
    // Every setting through its codec's checks (core/setting.h): what is written reads back.
    SimulationSettings copy;
    settings_from_json(copy, settings_to_json(s), where);
}

}  // namespace lamina

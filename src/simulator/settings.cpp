#include "simulator/goniophotometer.h"

namespace lamina {

// Apart from the kernels' translation unit (goniophotometer.cpp), so that what the settings
// instantiate (JSON) leaves the compiler's inlining of the particle code as it is.
void validate_settings(const SimulationSettings& s, const std::string& where) {
    // Every setting through its codec's checks (core/setting.h): what is written reads back.
    SimulationSettings copy;
    settings_from_json(copy, settings_to_json(s), where);
    // The run's own fields, set by the Mueller tables (simulator/mueller.h).
    if (s.incident_polarization < 0 || s.incident_polarization > 6)
        throw InputError(where, "incident_polarization", "must be in [0, 6]");
    if (!s.transport.polarization && (s.incident_polarization != 0 || s.stokes_tallies))
        throw InputError(where, "polarization",
                         "polarized incident light and Stokes tallies need polarization on");
}

}  // namespace lamina

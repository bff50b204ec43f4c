#pragma once
// The incidences θi lamina uses when none are given (the original study's seven angles), and the
// range every incidence must lie in: one owner for the simulator, the study and the CLI.
//
// Domain: θi in degrees from the macro-surface normal, [0, 90) — 90° is the horizon, where no
// light reaches the surface.

#include "core/error.h"

#include <fmt/format.h>

#include <string>
#include <vector>

namespace lamina {

/// 0, 15, 30, 45, 60, 70, 80 degrees.
inline std::vector<double> default_incidences_deg() {
    return {0, 15, 30, 45, 60, 70, 80};
}

/// The same as command-line text, "0,15,30,45,60,70,80".
inline std::string default_incidences_text() {
    return fmt::format("{}", fmt::join(default_incidences_deg(), ","));
}

/// θi in [0, 90) degrees (NaN is not).
inline bool incidence_in_range(double theta_i_deg) {
    return theta_i_deg >= 0 && theta_i_deg < 90;
}

/// InputError naming `where` and `field` for an incidence outside [0, 90) degrees.
inline void check_incidence(double theta_i_deg, const std::string& where,
                            const std::string& field) {
    if (!incidence_in_range(theta_i_deg))
        throw InputError(
            where, field,
            fmt::format("{} is outside the allowed range [0, 90) degrees", theta_i_deg));
}

/// Checks a list of incidences in place: each in range (check_incidence), none given twice (a
/// table holds one block per incidence); −0 becomes 0.
inline void check_incidence_list(std::vector<double>& theta_i_deg, const std::string& where,
                                 const std::string& field) {
    for (std::size_t k = 0; k < theta_i_deg.size(); ++k) {
        check_incidence(theta_i_deg[k], where, field);
        theta_i_deg[k] += 0.0;  // −0 + 0 = +0
        for (std::size_t m = 0; m < k; ++m)
            if (theta_i_deg[m] == theta_i_deg[k])
                throw InputError(where, field,
                                 fmt::format("{} degrees is given twice", theta_i_deg[k]));
    }
}

}  // namespace lamina

#pragma once
// What a tabulated Stokes vector says about the light's polarization (docs/physics.md §8): its
// degree of polarization, with a standard error, and the angle of its linear part. The vector is
// a bin's average (S0, S1, S2, S3) in the bin's tabulation frame (x ∝ ẑ × d, horizontal and ⊥ to
// the vertical plane of the direction d), each component with its own standard error.

#include <array>
#include <cmath>

namespace lamina {

struct StokesPolarization {
    /// Degree of polarization √(S1² + S2² + S3²) / S0, in [0, 1] for a physical vector (a bin's
    /// average of vectors of degree ≤ 1 has degree ≤ 1); NaN where S0 ≤ 0 (no light).
    double dop = NAN;
    /// Its standard error to first order, the components taken as independent (they are not:
    /// they come from the same particles, so this overestimates where the light is strongly
    /// polarized): √(Σ_k (S_k σ_k / (|S| S0))² + (dop σ_0 / S0)²); where |S| = 0, where the
    /// first order fails, √(Σ_k σ_k²) / S0, the size of |S| that noise alone gives. The estimate
    /// |S| / S0 is biased upwards by noise of that size.
    double dop_se = NAN;
    /// The angle of linear polarization ½ atan2(S2, S1) in degrees, (−90°, 90°], measured from
    /// the frame's x axis towards its y axis: 0 for light polarized along x (s-polarized in the
    /// plane of incidence), ±90 along y; 0 where S1 = S2 = 0.
    double aolp_deg = 0;
};

/// The polarization of the Stokes vector `s` (S0..S3) whose components have the standard errors
/// `se`.
inline StokesPolarization stokes_polarization(const std::array<double, 4>& s,
                                              const std::array<double, 4>& se) {
    StokesPolarization p;
    p.aolp_deg = 0.5 * std::atan2(s[2], s[1]) * (180.0 / M_PI);
    if (!(s[0] > 0)) return p;
    const double norm = std::sqrt(s[1] * s[1] + s[2] * s[2] + s[3] * s[3]);
    p.dop = norm / s[0];
    double var = 0;
    if (norm > 0) {
        for (int k = 1; k < 4; ++k) {
            const double d = s[k] * se[k] / (norm * s[0]);
            var += d * d;
        }
        const double d0 = p.dop * se[0] / s[0];
        var += d0 * d0;
    } else {
        var = (se[1] * se[1] + se[2] * se[2] + se[3] * se[3]) / (s[0] * s[0]);
    }
    p.dop_se = std::sqrt(var);
    return p;
}

}  // namespace lamina

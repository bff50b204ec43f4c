#pragma once
// Hand-written references shared by the transfer-matrix tests (tm2, tm6): written here from the
// physics and from the released code's fitted formulas (Randrianandrasana, Callet & Lucas 2021,
// the public plugins), independently of src/models/transfer_matrix/transfer_matrix.cpp and
// physics/fresnel.h.

#include <algorithm>
#include <cmath>

namespace lamina::test {

/// Unpolarized Fresnel reflectance of a smooth dielectric, relative index eta, from the s and p
/// amplitudes (Born & Wolf §1.5).
inline double fresnel_by_hand(double cos_i, double eta) {
    const double sin2_t = (1 - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1) return 1;
    const double cos_t = std::sqrt(1 - sin2_t);
    const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

/// The paper's GGX ↔ HG mapping (the released code's fit) and its inverse, and the refraction of
/// an HG lobe.
inline double g_of_alpha(double a) {
    return a <= 0 ? 1.0 : std::clamp(-0.085 + 1.085 / (1 + std::pow(a / 0.5, 1.3)), 0.0, 1.0);
}
inline double alpha_of_g(double g) {
    return std::clamp(0.5 * std::pow(1.085 / (std::max(g, 0.2) + 0.085) - 1, 1 / 1.3), 1e-4, 1.0);
}
inline double g_refracted(double g, double eta) {
    return std::min(std::sqrt(std::max(1 - (1 - g * g) * std::pow(eta, 0.75), 0.0)), 1.0);
}

}  // namespace lamina::test

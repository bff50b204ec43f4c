#pragma once
// Stacks for the model tests, built in code on layers/stack.h's builders.

#include "core/math.h"
#include "core/rgb.h"
#include "core/spherical.h"
#include "layers/stack.h"

#include <fmt/format.h>

#include <string>
#include <utility>
#include <vector>

namespace lamina::test {

/// The upper-hemisphere direction at polar angle theta_deg and azimuth phi_deg (degrees).
inline Vec3d dir(double theta_deg, double phi_deg) {
    return direction_from_angles(deg_to_rad(theta_deg), deg_to_rad(phi_deg));
}

inline InterfaceSpec lambertian(Rgbd albedo) {
    return lambertian_interface(albedo);
}
inline InterfaceSpec dielectric(double eta, double alpha) {
    return dielectric_interface(eta, alpha);
}
inline InterfaceSpec conductor(Rgbd eta, Rgbd k, double alpha) {
    return conductor_interface(eta, k, alpha);
}
/// Gold at (R, G, B) ≈ (650, 550, 450) nm (Johnson & Christy 1972, rounded).
inline InterfaceSpec gold(double alpha) {
    return conductor(Rgbd(0.18, 0.42, 1.37), Rgbd(3.4, 2.35, 1.85), alpha);
}

/// ambient (index 1) | dielectric coat (eta0, alpha0) with absorption tau_a (and tau_s, g) |
/// base.
inline Stack coated(double eta0, double alpha0, const InterfaceSpec& base, Rgbd tau_a = Rgbd(0.0),
                    Rgbd tau_s = Rgbd(0.0), double g = 0.0) {
    Stack s;
    s.name = "test";
    Layer coat = layer_of(dielectric(eta0, alpha0));
    if (tau_a.max() > 0 || tau_s.max() > 0) coat = with_medium(coat, tau_a, tau_s, Rgbd(g));
    s.layers = {coat, layer_of(base)};
    return s;
}

/// Brushed gold (α_x = b_x, α_y = b_y at tangent psi1 degrees) under a coat of η 1.5 absorbing
/// τ = (0.1, 0.2, 0.3) (α_x = c_x, α_y = c_y at psi0); equal α's leave that interface isotropic.
inline Stack brushed(double c_x, double c_y, double psi0, double b_x, double b_y, double psi1) {
    Stack s = coated(1.5, c_x, gold(b_x), Rgbd(0.1, 0.2, 0.3));
    if (c_y != c_x) s.layers[0].interface = anisotropic(s.layers[0].interface, c_x, c_y, psi0);
    if (b_y != b_x) s.layers[1].interface = anisotropic(s.layers[1].interface, b_x, b_y, psi1);
    return s;
}

/// A single interface (ambient over a half-space or a bare conductor).
inline Stack single(const InterfaceSpec& interface) {
    Stack s;
    s.name = "single";
    s.layers = {layer_of(interface)};
    return s;
}

/// The coats the energy tests sweep: indices 1.2, 1.5, 2 and roughness 0, 0.1, 0.5 over a white
/// Lambertian, gold at α 0.05 and 0.4, a smooth near-mirror conductor and, with
/// `dielectric_base`, a rough dielectric of index 1.33 (a transmitting stack).
inline std::vector<std::pair<std::string, Stack>> energy_sweep(bool dielectric_base) {
    std::vector<std::pair<std::string, InterfaceSpec>> bases = {
        {"white lambertian", lambertian(Rgbd(1.0))},
        {"gold a=0.05", gold(0.05)},
        {"gold a=0.4", gold(0.4)},
        {"smooth mirror-ish", conductor(Rgbd(0.05), Rgbd(8.0), 0.0)},
    };
    if (dielectric_base) bases.push_back({"dielectric 1.33 a=0.2", dielectric(1.33, 0.2)});
    std::vector<std::pair<std::string, Stack>> out;
    for (const auto& [bname, base] : bases)
        for (double eta : {1.2, 1.5, 2.0})
            for (double alpha : {0.0, 0.1, 0.5})
                out.push_back({fmt::format("eta0={} a0={} base {}", eta, alpha, bname),
                               coated(eta, alpha, base)});
    return out;
}

}  // namespace lamina::test

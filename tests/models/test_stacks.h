#pragma once
// Stacks for the model tests, built in code on layers/stack.h's builders.

#include "core/math.h"
#include "core/rgb.h"
#include "core/spherical.h"
#include "layers/stack.h"

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

/// A single interface (ambient over a half-space or a bare conductor).
inline Stack single(const InterfaceSpec& interface) {
    Stack s;
    s.name = "single";
    s.layers = {layer_of(interface)};
    return s;
}

}  // namespace lamina::test

#pragma once
// Stacks for the model tests, built in code (the JSON parser lives in another branch).

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
    InterfaceSpec s;
    s.type = InterfaceType::Lambertian;
    s.albedo = albedo;
    return s;
}
inline InterfaceSpec dielectric(double eta, double alpha) {
    InterfaceSpec s;
    s.type = InterfaceType::Dielectric;
    s.eta = eta;
    s.alpha = alpha;
    return s;
}
inline InterfaceSpec conductor(Rgbd eta, Rgbd k, double alpha) {
    InterfaceSpec s;
    s.type = InterfaceType::Conductor;
    s.eta_rgb = eta;
    s.k = k;
    s.alpha = alpha;
    return s;
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
    Layer coat;
    coat.interface = dielectric(eta0, alpha0);
    if (tau_a.max() > 0 || tau_s.max() > 0) {
        coat.has_medium = true;
        coat.medium.tau_a = tau_a;
        coat.medium.tau_s = tau_s;
        coat.medium.g = Rgbd(g);
    }
    Layer b;
    b.interface = base;
    s.layers = {coat, b};
    return s;
}

/// A single interface (ambient over a half-space or a bare conductor).
inline Stack single(const InterfaceSpec& interface) {
    Stack s;
    s.name = "single";
    Layer l;
    l.interface = interface;
    s.layers = {l};
    return s;
}

}  // namespace lamina::test

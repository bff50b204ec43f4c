#pragma once
// Stacks built in code for tests (the JSON parser has its own tests), on layers/stack.h's builders.

#include "layers/stack.h"
#include "layers/transport_settings.h"

namespace lamina::test {

inline Layer dielectric_layer(double eta, double alpha) {
    return layer_of(dielectric_interface(eta, alpha));
}

using lamina::with_medium;

inline Layer lambertian_layer(Rgbd albedo) {
    return layer_of(lambertian_interface(albedo));
}

inline Layer conductor_layer(Rgbd eta, Rgbd k, double alpha) {
    return layer_of(conductor_interface(eta, k, alpha));
}

inline Stack make_stack(std::vector<Layer> layers, std::string name = "test") {
    return Stack{std::move(name), 1.0, std::move(layers)};
}

/// examples/<name>.json, a stack lamina ships.
inline Stack example(const std::string& name) {
    return load_stack(std::string(LAMINA_SOURCE_DIR) + "/examples/" + name + ".json");
}

/// The 2019 reference's transport (unpolarized Fresnel factors, single-scattering interfaces):
/// the one most closed forms in the tests are written for.
inline TransportSettings bpb19_transport() {
    TransportSettings t;
    apply_physics(ReferencePhysics::Bpb19, t);
    return t;
}

}  // namespace lamina::test

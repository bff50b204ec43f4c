#pragma once
// Stacks built in code for tests (the JSON parser has its own tests).

#include "layers/stack.h"

namespace lamina::test {

inline Layer dielectric_layer(double eta, double alpha) {
    Layer l;
    l.interface.type = InterfaceType::Dielectric;
    l.interface.eta = eta;
    l.interface.alpha = alpha;
    return l;
}

inline Layer with_medium(Layer l, Rgbd tau_a, Rgbd tau_s = Rgbd(0.0), Rgbd g = Rgbd(0.0)) {
    l.has_medium = true;
    l.medium.tau_a = tau_a;
    l.medium.tau_s = tau_s;
    l.medium.g = g;
    return l;
}

inline Layer lambertian_layer(Rgbd albedo) {
    Layer l;
    l.interface.type = InterfaceType::Lambertian;
    l.interface.albedo = albedo;
    return l;
}

inline Layer conductor_layer(Rgbd eta, Rgbd k, double alpha) {
    Layer l;
    l.interface.type = InterfaceType::Conductor;
    l.interface.eta_rgb = eta;
    l.interface.k = k;
    l.interface.alpha = alpha;
    return l;
}

inline Stack make_stack(std::vector<Layer> layers, std::string name = "test") {
    return Stack{std::move(name), 1.0, std::move(layers)};
}

}  // namespace lamina::test

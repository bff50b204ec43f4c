#include "simulator/trace_stack.h"

namespace lamina {

TraceStack::TraceStack(const Stack& stack, TransmissionMasking masking)
    : transmits(stack.transmits()) {
    for (std::size_t i = 0; i < stack.layers.size(); ++i) {
        const Layer& layer = stack.layers[i];
        const InterfaceSpec& spec = layer.interface;
        // Relative indices against the medium above (docs/physics.md §2).
        const double eta_above = stack.eta_above(i);
        TraceLayer t;
        t.type = spec.type;
        switch (spec.type) {
            case InterfaceType::Dielectric:
                t.dielectric = {float(spec.eta / eta_above), float(spec.alpha)};
                t.dielectric.transmission_masking = masking;
                break;
            case InterfaceType::Conductor:
                t.conductor = {Rgbf(spec.eta_rgb / eta_above), Rgbf(spec.k / eta_above),
                               float(spec.alpha)};
                break;
            case InterfaceType::Lambertian:
                t.lambertian = {Rgbf(spec.albedo)};
                break;
        }
        if (layer.has_medium) {
            const MediumSpec& m = layer.medium;
            t.medium.tau_a = Rgbf(m.tau_a);
            t.medium.tau_s = Rgbf(m.tau_s);
            t.medium.tau_t = Rgbf(m.tau_t());
            t.medium.g = Rgbf(m.g);
            t.medium.absorbs = m.tau_a.max() > 0;
            t.medium.scatters = m.tau_s.max() > 0;
            t.medium.uniform_g = m.g[0] == m.g[1] && m.g[1] == m.g[2];
            const Rgbf tau_t = t.medium.tau_t;
            t.medium.uniform_tau_t = tau_t[0] == tau_t[1] && tau_t[1] == tau_t[2];
            for (int c = 0; c < 3; ++c)
                t.medium.single_scattering_albedo[c] =
                    tau_t[c] > 0 ? float(m.tau_s[c] / m.tau_t()[c]) : 0.f;
        }
        layers.push_back(t);
    }
}

}  // namespace lamina

#pragma once
// The stack as the particle tracer sees it: per interface the BSDF with *relative* indices (against
// the medium above it), per medium its optical depths, all in float (docs/physics.md §2–§4).
// Built once per simulation from the layers::Stack description; no virtual calls, no allocation
// while tracing.

#include "core/rgb.h"
#include "layers/stack.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"

#include <vector>

namespace lamina {

struct TraceMedium {
    Rgbf tau_a{0.f}, tau_s{0.f}, tau_t{0.f}, g{0.f};
    bool absorbs = false;
    bool scatters = false;
    /// All channels share one g: the phase function needs no spectral MIS.
    bool uniform_g = true;
    /// All channels share one extinction τt: free flights need no spectral MIS, and a scattering
    /// event multiplies the flux by the single-scattering albedo τs/τt (exactly 1 when τa = 0).
    bool uniform_tau_t = true;
    Rgbf single_scattering_albedo{0.f};
    bool is_empty() const { return !absorbs && !scatters; }
};

struct TraceLayer {
    InterfaceType type = InterfaceType::Dielectric;
    DielectricInterface<float> dielectric{1.f, 0.f};
    ConductorInterface<float> conductor{Rgbf(1.f), Rgbf(0.f), 0.f};
    LambertianInterface<float> lambertian{Rgbf(0.f)};
    TraceMedium medium;  ///< the medium below this interface (empty for the last layer)
};

struct TraceStack {
    std::vector<TraceLayer> layers;
    bool transmits = false;  ///< the base is a dielectric: light can leave downwards
    /// Rough interfaces scatter light on their microsurfaces until it leaves (Heitz et al. 2016)
    /// instead of dropping what their first facet does not let escape; at most this many facets.
    bool multiple_scattering = false;
    int max_microsurface_order = 0;

    /// `masking`: the refraction masking of every rough dielectric (physics/microfacet.h).
    explicit TraceStack(const Stack& stack,
                        TransmissionMasking masking = TransmissionMasking::Smith);
};

}  // namespace lamina

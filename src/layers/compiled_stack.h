#pragma once
// The stack as the particle tracers see it (the goniophotometer's kernels in float, the random
// walk in double): per interface its BSDF with *relative* indices (against the medium above it,
// docs/physics.md §2), per medium its optical depths and the flags the samplers branch on (all
// lanes alike), all in the precision Real. Built once, by compile_stack, from the layers::Stack
// description and the microsurface settings; no virtual calls, no allocation while tracing.

#include "core/rgb.h"
#include "layers/stack.h"
#include "layers/transport_settings.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/microfacet.h"
#include "physics/thin_film.h"

#include <vector>

namespace lamina {

/// A homogeneous medium between two interfaces (physics/medium.h reads these fields). Optical
/// depths per unit of layer thickness, per channel.
template <typename Real>
struct CompiledMedium {
    Rgb<Real> tau_a{Real(0)}, tau_s{Real(0)}, tau_t{Real(0)}, g{Real(0)};
    bool absorbs = false;   ///< some τa > 0
    bool scatters = false;  ///< some τs > 0
    /// All channels share one g: the phase function needs no spectral MIS.
    bool uniform_g = true;
    /// All channels share one extinction τt: free flights need no spectral MIS, and a scattering
    /// event multiplies the flux by the single-scattering albedo τs/τt (exactly 1 when τa = 0).
    bool uniform_tau_t = true;
    Rgb<Real> single_scattering_albedo{Real(0)};  ///< τs/τt per channel (0 where τt = 0)
    bool is_empty() const { return !absorbs && !scatters; }
};

/// One interface and the medium below it.
template <typename Real>
struct CompiledLayer {
    InterfaceType type = InterfaceType::Dielectric;
    DielectricInterface<Real> dielectric{Real(1), Real(0)};
    ConductorInterface<Real> conductor{Rgb<Real>(Real(1)), Rgb<Real>(Real(0)), Real(0)};
    LambertianInterface<Real> lambertian{Rgb<Real>(Real(0))};
    /// Smooth or index-matched (dielectric), smooth (conductor): a delta interface, no density.
    bool delta = false;
    /// Rough, and its light scatters on the microsurface until it leaves (the microsurface walk
    /// of Heitz et al. 2016, physics/microsurface_walk.h) instead of after a single facet.
    bool multiple = false;
    /// The absolute index of the region below (the one above for an opaque base).
    Real eta_below = Real(1);
    /// A thin film on the interface (docs/physics.md §9), evaluated in double by the scalar
    /// kernel's film events (physics/thin_film_event.h).
    bool has_film = false;
    FilmOptics film;
    CompiledMedium<Real> medium;  ///< the medium below this interface (empty for the last layer)
};

template <typename Real>
struct CompiledStack {
    std::vector<CompiledLayer<Real>> layers;  ///< top to bottom
    Real eta_above = Real(1);                 ///< the ambient medium's absolute index
    bool transmits = false;  ///< the base is a dielectric: light can leave downwards
    /// Microsurface::Multiple: a rough interface's layer has `multiple` set when this is.
    bool multiple_scattering = false;
    int max_microsurface_order = TransportSettings{}.max_microsurface_order;
    /// TransportSettings::polarization: the particles carry a polarization state
    /// (physics/polarization.h).
    bool polarization = false;
    /// Polarization states a particle needs: 1 when every Mueller matrix of the stack is the same
    /// in all channels (dielectrics, Lambertian bases, grey conductors), 3 when a conductor's
    /// index differs between channels, or a thin film's Mueller matrices do (it is traced at a
    /// different wavelength in each channel).
    int polarization_channels = 1;
    /// Some interface carries a thin film (the scalar kernel traces every film, the SIMD kernel
    /// those on conductors).
    bool has_film = false;
    /// Some rough interface is anisotropic (GgxAnisotropy::on): the tracers take the general
    /// (anisotropic) instance of the GGX formulas (GGX::lanes) at every interface.
    bool anisotropic = false;
};

/// The stack compiled in precision Real (float: the goniophotometer's kernels; double: the random
/// walk) for the transport `settings` (its microsurface model, order and refraction masking). With
/// multiple scattering an index-matched rough dielectric is the smooth index-matched pass-through:
/// every facet refracts straight on (F = 0) and the walk leaves below along −wi with all its flux
/// (the single-scattering one keeps G2/G1).
/// The film of interface `layer` of `stack` as the particle events see it (absolute indices, the
/// stack's channel wavelengths, the thickness range); the interface must carry a film. The models
/// that represent films read the same (models/production/film_fresnel.h).
FilmOptics stack_film_optics(const Stack& stack, std::size_t layer);

template <typename Real>
CompiledStack<Real> compile_stack(const Stack& stack, const TransportSettings& settings);

extern template CompiledStack<float> compile_stack<float>(const Stack&, const TransportSettings&);
extern template CompiledStack<double> compile_stack<double>(const Stack&, const TransportSettings&);

}  // namespace lamina

#pragma once
// A model's colour on a spectral stack (docs/models.md, "Spectral stacks"): the model evaluated at
// wavelengths across the visible range, each evaluation on the stack at those wavelengths
// (Stack::at_wavelengths), and the spectrum projected to linear sRGB under D65 as the spectral
// goniophotometer projects its tables (layers/colorimetry.h, docs/physics.md §10). Its eval is
// then comparable bin by bin with a spectral run's brdf.csv, where the model at the channels'
// wavelengths is three point samples of the spectrum.
//
// Quadrature: the range [min_nm, max_nm] cut into n equal intervals, the model evaluated at their
// middles λj and held constant over each; XYZ = Σ f(λj) Wj / ∫ S ȳ dλ with Wj = ∫ S (x̄, ȳ, z̄) dλ
// over interval j (the D65 power times the CIE 1931 functions, by the midpoint rule on 16 cells
// per interval) and the normalization over 360–830 nm whatever the range (d65_y_integral, as the
// spectral goniophotometer's): a constant spectrum over the whole range projects to D65's white,
// sRGB (1, 1, 1) within 2·10⁻³ (the IEC matrix against these tables). The models are built on
// three wavelengths at once (their RGB channels) where no dielectric's index is a spectrum; a
// dispersive stack gets one model per wavelength, whose refraction follows that wavelength's index.

#include "models/model.h"

#include <functional>
#include <memory>

namespace lamina {

/// The wavelength nodes of the projection: the midpoint rule's.
struct SpectralQuadrature {
    double min_nm = 360, max_nm = 830;
    /// Number of wavelengths, a multiple of 3 (16 triples of nodes ≈ 9.8 nm apart by default).
    int n = 48;
};

/// Builds a model for a stack (the registry's ModelEntry::make with its options bound).
using ModelFactory = std::function<std::unique_ptr<Model>(const Stack&)>;

/// The model's linear sRGB on `stack`. A model built on three wavelengths holds the c-th third of
/// the range in channel c, as a spectral particle's channels do (docs/physics.md §10), and reads an
/// RGB value given as numbers as the spectral goniophotometer does (Stack::at_wavelengths: the
/// number of the nearest of the stack's channel wavelengths); grey values are the same at every
/// wavelength. Supports what every per-wavelength model supports; samples by
/// picking one of them uniformly (its pdf the mean of theirs); delta lobes carry their projected
/// energies. Nothing here throws after construction. A model that integrates the spectrum
/// itself (Model::integrates_spectrum: a shipped film's colour) is returned as the factory builds
/// it on `stack`, its channels' wavelengths.
std::unique_ptr<Model> make_spectral_projection(const ModelFactory& factory, const Stack& stack,
                                                const SpectralQuadrature& quadrature = {});

}  // namespace lamina

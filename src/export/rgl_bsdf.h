#pragma once
// RGL .bsdf files (Dupuy & Jakob 2018, "An adaptive parameterization for efficient material
// acquisition and rendering", ACM TOG 37(6)), the format of pbrt-v4's `measured` material and
// Mitsuba 3's `measured` plugin, written from a BRDF (docs/formats.md, "Exports").
//
// The format tabulates, for incidences θi (the `theta_i` field, radians):
//   ndf       D(ωm) on the grid u = (√(θm/(π/2)), (φm + π)/(2π)) ∈ [0, 1]² (bilinear);
//   sigma     σ(ωi) = ∫ D(ωm) ⟨ωi·ωm⟩ dωm, the projected microfacet area, on the same u grid of ωi;
//   vndf      per θi, the density in u of the visible normals D(ωm)⟨ωi·ωm⟩/σ(ωi) (φm relative to
//             φi: isotropic), whose bilinear warp (export/bilinear_warp.h) maps a "sample" point
//             s ∈ [0, 1]² to a half vector ωm;
//   rgb, spectra  per θi, the values S on a regular grid of s, such that a reader evaluates
//             f(ωi, ωo) |cos θo| = S(s) D(ωm) / (4 σ(ωi)),  ωm = (ωi + ωo)/|ωi + ωo|,
//             s = vndf warp inverted at u(ωm), S bilinear in s and linear in θi and λ;
//   luminance per θi, a density over s for importance sampling (here Y of S);
//   description, jacobian (1: the D/(4σ) factor above applies), phi_i, wavelengths.
// Writing: S at each s node = f(ωi, ωo)|cos θo| 4σ(ωi)/D(ωm) with ωm the warp of s, D and σ the
// values the reader interpolates from the written tables: at the nodes a reader gives back f
// exactly (to float32), in between it interpolates. D is estimated from the BRDF's
// retro-reflection (D ∝ f(ωm, ωm) cos²θm, the microfacet relation at ωi = ωo = ωm; floored at 2%
// of its peak, since it divides S), so that the samples gather where the lobe is.
//
// Only the reflection side: neither pbrt-v4's nor Mitsuba 3's reader takes a BTDF. Isotropic:
// phi_i holds two equal slices (φi = −π and π). RGB → spectra: lamina is RGB; the spectra are a
// piecewise-linear upsampling (b below 450 nm, g at 550 nm, r above 650 nm, linear in between:
// grey stays grey exactly), since pbrt-v4 reads only the spectral data.

#include "export/brdf_source.h"
#include "export/tensor_file.h"

#include <string>
#include <vector>

namespace lamina {

struct RglOptions {
    std::vector<double> theta_i_deg;  ///< the incidences; empty: the source's, or 0..88° by 4°
    int resolution = 32;              ///< s-grid nodes a side (rgb, spectra, luminance)
    int vndf_resolution = 64;         ///< u-grid nodes a side of vndf
    int ndf_resolution = 64;          ///< u-grid nodes a side of ndf and sigma
    std::string description;
};

/// The wavelengths (nm) of the spectra field and the RGB weights of each.
const std::vector<double>& rgl_wavelengths();
Rgbd rgl_spectral_weights(std::size_t wavelength_index);

/// The tensor file of the BRDF. InputError for options out of range (resolutions in [2, 512],
/// incidences increasing in [0, 90)).
TensorFile rgl_bsdf(const BrdfSource& brdf, const RglOptions& options);

/// Checks the fields and shapes a reader requires (the structure pbrt-v4 and Mitsuba 3 check on
/// loading), InputError naming `where` and the field otherwise.
void check_rgl_bsdf(const TensorFile& file, const std::string& where);

}  // namespace lamina

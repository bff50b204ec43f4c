#pragma once
// RGL .bsdf files (Dupuy & Jakob 2018, "An adaptive parameterization for efficient material
// acquisition and rendering", ACM TOG 37(6)), the format of pbrt-v4's `measured` material and
// Mitsuba 3's `measured` plugin, written from a BRDF (docs/formats.md, "Exports").
//
// The format tabulates, for incidences θi (the `theta_i` field, radians), in the coordinates
// u = (√(θ/(π/2)), (φ + π)/(2π)) of rgl_parameterization.h:
//   ndf       D(ωm) on a node grid of u (φm relative to φi in isotropic files);
//   sigma     σ(θi) on a node grid of u(ωi);
//   vndf      per θi, a density on a node grid of u, whose bilinear warp (bilinear_warp.h) maps a
//             "sample" point s ∈ [0, 1]² to a half vector ωm;
//   spectra   per θi and wavelength, the values S on a regular grid of s, such that a reader
//             evaluates f(ωi, ωo) |cos θo| = S(s) D(ωm) / (4 σ(θi)), ωm = (ωi + ωo)/|ωi + ωo|,
//             s = the vndf warp inverted at u(ωm), S bilinear in s and linear in θi and λ
//             (rgl_reader.h evaluates a file as the readers do);
//   luminance per θi, a density over s the readers sample s from;
//   description, jacobian (1: the D/(4σ) factor above applies), phi_i, wavelengths.
// The format was designed (Dupuy & Jakob 2018) with D the material's microfacet distribution,
// σ its projected area and vndf the visible normals D⟨ωi·ωm⟩/σ, which makes S smooth for one
// rough interface. A layered BRDF is a sum of lobes whose ratios change with θi (a coat's
// near-specular reflection over a diffuse or rough base: at 80° the coat's share is tens of times
// its share at normal incidence), and no one D makes S smooth at every incidence. lamina writes:
//   D      the retro-reflection P(ωm, ωm) = Y(f(ωm, ωm)) cos²θm (for a microfacet BRDF F G D/4),
//          floored at 1e-4 of its peak, its log-slope limited so that the readers' linear
//          interpolation keeps it, normalized to ∫ D cos θm dωm = 1;
//   σ      cos θi, held past the last incidence: S = 4 f cos θi cos θo / D changes slowly with θi
//          (f cos θi cos θo is reciprocal and bounded), and f stays bounded as θi → 90°;
//   vndf   one density of u_x alone, the same at every incidence, so that s_x ↔ θm is one map:
//          S's features in θm (a lobe's core, where the coat's lobe gives way to the base's) line
//          up across the rows of s and across incidences, and the readers' blending of warps
//          between incidences changes nothing. Half of it is uniform, a quarter follows the changes
//          of ln P(ωm, ωm) (the nodes gather in a narrow lobe's core and edges), a quarter the
//          changes of ln S along θm over the incidences;
//   S      at each s node, f(ωi, ωo)|cos θo| 4σ(θi)/D(ωm), ωm the warp of the node and D, σ the
//          values a reader interpolates: at the nodes a reader gives back f to float32 precision;
//   luminance  Y(S) D (ωi·ωm) J / p (p the warp's density, J = dω/du): the readers then sample
//          ωo in proportion to f cos θo (floored at 1e-4 of its peak: every direction is sampled).
// The defaults (rgl_default_incidences, RglOptions) are sized so that a renderer gets within the
// goals of rgl_fidelity.h on the study's configurations (docs/formats.md gives the figures).
//
// An anisotropic source (BrdfSource::isotropic false: a brushed stack) gets φi slices: phi_i holds
// RglOptions::azimuths + 1 values from −π to π (the last slice repeats the first, so that the
// readers, which interpolate linearly in φi = atan2(ωi.y, ωi.x), have both ends and use no mirror
// symmetry); D is tabulated over the absolute azimuth of ωm (257 rows of u_y, 1.4° apart, the
// retro-reflection of each), u_y of the warp is then the absolute φm, and vndf, luminance and
// spectra hold one slice per (φi, θi). The readers take a file with more than two φi slices as
// anisotropic and then read ωm's azimuth as it is, not relative to φi.
//
// Only the reflection side: neither pbrt-v4's nor Mitsuba 3's reader takes a BTDF. Isotropic:
// phi_i holds one slice. RGB → spectra: lamina is RGB; the spectra are a piecewise-linear
// upsampling (b below 450 nm, g at 550 nm, r above 650 nm, linear in between: grey stays grey
// exactly), since pbrt-v4 reads only the spectral data; the colour is the spectra at 450, 550 and
// 650 nm.

#include "export/brdf_source.h"
#include "export/tensor_file.h"

#include <string>
#include <vector>

namespace lamina {

struct RglOptions {
    std::vector<double> theta_i_deg;  ///< the incidences; empty: the source's, or the defaults
    int resolution = 64;              ///< s nodes a side (spectra, luminance), in [2, 512]
    int vndf_resolution = 512;        ///< warp nodes along θm (u_x), in [2, 8192]
    int ndf_resolution = 512;         ///< ndf and sigma nodes along θ (u_x), in [2, 8192]
    int azimuths = 24;  ///< an anisotropic source's φi intervals over [−π, π], in [2, 360]
    std::string description;
};

/// The incidences (degrees) a model's file gets by default: every 4° while that is at most a
/// quarter of the distance to the horizon, then steps of a quarter of it (rounded to 0.01°), and
/// 88° last; 26 of them.
std::vector<double> rgl_default_incidences();

/// The wavelengths (nm) of the spectra field and the RGB weights of each.
const std::vector<double>& rgl_wavelengths();
Rgbd rgl_spectral_weights(std::size_t wavelength_index);

/// The tensor file of the BRDF. InputError for options out of range (the resolutions' ranges
/// above, incidences increasing in [0, 90)). Parallel over incidences (OpenMP); the file does not
/// depend on the thread count. An isotropic source's file is the same whatever `azimuths`.
TensorFile rgl_bsdf(const BrdfSource& brdf, const RglOptions& options);

/// Checks the fields and shapes a reader requires (the structure pbrt-v4 and Mitsuba 3 check on
/// loading) and their values (every one finite, the incidences in [0, π/2], the wavelengths
/// positive and increasing), InputError naming `where` and the field otherwise.
void check_rgl_bsdf(const TensorFile& file, const std::string& where);

}  // namespace lamina

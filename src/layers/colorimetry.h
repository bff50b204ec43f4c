#pragma once
// Colour of a spectrum (docs/physics.md §10): the CIE 1931 tristimulus values XYZ of a reflectance
// or transmittance spectrum lit by CIE illuminant D65, and their linear sRGB. The tables are the
// CIE's (data/cie, embedded), linearly interpolated between their 5 nm rows.

#include "core/rgb.h"

namespace lamina {

/// S(λ)·(x̄, ȳ, z̄)(λ): the D65 power times the CIE 1931 2° colour-matching functions at the
/// vacuum wavelength lambda_nm (zero outside 360–830 nm). The XYZ of a spectrum f is
/// ∫ f S (x̄, ȳ, z̄) dλ / ∫ S ȳ dλ, so that f = 1 has Y = 1 (CIE 015:2018, §7.1).
Rgbd d65_xyz_weights(double lambda_nm);

/// ∫ S ȳ dλ over 360–830 nm, the normalization of XYZ above (the midpoint rule on 0.1 nm cells):
/// what the spectral goniophotometer and the models' spectral projection divide by, whatever
/// range they trace, so that a narrower range is the colour of that part of the spectrum.
double d65_y_integral();

/// The CIE 1931 2° colour-matching functions (x̄, ȳ, z̄) as tabulated (data/cie): row i ∈ [0,
/// kCie1931Rows) at 360 + 5 i nm.
inline constexpr int kCie1931Rows = 95;
Rgbd cie1931_cmf_row(int i);

/// Linear sRGB of XYZ (IEC 61966-2-1:1999, the matrix of its §5.2; D65 white, Y = 1 → (1, 1, 1)).
Rgbd xyz_to_linear_srgb(const Rgbd& xyz);

}  // namespace lamina

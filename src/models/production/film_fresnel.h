#pragma once
// The Fresnel terms of a thin film on a coated metal as the production models evaluate them
// (docs/models.md, "Thin films"): the exact Airy reflectance of the stack's film (the physics of
// physics/thin_film.h, at the stack's channel wavelengths); Adobe openpbr-bsdf's, the same sum
// against the metal its F0 and edge tint describe; and three.js's iridescence
// (KHR_materials_iridescence as three.js evaluates it), Belcour & Barla 2017's Fourier-space Airy
// sum reduced to two orders on Schlick's Fresnel, integrated against the CIE colour matching
// functions and returned in linear sRGB.
//
// Both return a reflectance per RGB channel in [0, 1] and never throw. A film's thickness range
// [min, max] (a film uniformly distributed over the surface) is averaged over: the surface's mean
// reflectance, what a texture of the thickness shows over many pixels.

#include "core/rgb.h"
#include "layers/compiled_stack.h"
#include "models/model.h"
#include "physics/thin_film.h"

#include <cstddef>

namespace lamina {

/// Karis 2013 ("Real shading in Unreal Engine 4", SIGGRAPH course notes)'s spherical-Gaussian fit
/// of Schlick's weight (1 − c)⁵, 2^((−5.55473 c − 6.98316) c), as three.js's F_Schlick evaluates
/// it; c in [0, 1].
double schlick_weight_spherical_gaussian(double c);

// The film of a stack's interface: layers/compiled_stack.h, stack_film_optics (the same the
// particle events see).

/// The exact reflectance of `film` for unpolarized light arriving from above at the facet cosine
/// cos_theta ∈ [0, 1], per channel at its wavelength ((R_s + R_p)/2 of physics/thin_film.h),
/// averaged over the film's thickness range by Gauss–Legendre quadrature (32 nodes per period of
/// the interference, at most 2048).
Rgbd film_reflectance_exact(const FilmOptics& film, double cos_theta);

/// three.js's evalIridescence (KHR_materials_iridescence; Belcour & Barla 2017, Eqs. 6–10 and
/// their Gaussian fit of the sensitivity): a film of index film_ior and thickness thickness_nm
/// between a medium of index outside_ior and a base given by its normal reflectance base_f0 (per
/// channel, read as a dielectric of index (1 + √F0)/(1 − √F0) against air), lit at cos_theta_1.
/// The result is linear sRGB, clamped below at 0.
Rgbd threejs_iridescence(double outside_ior, double film_ior, double cos_theta_1,
                         double thickness_nm, const Rgbd& base_f0);

/// threejs_iridescence averaged over the thickness range [min_nm, max_nm] (the mean of what a
/// thickness texture uniform over the range shows), by Gauss–Legendre quadrature (32 nodes per
/// period of the interference, at most 2048 nodes); min_nm = max_nm is one thickness.
Rgbd threejs_iridescence_range(double outside_ior, double film_ior, double cos_theta_1,
                               double min_nm, double max_nm, const Rgbd& base_f0);

/// Gulbrandsen 2014 ("Artist friendly metallic Fresnel", JCGT 3(4)), Eqs. 3 and 4: the complex
/// index n + ik whose normal reflectance is r (clamped to [0, 0.99], as openpbr-bsdf clamps it)
/// with the edge tint g ∈ [0, 1] choosing n between (1 − r)/(1 + r) and (1 + √r)/(1 − √r).
std::complex<double> gulbrandsen_index(double r, double g);

/// Adobe openpbr-bsdf's film (openpbr_thin_film_iridescence_utils.h, openpbr_reflection_
/// transmission_coefficient.h): the exact Airy reflectance of `film` at the facet cosine
/// cos_theta (its eta_above the coat, its eta_below the metal's index as openpbr-bsdf derives
/// it, gulbrandsen_index of its F0 and F82 tint), total reflection where the film's first
/// boundary reflects totally (no tunnelling), faded in from the bare metal's reflectance `bare`
/// over the first 30 nm (smoothstep(1e-9, 30, d)); averaged over the thickness range.
Rgbd openpbr_bsdf_film_reflectance(const FilmOptics& film, double cos_theta, const Rgbd& bare);

}  // namespace lamina

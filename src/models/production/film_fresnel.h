#pragma once
// The Fresnel terms of a thin film on a coated metal as the production models evaluate them
// (docs/models.md, "Thin films"): the exact Airy reflectance of the stack's film (the physics of
// physics/thin_film.h, at the stack's channel wavelengths); Adobe openpbr-bsdf's, the same sum
// against the metal its F0 and edge tint describe; and three.js's iridescence
// (KHR_materials_iridescence as three.js evaluates it), Belcour & Barla 2017's Fourier-space Airy
// sum reduced to two orders on Schlick's Fresnel, integrated against the CIE colour matching
// functions and returned in linear sRGB; and Blender Cycles' (its Principled BSDF's thin film),
// the same Fourier-space sum with the exact phases of both boundaries, three orders, and its
// sensitivity read from a table of the CIE functions' Fourier transform (CyclesFilmSensitivity);
// and Belcour & Barla's own shader, the same sum with the paper's Gaussian fit of that transform,
// returned in CIE 1931 RGB.
//
// Each returns a reflectance per RGB channel in [0, 1] and never throws. A film's thickness range
// [min, max] (a film uniformly distributed over the surface) is averaged over: the surface's mean
// reflectance, what a texture of the thickness shows over many pixels.

#include "core/rgb.h"
#include "layers/compiled_stack.h"
#include "models/model.h"
#include "physics/thin_film.h"

#include <cstddef>
#include <optional>

namespace lamina {

/// Karis 2013 ("Real shading in Unreal Engine 4", SIGGRAPH course notes)'s spherical-Gaussian fit
/// of Schlick's weight (1 − c)⁵, 2^((−5.55473 c − 6.98316) c), as three.js's F_Schlick evaluates
/// it; c in [0, 1].
double schlick_weight_spherical_gaussian(double c);

// The film of a stack's interface: layers/compiled_stack.h, stack_film_optics (the same the
// particle events see).

/// The exact reflectance of `film` for unpolarized light arriving from above at the facet cosine
/// cos_theta ∈ [0, 1], per channel at its wavelength ((R_s + R_p)/2 of physics/thin_film.h),
/// averaged over the film's thickness range: in closed form where the film is transparent and its
/// wave propagates (physics/thin_film_average.h), else by Gauss–Legendre quadrature (32 nodes per
/// period of the interference, at most 2048).
Rgbd film_reflectance_exact(const FilmOptics& film, double cos_theta);

/// Belcour & Barla 2017's sensitivity S(OPD, shift) in linear sRGB: the Fourier transform of the
/// CIE 1931 colour matching functions at the optical path difference OPD (nm, ≥ 0), each of X, Y
/// and Z turned by its shift, by the paper's fit of each as a sum of Gaussians (their
/// supplemental material; the constants as three.js's evalSensitivity carries them: amplitudes,
/// centres and variances in the spatial frequency of metres, and the normalization 1.0685e-7
/// that makes the m = 0 term white), then the XYZ → linear sRGB (Rec. 709 primaries, D65) matrix
/// of IEC 61966-2-1 to seven digits.
Rgbd belcour_sensitivity_srgb(double opd_nm, const Rgbd& shift);

/// A bound on |belcour_sensitivity_srgb(OPD, shift)| per channel for every OPD ≥ opd0_nm ≥ 0:
/// the Gaussians' windows at opd0_nm through the matrix's magnitudes, and, where every shift is a
/// whole multiple of π, no more than the supremum over all OPD of that pattern of signs.
Rgbd belcour_sensitivity_srgb_bound(double opd0_nm, const Rgbd& shift);

/// three.js's evalIridescence (KHR_materials_iridescence; Belcour & Barla 2017, Eqs. 6–10 and
/// their Gaussian fit of the sensitivity): a film of index film_ior and thickness thickness_nm
/// between a medium of index outside_ior and a base given by its normal reflectance base_f0 (per
/// channel, read as a dielectric of index (1 + √F0)/(1 − √F0) against air), lit at cos_theta_1.
/// The result is linear sRGB, clamped below at 0. As three.js passes the three channels' phase
/// shifts (0 or π at the base, per channel) to its sensitivity as one vector, the shift of the R
/// channel's base turns the X lobes, G's the Y lobe and B's the Z lobe, for every channel.
Rgbd threejs_iridescence(double outside_ior, double film_ior, double cos_theta_1,
                         double thickness_nm, const Rgbd& base_f0);

/// threejs_iridescence averaged over the thickness range [min_nm, max_nm] (the mean of what a
/// thickness texture uniform over the range shows); min_nm = max_nm is one thickness. Beyond the
/// film's first 0.03 nm only the sensitivities depend on the thickness, through an optical path
/// linear in it, so the mean is in closed form (each Gaussian-windowed cosine of the sensitivity
/// integrated exactly: models/numerics/gaussian_fourier.h) wherever three.js's clamp at 0 cannot
/// act in the range; elsewhere, and over the first 0.03 nm, by Gauss–Legendre quadrature (32
/// nodes per period of the interference, at most 2048 nodes).
Rgbd threejs_iridescence_range(double outside_ior, double film_ior, double cos_theta_1,
                               double min_nm, double max_nm, const Rgbd& base_f0);

/// The mean of threejs_iridescence over thickness uniform in [min_nm, max_nm] in closed form,
/// where it is exact: 0.03 nm ≤ min_nm < max_nm (beyond three.js's fade of the film's index), and
/// three.js's clamp at 0 cannot act anywhere in the range (per channel, the DC term exceeds twice
/// the orders' coefficients times a bound on the sensitivity's magnitude from the range's smallest
/// optical path on). Nothing elsewhere.
std::optional<Rgbd> threejs_iridescence_range_closed_form(double outside_ior, double film_ior,
                                                          double cos_theta_1, double min_nm,
                                                          double max_nm, const Rgbd& base_f0);

/// Gulbrandsen 2014 ("Artist friendly metallic Fresnel", JCGT 3(4)), Eqs. 3 and 4: the complex
/// index n + ik whose normal reflectance is r (clamped to [0, r_max]: 0.99 as openpbr-bsdf clamps
/// it, 0.999 as Cycles does) with the edge tint g ∈ [0, 1] choosing n between (1 − r)/(1 + r) and
/// (1 + √r)/(1 − √r).
std::complex<double> gulbrandsen_index(double r, double g, double r_max = 0.99);

/// Adobe openpbr-bsdf's film (openpbr_thin_film_iridescence_utils.h, openpbr_reflection_
/// transmission_coefficient.h): the exact Airy reflectance of `film` at the facet cosine
/// cos_theta (its eta_above the coat, its eta_below the metal's index as openpbr-bsdf derives
/// it, gulbrandsen_index of its F0 and F82 tint), total reflection where the film's first
/// boundary reflects totally (no tunnelling), faded in from the bare metal's reflectance `bare`
/// over the first 30 nm (smoothstep(1e-9, 30, d)); averaged over the thickness range (the part
/// beyond 30 nm in closed form where film_reflectance_exact's holds).
Rgbd openpbr_bsdf_film_reflectance(const FilmOptics& film, double cos_theta, const Rgbd& bare);

/// Blender Cycles' table of the spectral sensitivity of its thin film (scene/shader.cpp,
/// compute_thin_film_table, after Belcour & Barla 2017, §4): per linear-sRGB channel c, the
/// discrete Fourier transform of the channel's colour-matching function r̄_c(λ) resampled in the
/// wavenumber ν = 1/λ, S_c[j] = Σ_k r̄_c(1/ν_k)/ν_k² e^(−2πi jk/N) for ν_k = k π/60 µm⁻¹,
/// k < N = 1022, j < 512, divided by its real DC term (so that a flat spectrum gives 1). lamina
/// derives it from its own CIE 1931 tables (data/cie, 5 nm rows from 360 to 830 nm, continued by
/// a zero row 5 nm beyond each end) through a not-a-knot cubic spline in λ, as Cycles' script
/// (doc/precompute/thin_film_table.py) splines the CIE's 1 nm table, and projects XYZ to linear
/// sRGB by the IEC 61966-2-1 matrix (Cycles' fallback without a colour-management configuration).
class CyclesFilmSensitivity {
  public:
    static constexpr int kSize = 512;
    /// The lookup's coordinate per nm of OPD, 2π/60000 nm: it spans OPD ∈ [0, 60000 nm/2π]
    /// and holds its last entry beyond.
    static constexpr double kPerNm = 2 * 3.14159265358979323846 / 60000;
    static const CyclesFilmSensitivity& get();
    /// Entry j ∈ [0, kSize) of channel c (linear sRGB), normalized.
    std::complex<double> entry(int channel, int j) const { return table_[channel][j]; }
    /// The kernel's lookup (iridescence_lookup_sensitivity_channel): the entries linearly
    /// interpolated at x = kPerNm · OPD ∈ [0, 1] (clamped) times 511.
    std::complex<double> operator()(int channel, double opd_nm) const;
    /// The exact mean of operator() over OPD uniform in [opd0_nm, opd1_nm] (0 ≤ opd0 < opd1):
    /// the integral of the piecewise-linear lookup from the entries' running trapezoid sums.
    std::complex<double> mean(int channel, double opd0_nm, double opd1_nm) const;
    /// The largest |entry| of channel c (the DC entry is 1).
    double max_magnitude(int channel) const { return max_magnitude_[channel]; }

  private:
    CyclesFilmSensitivity();
    /// ∫ of the lookup from x = 0 to x at channel c (x the lookup's coordinate in entries).
    std::complex<double> integral(int channel, double x) const;
    std::complex<double> table_[3][kSize];
    std::complex<double> running_[3][kSize];  ///< ∫ from 0 to entry j (trapezoids)
    double max_magnitude_[3] = {};
};

/// Cycles' THINFILM_THICKNESS_CUTOFF (kernel/closure/bsdf_util.h): a film of at most this thickness
/// (nm) is no film.
inline constexpr double kCyclesFilmCutoffNm = 0.1;

/// Cycles' thin film (kernel/closure/bsdf_util.h, fresnel_iridescence_channel) for light
/// arriving from a medium of index 1 at cos_theta_1 on a film of index film_ior and thickness
/// thickness_nm over a substrate: the reflectances and phases of both boundaries (each
/// polarization) summed to the third order of Belcour & Barla 2017's Eq. 10, each order's phase
/// integrated against channel c's sensitivity (CyclesFilmSensitivity); the film's index blended
/// towards 1 below 1 nm (smoothstep), 1 at total reflection on either boundary, the mean of s and
/// p clamped to [0, 1]. The substrate is a dielectric of index substrate_n (k = 0, f82 < 0), or a
/// conductor n + ik whose reflectance is the exact one (f82 < 0) or, for f82 ≥ 0, the F82 model
/// with its normal reflectance relative to the film and the value f82 at 82° (only the phase is
/// the conductor's), as Cycles' F82-tint metal calls it.
struct CyclesFilmSubstrate {
    bool conductor = false;
    double n = 1.5, k = 0;
    double f82 = -1;
};
double cycles_film_reflectance(int channel, double film_ior, double thickness_nm,
                               const CyclesFilmSubstrate& substrate, double cos_theta_1);
/// The same sum with the monochromatic sensitivity e^(−2πi OPD/λ) of the vacuum wavelength
/// wavelength_nm in place of channel c's table: summed to every order it would be the exact Airy
/// reflectance of the film at λ (physics/thin_film.h); Cycles' three orders leave out the terms
/// m ≥ 4 of Eq. 10.
double cycles_film_reflectance_monochromatic(double wavelength_nm, double film_ior,
                                             double thickness_nm,
                                             const CyclesFilmSubstrate& substrate,
                                             double cos_theta_1);

/// Belcour & Barla 2017's iridescent Fresnel term as their supplemental BRDF Explorer shader
/// evaluates it (its Airy function; "A practical extension to microfacet theory for the modeling
/// of varying iridescence", ACM TOG 36(4), Eqs. 6–10): a film of index film_ior over a base, lit
/// from a medium of index 1 at the facet cosine cos_theta_1 ∈ [0, 1]; the exact reflectances and
/// phases of both boundaries, each polarization summed to the third order of Eq. 10 (the sum Cycles
/// took over), each order's phase integrated against the paper's Gaussian fit of the CIE 1931
/// functions' Fourier transforms (the one three.js carries), the mean of s and p projected to
/// **CIE 1931 RGB** (equal-energy white, not sRGB) and clamped to [0, 1]; channel c of that
/// colour. dinc_um is the shader's Dinc, the film's optical path 2 η_f d at normal incidence in
/// µm (the sum's OPD is Dinc cos θ2); the film's index blends from 1 over Dinc ∈ [0, 0.03]
/// (smoothstep). The base's complex index is base_eta·(1 + i base_kappa): the shader's κ3 is Born
/// & Wolf's attenuation index (relative to η3), not the extinction coefficient k of n + ik.
/// channel ∈ {0, 1, 2}, film_ior ≥ 1, base_eta > 0, base_kappa ≥ 0 (0: a dielectric base, the
/// shader's fresnelDielectric). Where the shader leaves the reflectance unset (a total reflection
/// at either boundary: a film below 1, or a dielectric base below the film at steep facets; the
/// model refuses such stacks) lamina takes the exact total reflection, and where a facet's first
/// boundary reflects everything, the DC term alone (the white a flat spectrum gives, clamped).
/// `primaries` Srgb (not the shader's: an ablation) projects the same XYZ to linear sRGB (IEC
/// 61966-2-1) and divides each channel by what a flat spectrum gives it, so that white stays
/// white (the fit's XYZ of a flat spectrum is the equal-energy white).
enum class BelcourBarlaPrimaries { CieRgb, Srgb };
double belcour_barla_fresnel(int channel, double film_ior, double dinc_um, double base_eta,
                             double base_kappa, double cos_theta_1,
                             BelcourBarlaPrimaries primaries = BelcourBarlaPrimaries::CieRgb);
/// belcour_barla_fresnel in the three channels, channel c with the base base_eta[c]·(1 + i
/// base_kappa[c]) (the shader's base is one index: each channel is the shader run on its own).
Rgbd belcour_barla_fresnel(double film_ior, double dinc_um, const Rgbd& base_eta,
                           const Rgbd& base_kappa, double cos_theta_1,
                           BelcourBarlaPrimaries primaries = BelcourBarlaPrimaries::CieRgb);
/// belcour_barla_fresnel averaged over Dinc uniform in [dinc_min_um, dinc_max_um] (a thickness
/// uniform over a range) by Gauss–Legendre quadrature (32 nodes per period of the third order at
/// 360 nm, at most 2048), the two sides of the index blend's end (Dinc 0.03 µm) apart.
Rgbd belcour_barla_fresnel_range(double film_ior, double dinc_min_um, double dinc_max_um,
                                 const Rgbd& base_eta, const Rgbd& base_kappa, double cos_theta_1,
                                 BelcourBarlaPrimaries primaries = BelcourBarlaPrimaries::CieRgb);

/// Cycles' F82-tint metal under its thin film (kernel/closure/bsdf_microfacet.h, microfacet_fresnel
/// with F82_TINT): per channel the metal of normal reflectance f0 and F82 tint `tint` read as
/// Gulbrandsen's n + ik of r = min(f0, 0.999) and g = its F82-tint reflectance at 1/7, then
/// cycles_film_reflectance with that conductor and f82 = g. Films of thickness_nm ≤ 0.1 (Cycles'
/// THINFILM_THICKNESS_CUTOFF) leave the bare F82-tint metal.
Rgbd cycles_f82_tint_film(double film_ior, double thickness_nm, const Rgbd& f0, const Rgbd& tint,
                          double cos_theta);
/// cycles_f82_tint_film averaged over the thickness range [min_nm, max_nm]; min_nm = max_nm is one
/// thickness. The sum is linear in the sensitivity, whose lookup is piecewise linear in the
/// thickness: its mean is taken exactly (CyclesFilmSensitivity::mean) wherever Cycles' final clamp
/// to [0, 1] cannot act at any thickness of the range (the orders' largest swing about their DC
/// term stays inside it) and the range starts above 1 nm (where the film's index blends to 1);
/// elsewhere by Gauss–Legendre (32 nodes per period of the third order, at most 2048).
Rgbd cycles_f82_tint_film_range(double film_ior, double min_nm, double max_nm, const Rgbd& f0,
                                const Rgbd& tint, double cos_theta);

/// Cycles' film on a dielectric of index eta relative to the ambient (eta > 1), as its Principled
/// BSDF's specular layer evaluates it (kernel/closure/bsdf_microfacet.h,
/// generalized_schlick_fresnel with a film, at the node's default specular tint and IOR level,
/// where its rescaling towards the tinted F0 is the identity): per channel cycles_film_reflectance
/// over that dielectric. Films of thickness_nm ≤ 0.1 leave the bare dielectric's exact Fresnel
/// (Cycles' real Fresnel remapped between its own F0 and 1, which is itself).
Rgbd cycles_dielectric_film(double film_ior, double thickness_nm, double eta, double cos_theta);

}  // namespace lamina

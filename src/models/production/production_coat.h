#pragma once
// The coats that engines ship (docs/models.md, "Production coats"): OpenPBR Surface 1.1, Adobe's
// openpbr-bsdf, Autodesk Standard Surface, Dassault Enterprise PBR 2025x, Google Filament,
// glTF KHR_materials_clearcoat and three.js's MeshPhysicalMaterial, Blender Cycles Principled and
// Kulla & Conty 2017. Each is a sum of a coat lobe and the base's own lobe evaluated at the
// *outside* directions, the base scaled by a layering factor — none of them refracts, nor follows
// light between the interfaces:
//
//     f(wi, wo) = f_coat(wi, wo) + A(wi, wo) · T(wi, wo) · Δ(wo) · f_base'(wi, wo)
//
//   f_coat  the coat's microfacet reflection: Fresnel (exact or Schlick, at wi·h or at n·wo),
//           GGX D_α with α = r² (every engine squares its roughness parameter r; lamina's α0
//           maps to r = √α0) and a visibility term (height-correlated or uncorrelated Smith,
//           or Kelemen's);
//   A       the base attenuation: 1 − E_coat(μo) (albedo scaling), its reciprocal forms, or a
//           Schlick Fresnel at n·wo, wi·h or the larger of the two cosines;
//   T       the coat tint from τ_a: along both refracted paths, along the view's only, or a
//           constant e^(−2τ) (the tint matched at normal incidence, two ways);
//   Δ       OpenPBR's coat darkening (1 − K)/(1 − E_b K);
//   f_base' the Lambertian ρ/π, or the conductor's GGX lobe with the model's metal Fresnel
//           (exact, Schlick, F82-tint) and roughness after the model's base-roughening rule
//           (with openpbr-bsdf's compensation lobe for its multiple scattering).
//
// A recipe (CoatRecipe) names one model's choices; its flags switch each heuristic off and swap
// its leaves (Fresnel, visibility, roughness clamp, metal Fresnel) for lamina's exact ones. The
// directional albedos E_coat are lamina's FGD table (models/tables/fgd_table.h), or for
// openpbr-bsdf the albedo of its own lobe on its grid (models/production/uncorrelated_albedo.h,
// lamina's nodes): no engine's table is copied; the published fits a model ships (OpenPBR's E_F(η),
// Adobe's average Fresnel, Filament's F0 conversion) are implemented as shipped and cited where
// used.
//
// Represented: a dielectric coat (absorbing, not scattering) over a Lambertian or conductor base
// (BRDF only), anisotropic for the recipes that define anisotropic roughness (OpenPBR's), and for a
// recipe with a MetalFilm a thin film on the conductor; for a recipe with a DielectricFilm, a film
// on a plastic's interface (glossy_diffuse_film.h). Not supported, with the reason: other shapes, a
// scattering coat, a dielectric base (slab: the models' bases are opaque), and a coat IOR other
// than 1.5 for the models whose coat has a fixed IOR (Enterprise PBR, Filament, glTF).

#include "models/model.h"
#include "models/production/ggx_albedo.h"

#include <string>
#include <vector>

namespace lamina {

struct CoatRecipe {
    std::string name;
    enum class Fresnel {
        Exact,       ///< exact dielectric Fresnel of η0 (physics/fresnel.h)
        SchlickIor,  ///< Schlick with F0 = ((η0 − 1)/(η0 + 1))²
        Schlick004,  ///< Schlick with F0 = 0.04 (a fixed IOR 1.5: η0 must be 1.5)
    } coat_fresnel = Fresnel::Exact;
    /// The model's coat has no IOR parameter (IOR 1.5): another η0 is not supported.
    bool coat_ior_fixed = false;
    /// Schlick's weight (1 − c)⁵ replaced by the spherical-Gaussian fit 2^((−5.55473 c − 6.98316)
    /// c) (Karis 2013, "Real shading in Unreal Engine 4"; three.js's F_Schlick) on coat and metal.
    bool schlick_spherical_gaussian = false;
    /// The model clamps its coat IOR to ≥ 1 (Blender): η0 < 1 is not supported.
    bool coat_ior_at_least_one = false;
    /// The coat lobe's Fresnel at n·wo instead of wi·h (glTF's layering Fresnel).
    bool coat_fresnel_at_n = false;
    enum class Visibility {
        Smith,              ///< height-correlated Smith G2 / (4 μi μo) (Heitz 2014, Eq. 99)
        SmithUncorrelated,  ///< G1(wi) G1(wo) / (4 μi μo) (Heitz 2014, Eq. 98)
        Kelemen,  ///< 1 / (4 (wi·h)²) (Kelemen & Szirmay-Kalos 2001; Filament's V_Kelemen)
    } coat_visibility = Visibility::Smith;
    /// The metal lobe's masking-shadowing (Smith or SmithUncorrelated).
    Visibility metal_visibility = Visibility::Smith;
    /// Smallest coat roughness parameter r, a smooth coat included (Filament: 0.045); 0: none.
    double coat_min_roughness = 0;
    /// Smallest roughness parameter r of a rough lobe, coat or metal (openpbr-bsdf: 0.001); a
    /// smooth one (r = 0) stays a delta lobe.
    double lobe_min_roughness = 0;
    /// Smallest roughness parameter of the metal, a smooth one included (Filament: 0.045).
    double metal_min_roughness = 0;
    /// Largest value of D (Filament caps α/(1 − (n·h)²(1 − α²)) at 453.5, a half-precision
    /// guard, so D ≤ 453.5²/π in its coat and metal lobes); 0: none.
    double max_ndf = 0;

    /// Where E_coat, the coat lobe's directional albedo, comes from.
    enum class CoatAlbedo {
        Fgd,          ///< lamina's FGD table: exact Fresnel, height-correlated Smith
                      ///< (models/tables/fgd_table.h)
        OpenPbrBsdf,  ///< the uncorrelated lobe's albedo on openpbr-bsdf's grid, read as it reads
                      ///< it (models/production/uncorrelated_albedo.h)
        Cycles,       ///< Cycles' estimate of its compensated lobe's albedo,
                      ///< [E + F_ms (1 − E)] (F0 + (1 − F0) s) on its tables
                      ///< (models/production/cycles_albedo.h); F(μ; η0) for η0 ≤ 1
        MaterialX,    ///< MaterialX's: (F0 A + B) × its compensation, A and B its fit
                      ///< (materialx_ggx_albedo_fit)
    } coat_albedo = CoatAlbedo::Fgd;
    /// A compensation of the coat lobe for multiple scattering, a factor that depends on μo.
    enum class CoatEnergyCompensation {
        None,
        /// Cycles' on every dielectric microfacet closure: × (1 + F_ms (1 − E(μo))/E(μo)), E the
        /// white lobe's albedo on Cycles' table and F_ms = F_ss E_avg/(1 − F_ss (1 − E_avg)) with
        /// F_ss Kulla & Conty's fit of the coat's average Fresnel (kernel/closure/
        /// bsdf_microfacet.h, microfacet_ggx_preserve_energy).
        Cycles,
        /// MaterialX's (mx_ggx_energy_compensation, after Turquin 2019, Eqs. 14 and 16):
        /// × (1 + F_ss (1 − E)/E), F_ss = F0 + (1 − F0)/21, E = A + B of its fit at (μo, α).
        MaterialX,
    } coat_energy_compensation = CoatEnergyCompensation::None;
    /// A compensation of the metal lobe for multiple scattering, a factor on the lobe that
    /// depends on μo.
    enum class MetalEnergyCompensation {
        None,
        /// Filament: × (1 + F0 (1/E − 1)), E read from its DFG texture at (μo, r)
        /// (models/production/filament_dfg.h).
        Filament,
        /// Cycles' multiscatter GGX: × (1 + F_ms (1 − E)/E), E and E_avg from its tables,
        /// F_ms = F_ss E_avg/(1 − F_ss (1 − E_avg)), F_ss the F82-tint average F0 + (1 − F0)/21 −
        /// b/126.
        Cycles,
        /// three.js: × (1 + F0 (1/E − 1)), E read from its DFG texture at (r, μo)
        /// (models/production/threejs_dfg.h).
        ThreeJs,
        /// MaterialX: × (1 + F_ss (1 − E)/E), F_ss = F0 + (1 − F0)/21 (the F82 tint left out), E
        /// = A + B of its fit at (μo, α).
        MaterialX,
    } metal_energy_compensation = MetalEnergyCompensation::None;
    /// The metal's Schlick f90 = min(1, 16.5 (F0_r + F0_g + F0_b)) (Filament), not 1.
    bool metal_f90_from_f0 = false;
    /// A compensation lobe for the metal's multiple scattering between microfacets, of Kulla &
    /// Conty 2017's form c (1 − E(μi)) (1 − E(μo)) / (π (1 − E_avg)) with E a white lobe's albedo.
    enum class MetalMultipleScattering {
        None,
        /// openpbr-bsdf: c = F_avg², E the white uncorrelated lobe's albedo on its grid, the lobe
        /// clamped to 1/μi, for r ≥ 0.04.
        OpenPbrBsdf,
        /// dspbr-pt (Enterprise PBR): c = F_avg² E_avg/(1 − F_avg (1 − E_avg)) (Kulla & Conty 2017,
        /// slide 18), E(μ) = 1 − r (1 + (1 − μ)⁵)/2 and E_avg = 1 − 0.58 r + 0.08 r², both
        /// clamped to [0, 1] (its fits).
        EnterpriseApprox,
    } metal_multiple_scattering = MetalMultipleScattering::None;

    enum class Attenuation {
        AlbedoView,        ///< 1 − E(μo)
        AlbedoReciprocal,  ///< (1 − E(μi)) (1 − E(μo))
        KullaConty,        ///< (1 − E(μi)) (1 − E(μo)) / (1 − E_avg)
        FresnelView,       ///< 1 − F(μo) in the coat's own Fresnel
        FresnelHalf,       ///< 1 − F(wi·h)
        FresnelMax,        ///< 1 − max(F(μi), F(μo))
    } attenuation = Attenuation::AlbedoView;

    enum class Tint {
        TwoWay,    ///< exp(−τ (1/μt_i + 1/μt_o)), μt = √(1 − (1 − μ²)/η0²)
        ViewOnly,  ///< exp(−2τ/μt_o): the normal-incidence two-way tint along the view's path
        Constant,  ///< exp(−2τ): a model without a view-dependent tint (or none: baked in)
    } tint = Tint::TwoWay;

    enum class Darkening {
        None,
        Spec,   ///< OpenPBR 1.1: K = lerp(F(μo), K_r, r_b), E_F by d'Eon's fit, E_b from FGD
        Adobe,  ///< openpbr-bsdf: K_s = E_F (Kulla–Conty fit), E_b the average F82 Fresnel; the
                ///< diffuse base's specular (weight 0, relative index 1) still counts E_F(1)
        MaterialX,  ///< MaterialX's graph: K = 1 − (1 − F0)/η0² (F0 for E_F), E_b the base colour
    } darkening = Darkening::None;

    enum class Roughening {
        None,
        OpenPBR,          ///< r' = min(1, r⁴ + 2 r_c⁴)^¼
        Adobe,            ///< r' = min(1, r⁴ + (1 − 1/η0) r_c⁴)^¼
        Max,              ///< r' = max(r, r_c) (Filament)
        StandardSurface,  ///< r' = lerp(r, 1, r_c) (coat_affect_roughness = 1)
    } roughening = Roughening::None;

    enum class MetalFresnel {
        Exact,            ///< the conductor's exact Fresnel with η1/η0, κ1/η0
        Schlick,          ///< Schlick with the exact normal reflectance F0 under the coat
        F82Tint,          ///< Kutz et al. 2021's F82-tint: F0 and the tint from the exact F(1/7)
        SchlickFilament,  ///< Schlick with the F0 in air converted by f0ClearCoatToSurface
        /// The exact Fresnel of the n + ik that Gulbrandsen 2014's map (JCGT 3(4), Eqs. 3 and 4)
        /// gives for the metal's F0 under the coat (clamped to 0.99) and the edge colour g that
        /// makes n = η1/η0, clamped to the input's range [0, 1]: MaterialX's artistic_ior read
        /// from Standard Surface's base_color and specular_color. Inside the range it is Exact.
        Artistic,
    } metal_fresnel = MetalFresnel::Exact;

    /// A thin film on the metal base, between the coat and the metal (docs/models.md, "Thin
    /// films"): its reflectance replaces the metal's Fresnel in the base lobe.
    enum class MetalFilm {
        Unsupported,  ///< the model has no film under its coat: a filmed base is not supported
        /// The film's exact Airy reflectance relative to the coat at wi·h, per channel at the
        /// stack's wavelength, averaged over the thickness range (models/production/
        /// film_fresnel.h, film_reflectance_exact).
        Exact,
        /// three.js's iridescence Fresnel at n·wo against air (outside IOR 1), the base read from
        /// the metal's F0, averaged over the thickness range (threejs_iridescence_range); its
        /// thickness 0 turns the film off (the bare metal Fresnel).
        ThreeJs,
        /// openpbr-bsdf's: the Airy reflectance at wi·h between the coat and the metal's index
        /// from its F0 and F82 tint by Gulbrandsen's map, at the stack's wavelengths, faded in over
        /// the first 30 nm (openpbr_bsdf_film_reflectance); the metal's F82-tint Fresnel below.
        OpenPbrBsdf,
        /// Blender Cycles': its Fourier-space Airy sum at wi·h on its F82-tint metal read as
        /// Gulbrandsen's n + ik (cycles_f82_tint_film_range), the film's index and thickness
        /// taken relative to the coat (η_f/η_c, d η_c: Cycles' film sees an ambient of index 1);
        /// a film of at most 0.1 nm (so taken) leaves the bare metal.
        Cycles,
        /// OpenPBR Surface 1.1's ("Thin-film iridescence"): the film in the metal's Fresnel
        /// factor, evaluated from first principles at the stack's wavelengths (the
        /// specification's alternative to Belcour & Barla's model for renderers that sample
        /// wavelengths), the cases it leaves to the implementation taken exactly: the real
        /// indices of the coat (or ambient) above and of the metal below (η1 + iκ1, not an
        /// effective index of its F0 and F82 tint), tunnelling at the film's critical angle
        /// (film_reflectance_exact). A dielectric film only; thickness 0 (the whole range at 0)
        /// is no film: the metal's F82-tint Fresnel.
        OpenPbrSpec,
    } metal_film = MetalFilm::Unsupported;

    /// A thin film on a dielectric base's specular layer: a filmed plastic (ambient | film |
    /// dielectric | Lambertian) is the model's dielectric base without a coat, the film in its
    /// specular lobe's Fresnel factor (models/production/glossy_diffuse_film.h, which takes the
    /// layering from coat_albedo: Cycles' estimate, or else the filmed lobe's own albedo; the
    /// lobe's compensation from coat_energy_compensation; and, with the specification's
    /// darkening, the diffuse's colour darkened by it).
    enum class DielectricFilm {
        Unsupported,  ///< no film on the model's dielectric base
        Exact,        ///< the film's exact Airy reflectance (OpenPBR 1.1's open case taken exactly)
        Cycles,       ///< Cycles' film sum over the dielectric (cycles_dielectric_film)
    } dielectric_film = DielectricFilm::Unsupported;

    /// Standard Surface's coat_affect_color = 1: ρ ← ρ^2 (its default 0 leaves ρ).
    bool affect_color = false;
    /// The model defines anisotropic roughness as OpenPBR 1.1 does ("Specular" and "Coat":
    /// α_t = α √(2 / (1 + (1 − a)²)), α_b = (1 − a) α_t from α = r² and the anisotropy a), so an
    /// anisotropic interface is represented: its isotropic α is the root mean square
    /// √((α_x² + α_y²)/2), which the energy terms and the roughening read, and its lobe keeps the
    /// interface's α_y/α_x and tangent (docs/models.md, "Anisotropic coats"). Otherwise an
    /// anisotropic stack is not supported.
    bool anisotropic_roughness = false;
    /// MaterialX's OpenPBR: the diffuse base under the base's specular layer, whose weight 0 sets
    /// its index to 1 (no reflection) but whose throughput keeps 1 − B (1 + (1 − E)/(21 E)) of
    /// its fit at the default specular roughness after roughening.
    bool diffuse_specular_throughput = false;
};

/// Flags every production model shares, appended to its own: leaves=shipped|exact swaps the
/// coat's Fresnel, visibility and roughness clamp and the metal Fresnel for lamina's exact ones.
OptionSpec leaves_option();
/// Applies leaves=exact to a recipe.
void use_exact_leaves(CoatRecipe& recipe);

/// The isotropic α of an interface in OpenPBR 1.1's anisotropy parametrization (the inverse of
/// its α_t, α_b of α and a): √((α_x² + α_y²)/2); α itself for an isotropic interface.
double openpbr_isotropic_alpha(const InterfaceSpec& interface);

/// Builds a production coat; never fails (unsupported stacks say why in support()).
std::unique_ptr<Model> make_production_coat(const Stack& stack, const CoatRecipe& recipe);

/// OpenPBR's hemispherical Fresnel albedo E_F(η) = 2 ∫ F(μ; η) μ dμ by the fit of d'Eon 2021
/// as the OpenPBR 1.1 specification gives it (footnote "avg_fresnel", "accurate to within 0.2%"
/// for η ∈ [1, 3]: in reflectance, 1.5·10⁻³ at most, which is 1.4 % of E_F at η 1.5 and 5.8 % at
/// 1.1); η < 1 through E_F(η) = 1 − η² (1 − E_F(1/η)).
double openpbr_average_fresnel_fit(double eta);
/// OpenPBR 1.1 ("Darkening"): the internal reflectance of a rough coat's underside,
/// K_r = 1 − (1 − E_F)/η², from its average Fresnel E_F (the specification's fit, or a model's
/// own).
double openpbr_internal_reflectance(double eta, double average_fresnel);
/// OpenPBR 1.1 ("Darkening"): the darkening (1 − K)/(1 − E_b K) of a base of albedo E_b under a
/// coat whose underside reflects K: 0 where the coat reflects everything (K ≥ 1: a coat less
/// dense than the ambient medium past its critical angle), never 0/0 with a perfect base
/// (E_b = 1).
double openpbr_coat_darkening(double K, double E_b);
/// Kulla & Conty 2017 (slide 18)'s fit of the same average, as Adobe's openpbr-bsdf ships it
/// (openpbr_average_fresnel): (η − 1)/(4.08567 + 1.00071 η) for η > 1.
double kulla_conty_average_fresnel_fit(double eta);
/// Filament's conversion of an F0 against air to an F0 against a coat of IOR 1.5
/// (Filament documentation, "Clear coat", f0ClearCoatToSurface; a fit).
double filament_f0_clear_coat_to_surface(double f0);
/// MaterialX's rational fit of the split-sum's scale A and bias B of a GGX lobe with the
/// height-correlated Smith term (libraries/pbrlib/genglsl/lib/mx_microfacet_specular.glsl,
/// mx_ggx_dir_albedo_analytic: "rational quadratic fit to Monte Carlo data"), E_F0 = F0 A + B,
/// at (μ, α) with α the GGX α; A and B clamped to [0, 1].
SchlickSplit materialx_ggx_albedo_fit(double mu, double alpha);
/// Kutz, Hasan & Edmondson 2021 (OpenPBR 1.1, "Metal"): the F82-tint metal Fresnel,
/// F_Schlick(μ) − b μ (1 − μ)⁶ with b = F_Schlick(μ̄)(1 − tint)/(μ̄ (1 − μ̄)⁶), μ̄ = 1/7.
double f82_tint_fresnel(double cos_theta, double f0, double tint);

}  // namespace lamina

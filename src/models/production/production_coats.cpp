// The production coats as their authors ship them (docs/models.md, "Production coats"): one
// recipe of models/production/production_coat.h per model, with its flags. Sources, read for the
// equations (no code copied):
//   OpenPBR Surface 1.1 specification (Academy Software Foundation), "Coat" (darkening,
//     view-dependent absorption, roughening), "Layering" (albedo scaling) and "Thin-film
//     iridescence";
//   Adobe openpbr-bsdf (impl/openpbr_coating_lobe.h, impl/openpbr_bsdf.h; the reciprocal
//     coat attenuation is the OPENPBR_RECIPROCAL_COAT_AND_FUZZ switch, off by default);
//   Autodesk Standard Surface specification, "Coating", and its MaterialX graph
//     (libraries/bxdf/standard_surface.mtlx with pbrlib's genglsl functions);
//   Dassault Systèmes Enterprise PBR 2025x specification, "Clearcoat";
//   Google Filament documentation, "Clear coat model" and "Clear coat parameterization";
//   Khronos KHR_materials_clearcoat, "Layering" (and three.js's half-vector Fresnel in the lobe);
//   Blender Cycles, the Principled BSDF (kernel/svm/closure.h, kernel/closure/bsdf_microfacet.h);
//   Kulla & Conty 2017, "Revisiting physically based shading at Imageworks" (SIGGRAPH course).
#include "models/production/production_coats.h"
#include "models/production/production_coat.h"

#include "core/math.h"

namespace lamina {

namespace {

const char* on_off(bool b) {
    return b ? "on" : "off";
}
bool is_on(const ModelOptions& o, const std::string& key) {
    return option_value(o, key) == "on";
}
bool exact_leaves(const ModelOptions& o) {
    return option_value(o, "leaves") == "exact";
}

OptionSpec on_off_option(const std::string& key, bool default_on, const std::string& help) {
    return {key, {"on", "off"}, on_off(default_on), help};
}

// --- OpenPBR Surface 1.1 (the specification) ------------------------------------------------
CoatRecipe openpbr_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "openpbr";
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.attenuation = CoatRecipe::Attenuation::AlbedoView;  // Eq. coat_layering_formula
    r.tint = is_on(o, "view-tint") ? CoatRecipe::Tint::TwoWay : CoatRecipe::Tint::Constant;
    r.darkening = is_on(o, "darkening") ? CoatRecipe::Darkening::Spec : CoatRecipe::Darkening::None;
    r.roughening =
        is_on(o, "roughening") ? CoatRecipe::Roughening::OpenPBR : CoatRecipe::Roughening::None;
    r.metal_fresnel = CoatRecipe::MetalFresnel::F82Tint;
    // thin_film_weight 1 ("Thin-film iridescence"): the film on the metal under the coat.
    r.metal_film = CoatRecipe::MetalFilm::OpenPbrSpec;
    // ... and on the dielectric base's specular layer ("Glossy-diffuse"), taken exactly.
    r.dielectric_film = CoatRecipe::DielectricFilm::Exact;
    // specular_roughness_anisotropy and coat_roughness_anisotropy ("Specular", "Coat").
    r.anisotropic_roughness = true;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Adobe openpbr-bsdf --------------------------------------------------------------------
CoatRecipe adobe_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "openpbr-adobe";
    // Its thin film (thin_film_weight 1) on the metal under the coat.
    r.metal_film = CoatRecipe::MetalFilm::OpenPbrBsdf;
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.attenuation = is_on(o, "reciprocal") ? CoatRecipe::Attenuation::AlbedoReciprocal
                                           : CoatRecipe::Attenuation::AlbedoView;
    r.tint = is_on(o, "view-tint") ? CoatRecipe::Tint::TwoWay : CoatRecipe::Tint::Constant;
    r.darkening =
        is_on(o, "darkening") ? CoatRecipe::Darkening::Adobe : CoatRecipe::Darkening::None;
    r.roughening =
        is_on(o, "roughening") ? CoatRecipe::Roughening::Adobe : CoatRecipe::Roughening::None;
    r.metal_fresnel = CoatRecipe::MetalFresnel::F82Tint;
    // Its leaves (openpbr_lobe_utils.h, openpbr_eval_aniso_smith_g2): the uncorrelated Smith
    // masking-shadowing on coat and metal, r ≥ 0.001, E_coat the albedo of that lobe as its table
    // holds it, and the metal's multiple-scattering compensation lobe.
    r.coat_visibility = CoatRecipe::Visibility::SmithUncorrelated;
    r.metal_visibility = CoatRecipe::Visibility::SmithUncorrelated;
    r.lobe_min_roughness = 0.001;
    // Anisotropic α on both lobes, its energy terms at the isotropic α (openpbr_bsdf.h,
    // openpbr_compute_anisotropic_alpha, openpbr_get_isotropic_alpha).
    r.anisotropic_roughness = true;
    r.coat_albedo = CoatRecipe::CoatAlbedo::OpenPbrBsdf;
    r.metal_multiple_scattering = is_on(o, "multiple-scattering")
                                      ? CoatRecipe::MetalMultipleScattering::OpenPbrBsdf
                                      : CoatRecipe::MetalMultipleScattering::None;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- MaterialX's graphs (their GLSL generator) -------------------------------------------------
// The coat layer both graphs build from pbrlib: a dielectric_bsdf (exact Fresnel) layered over
// the base by its throughput 1 - E(mu_o) from the generator's fitted albedo, the constant
// coat_color on the base, and (energy-compensation) the coat and metal lobes compensated for
// multiple scattering by that fit.
void materialx_coat_layer(CoatRecipe& r, const ModelOptions& o) {
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.attenuation = CoatRecipe::Attenuation::AlbedoView;
    r.coat_albedo = CoatRecipe::CoatAlbedo::MaterialX;
    r.coat_energy_compensation = is_on(o, "energy-compensation")
                                     ? CoatRecipe::CoatEnergyCompensation::MaterialX
                                     : CoatRecipe::CoatEnergyCompensation::None;
    r.metal_energy_compensation = is_on(o, "energy-compensation")
                                      ? CoatRecipe::MetalEnergyCompensation::MaterialX
                                      : CoatRecipe::MetalEnergyCompensation::None;
    r.tint = CoatRecipe::Tint::Constant;
}

// --- OpenPBR in MaterialX (its graph, its GLSL generator) --------------------------------------
CoatRecipe materialx_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "openpbr-materialx";
    // libraries/bxdf/open_pbr_surface.mtlx as the GLSL generator evaluates it (pbrlib genglsl,
    // the analytic directional albedo): the coat a dielectric_bsdf layered over the base by its
    // throughput 1 - E(mu_o), the constant coat_color, the graph's darkening with
    // Kcoat = 1 - (1 - F0)/eta^2, the specification's roughening, every lobe compensated for
    // multiple scattering by the fitted albedo, and a diffuse base under its specular layer at
    // index 1.
    materialx_coat_layer(r, o);
    r.darkening =
        is_on(o, "darkening") ? CoatRecipe::Darkening::MaterialX : CoatRecipe::Darkening::None;
    r.roughening =
        is_on(o, "roughening") ? CoatRecipe::Roughening::OpenPBR : CoatRecipe::Roughening::None;
    r.metal_fresnel = CoatRecipe::MetalFresnel::F82Tint;
    r.diffuse_specular_throughput = true;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Autodesk Standard Surface --------------------------------------------------------------
CoatRecipe standard_surface_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "standard-surface";
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;  // coat_IOR, a dielectric GGX closure
    r.attenuation = CoatRecipe::Attenuation::AlbedoView;
    r.tint = CoatRecipe::Tint::Constant;  // coat_color multiplies every layer below
    r.roughening = option_value(o, "affect-roughness") == "1"
                       ? CoatRecipe::Roughening::StandardSurface
                       : CoatRecipe::Roughening::None;
    r.affect_color = option_value(o, "affect-color") == "1";
    // Gulbrandsen 2014's artist-friendly metal reproduces the exact conductor Fresnel of the
    // (η, κ) its two colours are derived from (docs/models.md says where it cannot).
    r.metal_fresnel = CoatRecipe::MetalFresnel::Exact;
    return r;
}

// --- Standard Surface in MaterialX (its graph, its GLSL generator) -----------------------------
CoatRecipe standard_surface_materialx_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "standard-surface-materialx";
    // libraries/bxdf/standard_surface.mtlx as the GLSL generator evaluates it: the coat a
    // dielectric_bsdf (weight coat, untinted) layered over the base by its throughput
    // 1 - E(mu_o) from the fitted albedo, the base times coat_attenuation = coat_color, coat and
    // metal lobes compensated for multiple scattering by that fit, the metal a conductor_bsdf of
    // the n + ik artistic_ior derives from base_color and specular_color, a diffuse base under a
    // specular layer of weight 0 (which passes it whole). No darkening; coat_affect_color and
    // coat_affect_roughness at their default 0.
    materialx_coat_layer(r, o);
    r.metal_fresnel = CoatRecipe::MetalFresnel::Artistic;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Dassault Enterprise PBR 2025x ----------------------------------------------------------
CoatRecipe enterprise_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "enterprise-pbr";
    r.coat_fresnel = CoatRecipe::Fresnel::Schlick004;
    r.coat_ior_fixed = true;
    r.attenuation = CoatRecipe::Attenuation::FresnelMax;  // 1 − c max(F_c(v·n), F_c(l·n))
    r.tint = CoatRecipe::Tint::Constant;                  // no coat tint: baked into the base
    r.metal_fresnel = CoatRecipe::MetalFresnel::Schlick;
    // As Dassault's path tracer dspbr-pt ships it (its material kernel): r ≥ 0.002 on coat and
    // metal, the metal's multiple-scattering lobe with its fitted albedos.
    r.lobe_min_roughness = 0.002;
    r.metal_multiple_scattering = is_on(o, "multiple-scattering")
                                      ? CoatRecipe::MetalMultipleScattering::EnterpriseApprox
                                      : CoatRecipe::MetalMultipleScattering::None;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Google Filament ------------------------------------------------------------------------
CoatRecipe filament_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "filament";
    r.coat_fresnel = CoatRecipe::Fresnel::Schlick004;
    r.coat_ior_fixed = true;
    r.coat_visibility = CoatRecipe::Visibility::Kelemen;
    // Its shaders (common_material.fs, surface_shading_lit.fs, surface_brdf.fs), desktop target:
    // perceptual roughness of coat and metal clamped to [0.045, 1] (0.089 on mobile), D capped,
    // the metal's f90 from its F0 and its energy compensation from the DFG texture.
    r.coat_min_roughness = 0.045;
    r.metal_min_roughness = 0.045;
    r.max_ndf = 453.5 * 453.5 / kPi<double>;
    r.metal_f90_from_f0 = true;
    r.metal_energy_compensation = is_on(o, "energy-compensation")
                                      ? CoatRecipe::MetalEnergyCompensation::Filament
                                      : CoatRecipe::MetalEnergyCompensation::None;
    r.attenuation = option_value(o, "attenuation") == "h" ? CoatRecipe::Attenuation::FresnelHalf
                                                          : CoatRecipe::Attenuation::FresnelView;
    r.tint = CoatRecipe::Tint::Constant;  // no coat tint: baked into the base
    r.roughening =
        is_on(o, "roughening") ? CoatRecipe::Roughening::Max : CoatRecipe::Roughening::None;
    r.metal_fresnel = is_on(o, "f0-conversion") ? CoatRecipe::MetalFresnel::SchlickFilament
                                                : CoatRecipe::MetalFresnel::Schlick;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- glTF KHR_materials_clearcoat -----------------------------------------------------------
CoatRecipe gltf_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "gltf-clearcoat";
    r.coat_fresnel = CoatRecipe::Fresnel::Schlick004;
    r.coat_ior_fixed = true;
    // mix(material, clearcoat_brdf, clearcoat · F(0.04, N·V)): the layering Fresnel at n·wo
    // weighs the coat lobe too; three.js evaluates the lobe's own Fresnel at v·h.
    r.coat_fresnel_at_n = option_value(o, "coat-fresnel") == "n";
    r.attenuation = CoatRecipe::Attenuation::FresnelView;
    r.tint = CoatRecipe::Tint::Constant;  // no coat tint: baked into the base
    r.metal_fresnel = CoatRecipe::MetalFresnel::Schlick;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- three.js MeshPhysicalMaterial (glTF's clear coat) ---------------------------------------
CoatRecipe threejs_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "threejs-clearcoat";
    // KHR_materials_iridescence on the base (iridescence_fragment, lights_fragment_begin):
    // evalIridescence at n.v replaces the base's Fresnel in its lobe.
    r.metal_film = CoatRecipe::MetalFilm::ThreeJs;
    // Its shaders (lights_physical_pars_fragment, lights_physical_fragment, meshphysical, common):
    // Schlick 0.04 in Karis's spherical-Gaussian form at v.h on the coat lobe, the base times
    // 1 - clearcoat F(n.v), the height-correlated visibility, roughness of coat and base clamped
    // to >= 0.045, the metal's Schlick with f90 = 1 and its multiple-scattering compensation from
    // the DFG texture.
    r.coat_fresnel = CoatRecipe::Fresnel::Schlick004;
    r.coat_ior_fixed = true;
    r.schlick_spherical_gaussian = true;
    r.attenuation = CoatRecipe::Attenuation::FresnelView;
    r.tint = CoatRecipe::Tint::Constant;  // no coat tint: baked into the base
    r.coat_min_roughness = 0.045;
    r.metal_min_roughness = 0.045;
    r.metal_fresnel = CoatRecipe::MetalFresnel::Schlick;
    r.metal_energy_compensation = is_on(o, "energy-compensation")
                                      ? CoatRecipe::MetalEnergyCompensation::ThreeJs
                                      : CoatRecipe::MetalEnergyCompensation::None;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Blender Cycles Principled --------------------------------------------------------------
CoatRecipe blender_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "blender-principled";
    // The Principled BSDF's thin film on its metal (kernel/svm/closure.h; microfacet_fresnel's
    // F82-tint case in kernel/closure/bsdf_microfacet.h).
    r.metal_film = CoatRecipe::MetalFilm::Cycles;
    // ... and on the dielectric base's specular layer (the Specular component's generalized
    // Schlick Fresnel with the film).
    r.dielectric_film = CoatRecipe::DielectricFilm::Cycles;
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.coat_ior_at_least_one = true;
    r.attenuation = CoatRecipe::Attenuation::AlbedoView;
    r.tint = is_on(o, "view-tint") ? CoatRecipe::Tint::ViewOnly : CoatRecipe::Tint::Constant;
    r.metal_fresnel = CoatRecipe::MetalFresnel::F82Tint;
    // As Cycles ships it (kernel/svm/closure.h, kernel/closure/bsdf_microfacet.h): every
    // dielectric closure compensated for multiple scattering, the coat's albedo its estimate on
    // Cycles' tables, the metal with the node's default multiscatter GGX.
    r.coat_energy_compensation = is_on(o, "energy-compensation")
                                     ? CoatRecipe::CoatEnergyCompensation::Cycles
                                     : CoatRecipe::CoatEnergyCompensation::None;
    r.coat_albedo = CoatRecipe::CoatAlbedo::Cycles;
    r.metal_energy_compensation = is_on(o, "energy-compensation")
                                      ? CoatRecipe::MetalEnergyCompensation::Cycles
                                      : CoatRecipe::MetalEnergyCompensation::None;
    if (exact_leaves(o)) use_exact_leaves(r);
    return r;
}

// --- Kulla & Conty 2017 ---------------------------------------------------------------------
CoatRecipe kulla_conty_recipe(const ModelOptions& o) {
    CoatRecipe r;
    r.name = "kulla-conty";
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.attenuation = option_value(o, "form") == "reciprocal" ? CoatRecipe::Attenuation::KullaConty
                                                            : CoatRecipe::Attenuation::AlbedoView;
    r.tint = CoatRecipe::Tint::TwoWay;  // Beer–Lambert along both refracted paths at n
    r.metal_fresnel = CoatRecipe::MetalFresnel::Exact;
    return r;
}

}  // namespace

std::vector<OptionSpec> openpbr_options() {
    return {on_off_option("darkening", true,
                          "coat darkening (1 - K)/(1 - E_b K), K = lerp(F(mu_o), K_r, r_b)"),
            on_off_option("roughening", true, "base roughening r' = min(1, r^4 + 2 r_c^4)^(1/4)"),
            on_off_option("view-tint", true,
                          "coat tint T^(1/mu_t,i + 1/mu_t,o); off: the constant coat_color"),
            leaves_option()};
}
std::unique_ptr<Model> make_openpbr(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, openpbr_recipe(options));
}

std::vector<OptionSpec> openpbr_adobe_options() {
    return {on_off_option("reciprocal", false,
                          "the light side's 1 - E_coat(wi) too (OPENPBR_RECIPROCAL_COAT_AND_FUZZ)"),
            on_off_option("darkening", true, "coat darkening with K_s = E_F (average Fresnel)"),
            on_off_option("roughening", true,
                          "base roughening r' = min(1, r^4 + (1 - 1/eta0) r_c^4)^(1/4)"),
            on_off_option("view-tint", true,
                          "coat tint on both passages; off: the constant coat_color"),
            on_off_option("multiple-scattering", true,
                          "the metal's compensation lobe for multiple scattering between its "
                          "microfacets (leaves=exact drops it)"),
            leaves_option()};
}
std::unique_ptr<Model> make_openpbr_adobe(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, adobe_recipe(options));
}

std::vector<OptionSpec> standard_surface_options() {
    return {{"affect-roughness",
             {"0", "1"},
             "0",
             "coat_affect_roughness: r <- lerp(r, 1, r_c) for the metal below"},
            {"affect-color",
             {"0", "1"},
             "0",
             "coat_affect_color: base_color <- base_color^2 (diffuse only)"}};
}
std::unique_ptr<Model> make_standard_surface(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, standard_surface_recipe(options));
}

std::vector<OptionSpec> standard_surface_materialx_options() {
    return {on_off_option("energy-compensation", true,
                          "coat and metal lobes x (1 + F_ss (1 - E)/E), E by MaterialX's fit "
                          "(leaves=exact drops it)"),
            leaves_option()};
}
std::unique_ptr<Model> make_standard_surface_materialx(const Stack& stack,
                                                       const ModelOptions& options) {
    return make_production_coat(stack, standard_surface_materialx_recipe(options));
}

std::vector<OptionSpec> enterprise_pbr_options() {
    return {on_off_option("multiple-scattering", true,
                          "the metal's multiple-scattering lobe (dspbr-pt's Kulla-Conty form with "
                          "its fitted albedos; leaves=exact drops it)"),
            leaves_option()};
}
std::unique_ptr<Model> make_enterprise_pbr(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, enterprise_recipe(options));
}

std::vector<OptionSpec> filament_options() {
    return {
        {"attenuation",
         {"h", "n"},
         "h",
         "base attenuation 1 - F_c at l.h (punctual lights) or at n.v (image-based lighting)"},
        on_off_option("roughening", true, "base roughness at least the coat's"),
        on_off_option("f0-conversion", true,
                      "f0ClearCoatToSurface: the metal's F0 in air converted to under the coat"),
        on_off_option("energy-compensation", true,
                      "the metal lobe x (1 + F0 (1/E - 1)), E from the DFG texture (leaves=exact "
                      "drops it)"),
        leaves_option()};
}
std::unique_ptr<Model> make_filament(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, filament_recipe(options));
}

std::vector<OptionSpec> gltf_clearcoat_options() {
    return {{"coat-fresnel",
             {"n", "h"},
             "n",
             "the coat lobe's Fresnel: the layering F(N.V) of the extension, or F(V.H) (three.js)"},
            leaves_option()};
}
std::unique_ptr<Model> make_gltf_clearcoat(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, gltf_recipe(options));
}

std::vector<OptionSpec> blender_principled_options() {
    return {on_off_option("view-tint", true,
                          "coat tint^(1/mu_t,o) along the view; off: the constant tint"),
            on_off_option("energy-compensation", true,
                          "Cycles' compensation of the coat and metal lobes for multiple "
                          "scattering, 1 + F_ms (1 - E)/E (leaves=exact drops it)"),
            leaves_option()};
}
std::unique_ptr<Model> make_blender_principled(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, blender_recipe(options));
}

std::vector<OptionSpec> threejs_clearcoat_options() {
    return {
        on_off_option("energy-compensation", true,
                      "the metal lobe x (1 + F0 (1/E - 1)), E from the DFG texture (leaves=exact "
                      "drops it)"),
        leaves_option()};
}
std::unique_ptr<Model> make_threejs_clearcoat(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, threejs_recipe(options));
}

std::vector<OptionSpec> openpbr_materialx_options() {
    return {
        on_off_option("darkening", true,
                      "the graph's coat darkening (1 - K)/(1 - E_b K), K = 1 - (1 - F0)/eta0^2"),
        on_off_option("roughening", true, "base roughening r' = min(1, r^4 + 2 r_c^4)^(1/4)"),
        on_off_option("energy-compensation", true,
                      "coat and metal lobes x (1 + F_ss (1 - E)/E), E by MaterialX's fit "
                      "(leaves=exact drops it)"),
        leaves_option()};
}
std::unique_ptr<Model> make_openpbr_materialx(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, materialx_recipe(options));
}

std::vector<OptionSpec> kulla_conty_options() {
    return {{"form",
             {"reciprocal", "view"},
             "reciprocal",
             "(1 - E(mu_i))(1 - E(mu_o))/(1 - E_avg), or the view-only 1 - E(mu_o)"}};
}
std::unique_ptr<Model> make_kulla_conty(const Stack& stack, const ModelOptions& options) {
    return make_production_coat(stack, kulla_conty_recipe(options));
}

}  // namespace lamina

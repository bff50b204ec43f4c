#pragma once
// lamina-coat: a coat engines can take instead of OpenPBR's, in the same structure and cost class
// (docs/lamina-coat.md: the derivation, the fit, the tables, the GLSL form and what it is
// accurate for). A coat lobe, the coat's multiple scattering, and the base evaluated at the
// directions refracted into the coat, attenuated and tinted on both paths:
//
//   f(wi, wo) = f_c(wi, wo) + k_g (1 − E_w(μi)) (1 − E_w(μo)) / (π (1 − Ē_w))
//             + t(μi) t(μo) f_b(wi', wo') / η²
//
//   f_c   the coat's GGX lobe, exact Fresnel of η, height-correlated Smith (α0 = r²);
//   k_g   grazing energy: the part of the coat's multiple scattering (white GGX albedo E_w)
//         reflected (Kulla & Conty 2017's lobe shape), fitted;
//   t(μ)  (1 − E_c(μ) − k_g (1 − E_w(μ))) exp(−s τ / μt(μ)): what the coat transmits along a
//         path, E_c its directional albedo, μt the refracted cosine, s = 1 + c_τ r the rough
//         coat's longer paths (view-dependent tint), c_τ fitted;
//   wi'   the refracted directions (x, y)/η, μt (Snell at the mean surface); f_b / η² the base's
//         BRDF inside, its radiance compressed by η² on the way out;
//   f_b   Lambertian: ρ / (π (1 − ρ K)), K = (1 − (1 − Ē)/η²) K_τ, the light the coat returns
//         to the base from inside (darkening), Ē the coat's hemispherical albedo, K_τ the smooth
//         coat's internal reflectance under absorption over its value without;
//         conductor: GGX with the exact conductor Fresnel at wi'·h' and α_b² = α1² + k_r α0²
//         (base roughening: the coat's two rough refractions widen the base's lobe), k_r fitted.
//
// Reciprocal (every factor is symmetric in wi, wo) and energy conserving (tests/models/
// lamina_coat/): the coat reflects E_c + k_g (1 − E_w) and transmits at most t; the Lambertian
// base returns t(μi) ρ (1 − K)/(1 − ρ K) ≤ t(μi), a conductor's lobe at most its own albedo.
// The tables (LaminaCoatTable) are docs/lamina-coat/tables.{csv,png}: 577 × 32 16-bit values.

#include "core/rgb.h"
#include "core/vec.h"
#include "models/model.h"

#include <memory>

namespace lamina {

/// The constants fitted on the study's configurations (scripts/lamina_coat_fit.py fit).
struct LaminaCoatFit {
    double grazing = 0;     ///< k_g
    double roughening = 0;  ///< k_r
    double tint_path = 0;   ///< c_τ
};
LaminaCoatFit lamina_coat_fit();

/// A coated material: coat index η ∈ [1.1, 2.6] (relative to the medium above), coat α0 = r²,
/// optical depth τ of the coat at normal incidence, and a Lambertian (ρ) or conductor (η1, κ1
/// relative to the coat, α1) base.
struct LaminaCoatMaterial {
    double eta = 1.5, alpha_coat = 0;
    Rgbd tau{0.0};
    bool conductor = false;
    Rgbd albedo{0.0};
    Rgbd base_eta{1.0}, base_k{0.0};
    double alpha_base = 0;
};

/// What the evaluation needs of a material, derived once.
struct LaminaCoatPrepared {
    LaminaCoatMaterial m;
    double r = 0;           ///< the coat's roughness parameter √α0
    double white_norm = 0;  ///< k_g / (π (1 − Ē_w)), 0 for a smooth coat
    Rgbd tau_path{0.0};     ///< s τ
    Rgbd lambert{0.0};      ///< ρ / (π (1 − ρ K)) (Lambertian base)
    double alpha_base = 0;  ///< α_b, the roughened base (conductor)
};

/// The tables' lookups (trilinear or bilinear on the nodes, arguments clamped to the table).
double lamina_coat_albedo(double mu, double r, double eta);      ///< E_c
double lamina_coat_white_albedo(double mu, double r);            ///< E_w
double lamina_coat_average_albedo(double r, double eta);         ///< Ē_c
double lamina_coat_white_average_albedo(double r);               ///< Ē_w
double lamina_coat_internal_absorption(double tau, double eta);  ///< K_τ

LaminaCoatPrepared lamina_coat_prepare(const LaminaCoatMaterial& m);
/// f(wi, wo), 1/sr; 0 unless wi.z > 0 and wo.z > 0. Smooth lobes (α = 0) are delta lobes: not here.
Rgbd lamina_coat_eval(const LaminaCoatPrepared& p, const Vec3d& wi, const Vec3d& wo);
/// t(μ): what the coat transmits along a path of cosine μ (no tint).
double lamina_coat_transmittance(const LaminaCoatPrepared& p, double mu);

/// The registry's model: coated stacks with η0 ∈ [1.1, 2.6], an absorbing coat, a Lambertian or
/// conductor base.
std::vector<OptionSpec> lamina_coat_options();
std::unique_ptr<Model> make_lamina_coat(const Stack& stack, const ModelOptions& options);

}  // namespace lamina

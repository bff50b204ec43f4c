#pragma once
// ddb22: lamina's reading of de Dinechin & Belcour 2022, "Rendering layered materials with diffuse
// interfaces" (I3D 2022, arXiv 2203.11835), for a rough dielectric coat (η0, α0, optional
// absorbing medium τ_a) over a Lambertian base (albedo ρ). The paper's text was not available to
// lamina: what follows its abstract ("two microfacet lobes accounting for direct and indirect
// interactions", fitted to "the first order directional statistics (energy, mean and variance)")
// and what is lamina's own choice is set out in docs/models.md, "ddb22". The BRDF is
//
//   f(wi, wo) = f_top(wi, wo)                                   direct lobe: the coat's exact
//                                                               single-scattering reflection
//             + E_ind(μi) · D_β(h_n) G2_β(n, wo) / (4 μo A(β))  indirect lobe
//
// with h_n = normalize(n + wo): a GGX lobe centred on the normal, the mean direction of the light
// a Lambertian base sends back (it forgets where the light came from). Its energy is the series
//
//   E_ind(μi) = T01(μi) a(μi') · ρ T̄ / (1 − ρ r̄),
//   T̄ = ∫ 2μ' a(μ') T10(μ') dμ',   r̄ = ∫ 2μ' a(μ')² R10(μ') dμ',
//
// T01/T10 the coat's directional transmittance from outside/inside (coat_transmittance.h), R10 its
// inside reflectance (the FGD table at 1/η0, with total internal reflection), a = exp(−τ_a/μ')
// along the macro refraction. β is the roughness whose unit lobe has the projected variance of
// the exiting light's directions (GgxNormalLobeTable), A(β) that lobe's albedo, so the indirect
// lobe reflects exactly E_ind. Each choice is a flag (Ddb22Choices). Several coats over the
// Lambertian (lamina's reading of the paper's Lambertian interface in Belcour 2018's adding): the
// direct lobes are Bel''s, and T01, T10, R10 become the coats' energies from Bel18's adding, down
// from the top and up from the base (Ddb22Stack).

#include "models/belcour/belcour.h"
#include "models/model.h"
#include "models/model_options.h"

#include <array>
#include <string>
#include <vector>

namespace lamina {

/// The moments of the unit GGX reflection lobe at normal incidence, g_α(wo) = D_α(h) G2_α(n, wo) /
/// (4 μo), h = normalize(n + wo) (the lobe shape of Belcour 2018, Eq. 1, for wi = n):
///   albedo   A(α) = ∫ g_α μo dωo ≤ 1 (1 for α = 0),
///   variance V(α) = ∫ g_α μo sin²θo dωo / A(α): the flux-weighted variance of its directions
///                   projected on the tangent plane (their mean is the normal), 0 for α = 0.
struct NormalLobeMoments {
    double albedo = 1;
    double variance = 0;
};

/// Both moments by n-point Gauss–Legendre rules over Heitz's visible normals at normal incidence
/// (u = tan²θh/(α² + tan²θh) uniform; wo leaves above the surface for tan θh < 1), in two pieces
/// (ddb22.cpp). α ∈ [0, 1].
NormalLobeMoments ggx_normal_lobe_moments(double alpha, int n = 64);

/// ggx_normal_lobe_moments on α = s² (65 nodes, s uniform in [0, 1]), linear in s; computed once
/// per process (65 × 64 lobe evaluations, well under a millisecond: cheaper than the disk cache).
class GgxNormalLobeTable {
  public:
    static const GgxNormalLobeTable& get();
    double albedo(double alpha) const;    ///< α ∈ [0, 1] (clamped)
    double variance(double alpha) const;  ///< α ∈ [0, 1] (clamped)
    /// The roughness whose lobe has projected variance v: V is increasing, inverted on the table's
    /// nodes. v ≤ 0 gives 0; v ≥ V(1) gives 1 (a lobe wider than the roughest GGX lobe).
    double alpha_of_variance(double v) const;
    static constexpr int kN = 65;

  private:
    GgxNormalLobeTable();
    std::array<double, kN> albedo_{}, variance_{};
};

struct Ddb22Choices {
    /// The indirect lobe's roughness from its variance: matched to the unit GGX lobe's own
    /// projected variance (GgxNormalLobeTable, true), or through Belcour 2018's mapping
    /// α((V/(1 − V))) (models/belcour/belcour.h), lamina's guess at reading V as Belcour's σ/(1 +
    /// σ).
    bool matched_variance = true;
    /// The indirect lobe centred on the normal, the mean of the light the base sends back (true),
    /// or a plain GGX reflection lobe of wi, D(h) G2(wi, wo)/(4 μi μo) normalized by its albedo
    /// at μi (false): the two readings of "a microfacet lobe" for the indirect light.
    bool lobe_at_normal = true;
};

/// The model's flags.
const ModelOptionTable<Ddb22Choices>& ddb22_option_table();

/// What the model computes once per stack (exposed for the tests): the per-channel series factor
/// K = ρ T̄/(1 − ρ r̄), the hemispherical integrals T̄ and r̄, the projected variance of the
/// exiting light V_exit and the indirect lobe's roughness β; the top interface and the base.
struct Ddb22Stack {
    Rgbd K{0.0}, T_bar{0.0}, r_bar{0.0};
    double v_exit = 0, beta = 0;
    double eta0 = 1.5, alpha0 = 0;  ///< the top coat: relative index to the ambient, roughness
    Rgbd tau_base{0.0};             ///< absorption of the medium right above the Lambertian
    Rgbd albedo{0.0};               ///< the Lambertian's ρ
    /// Two or more coats (lamina's reading of the paper's Lambertian interface in Bel18's adding,
    /// docs/models.md): the coats as operators of Belcour's adding scheme, top down without the
    /// medium above the base (`down`), and the same seen from the base, bottom up (`up`). Empty for
    /// one coat, whose energies come from the coat tables directly.
    std::vector<BelcourOperator> down, up;
    bool layered() const { return !down.empty(); }
};

/// Fills `out` for a stack ddb22 supports, or explains (in `why`) why it does not: one or more
/// dielectric coats (each relative index within the coat tables' [0.25, 4], at most 8) with
/// absorbing media over a Lambertian base.
bool ddb22_stack(const Stack& stack, const Ddb22Choices& choices, Ddb22Stack& out,
                 std::string& why);

/// The light of incidence μ ∈ (0, 1] that reaches the base (RGB, after the medium above it): the
/// coat's T01(μ) a(μ') for one coat, Bel18's transmitted energy of the coats for several.
Rgbd ddb22_transmittance_down(const Ddb22Stack& s, double mu);

/// The model with `choices` (the registry's; `name` is its registry name).
std::unique_ptr<Model> make_ddb22_model(const std::string& name, const Stack& stack,
                                        const Ddb22Choices& choices);

}  // namespace lamina

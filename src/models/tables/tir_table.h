#pragma once
// τ_TIR(c, α, η): the fraction of the light going up inside a layer at mean cosine c that leaves
// through the interface above it (relative index η = η_beyond / η_here, η < 1 from the denser
// side), the rest being totally internally reflected. Belcour 2018's adding scales the upward
// transmission of the stack above by τ_TIR and moves the rest to upward reflection; the transfer
// matrices of Randrianandrasana et al. 2021 do the same on an interface's own upward (and, into a
// lower index, downward) factors. α is the roughness the statistics attach to that step; what the
// table holds is one of three definitions (docs/models.md, "The tables lamina computes"):
//
// - LobeFresnel (the table shipped with Belcour's supplemental code, as third parties committed
//   it; measured): the light arrives as a normalized GGX reflection lobe of roughness α around
//   the cosine c and crosses a *smooth* interface, τ = ⟨1 − F(μo; η)⟩ over the lobe — the
//   "decoupling approximation" of the author's code: the roughness is the spread of the arriving
//   light, the interface itself is flat. Fresnel is included; τ → 1 − F(c; η) as α → 0.
// - Lobe (the table released with the transfer-matrix code, as its complement; measured): the
//   same lobe, the fraction of it above the critical cosine μc = √(1 − η²), without Fresnel;
//   τ → the step at μc as α → 0; τ = 1 for η ≥ 1.
// - Microfacet (lamina's own reading): collimated light at c on a *rough* interface of roughness
//   α, the fraction whose visible microfacet refracts it to the other side, without Fresnel;
//   τ → the step at μc; τ = 1 for η ≥ 1.
//
// The lobe is D_α(h) G1(wi) G1(wo) / (4 μi μo) μo, the reflection lobe of the incidence wi at
// cosine c over its directions above the horizon, normalized to unit energy; the separable Smith
// term is the one the committed tables hold (measured against them at 150 and 120 random nodes:
// mean difference 8e-4 and 1.6e-3 with it, 5.5e-3 and 1e-2 with the height-correlated G2).
//
// lamina computes each table itself. Lobe tables: for each node the three integrals (the lobe's
// energy, its Fresnel-weighted and its above-μc parts) over the visible normals of wi (Heitz
// 2018), by the split rule of models/numerics/visible_normal_quadrature.h with the radius split
// where the reflected direction crosses the horizon and μc; axes and interpolation of
// models/tables/critical_cosine_axes.h (log2 η ∈ [−2, 2]), the residual from w(α) times the α = 0
// limit; α = 0 returns the limit exactly. Microfacet table: stratified Monte Carlo through the
// interface (32 × 32 jittered strata of Heitz's sampling square per node, fixed seeds: bitwise
// reproducible), η ∈ [0.2, 1] with 33 nodes uniform in μc, α = s² (33), c with 49 nodes relative
// to each η node's μc (16 below, 32 above, quadratic spacing); bilinear in (c, α) at each of the
// two η nodes, then linear in η; η below 0.2 clamped. All are cached on disk like the FGD table.

#include "core/enum_names.h"

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

namespace lamina {

/// What τ_TIR holds (above).
enum class TirDefinition { LobeFresnel, Lobe, Microfacet };

inline constexpr std::array<EnumName<TirDefinition>, 3> enum_names(TirDefinition) {
    return {{{TirDefinition::LobeFresnel, "lobe-fresnel", "Fresnel over the light's GGX lobe"},
             {TirDefinition::Lobe, "lobe", "the lobe's part inside the escape cone"},
             {TirDefinition::Microfacet, "microfacet", "what the microfacets refract"}}};
}
inline const char* enum_noun(TirDefinition) {
    return "a TIR table";
}

/// τ_TIR(c, α, η) of a definition: c ∈ [0, 1], α ∈ [0, 1], η > 0 (clamped to the tables' axes).
/// The tables are computed (or loaded) on first use; tir_table_prepare builds one in advance.
double tir_fraction(TirDefinition definition, double c, double alpha, double eta);
void tir_table_prepare(TirDefinition definition);

/// The two lobe definitions (LobeFresnel, Lobe) in one table.
class LobeTirTable {
  public:
    static const LobeTirTable& get();

    /// Interpolated τ of a lobe definition (above); α = 0 gives the limit exactly.
    double operator()(TirDefinition definition, double c, double alpha, double eta) const;

    /// The same integrals with n_r nodes in u per piece × n_phi in φ, no table: the reference the
    /// table is tested against.
    static double direct(TirDefinition definition, double c, double alpha, double eta, int n_r = 48,
                         int n_phi = 96);
    /// The α = 0 limit: 1 − F(c; η) (LobeFresnel) or the step at μc (Lobe).
    static double smooth_limit(TirDefinition definition, double c, double eta);

    static constexpr int kNbelow = 33, kNc = 49, kNalpha = 33, kNeta = 41;
    static constexpr double kLog2EtaMin = -2, kLog2EtaMax = 2;

  private:
    LobeTirTable();
    std::vector<float> values_;
};

/// The Microfacet definition.
class TirTable {
  public:
    static const TirTable& get();

    /// Interpolated τ_TIR. c ∈ [0, 1], α ∈ [0, 1], η > 0 (1 when η ≥ 1).
    double operator()(double c, double alpha, double eta) const;

    /// Plain Monte Carlo estimate with n independent samples (seeded): the test reference.
    static double direct_mc(double c, double alpha, double eta, std::uint64_t n,
                            std::uint64_t seed = 7);
    /// The same fraction for one pair of uniforms: 1 if the sampled microfacet transmits.
    static bool transmits(double c, double alpha, double eta, double u1, double u2);

    static constexpr int kNc = 49, kNalpha = 33, kNeta = 33;
    static constexpr double kEtaMin = 0.2;

  private:
    TirTable();
    std::vector<float> values_;
};

}  // namespace lamina

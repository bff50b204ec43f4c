#pragma once
// The albedos Blender Cycles tabulates for its microfacet closures and reads back to compensate
// them for multiple scattering and to layer its Principled BSDF (docs/models.md,
// "`blender-principled`"), as lamina re-derives them:
//
//   E(μ, α)     the directional albedo of a white GGX lobe (F = 1) with the height-correlated
//               Smith term, ∫ D_wi(h) G2/G1(wi) dh over the visible normals of wi whose
//               reflection leaves above the horizon (Heitz 2018: visible-normal sampling leaves
//               the weight G2/G1);
//   E_avg(α)    its cosine-weighted average 2 ∫ E(μ) μ dμ;
//   s(μ, α, η)  the mean over the same visible normals of the Fresnel factor's position between
//               its ends, ŝ(c) = clamp((F(c; η) − F0)/(1 − F0), 0, 1), F the exact dielectric
//               Fresnel of relative index η > 1 and F0 = ((η − 1)/(η + 1))² (a normal whose
//               reflection goes below the horizon counts 0). Cycles takes F0 + (1 − F0) s as the
//               albedo of a rough dielectric's reflection relative to its own lobe.
//
// Cycles does not evaluate these integrals: it estimates them once by Monte Carlo (its
// cycles_precompute tool) on fixed nodes and interpolates them linearly in the node index. The
// grids here reproduce that reading with lamina's own node values (the integrals by quadrature
// over the visible normals):
//
//   - the roughness axis is the parameter r = √α, uniform over the nodes (32 for E and E_avg,
//     16 for s), the first node at r = 10⁻⁴;
//   - μ uniform over the nodes (32 for E, 16 for s), the first at μ = 10⁻⁴;
//   - η through z = √((η − 1)/(η + 1)), uniform over 16 nodes (z = 10⁻⁴ at the first, 0.99 at
//     the last), so that F0 = z⁴;
//   - each coordinate clamped to [0, 1] and read by x (n − 1): node ⌊·⌋ and its successor.
//
// Only the nodes a lobe reads are computed: 2 × 32 values of E and 2 of E_avg at one r, 2 × 16 × 2
// values of s at one (r, η).

#include <array>

namespace lamina {

/// E(μ, α) of the white GGX lobe with height-correlated Smith masking. μ ∈ [0, 1] (taken at
/// μ ≥ 10⁻⁶), α ≥ 0 (α = 0 gives 1). n_r Gauss–Legendre nodes per piece of the visible-normal
/// radius (split where the reflection crosses the horizon) × n_phi nodes in φ.
double correlated_ggx_albedo_white(double mu, double alpha, int n_r = 24, int n_phi = 48);

/// s(μ, α, η) above, η > 1; α = 0 gives ŝ(μ).
double cycles_fresnel_factor(double mu, double alpha, double eta, int n_r = 24, int n_phi = 48);

/// Cycles' tables ggx_E and ggx_Eavg read at one roughness parameter r ∈ [0, 1].
class CyclesWhiteAlbedo {
  public:
    static constexpr int kN = 32;
    explicit CyclesWhiteAlbedo(double r);
    /// E at μ ∈ [0, 1], as Cycles interpolates its table.
    double albedo(double mu) const;
    /// E_avg, as Cycles interpolates its table.
    double average() const { return average_; }

  private:
    std::array<double, 2 * kN> albedo_{};  // the two r columns, μ nodes
    double t_r_ = 0, average_ = 0;
};

/// Cycles' table ggx_gen_schlick_ior_s read at one roughness parameter r ∈ [0, 1] and one relative
/// index η > 1.
class CyclesFresnelFactor {
  public:
    static constexpr int kN = 16;
    CyclesFresnelFactor(double r, double eta);
    /// s at μ ∈ [0, 1], as Cycles interpolates its table.
    double factor(double mu) const;

    /// The node coordinates: r and μ at node i of 16, and η at node k.
    static double unit_node(int i);
    static double eta_node(int k);

  private:
    std::array<double, 2 * 2 * kN> factor_{};  // [z node][r node][μ node]
    double t_r_ = 0, t_z_ = 0;
};

}  // namespace lamina

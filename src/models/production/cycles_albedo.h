#pragma once
// The albedos Blender Cycles tabulates for its microfacet closures and reads back to compensate
// them for multiple scattering and to layer its Principled BSDF (docs/models.md,
// "`blender-principled`"), as lamina re-derives them:
//
//   E(μ, α)     the directional albedo of the white GGX lobe with the height-correlated Smith
//               term (models/production/ggx_albedo.h);
//   E_avg(α)    its cosine-weighted average 2 ∫ E(μ) μ dμ;
//   s(μ, α, η)  the mean Fresnel factor position (ggx_albedo.h, cycles_fresnel_factor).
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

#include "models/production/ggx_albedo.h"

#include <array>

namespace lamina {

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

/// Kulla & Conty 2017 (slide 18)'s colour of the multiply scattered energy with one Fresnel
/// bounce taken out, F_ms = F_ss E_avg/(1 − F_ss (1 − E_avg)), as Cycles scales its lobes
/// (kernel/closure/bsdf_microfacet.h, microfacet_ggx_preserve_energy): F_ss the lobe's average
/// Fresnel, E_avg its white lobe's average albedo.
inline double cycles_multiple_scattering_fresnel(double f_ss, double e_avg) {
    return f_ss * e_avg / (1 - f_ss * (1 - e_avg));
}

}  // namespace lamina

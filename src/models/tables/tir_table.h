#pragma once
// τ_TIR(c, α, η): the fraction of light arriving at a rough dielectric interface from its denser
// side (relative index η = η_beyond / η_here < 1, arriving cosine c) whose visible microfacet lets
// it through, i.e. refraction exists at the microfacet and the refracted direction leaves to the
// other side. Belcour 2018, §6 ("total internal reflection"): upward energy transmitted through
// the top interface is scaled by τ_TIR and the rest moved to upward reflection. Fresnel and
// shadowing are *not* included (they are in the FGD energies already); only the geometric
// TIR condition, over the visible normals D_w (Heitz 2018).
//
// lamina computes the table itself by stratified Monte Carlo through the interface: 32 × 32
// jittered strata of Heitz's sampling square per node, fixed seeds (bitwise reproducible). Axes:
// η ∈ [0.2, 1] (33 nodes uniform in c_crit = √(1 − η²)); α = s² (33 nodes, s uniform); c (49 nodes)
// relative to each η node's critical cosine c_crit = √(1 − η²), dense on both sides of it (16 nodes
// below, 32 above, quadratic spacing), where τ is a step smoothed over a width ~α. τ = 1 for η ≥ 1;
// η below 0.2 clamped; α = 0 gives the exact step. Interpolation: bilinear in (c, α) at each of the
// two η nodes (each with its own c axis), then linear in η. Cached on disk like the FGD table.

#include <cstdint>
#include <vector>

namespace lamina {

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

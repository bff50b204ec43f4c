#pragma once
// The directional albedo of a GGX reflection lobe with the *uncorrelated* Smith masking–shadowing
// G1(wi) G1(wo) (Heitz 2014, "Understanding the masking-shadowing function in microfacet-based
// BRDFs", JCGT 3(2), Eq. 98),
//
//     E(μ, α, η) = ∫ F(wi·h; η) D_α(h) G1(wi) G1(wo) / (4 μi μo) μo dωo,   μi = μ,
//
// the lobe Adobe's openpbr-bsdf ships for its coat and its metal, and the albedo its energy tables
// hold (docs/models.md, "Production coats": the "opaque dielectric" table is E with the exact
// dielectric Fresnel, the "ideal metal" table E with F = 1). lamina computes the integral itself
// over the visible normals of wi (Heitz 2018): E = ∫ D_wi(h) F(wi·h) G1(wo) dh.
//
// OpenPbrBsdfEnergyGrid reads these albedos as openpbr-bsdf tabulates and reads them — 32 nodes
// per axis (μ and the roughness r = √α uniform in [0, 1]; the relative index in two halves,
// [1, 2.5] uniform in η above 1 and uniform in 1/η below), trilinear interpolation in node
// indices, clamped at the ends, and its extrapolation past η = 2.5 (the complement scaled down
// linearly in F0) — with the node values openpbr-bsdf ships (data/production, its Monte Carlo
// estimates of the integrals above as 16-bit integers: within 1.41e-3 of them, which no
// re-derivation reproduces; tests/models/production/uncorrelated_albedo_test.cpp).

#include <array>

namespace lamina {

/// E(μ, α, η) with the exact dielectric Fresnel of relative index η (η < 1: total internal
/// reflection included); α = 0 gives the Fresnel factor F(μ; η). μ ∈ [0, 1] (0: the limit),
/// α ≥ 0. n_r Gauss–Legendre nodes per piece in u = √(1 − r) × n_phi nodes in φ, the radius split
/// where wo crosses the horizon (0: 24 × 48, within 6e-5 of the converged integral, measured on
/// openpbr-bsdf's nodes; worst at α = 0.05, normal incidence). For η < 1
/// the step of total internal reflection, where wi·h crosses the critical cosine, is not one
/// crossing per radius that the split could find: 0 there takes 96 × 400 (within 1e-4).
double uncorrelated_ggx_albedo(double mu, double alpha, double eta, int n_r = 0, int n_phi = 0);
/// The same with F = 1 (the lobe's own shadowing and masking losses only); α = 0 gives 1.
double uncorrelated_ggx_albedo_white(double mu, double alpha, int n_r = 0, int n_phi = 0);

/// openpbr-bsdf's 32-node energy grid, read as openpbr-bsdf reads it, at one (η, α) (or one α for
/// the white lobe), with openpbr-bsdf's node values.
class OpenPbrBsdfEnergyGrid {
  public:
    static constexpr int kN = 32;
    static constexpr double kEtaMax = 2.5;

    /// The dielectric lobe of relative index η > 0 at α ≥ 0.
    static OpenPbrBsdfEnergyGrid dielectric(double eta, double alpha);
    /// The white lobe (F = 1) at α ≥ 0, with its cosine-weighted average.
    static OpenPbrBsdfEnergyGrid white(double alpha);

    /// 1 − E(μ) interpolated as openpbr-bsdf interpolates its table (μ clamped to [0, 1]).
    double complement(double mu) const;
    /// 1 − 2 ∫ E(μ) μ dμ at the α nodes, interpolated in α (the white lobe's "average energy
    /// complement", openpbr-bsdf's table of it).
    double average_complement() const;

    /// The node coordinates openpbr-bsdf uses: the fractional index of η, of α (r = √α) and of μ.
    static double eta_index(double eta);
    static double alpha_index(double alpha);
    static double mu_index(double mu);
    /// The node values of the axes (the inverse of the indices at integers).
    static double eta_node(int i);
    static double alpha_node(int j);

  private:
    OpenPbrBsdfEnergyGrid() = default;
    // 1 − E at the two bracketing η nodes × two α nodes × every μ node.
    std::array<double, 2 * 2 * kN> complement_{};
    std::array<double, 2> average_complement_{};
    double t_eta_ = 0, t_alpha_ = 0;
    double extrapolation_ = 1;  // the scale of the complement past η = 2.5
};

}  // namespace lamina

#pragma once
// Unity HDRP's StackLit coat (docs/models.md, "Production coats", `unity-stacklit`): a production
// Belcour 2018 (the adding of a lobe's energy, mean cosine and variance through the coat, its
// medium and the base; Belcour 2018, §4–6) as StackLit.hlsl ships it for a directional or point
// light — the statistics taken once per view (its GetPreLightData, ComputeAdding), then three
// lobes at the outside directions:
//
//     f(wi, wo) = E_0(μo) c_0(μo) DV(α_c) + E_2(μo) c_2(μo) DV(α_b'(μo)) + ρ T_↑(μo)/π
//
//   E_0, E_2  the energies the adding gives the coat's and the base's lobes (exact Fresnel of the
//             coat and Schlick's of the base at the tracked cosines, no FGD, no TIR);
//   α_b'      the base's roughness after adding the coat's variances (σ = α^1.1/(1 − α^1.1));
//   c_0, c_2  its energy compensation 1 + F0 (1/E(μ, r) − 1) per lobe, E read from Unity's FGD
//             texture (UnityFgdTexture below);
//   DV        the GGX lobe D G2/(4 μi μo) (height-correlated Smith), α ≥ 1/1024 on every lobe;
//   T_↑       the energy the adding lets up through the stack (the diffuse base's hacked term).
//
// Represented: a clear or absorbing dielectric coat of η0 ≥ 1 over a Lambertian or conductor base,
// the conductor anisotropic too (StackLit's anisotropy is the base's: α_t = α (1 + a), α_b =
// α (1 − a)); BRDF only.

#include "models/model.h"

#include <array>

namespace lamina {

/// The white GGX lobe's directional albedo E(μ, r) as StackLit reads it from HDRP's
/// pre-integrated FGD texture (its channel y, "reflectivity"; PreIntegratedFGD.hlsl,
/// GetPreIntegratedFGDGGXAndDisneyDiffuse). lamina rebuilds the texture as HDRP renders it
/// (preIntegratedFGD_GGXDisneyDiffuse.shader), with its own code for each step:
///   - 64 × 64 texels; texel (i, j) at √μ = i/63 and perceptual roughness r = j/63 (α = r²);
///   - each the estimator IntegrateGGXAndDisneyDiffuseFGD, 4096 Hammersley points
///     (FilamentDfgTexture::estimate with the coordinates swapped, HammersleyAzimuth::Second);
///   - stored as 10-bit unsigned normalized values (A2B10G10R10): round(1023 E)/1023;
///   - read bilinearly with clamped edges at (√μ, r), the texel centres spanning [0, 1]
///     (Remap01ToHalfTexelCoord).
/// Built once per process (16.7 million estimator points).
class UnityFgdTexture {
  public:
    static constexpr int kSize = 64;
    static constexpr int kSamples = 4096;
    static const UnityFgdTexture& get();
    /// E as the texture returns it at μ ∈ [0, 1], perceptual roughness r ∈ [0, 1].
    double albedo(double mu, double perceptual_roughness) const;
    /// The stored texel (i at √μ = i/63, j at r = j/63).
    double texel(int i, int j) const { return texels_[std::size_t(j * kSize + i)]; }

  private:
    UnityFgdTexture();
    std::array<double, kSize * kSize> texels_{};
};

/// Builds `unity-stacklit` for a stack; never fails (unsupported stacks say why in support()).
std::unique_ptr<Model> make_unity_stacklit(const Stack& stack, const ModelOptions& options);
std::vector<OptionSpec> unity_stacklit_options();

}  // namespace lamina

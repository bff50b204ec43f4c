#pragma once
// The albedo of a white GGX lobe with the height-correlated Smith term, as Filament reads it from
// its "DFG" texture to compensate its specular lobe for multiple scattering (Filament
// documentation, "Energy compensation"; its shaders' getEnergyCompensationPixelParams):
//
//     energyCompensation = 1 + f0 (1/E − 1),   E = E(μo, r) = ∫ D G2 / (4 μi μo) μi dωi
//
// with r the lobe's perceptual roughness (α = r²). Filament does not evaluate that integral: it
// bakes E into a 128 × 128 half-float texture with its own estimator and reads it back with
// bilinear filtering at (μo, r). lamina reproduces that reading exactly, with its own code for
// each step, so that its `filament` model is the shipped shading (docs/models.md lists how far
// the texture is from the integral):
//
//   - the estimator (Filament's cmgen, "DFV_Multiscatter"): 1024 points of the Hammersley set
//     (u1 = i/1024, u2 the base-2 radical inverse of i), each a normal h drawn from D_α(h) cos θh,
//     with the reflected direction's contribution 4 V(μo, μi) μi (wo·h)/(n·h) (V the visibility
//     G2/(4 μi μo)), averaged; wo = (√(1 − μo²), 0, μo);
//   - the texels: column x at μo = (x + ½)/128; the row sampled at texture coordinate
//     t = (y + ½)/128 holds r = min(1, (y + 3/2)/128) — one texel rougher than its coordinate
//     (the generator's row centre and the row flip of its writer do not agree);
//   - each value rounded to half precision (IEEE 754 binary16);
//   - bilinear filtering with the texture's edges clamped.

#include <array>
#include <cstdint>

namespace lamina {

/// The base-2 radical inverse of i (van der Corput), the Hammersley set's second coordinate.
double hammersley_radical_inverse(std::uint32_t i);

/// Which coordinate of the Hammersley point (i/n, radical inverse of i) the estimators below take
/// for the azimuth of the sampled normal: Filament's cmgen the first, Unity HDRP's
/// IntegrateGGXAndDisneyDiffuseFGD the second (the first then draws cos θh).
enum class HammersleyAzimuth { First, Second };

class FilamentDfgTexture {
  public:
    static constexpr int kSize = 128;
    static constexpr int kSamples = 1024;

    /// The two texture rows a lookup at perceptual roughness r ∈ [0, 1] reads.
    explicit FilamentDfgTexture(double perceptual_roughness);

    /// E as the texture returns it at (μo, r): μo ∈ [0, 1].
    double albedo(double mu_o) const;

    /// Filament's estimator of E at one (μo, α) with n points (no texture, no rounding).
    /// `azimuth` = Second is Unity HDRP's estimator of the same integral (the Hammersley
    /// coordinates swapped; μo taken at ≥ 2⁻²⁴ as it takes it).
    static double estimate(double mu_o, double alpha, int n = kSamples,
                           HammersleyAzimuth azimuth = HammersleyAzimuth::First);
    /// The perceptual roughness the texture row sampled at coordinate (y + ½)/128 holds.
    static double row_roughness(int y);

  private:
    std::array<float, 2 * kSize> rows_{};  // the two rows, half-precision values
    double t_ = 0;                         // the upper row's weight
};

}  // namespace lamina

#pragma once
// The albedo of a white GGX lobe with the height-correlated Smith term as three.js reads it from
// its "DFG" texture to compensate its specular lobe for multiple scattering (three.js r187,
// lights_fragment_begin.glsl.js, after Turquin 2019, "Practical multiple scattering compensation
// for microfacet models", Eq. 16):
//
//     multiScatteringCompensation = 1 + F0 (1/E − 1),   E = scale + bias at (r, μo)
//
// with r the lobe's roughness parameter after three.js's clamp (α = r²). three.js ships the
// texture as data (DFGLUTData.js: 16 × 16 texels of two half floats, the split-sum's scale and
// bias, "4096 samples per texel") and reads it with bilinear filtering and clamped edges. lamina
// reads three.js's own texel values (data/production/threejs_dfg.csv, at r = (x + ½)/16,
// μ = (y + ½)/16): they are a Monte Carlo estimate, up to 1.47e-2 off the integral they stand for
// (models/production/ggx_albedo.h, correlated_ggx_schlick_split), which no re-derivation
// reproduces; tests/models/production/ggx_albedo_test.cpp bounds the difference.

#include <array>

namespace lamina {

class ThreeJsDfgTexture {
  public:
    static constexpr int kSize = 16;

    /// The two texel columns a lookup at roughness parameter r ∈ [0, 1] reads.
    explicit ThreeJsDfgTexture(double roughness);

    /// E = scale + bias as the texture returns it at (r, μo): μo ∈ [0, 1].
    double albedo(double mu_o) const;

    /// The texel centre of index i: (i + ½)/16.
    static double texel_centre(int i) { return (i + 0.5) / kSize; }

  private:
    std::array<double, 2 * kSize> albedo_{};  // the two columns, scale + bias of each texel
    double t_ = 0;                            // the upper column's weight
};

}  // namespace lamina

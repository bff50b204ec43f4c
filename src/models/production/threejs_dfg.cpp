#include "models/production/threejs_dfg.h"

#include "core/math.h"
#include "models/production/ggx_albedo.h"

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {

/// A value rounded to IEEE 754 binary16 (round to nearest, ties to even), as a half-float texel
/// holds it; the texture's values lie in the normal range of binary16 or are flushed by the same
/// rule (three.js's values are ≥ 2⁻²⁴).
double to_half(double x) {
    if (x == 0) return 0;
    int e = 0;
    std::frexp(std::abs(x), &e);  // |x| = m 2^e, m ∈ [½, 1)
    // binary16: 11 significant bits for normal numbers (e ≥ −13), a fixed step 2⁻²⁴ below.
    const int exponent = std::max(e - 11, -24);
    return std::nearbyint(std::ldexp(x, -exponent)) * std::ldexp(1.0, exponent);
}

/// The GL reading of a coordinate on an axis of n texels with clamped edges: the texel below
/// the sample point (x n − ½), the weight of the next; both indices clamped to [0, n − 1].
struct Bracket {
    int i0, i1;
    double t;
};
Bracket texel_bracket(double x, int n) {
    const double u = x * n - 0.5, lower = std::floor(u);
    const int i = int(lower);
    return {std::clamp(i, 0, n - 1), std::clamp(i + 1, 0, n - 1), u - lower};
}

}  // namespace

ThreeJsDfgTexture::ThreeJsDfgTexture(double roughness) {
    const Bracket b = texel_bracket(roughness, kSize);
    t_ = b.t;
    const int columns[2] = {b.i0, b.i1};
    for (int c = 0; c < 2; ++c) {
        const double alpha = sqr(texel_centre(columns[c]));
        for (int y = 0; y < kSize; ++y) {
            const SchlickSplit s = correlated_ggx_schlick_split(texel_centre(y), alpha);
            albedo_[c * kSize + y] = to_half(s.scale) + to_half(s.bias);
        }
    }
}

double ThreeJsDfgTexture::albedo(double mu_o) const {
    const Bracket b = texel_bracket(mu_o, kSize);
    auto at = [&](int c) {
        return std::lerp(albedo_[c * kSize + b.i0], albedo_[c * kSize + b.i1], b.t);
    };
    return std::lerp(at(0), at(1), t_);
}

}  // namespace lamina

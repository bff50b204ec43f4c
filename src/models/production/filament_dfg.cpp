#include "models/production/filament_dfg.h"

#include "core/math.h"
#include "core/npy.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>

namespace lamina {

double hammersley_radical_inverse(std::uint32_t i) {
    std::uint32_t bits = (i << 16) | (i >> 16);
    bits = ((bits & 0x55555555u) << 1) | ((bits & 0xAAAAAAAAu) >> 1);
    bits = ((bits & 0x33333333u) << 2) | ((bits & 0xCCCCCCCCu) >> 2);
    bits = ((bits & 0x0F0F0F0Fu) << 4) | ((bits & 0xF0F0F0F0u) >> 4);
    bits = ((bits & 0x00FF00FFu) << 8) | ((bits & 0xFF00FF00u) >> 8);
    return bits * 0x1p-32;
}

namespace {

float to_half_precision(double v) {
    return half_to_float(float_to_half(float(v)));
}

}  // namespace

double FilamentDfgTexture::estimate(double mu_o, double alpha, int n, HammersleyAzimuth azimuth) {
    // Unity's IntegrateGGXAndDisneyDiffuseFGD takes n·v at ≥ REAL_EPS (2⁻²⁴).
    if (azimuth == HammersleyAzimuth::Second) mu_o = std::max(mu_o, 0x1p-24);
    const double sin_o = std::sqrt(std::max(0.0, 1 - mu_o * mu_o));
    const double a2 = alpha * alpha;
    // Filament's u1 = i · (1/n) with 1/n in single precision.
    const float inv_n = 1.0f / float(n);
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        double u1 = double(i) * double(inv_n), u2 = hammersley_radical_inverse(std::uint32_t(i));
        if (azimuth == HammersleyAzimuth::Second) std::swap(u1, u2);
        // h from D(h) cos θh: cos²θh = (1 − u2)/(1 + (α² − 1) u2) (Walter et al. 2007, Eq. 35).
        const double phi = 2 * kPi<double> * u1;
        const double cos2 = (1 - u2) / (1 + (alpha + 1) * ((alpha - 1) * u2));
        const double cos_h = std::sqrt(cos2), sin_h = std::sqrt(1 - cos2);
        const double hx = sin_h * std::cos(phi);
        const double wo_h = sin_o * hx + mu_o * cos_h;
        const double mu_i = clamp(2 * wo_h * cos_h - mu_o, 0.0, 1.0);
        if (!(mu_i > 0)) continue;
        // V = G2/(4 μi μo) in the height-correlated form (Heitz 2014, Eq. 99).
        const double lambda_o = mu_i * std::sqrt((mu_o - mu_o * a2) * mu_o + a2);
        const double lambda_i = mu_o * std::sqrt((mu_i - mu_i * a2) * mu_i + a2);
        const double V = 0.5 / (lambda_o + lambda_i);
        sum += V * mu_i * (clamp(wo_h, 0.0, 1.0) / clamp(cos_h, 0.0, 1.0));
    }
    return sum * 4 / n;
}

double FilamentDfgTexture::row_roughness(int y) {
    return std::min(1.0, (y + 1.5) / kSize);
}

FilamentDfgTexture::FilamentDfgTexture(double perceptual_roughness) {
    // Bilinear filtering: texel centres at (y + ½)/128, edges clamped.
    const double ty = clamp(perceptual_roughness, 0.0, 1.0) * kSize - 0.5;
    const int y0 = int(std::floor(ty));
    t_ = ty - y0;
    for (int k = 0; k < 2; ++k) {
        const int y = std::clamp(y0 + k, 0, kSize - 1);
        const double alpha = sqr(row_roughness(y));
        for (int x = 0; x < kSize; ++x)
            rows_[k * kSize + x] = to_half_precision(estimate((x + 0.5) / kSize, alpha));
    }
}

double FilamentDfgTexture::albedo(double mu_o) const {
    const double tx = clamp(mu_o, 0.0, 1.0) * kSize - 0.5;
    const int x0 = int(std::floor(tx));
    const double s = tx - x0;
    auto at = [&](int k, int x) { return double(rows_[k * kSize + std::clamp(x, 0, kSize - 1)]); };
    const double lower = mix(at(0, x0), at(0, x0 + 1), s);
    const double upper = mix(at(1, x0), at(1, x0 + 1), s);
    return mix(lower, upper, t_);
}

}  // namespace lamina

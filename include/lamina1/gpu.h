#pragma once
// lamina-1's per-material state for its GLSL form (lamina1/lamina1.glsl): the precomputed curves
// and scalars eval reads, packed as float32 for a texture; the GLSL is eval_with's reflection
// line for line (lamina1/eval.h), so every curve is interpolated there as here.
//
// Covered by eval: the reflection (wo.z > 0) of a coat, rough or smooth (its delta lobes are not in
// eval: lamina1_delta gives their reflectance at the mirror direction, Bsdf::delta_lobes), with
// an absorbing medium, over a Lambertian, conductor or dielectric base, with the default choices
// or any of spread, first-order-lobe, eta2-factor, inside-exit, lobe-normalization,
// inter-reflection and directional-transmittance, with or without the microsurfaces' orders ≥ 2
// (microsurface), a slab's later orders in bins (slab-orders=bins) or as the series. Not covered
// (gpu_state says why and returns nothing): scattering media, anisotropic interfaces and a slab's
// transmission (the GLSL returns 0 for wo.z < 0). Covered by sample and pdf: the same but slabs
// (their mixture holds the transmission's lobes); the base lobe's weight in the mixture reads the
// base's mean albedo from a curve (kGpuBaseAlbedo), so the GLSL pdf is the C++ one to that curve's
// interpolation, and equal to the GLSL sample's own density.
//
// Layout (kGpu* below): kGpuScalars scalars, then the curves at fixed offsets, then the generic
// slope-sum table (lamina1/table_lookups.h, SlopeSumFormat) at kGpuSlopeSum; kGpuSize floats in
// all (kGpuBinsEnd for a slab with its bins, which follow the table), which lamina1.glsl reads with
// texelFetch from an R32F texture kGpuWidth texels wide (index i at (i % kGpuWidth, i /
// kGpuWidth)). The file `lamina export --lamina1-gpu` writes is these floats, little-endian.

#include "lamina1/bsdf.h"

#include <cstring>

namespace lamina1 {

constexpr int kGpuWidth = 256;
constexpr int kGpuScalars = 64;
constexpr int kGpuTTop = kGpuScalars;                      // T(μ): below[kNmu], above[kNmu]
constexpr int kGpuTTopIn = kGpuTTop + 2 * kNmu;            // T_in(μ'): the same
constexpr int kGpuX = kGpuTTopIn + 2 * kNmu;               // X(μ): kNx × RGB
constexpr int kGpuLobeNorm = kGpuX + 3 * kNx;              // 1/√N(μ'): kNnorm
constexpr int kGpuMirrorSeries = kGpuLobeNorm + kNnorm;    // kNmu × RGB (or the round trip's)
constexpr int kGpuEntering = kGpuMirrorSeries + 3 * kNmu;  // sin δ, cos δ, weight: 3 × 129
constexpr int kGpuLeaving = kGpuEntering + 3 * FacetDeflection::kN;
constexpr int kGpuBaseAlbedo = kGpuLeaving + 3 * FacetDeflection::kN;  // Ē_b(μ'): kNmu
constexpr int kGpuDRTop = kGpuBaseAlbedo + kNmu;        // the coat's orders ≥ 2, ΔR(μ): kNmu
constexpr int kGpuDEBase = kGpuDRTop + kNmu;            // the base's, ΔE(μ'): kNmu
constexpr int kGpuCoatAttenuation = kGpuDEBase + kNmu;  // a rough coat's a(μ): kNmu × RGB
constexpr int kGpuPolarization = kGpuCoatAttenuation + 3 * kNmu;  // a slab's √k_R(μ): kNfirst × RGB
constexpr int kGpuSlopeSum = 1860;
constexpr int kGpuSize =
    kGpuSlopeSum + SlopeSumFormat::kNx * SlopeSumFormat::kNy * SlopeSumFormat::kNu;
static_assert(kGpuPolarization + 3 * kNfirst <= kGpuSlopeSum, "the curves overlap");

// A slab's inside light in bins (slab-orders=bins, lamina1/slab.h), after the slope-sum table in
// states that have the flag kGpuBinsOn (the others end at kGpuSize): the coat's entry curve
// C(μ) (coat_bins_: the number of its cuts, the cuts, then kBinPer nodes per segment of 2 kNbins
// values: each bin's energy, then its forward moment), g(μ) (bins_g_: kNslab × RGB) and W P₁,
// W P₂ (bins_first_, bins_later_: per channel and azimuthal order, kNbins × kNbins row-major).
// The curve's segments are padded to the most a slab can have (the cuts are 0, 1 and where a
// smooth coat refracts each bin's edge and centre).
constexpr int kGpuBinsMaxCuts = 2 * kNbins + 3;
constexpr int kGpuBinsCuts = kGpuSize;  ///< n, then n cuts (n ≤ kGpuBinsMaxCuts)
constexpr int kGpuBinsNodes = kGpuBinsCuts + 1 + kGpuBinsMaxCuts;
constexpr int kGpuBinsG = kGpuBinsNodes + (kGpuBinsMaxCuts - 1) * kBinPer * 2 * kNbins;
constexpr int kGpuBinsFirst = kGpuBinsG + 3 * kNslab;
constexpr int kGpuBinsLater = kGpuBinsFirst + 3 * 2 * kNbins * kNbins;
constexpr int kGpuBinsEnd = kGpuBinsLater + 3 * 2 * kNbins * kNbins;

/// Bits of the flags scalar (index 0).
enum GpuFlag : unsigned {
    kGpuRoughCoat = 1u << 0,
    kGpuAbsorbs = 1u << 1,
    kGpuSeries = 1u << 2,
    kGpuXExact = 1u << 3,
    kGpuInsideExit = 1u << 4,
    kGpuMirrorSeriesOn = 1u << 5,
    kGpuLobeNormOn = 1u << 6,
    kGpuShapedLobe = 1u << 7,
    kGpuCompressed = 1u << 8,
    kGpuEta2 = 1u << 9,
    kGpuTTopExact = 1u << 10,
    kGpuTTopInExact = 1u << 11,
    kGpuSpreadNormal = 1u << 12,
    kGpuSpreadOff = 1u << 13,
    kGpuSampling = 1u << 14,         ///< lamina1_sample and lamina1_pdf cover it (not a slab)
    kGpuInterReflection = 1u << 15,  ///< the choice inter-reflection (lamina1_delta's series)
    kGpuTopOrders = 1u << 16,        ///< the coat's orders ≥ 2: ΔR(μi) ΔR(μo)/(π ΔR̄)
    kGpuBaseOrders = 1u << 17,       ///< the base's: F_ms ΔE(μi') ΔE(μo')/(π ΔĒ)
    kGpuBinsOn = 1u << 18,           ///< a slab's inside light in bins, from kGpuBinsCuts on
    kGpuCoatSpread = 1u << 19,       ///< a rough absorbing coat's a(μ) (Bsdf::coat_attenuation)
    /// The round trips' lobe (Bsdf::round_trip), its curve (kNx nodes over outside cosines) at
    /// kGpuMirrorSeries (the mirror series is never on with it).
    kGpuRoundTrip = 1u << 20,
    /// A slab's polarization (lamina1/polarization.h): a rough one's reflection beyond the coat's
    /// own scaled by √k_R(μi) √k_R(μo) (kGpuPolarization); a smooth one's delta series summed per
    /// polarization (lamina1_delta).
    kGpuPolarized = 1u << 21,
};

inline std::vector<float> Bsdf::gpu_state(std::string* why) const {
    auto refuse = [&](const char* reason) {
        if (why) *why = reason;
        return std::vector<float>();
    };
    if (!support_.brdf) return refuse("lamina-1 does not model these layers");
    if (scatters_) return refuse("a scattering medium (the GLSL form covers absorbing ones)");
    if (aniso_) return refuse("an anisotropic interface (the GLSL form is isotropic)");
    if (bins_ && coat_bins_.cut.size() > std::size_t(kGpuBinsMaxCuts))
        return refuse("more cuts in the bins' entry curve than the layout holds");
    std::vector<float> v(bins_ ? kGpuBinsEnd : kGpuSize, 0.0f);
    unsigned flags = 0;
    auto flag = [&](bool on, unsigned bit) { flags |= on ? bit : 0u; };
    flag(alpha0_ > 0, kGpuRoughCoat);
    flag(has_absorption_, kGpuAbsorbs);
    flag(series_on_, kGpuSeries);
    flag(x_exact_, kGpuXExact);
    flag(inside_exit_, kGpuInsideExit);
    flag(mirror_series_, kGpuMirrorSeriesOn);
    flag(lobe_norm_on_, kGpuLobeNormOn);
    flag(shaped_lobe_, kGpuShapedLobe);
    flag(ch_.first_order_lobe == Options::FirstOrderLobe::Compressed, kGpuCompressed);
    flag(ch_.eta2_factor, kGpuEta2);
    flag(T_top_.exact, kGpuTTopExact);
    flag(T_top_in_.exact, kGpuTTopInExact);
    flag(ch_.spread == Options::Spread::Normal, kGpuSpreadNormal);
    flag(ch_.spread == Options::Spread::Off, kGpuSpreadOff);
    flag(!support_.btdf, kGpuSampling);
    flag(ch_.inter_reflection, kGpuInterReflection);
    flag(top_ms_, kGpuTopOrders);
    flag(base_ms_, kGpuBaseOrders);
    flag(bins_, kGpuBinsOn);
    flag(a_coat_on_, kGpuCoatSpread);
    flag(round_trip_on_, kGpuRoundTrip);
    flag(pol_.has_value(), kGpuPolarized);
    v[0] = float(flags);  // exact in float32 (fewer than 2^24)
    v[1] = float(int(layers_.base));
    v[2] = float(eta0_);
    v[3] = float(inv_eta0_);
    v[4] = float(alpha0_);
    v[5] = float(alpha1_);
    v[6] = float(eta_b_);
    for (int c = 0; c < 3; ++c) {
        v[7 + c] = float(tau_t_[c]);
        v[10 + c] = float(layers_.albedo[c]);
        v[13 + c] = float(layers_.base_eta[c]);
        v[16 + c] = float(layers_.base_k[c]);
        v[19 + c] = float(K_[c]);
        v[22 + c] = float(r_bar_[c]);
    }
    v[25] = float(T_top_.curve.split);
    v[26] = float(T_top_.eta);
    v[27] = float(T_top_in_.curve.split);
    v[28] = float(T_top_in_.eta);
    v[29] = float(entering_.g_max);
    v[30] = float(leaving_.g_max);
    for (int c = 0; c < 3; ++c) {
        v[31 + c] = float(X_bar_[c]);
        v[34 + c] = float(F_ms_[c]);
    }
    v[37] = float(dR_top_bar_);
    v[38] = float(dE_base_bar_);
    for (int i = 0; i < kNmu; ++i) {
        v[kGpuTTop + i] = float(T_top_.curve.below[i]);
        v[kGpuTTop + kNmu + i] = float(T_top_.curve.above[i]);
        v[kGpuTTopIn + i] = float(T_top_in_.curve.below[i]);
        v[kGpuTTopIn + kNmu + i] = float(T_top_in_.curve.above[i]);
        if (!round_trip_on_)
            for (int c = 0; c < 3; ++c)
                v[kGpuMirrorSeries + 3 * i + c] = float(mirror_series_curve_.v[i][c]);
        if (top_ms_) v[kGpuDRTop + i] = float(dR_top_.v[i]);
        if (base_ms_) v[kGpuDEBase + i] = float(dE_base_.v[i]);
        if (a_coat_on_)
            for (int c = 0; c < 3; ++c)
                v[kGpuCoatAttenuation + 3 * i + c] = float(a_coat_.v[i][c]);
    }
    if (pol_on_)
        for (int i = 0; i < kNfirst; ++i)
            for (int c = 0; c < 3; ++c)
                v[kGpuPolarization + 3 * i + c] = float(pol_R_.v[i][c]);
    // The sampler's mixture weighs the base lobe by the base's mean albedo at the inside cosine:
    // a curve over μ' = s² (the FGD lookups it stands for stay in C++).
    for (int i = 0; i < kNmu; ++i)
        v[kGpuBaseAlbedo + i] = float(base_albedo(sqr(double(i) / (kNmu - 1))).mean());
    for (int i = 0; i < kNx; ++i)
        for (int c = 0; c < 3; ++c) {
            v[kGpuX + 3 * i + c] = float(X_.v[i][c]);
            if (round_trip_on_) v[kGpuMirrorSeries + 3 * i + c] = float(round_trip_curve_.v[i][c]);
        }
    for (int i = 0; i < kNnorm; ++i)
        v[kGpuLobeNorm + i] = float(lobe_norm_.v[i]);
    for (int i = 0; i < FacetDeflection::kN; ++i) {
        v[kGpuEntering + 3 * i] = float(entering_.sin_delta[i]);
        v[kGpuEntering + 3 * i + 1] = float(entering_.cos_delta[i]);
        v[kGpuEntering + 3 * i + 2] = float(entering_.weight[i]);
        v[kGpuLeaving + 3 * i] = float(leaving_.sin_delta[i]);
        v[kGpuLeaving + 3 * i + 1] = float(leaving_.cos_delta[i]);
        v[kGpuLeaving + 3 * i + 2] = float(leaving_.weight[i]);
    }
    if (const float* table = tables_->slope_sum())
        std::memcpy(&v[kGpuSlopeSum], table, SlopeSumFormat::size() * sizeof(float));
    if (bins_) {
        const std::size_t n = coat_bins_.cut.size();
        v[kGpuBinsCuts] = float(n);
        for (std::size_t i = 0; i < n; ++i)
            v[kGpuBinsCuts + 1 + i] = float(coat_bins_.cut[i]);
        for (std::size_t i = 0; i < coat_bins_.v.size(); ++i)
            for (int k = 0; k < 2 * kNbins; ++k)
                v[kGpuBinsNodes + 2 * kNbins * i + k] = float(coat_bins_.v[i].v[k]);
        for (int i = 0; i < kNslab; ++i)
            for (int c = 0; c < 3; ++c)
                v[kGpuBinsG + 3 * i + c] = float(bins_g_.v[i][c]);
        for (int c = 0; c < 3; ++c)
            for (int m = 0; m < 2; ++m)
                for (int jk = 0; jk < kNbins * kNbins; ++jk) {
                    const int at = (c * 2 + m) * kNbins * kNbins + jk;
                    v[kGpuBinsFirst + at] = float(bins_first_[c][m][jk]);
                    v[kGpuBinsLater + at] = float(bins_later_[c][m][jk]);
                }
    }
    return v;
}

}  // namespace lamina1

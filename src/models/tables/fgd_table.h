#pragma once
// FGD(c, α, η, κ): the directional albedo of a single GGX microfacet reflection lobe with exact
// Fresnel (Belcour 2018, §5.1 and supplemental: the tabulated "FGD" term),
//
//     FGD = ∫ F(wi·h; η + iκ) D_α(h) G2_α(wi, wo) / (4 μi μo) μo dωo,   μi = c,
//
// with the height-correlated G2 (Heitz 2014, Eq. 99) and relative index η + iκ (κ = 0: dielectric,
// η < 1 included: light from the denser side, with total internal reflection). lamina computes it
// itself (never copies the author's table): for each (c, α) the integral is written over the
// visible normals (Heitz 2018), FGD = ∫ D_wi(wm) F(wi·wm) G2/G1(wi) dwm, evaluated by a product
// Gauss–Legendre (in r, weight 2r) × trapezoid (in φ) rule on Heitz's sampling disk, whose nodes
// are then grouped by x = wi·wm into 64 bins (weight and weighted mean x): FGD = Σ_b W_b F(x̄_b).
// The Fresnel factor only depends on x, so one set of bins serves every (η, κ).
//
// Axes (docs/models.md has the measured accuracy): c = s² (41 nodes, s uniform in [0, 1]),
// α = s² (33 nodes), log2 η ∈ [−5, 3] (81, η = 1 is a node), κ = 10 s², s ∈ [0, 1] (21); outside,
// the arguments are clamped. Multilinear interpolation; α = 0 returns the exact Fresnel factor.
// The axes, the nodes' sum over the bins and the interpolation are the table's format, which
// lamina-1's header library holds (include/lamina1/table_lookups.h, FgdFormat) and reads.
// Computed on first use (≈1 s on 2 cores) and cached on disk (models/tables/table_cache.h).

#include "core/rgb.h"
#include "lamina1/table_lookups.h"

#include <array>
#include <vector>

namespace lamina {

class FgdTable {
  public:
    /// The process-wide table (computed or loaded once, thread-safe).
    static const FgdTable& get();

    /// Interpolated FGD. c = cos θi ∈ [0, 1], α ∈ [0, 1], η > 0, κ ≥ 0 (clamped to the axes).
    double operator()(double c, double alpha, double eta, double k) const;

    /// The (η, κ) part of a lookup, located once per interface (the symmetric Belcour variant
    /// looks the same indices up for every evaluation).
    using Index = lamina1::FgdFormat::Index;
    static Index locate(double eta, double k);
    double operator()(double c, double alpha, const Index& at) const;
    /// Three channels at once (a conductor), sharing the (c, α) part of the lookup.
    Rgbd rgb(double c, double alpha, const std::array<Index, 3>& at) const;

    /// The same integral computed directly (no table, no binning) with an n_r × n_phi rule: the
    /// reference the table is tested against.
    static double direct(double c, double alpha, double eta, double k, int n_r = 96,
                         int n_phi = 128);

    static constexpr int kNc = lamina1::FgdFormat::kNc, kNalpha = lamina1::FgdFormat::kNalpha,
                         kNeta = lamina1::FgdFormat::kNeta, kNk = lamina1::FgdFormat::kNk;
    static constexpr double kLog2EtaMin = lamina1::FgdFormat::kLog2EtaMin,
                            kLog2EtaMax = lamina1::FgdFormat::kLog2EtaMax,
                            kKMax = lamina1::FgdFormat::kKMax;

    /// The nodes (lamina1::FgdFormat's layout; lamina-1 reads them).
    const float* data() const { return data_; }
    /// The bins of x = wi·wm each (c, α) node is summed from (lamina-1's data file holds the
    /// table as them: lamina1::FgdBins).
    static lamina1::FgdBins bins();

  private:
    FgdTable();
    const float* data_;
    std::vector<float> values_;
};

/// E(c, α): the directional albedo of a GGX reflection lobe without its Fresnel factor (F = 1),
///
///     E = ∫ D_α(h) G2_α(wi, wo) / (4 μi μo) μo dωo,   μi = c,
///
/// the energy the lobe shape of belcour.h's ggx_lobe_shape reflects: what the released tm6 divides
/// its lobes by so that each reflects exactly its energy (its "GD" table; lamina computes its own
/// by FgdTable's visible-normal rule with F = 1, same c and α axes, cached on disk as FGD).
/// E ≤ 1, E = 1 for α = 0; bilinear interpolation in (√c, √α).
class GgxAlbedoTable {
  public:
    static const GgxAlbedoTable& get();
    /// c ∈ [0, 1], α ∈ [0, 1] (clamped).
    double operator()(double c, double alpha) const;
    /// The same integral by an n_r × n_phi rule, no table: the reference of the tests.
    static double direct(double c, double alpha, int n_r = 96, int n_phi = 128);

  private:
    GgxAlbedoTable();
    std::vector<float> values_;
};

/// Unpolarized Fresnel reflectance for a complex relative index η + iκ with light arriving from
/// the real (dielectric) side at cos_theta ∈ [0, 1] (lamina1::fresnel_complex, which cites the
/// closed form). With κ = 0 and η < 1 it gives 1 under total internal reflection. Equal to
/// physics/fresnel.h's fresnel_conductor, about 4× faster.
inline double fresnel_complex_fast(double cos_theta, double eta, double k) {
    return lamina1::fresnel_complex(cos_theta, eta, k);
}

/// The same for three channels at once (written as one loop over 4 lanes so the compiler
/// vectorizes it; lamina_models is built with -fno-math-errno for that).
inline Rgbd fresnel_complex_rgb(double cos_theta, const Rgbd& eta, const Rgbd& k) {
    const lamina1::Rgb f =
        lamina1::fresnel_complex_rgb(cos_theta, {eta[0], eta[1], eta[2]}, {k[0], k[1], k[2]});
    return {f[0], f[1], f[2]};
}

}  // namespace lamina

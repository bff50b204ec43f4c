#pragma once
// The energy that multiple scattering on a rough GGX microsurface adds to the single-scattering
// interface: the directional albedos of the scattering orders ≥ 2 of the microsurface random walk
// (Heitz, Hanika, d'Eon & Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the Smith
// model", ACM TOG 35(4); physics/microsurface_walk.h), for light arriving at cosine μ:
//
//     ΔR(μ, α, η) = P(the walk leaves on the side it came from, after ≥ 2 facets)
//     ΔT(μ, α, η) = P(the walk leaves on the other side, after ≥ 2 facets)
//     ΔE(μ, α)    = the same ΔR for a white conductor (Fresnel factor 1), = 1 − E_ss(μ, α)
//
// η is the relative index beyond / here (η < 1: light inside the denser medium). The first order
// of the walk is the single-scattering interface with the Smith surface's own masking (G2 for
// reflection, B(1 + Λi, 1 + Λo) for refraction; smith_masking.h), so single scattering plus these
// orders is the multiple-scattering interface's albedo, and ΔR + ΔT is exactly the energy that
// single scattering loses (docs/physics.md, "lost to the microsurface").
//
// lamina computes the table itself by the walk (the very code of the goniophotometer's
// --microsurface multiple), from lamina's counter-based generator with a fixed seed (the same on
// every machine up to the rounding of the math library), and caches it on disk as the FGD table
// (models/tables/table_cache.h). For the dielectric it stores only how the orders ≥ 2 split, s = ΔR
// / (ΔR + ΔT) (2^12 walks per node); their total is what single scattering loses, taken from the
// single-scattering tables, L = 1 − FGD(μ, α, η) − T(μ, α, η) (models/tables/fgd_table.h,
// models/tables/coat_transmittance.h with the Smith masking): ΔR = s L, ΔT = (1 − s) L, so that a
// rough dielectric with its orders ≥ 2 conserves energy by construction. The conductor's ΔE is
// stored itself (2^13 walks per node, standard error ≤ 0.0056). Axes: μ = s² (17 nodes, the first
// at 10⁻³), α = s² (17, α = 0 gives 0 exactly: a smooth interface has one order), log2 η ∈ [−2, 2]
// (25, η = 1 a node; the split changes fast near η = 1, where total internal reflection begins);
// arguments outside are clamped; multilinear interpolation.

#include "lamina1/table_lookups.h"

#include <vector>

namespace lamina {

class MultipleScatteringAlbedo {
  public:
    /// The process-wide table (computed or loaded once, thread-safe).
    static const MultipleScatteringAlbedo& get();

    /// ΔR and ΔT.
    using Dielectric = lamina1::MultipleScatteringFormat::Dielectric;
    /// Orders ≥ 2 of a rough dielectric. μ ∈ [0, 1], α ∈ [0, 1], η > 0.
    Dielectric dielectric(double mu, double alpha, double eta) const;
    /// Orders ≥ 2 of a rough white conductor (ΔE). μ ∈ [0, 1], α ∈ [0, 1].
    double conductor(double mu, double alpha) const;

    /// The walk's estimates of ΔR and ΔT at one node with `walks` walks (no table): what the
    /// table's split comes from and what the tests check it against.
    static Dielectric walk_dielectric(double mu, double alpha, double eta, int walks,
                                      unsigned stream);
    static double walk_conductor(double mu, double alpha, int walks, unsigned stream);

    static constexpr int kNmu = lamina1::MultipleScatteringFormat::kNmu,
                         kNalpha = lamina1::MultipleScatteringFormat::kNalpha,
                         kNeta = lamina1::MultipleScatteringFormat::kNeta;
    static constexpr int kWalksSplit = 1 << 12, kWalksConductor = 1 << 13;
    static constexpr double kLog2EtaMin = lamina1::MultipleScatteringFormat::kLog2EtaMin,
                            kLog2EtaMax = lamina1::MultipleScatteringFormat::kLog2EtaMax,
                            kMuMin = lamina1::MultipleScatteringFormat::kMuMin;

    /// The nodes (lamina1::MultipleScatteringFormat's layout; lamina-1 reads them).
    const std::vector<float>& values() const { return values_; }

  private:
    MultipleScatteringAlbedo();
    // [μ][α][η] s, then [μ][α] ΔE.
    std::vector<float> values_;
};

}  // namespace lamina

#pragma once
// T(c, α, η): the directional transmittance of a single rough GGX dielectric interface (Walter et
// al. 2007, "Microfacet models for refraction through rough surfaces", EGSR, Eq. 21),
//
//     T = ∫ f_t(wi, wo) |cos θo| dωo  over the other side,   μi = c,
//
// i.e. the fraction of the light arriving at cosine c that the single-scattering interface
// refracts and lets leave on the other side. What the microsurface masks after the refraction is
// lost (docs/physics.md §3 of the study; docs/models.md, lamina-1); the masking of the refracted
// ray is one of two forms (TransmissionMasking, physics/microfacet.h): the Smith surface's own
// height-correlated B(1 + Λi, 1 + Λo) (a refracted ray sees the heights below it; Heitz 2014,
// "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT 3(2), §6 with the
// Smith height distribution, and Heitz et al. 2016, §5.3) or Walter's 1/(1 + Λi + Λo) (Walter et
// al. 2007, Eq. 23 with the height-correlated Smith term of Heitz 2014, Eq. 99).
//
// η is the relative index η_beyond / η_here (η < 1: light from the denser side, with total
// internal reflection). lamina computes the table itself: for each (c, α) the integral is written
// over the visible normals (Heitz 2018, "Sampling the GGX distribution of visible normals",
// JCGT 7(4)), T = ∫ D_wi(wm) (1 − F(wi·wm)) G_t(wi, wt)/G1(wi) dwm, wt the refraction of wi about
// wm, by the split visible-normal rule of models/numerics/visible_normal_quadrature.h
// (Gauss–Legendre in u = √(1 − r) on each side of the facets' total internal reflection × midpoint
// in φ, half the disk and its mirror image). Axes and interpolation:
// models/tables/critical_cosine_axes.h (c in two pieces split at the critical cosine
// μc(η) = √(1 − η²), α = s², η in two halves meeting at η = 1), the residual from the smooth limit
// w(α)(1 − F(c)) interpolated (the control variate of the FGD table, for the step of TIR); α = 0
// returns 1 − F(c) exactly. Cached on disk
// like the FGD table (models/tables/table_cache.h). Its accuracy by region: docs/models.md,
// lamina-1.

#include "core/vec.h"
#include "lamina1/table_lookups.h"
#include "physics/transmission_masking.h"

#include <vector>

namespace lamina {

/// G_t/G1(wi) for the refraction pair (wi, wt) on GGX of roughness alpha, for either masking:
/// (1 + Λi) B(1 + Λi, 1 + Λt) or (1 + Λi)/(1 + Λi + Λt). Both are 1 when α = 0.
double refraction_escape(TransmissionMasking masking, double lambda_i, double lambda_t);

class CoatTransmittanceTable {
  public:
    /// The process-wide table for one masking (computed or loaded once, thread-safe).
    static const CoatTransmittanceTable& get(TransmissionMasking masking);

    /// Interpolated T. c ∈ [0, 1], α ∈ [0, 1], η > 0 (clamped to the axes).
    double operator()(double c, double alpha, double eta) const;

    /// The same integral with n_r nodes in u per piece × n_phi in φ, no table: the reference it is
    /// tested against.
    static double direct(double c, double alpha, double eta, TransmissionMasking masking,
                         int n_r = 64, int n_phi = 64);

    /// Nodes of the c axis below the critical cosine μc(η) = √(1 − η²) (η < 1) and above it
    /// (with μc = 0 where there is no total internal reflection), of α and of log2 η.
    static constexpr int kNbelow = lamina1::TransmittanceFormat::kNbelow,
                         kNc = lamina1::TransmittanceFormat::kNc,
                         kNalpha = lamina1::TransmittanceFormat::kNalpha,
                         kNeta = lamina1::TransmittanceFormat::kNeta;
    static constexpr double kLog2EtaMin = lamina1::TransmittanceFormat::kLog2EtaMin,
                            kLog2EtaMax = lamina1::TransmittanceFormat::kLog2EtaMax;

    /// The nodes (the layout of lamina1::TransmittanceFormat; lamina-1 reads them).
    const std::vector<float>& values() const { return values_; }

  private:
    explicit CoatTransmittanceTable(TransmissionMasking masking);
    std::vector<float> values_;
};

}  // namespace lamina

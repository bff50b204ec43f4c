#pragma once
// The density of a sum of independent GGX slopes (docs/models.md, lamina-1, item 4 and
// "Why the frosted metals stay at 20 %").
//
// The slopes s = (−m_x/m_z, −m_y/m_z) of GGX normals drawn with density D(m) cos θm are an
// isotropic bivariate Student t with ν = 2: P(s; a) = a² / (π (a² + |s|²)²), whose characteristic
// function is φ(a q) = a q K₁(a q) (K₁ the modified Bessel function of the second kind). A sum of
// independent such slopes of scales a_1, a_2, a_3 is not a GGX slope: its tail is that of one GGX
// of the summed variance σ² = Σ a_j² (the tail of a heavy-tailed sum is the sum of the tails,
// a_j²/(π |s|⁴) each), but its core is lower and wider — two equal scales have 2/3 of that GGX's
// density at s = 0 (∫₀^∞ x³ K₁(x)² dx = 2/3). The density, by the Hankel transform of the product
// of the characteristic functions,
//
//     P_sum(r) = (1/2π) ∫₀^∞ Π_j φ(a_j q) J₀(q r) q dq,
//
// is tabulated relative to that GGX, R = P_sum / P(·; σ), on generic axes: the first scale's share
// of the variance x = a_1²/σ² (25 nodes in [0, 1], x = (1 − cos πs)/2 with s uniform: a share
// that vanishes moves R like f ln f, so the nodes crowd at both ends), the second's share of the
// rest y = a_2²/(a_2² + a_3²) (13 nodes in [0, 1/2], y = s²/2; R is symmetric in y ↔ 1 − y),
// and the radius ρ = r/σ on u = ρ/(1 + ρ) (33 nodes in [0, 1]; R → 1 as ρ → ∞, and R = 1 when
// one scale holds all the variance). lamina computes it itself (composite Simpson rule in q on
// [0, 40], 4 001 nodes; std::cyl_bessel_k and std::cyl_bessel_j), well under a second on first
// use, cached on disk like the FGD table; trilinear interpolation in (s_x, s_y, u). The axes and
// the lookup are the table's format, lamina-1's header library's (include/lamina1/
// table_lookups.h, SlopeSumFormat), which reads the same values.

#include "lamina1/table_lookups.h"

#include <vector>

namespace lamina {

class SlopeSumTable {
  public:
    static const SlopeSumTable& get();

    /// The (x, y) part of a lookup, located once for every radius of one lobe.
    using Shares = lamina1::SlopeSumFormat::Shares;
    /// x, y clamped to [0, 1] (NaN to 0; y folded to [0, 1/2]).
    static Shares locate(double x, double y);

    /// R(ρ; x, y) = P_sum / P_GGX(σ) at radius ρ = r/σ ≥ 0 (NaN and negative read ρ = 0).
    double ratio(double rho, const Shares& at) const;
    double ratio(double rho, double x, double y) const { return ratio(rho, locate(x, y)); }

    /// The density P_sum(r) of a sum of GGX slopes of scales a_1, a_2, a_3 (any ≥ 0, not all 0),
    /// through the table: P(r; σ) R(r/σ; x, y).
    double density(double r, double a1, double a2, double a3) const;

    /// The same density by the Hankel integral directly (no table; an n-node Simpson rule on
    /// [0, q_max]): the reference of the tests.
    static double direct(double r, double a1, double a2, double a3, int n = 20001,
                         double q_max = 60);

    static constexpr int kNx = lamina1::SlopeSumFormat::kNx, kNy = lamina1::SlopeSumFormat::kNy,
                         kNu = lamina1::SlopeSumFormat::kNu;

    /// The nodes (lamina1::SlopeSumFormat's layout; lamina-1 reads them).
    const std::vector<float>& values() const { return values_; }

  private:
    SlopeSumTable();
    std::vector<float> values_;
};

}  // namespace lamina

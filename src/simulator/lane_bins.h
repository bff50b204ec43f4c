// Exit directions binned on SIMD lanes: the bin HemisphereGrid::bin_of gives, computed on
// vectors wherever the float arithmetic provably agrees with it. The SIMD kernel
// (simulator/kernel_simd.cpp) bins its exits so; the tests check the lanes against bin_of at and
// near every edge of several grids. A per-target header (core/lane_hwy.h).

#include "core/grid.h"
#include "core/lane_hwy.h"
#include "core/math.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_BINS_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_BINS_H
#undef LAMINA_SIMULATOR_LANE_BINS_H
#else
#define LAMINA_SIMULATOR_LANE_BINS_H
#endif

LAMINA_LANE_BEGIN

// The grid's bins on vectors. HemisphereGrid::bin_of's rule puts x = cos θ (or the folded cos φ,
// x/r in double) in bin b when edge[b] ≥ x > edge[b + 1], edge[b] = cos(b Δ): the bin of the
// angle acos(x), floor(acos(x)/Δ) clamped to [0, n − 1], wherever acos(x) is not within the edges'
// double rounding (~1e-16) of a multiple of Δ. The lanes compute the angle in float, t = Acos(x)/Δ
// in bins, with an error below η bins; where t − η and t + η fall in the same bin, that bin is
// bin_of's. The error bound η:
//   θ: x = min(|z|, 1) is bin_of's own; Acos's kAcosErrorBound, and t's own rounding (n ulps);
//   φ: x/r in float is within 2^-23 ≈ 1.2e-7 of bin_of's double x/r (two roundings in x² + y²,
//      halved by the square root, one in the square root and one in the quotient; 2e-7 is
//      used). To land more than η beyond an edge φe the float angle must move the cosine by at
//      least sin φe · η Δφ, and an inner edge has sin φe ≥ sin Δφ; the rest as for θ.
// Both get a factor of 4 of safety. A lane whose bin is not certain (in practice 1 exit in 10³ on
// the default grid) or whose r is below 1e-15 (x² + y² subnormal; bin_of's r = 0 is bin 0) takes
// bin_of itself; tests/simulator/kernel_simd_test.cpp checks the lanes against bin_of at and near
// every edge of several grids, folded and unfolded.
// An unfolded grid (core/grid.h) bins the folded cos φ among the folded grid's edges as bin_of does
// and, for y < 0, takes its mirror bin n_phi − 1 − b: the same rule, the sign of y exact in float.
struct VectorBins {
    int n_theta, n_phi;        // the grid's bins (n_phi: 2 n_folded when unfolded)
    int n_folded;              // the φ bins over [0, π] that cos φ is binned among
    bool unfolded;             // φ over [0, 2π): y < 0 takes the mirror bin
    float to_theta, to_phi;    // bins per radian
    float eta_theta, eta_phi;  // the error bounds, in bins
    explicit VectorBins(const HemisphereGrid& grid)
        : n_theta(grid.n_theta()),
          n_phi(grid.n_phi()),
          n_folded(grid.is_unfolded() ? grid.n_phi() / 2 : grid.n_phi()),
          unfolded(grid.is_unfolded()),
          to_theta(float(grid.n_theta() / (0.5 * kPi<double>))),
          to_phi(float(n_folded / kPi<double>)) {
        const double ulp = 0x1p-23;  // a float's relative spacing, at most
        const double d_phi = kPi<double> / n_folded;
        eta_theta = float(4 * (kAcosErrorBound * to_theta + n_theta * ulp));
        eta_phi = float(
            4 * ((kAcosErrorBound + 2e-7 / std::sin(std::min(d_phi, kPi<double> / 2))) * to_phi +
                 n_folded * ulp));
    }
};

// The θ and φ bins of the lanes' directions d (unit vectors), stored per lane; bit l of the
// result is set where lane l's pair is certainly bin_of's (VectorBins says when).
HWY_INLINE std::uint64_t LaneBins(const VectorBins& g, const V3& d, std::int32_t* theta_bin,
                                  std::int32_t* phi_bin) {
    const DF df;
    const DI di;
    const VF one = hn::Set(df, 1.f);
    const VF cos_theta = hn::Min(hn::Abs(d.z), one);
    const VF r = hn::Sqrt(hn::MulAdd(d.x, d.x, hn::Mul(d.y, d.y)));
    const MF resolved = hn::Gt(r, hn::Set(df, 1e-15f));
    const VF cos_phi =
        hn::Min(hn::Max(hn::Div(d.x, hn::IfThenElse(resolved, r, one)), hn::Set(df, -1.f)), one);
    // The bin of t − η and whether t + η shares it; truncation is the floor here (t ≥ 0), and
    // a negative t − η is clamped to bin 0 as floor would be.
    auto bin = [&](VF t, float eta, int n, std::int32_t* out) {
        const VI last = hn::Set(di, n - 1);
        const VI lo =
            hn::Min(hn::Max(hn::ConvertTo(di, hn::Sub(t, hn::Set(df, eta))), hn::Zero(di)), last);
        const VI hi =
            hn::Min(hn::Max(hn::ConvertTo(di, hn::Add(t, hn::Set(df, eta))), hn::Zero(di)), last);
        hn::Store(lo, di, out);
        return hn::RebindMask(df, hn::Eq(lo, hi));
    };
    const MF theta_known =
        bin(hn::Mul(Acos(cos_theta), hn::Set(df, g.to_theta)), g.eta_theta, g.n_theta, theta_bin);
    const MF phi_known =
        bin(hn::Mul(Acos(cos_phi), hn::Set(df, g.to_phi)), g.eta_phi, g.n_folded, phi_bin);
    if (g.unfolded) {
        const VI folded = hn::Load(di, phi_bin);
        const VI mirror = hn::Sub(hn::Set(di, g.n_phi - 1), folded);
        hn::Store(hn::IfThenElse(hn::RebindMask(di, hn::Lt(d.y, hn::Zero(df))), mirror, folded), di,
                  phi_bin);
    }
    return MaskBits(hn::And(resolved, hn::And(theta_known, phi_known)));
}

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_BINS_H

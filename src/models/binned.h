#pragma once
// A model averaged over the goniophotometer's bins (physics.md §5): for each incidence, side and
// bin, the cos-weighted average ∫_bin f |cos θ| dω / ∫_bin |cos θ| dω, in exactly the BinnedTable
// (`brdf.csv`) form of the reference.
//
// Quadrature: the measure |cos θ| dω = ½ d(sin²θ) dφ is uniform in (u = sin²θ, φ), so the bin
// average is a plain average over a rectangle in (u, φ) (one folded half: the stack is isotropic).
// Each rectangle gets a 2×2 and a 3×3 Gauss–Legendre product rule (13 evaluations); if they differ
// by more than rel_tol·|I| + abs_tol in any channel, it is bisected in both coordinates
// (recursively, up to max_depth, within an evaluation budget per bin), and the 3×3 value of
// accepted rectangles is kept. A rectangle that contains one of the model's peak directions
// (mirror; refracted for a BTDF) is always bisected towards it, down to a size of ~1e-10 in u:
// a lobe of α = 0.001 inside one bin is then resolved even though no coarse node sees it. Delta
// lobes add energy / Ω⊥ to the bin they hit. Parallel over (incidence, side, θ row) with OpenMP;
// every bin is computed independently, so the output does not depend on the thread count.

#include "core/grid.h"
#include "core/table.h"
#include "models/model.h"

#include <vector>

namespace lamina {

struct BinnedOptions {
    double rel_tol = 1e-4;
    double abs_tol = 1e-7;      ///< 1/sr: far below any measurable value
    int max_depth = 10;         ///< bisection levels driven by the error estimate
    int peak_depth = 40;        ///< bisection levels towards a peak direction
    long eval_budget = 200000;  ///< evaluations per bin before accepting the current estimate
};

/// Bins the sides the model supports (support().brdf → R, .btdf → T). theta_i_deg ∈ [0, 90).
BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, const BinnedOptions& options = {});

/// The cos-weighted average of f over one rectangle of (u = sin²θ, φ) (radians) on `side`, by the
/// same adaptive rule (exposed for tests).
Rgbd cos_weighted_average(const IncidentEvaluator& f, Side side, double u0, double u1, double phi0,
                          double phi1, const std::vector<Vec3d>& peaks,
                          const BinnedOptions& options = {});

/// Directional albedo ∫ f |cos θo| dωo of one side (RGB) for incidence wi, by the same adaptive
/// rule over the whole hemisphere, plus the delta lobes' energies on that side.
Rgbd model_albedo(const Model& model, const Vec3d& wi, Side side,
                  const BinnedOptions& options = {});

}  // namespace lamina

#pragma once
// A model averaged over the goniophotometer's bins (docs/physics.md §5): for each incidence, side
// and bin, the cos-weighted average ∫_bin f |cos θ| dω / ∫_bin |cos θ| dω, in exactly the
// BinnedTable (`brdf.csv`) form of the reference.
//
// On the folded grid the light lies in the plane φ = 0 and each bin is averaged over its half
// y ≥ 0 (an isotropic stack is mirror-symmetric about that plane); on the unfolded grid (an
// anisotropic stack, or light from φi ≠ 0: core/grid.h) over its one patch of φ ∈ [0°, 360°).
//
// Quadrature: over one rectangle of (θ, φ), with the weight
// sin θ cos θ in the integrand. (The measure is uniform in u = sin²θ, but in u the integrand has
// square-root edges at the normal and at grazing that adaptive bisection cannot shake off; in θ it
// is smooth up to both ends.)
// bin_model first evaluates the model on the lattice of half-bin steps, whose nodes neighbouring
// bins share (about 4 evaluations per bin), and takes a bin's 5 × 5-node rule where it agrees with
// the bin's own Simpson rule well within τ (below) and no peak direction is near (binned.cpp, "The
// shared-node pass": the rules, and the margin that covers jumps and kinks); every other bin, and
// every rectangle of cos_weighted_average and model_albedo, gets the adaptive rule.
// Each rectangle gets the 3×3 Gauss–Legendre product rule and the degree-3 rule embedded in its
// centre and axis nodes (9 evaluations); if they differ by more than the bin's tolerance
// τ = rel_tol·|bin average| + abs_tol (largest channel), it is bisected in both coordinates (up
// to max_depth), and the 3×3 value of accepted rectangles is kept; the difference estimates the
// error of the lower-degree rule, so the kept value is conservative. The rectangles are split
// best first — the largest error times weight next — within an evaluation budget per bin (in
// proportion to its size in (θ, φ)): within it the accepted rectangles are those of plain
// recursive bisection; where a model's value jumps along a curve (a cut-off such as total
// internal reflection inside a bin), the rectangles along the curve keep their error however
// small they get, and the budget is then spent evenly along it rather than on one end to
// max_depth. A rectangle that contains one of the model's peak directions (mirror; refracted for
// a BTDF) is always bisected towards it, down to a size of ~1e-10 in u, and for the first levels
// so are the rectangles near it, measured on the sphere (a sharp lobe at grazing is narrow in φ
// and wider in θ, and leaks into them; one just off the normal spills over the pole into bins of
// every azimuth): a lobe of α = 0.001 inside one bin is then resolved even though no coarse
// node sees it. Rectangles are halved across their longer side on the sphere (near the normal a
// bin is a sliver: in θ alone) or both ways. The embedded rule's estimate is blind to variation
// along one coordinate alone (on a function of θ alone the two rules agree): a sharp lobe's bins
// in the row at the horizon, where masking falls to 0 within about α of 90°, are the ones it
// leaves off (docs/models.md, "Evaluating a model"). Delta lobes add energy / Ω⊥ to the bin they
// hit. Parallel over (incidence, side, block of θ rows) with OpenMP, each block through the
// incidence's evaluator for one thread where the model has one (IncidentEvaluator::for_one_thread:
// the same values, bit for bit); a bin's value depends on the lattice's nodes and its own
// rectangle alone, so the output does not depend on the thread count.

#include "core/grid.h"
#include "core/table.h"
#include "models/model.h"

#include <vector>

namespace lamina {

struct BinnedOptions {
    double rel_tol = 1e-4;
    double abs_tol = 1e-7;  ///< 1/sr: far below any measurable value
    int max_depth = 10;     ///< bisection levels driven by the error estimate
    int peak_depth = 40;    ///< bisection levels towards a peak direction
    /// Evaluations per bin of 1° × 2° in (θ, φ) (the default grid's), in proportion for larger
    /// rectangles (a coarser grid's bins, model_albedo's), past which the rectangles not yet
    /// split are accepted. 10⁴: on the study's models the bins that reach it lie along a model's
    /// own discontinuity or hold an α = 0.001 peak, and a budget of 2·10⁵ moves them by less
    /// than 4·10⁻⁶ relative (16 models on 8 of the study's configurations, 7 incidences) at 1.9×
    /// WW09's cost.
    long eval_budget = 10000;
    /// model_albedo: integrate φ over [0, 2π) rather than twice [0, π] (which assumes the model
    /// mirror-symmetric about the plane of wi, i.e. an isotropic stack and wi.y = 0; wi.y ≠ 0
    /// always takes the full range).
    bool full_azimuth = false;
};

/// Bins the sides the model supports (support().brdf → R, .btdf → T). theta_i_deg ∈ [0, 90);
/// the light comes from azimuth φi = 0.
BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, const BinnedOptions& options = {});

/// The same with the light from azimuth phi_i_deg ∈ [0, 360] (wi = (sin θi cos φi, sin θi sin φi,
/// cos θi), as the goniophotometer's --phi-i): the bins the goniophotometer tabulates with that
/// incidence. A folded grid needs phi_i_deg = 0 (checked); pass the unfolded one otherwise.
BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, double phi_i_deg,
                      const BinnedOptions& options = {});

/// The cos-weighted average of f over one rectangle [θ0, θ1] × [φ0, φ1] (radians) on `side`, by
/// the same adaptive rule.
Rgbd cos_weighted_average(const IncidentEvaluator& f, Side side, double theta0, double theta1,
                          double phi0, double phi1, const std::vector<Vec3d>& peaks,
                          const BinnedOptions& options = {});

/// Directional albedo ∫ f |cos θo| dωo of one side (RGB) for incidence wi, by the same adaptive
/// rule over the whole hemisphere, plus the delta lobes' energies on that side.
Rgbd model_albedo(const Model& model, const Vec3d& wi, Side side,
                  const BinnedOptions& options = {});

}  // namespace lamina

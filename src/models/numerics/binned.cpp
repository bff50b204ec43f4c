#include "models/numerics/binned.h"

#include "core/check.h"
#include "core/math.h"
#include "core/spherical.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace lamina {

namespace {

// Gauss–Legendre on [0, 1]: 3 points at ½, ½ ± √(3/5)/2, weights 8/18, 5/18 (Abramowitz &
// Stegun, Table 25.4).
constexpr double kG3[3] = {0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
constexpr double kW3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
constexpr double kMinDtheta = 1e-9, kMinDphi = 1e-8;
constexpr double kPoleTheta = 1e-9;
// Forced levels over which the rectangles next to a peak's are split with it: down to 1/16384 of
// a 1° bin, ~10⁻⁶ rad, below the width of the sharpest lobe a stack may have (α = 10⁻⁴) at grazing.
constexpr int kNeighbourDepth = 14;
// Over the first kWideNeighbourDepth of them "next to" reaches twice the rectangle's size: the
// bins one row past a peak's neighbours can hold a lobe's steep tail that their two rules agree on
// by accident (α = 0.001 at θi = 0.5°: 8·10⁻⁴ off in the pole's second row; α = 0.1 at
// θi = 80°: 9·10⁻⁴ two rows from the peak; model_albedo 2.7·10⁻⁴ low at 85°). At 1.5 % more
// evaluations (the wide margin at every level would cost 3 %).
constexpr double kNeighbourMargin = 2.0;
constexpr int kWideNeighbourDepth = 6;

double max_abs(const Rgbd& v) {
    return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
}

struct Peak {
    double theta, phi;
    bool pole;  ///< at the normal: every φ
};

/// ∫ |cos θ| dω over [θ0, θ1] × [φ0, φ1] (one folded half), the weight of a rectangle, from the
/// sines of its θ edges.
double measure_of(double sin_t0, double sin_t1, double p0, double p1) {
    return 0.5 * (p1 - p0) * (sqr(sin_t1) - sqr(sin_t0));
}
double measure(double t0, double t1, double p0, double p1) {
    return measure_of(std::sin(t0), std::sin(t1), p0, p1);
}

// A rectangle's θ range and φ range, each with what the rule needs at its 3 Gauss–Legendre nodes,
// computed once per range: neighbouring bins of a row share the θ range, of a column the φ range,
// and the children of a bisected rectangle share theirs in pairs.

/// θ ∈ [lo, hi]: the edges' sines (for the measure), and at the nodes sin θ, cos θ and the weight
/// sin 2θ.
struct ThetaRange {
    double lo, hi, sin_lo, sin_hi;
    double sin_theta[3], cos_theta[3], weight[3];
};

ThetaRange theta_range(double lo, double hi, double sin_lo, double sin_hi) {
    ThetaRange r{lo, hi, sin_lo, sin_hi, {}, {}, {}};
    const double dt = hi - lo;
    for (int a = 0; a < 3; ++a) {
        const double theta = lo + dt * kG3[a];
        r.weight[a] = std::sin(2 * theta);
        r.sin_theta[a] = std::sin(theta);
        r.cos_theta[a] = std::cos(theta);
    }
    return r;
}
ThetaRange theta_range(double lo, double hi) {
    return theta_range(lo, hi, std::sin(lo), std::sin(hi));
}

/// φ ∈ [lo, hi]: cos φ and sin φ at the nodes.
struct PhiRange {
    double lo, hi;
    double cos_phi[3], sin_phi[3];
};

PhiRange phi_range(double lo, double hi) {
    PhiRange r{lo, hi, {}, {}};
    const double dp = hi - lo;
    for (int b = 0; b < 3; ++b) {
        const double phi = lo + dp * kG3[b];
        r.cos_phi[b] = std::cos(phi);
        r.sin_phi[b] = std::sin(phi);
    }
    return r;
}

double measure(const ThetaRange& t, const PhiRange& p) {
    return measure_of(t.sin_lo, t.sin_hi, p.lo, p.hi);
}

/// Which sides of a rectangle to halve: its longer one on the sphere, where the φ side measures
/// sin θ Δφ at its wider end, or both when neither is more than about twice the other (the
/// thresholds 2 and 2.5 keep the default grid's bins, whose φ side is at most exactly twice the
/// θ side, at grazing, clear of a tie decided by rounding).
std::pair<bool, bool> sides_to_halve(const ThetaRange& t, const PhiRange& p) {
    const double length_t = t.hi - t.lo, length_phi = t.sin_hi * (p.hi - p.lo);
    return {!(length_phi > 2.5 * length_t), !(length_t > 2 * length_phi)};
}

// Rectangles live in (θ, φ), where the integrand f·sin θ cos θ is smooth up to both ends of the
// hemisphere (in u = sin²θ it has square-root edges at the normal and at grazing, which adaptive
// bisection cannot shake off).
class RectIntegrator {
  public:
    RectIntegrator(const IncidentEvaluator& f, Side side, std::vector<Peak> peaks,
                   const BinnedOptions& o)
        : f_(f), transmission_(side == Side::Transmission), peaks_(std::move(peaks)), o_(o) {}

    /// The cos-weighted average over the rectangle. Error control is on this average: every
    /// sub-rectangle's average must be good to τ = rel_tol·|average| + abs_tol (a sub-rectangle
    /// of weight fraction a then adds at most a·τ to the error, so the sum stays within τ).
    Rgbd average(const ThetaRange& t, const PhiRange& p) {
        evals_ = 0;
        // The budget per 1° × 2° of (θ, φ), a bin of the default grid: a larger rectangle has
        // longer discontinuities and more room for peaks.
        constexpr double kBudgetArea = (kPi<double> / 180) * (kPi<double> / 90);
        budget_ = std::max(double(o_.eval_budget),
                           double(o_.eval_budget) * (t.hi - t.lo) * (p.hi - p.lo) / kBudgetArea);
        const std::pair<Rgbd, Rgbd> whole = rule(t, p);
        const Rgbd coarse = whole.second;
        // The top level reuses the coarse rule's nodes: the same values, not evaluated twice.
        const Rgbd first = refine(t, p, o_.rel_tol * max_abs(coarse) + o_.abs_tol, &whole);
        // A narrow lobe missed by the coarse nodes made τ far too strict: redo with the real size.
        if (max_abs(first) > 10 * max_abs(coarse)) {
            evals_ = 0;
            return refine(t, p, o_.rel_tol * max_abs(first) + o_.abs_tol);
        }
        return first;
    }

    /// Whether a peak direction forces the rectangle to be split before its rule is taken.
    bool forced_split(const ThetaRange& t, const PhiRange& p) const {
        if (o_.peak_depth <= 0) return false;
        bool split_t = false, split_phi = false;
        peak_split(t, p, 0, split_t, split_phi);
        return split_t || split_phi;
    }

  private:
    /// Cos-weighted averages by two embedded rules on the same 9 nodes, each normalized by the
    /// same rule applied to the weight sin θ cos θ (so constants are exact): the 3×3
    /// Gauss–Legendre product rule (degree 5) and the 5-point degree-3 rule on its centre and
    /// its 4 axis nodes (weights −1/9 and 5/18: exact for 1, x², y²). Their difference estimates
    /// the error of the lower one, so keeping the 3×3 value is conservative.
    std::pair<Rgbd, Rgbd> rule(const ThetaRange& t, const PhiRange& p) {
        constexpr double kW5Centre = -1.0 / 9, kW5Axis = 5.0 / 18;
        Rgbd i3(0.0), i5(0.0);
        double w3 = 0, w5 = 0;
        evals_ += 9;
        for (int a = 0; a < 3; ++a) {
            const double w = t.weight[a], sin_theta = t.sin_theta[a];
            const double z = transmission_ ? -t.cos_theta[a] : t.cos_theta[a];
            w3 += w * kW3[a];
            for (int b = 0; b < 3; ++b) {
                const Rgbd g =
                    f_.eval(Vec3d(sin_theta * p.cos_phi[b], sin_theta * p.sin_phi[b], z)) * w;
                i3 += g * (kW3[a] * kW3[b]);
                const bool centre = a == 1 && b == 1, axis = (a == 1) != (b == 1);
                if (centre || axis) {
                    const double c5 = centre ? kW5Centre : kW5Axis;
                    i5 += g * c5;
                    w5 += w * c5;
                }
            }
        }
        if (w3 <= 0 || w5 <= 0) return {Rgbd(0.0), Rgbd(0.0)};
        return {i5 / w5, i3 / w3};
    }

    /// Which coordinates must be split to approach a peak inside the (closed) rectangle or, for
    /// the first kNeighbourDepth levels, near it: within the rectangle's own size of it along θ
    /// and along the parallel (twice that over the first kWideNeighbourDepth levels). Without the
    /// neighbours a lobe narrower than the node spacing leaks past the edge of the rectangle that
    /// holds its peak into one whose nodes all miss it, or into one whose two rules agree by
    /// accident on a wrong value: at grazing a sharp lobe is narrow in φ and wider in θ (α = 0.001
    /// at 85°: the rectangles along the peak's row missed 0.4 % of the light, 3.6 % with rel_tol
    /// 10⁻³, against the model's own sampling).
    ///
    /// Sizes and distances are taken on the sphere, where a rectangle's φ side measures
    /// sin θ Δφ: near the normal a bin of 1° × 2° is a sliver, and a lobe 0.1° across a peak at
    /// θ = 0.5° covers a dozen bins of its row in φ. So the margin along the parallel is the larger
    /// of the two sides (in φ, that over sin θ at the peak; beyond θ = 30° the bins' φ side is the
    /// larger and this is one rectangle, as along θ); and since every azimuth touches the normal,
    /// a rectangle at the pole is within t1 + θ_peak of any peak, whatever its φ (θi = 0.01°,
    /// α = 0.001: the pole's bins missed half the light). A rectangle near a peak is halved across
    /// its longer side on the sphere, or both ways (sides_to_halve, as the error-driven splits:
    /// near the normal, in θ alone).
    void peak_split(const ThetaRange& t, const PhiRange& p, int peak_depth, bool& split_t,
                    bool& split_phi) const {
        split_t = split_phi = false;
        const double t0 = t.lo, t1 = t.hi, p0 = p.lo, p1 = p.hi;
        const double side_t = t1 - t0, side_phi = t.sin_hi * (p1 - p0);
        const bool neighbours = peak_depth < kNeighbourDepth;
        const double margin = !neighbours                        ? 0.0
                              : peak_depth < kWideNeighbourDepth ? kNeighbourMargin
                                                                 : 1.0;
        const double mt = margin * side_t, m_parallel = margin * std::max(side_t, side_phi);
        bool near = false;
        for (const Peak& pk : peaks_) {
            if (pk.pole) {
                if (t0 <= kPoleTheta && side_t > kMinDtheta) split_t = true;
                continue;
            }
            // Distances equal to the margin (a peak on a bin edge, a whole number of bins away)
            // count as near whatever their rounding: the same light from another azimuth, or
            // mirrored, then splits the same rectangles.
            constexpr double kTie = 1 + 1e-9;
            const bool via_pole = neighbours && t0 <= kPoleTheta && pk.theta <= (t1 + mt) * kTie;
            const double d_t = std::max({0.0, t0 - pk.theta, pk.theta - t1});
            const double d_phi = std::max({0.0, p0 - pk.phi, pk.phi - p1});
            const double d_parallel = d_phi * std::sin(std::clamp(pk.theta, t0, t1));
            if (via_pole ||
                (d_t <= mt * kTie && d_parallel <= m_parallel * kTie && (neighbours || d_phi == 0)))
                near = true;
        }
        if (!near) return;
        const auto [halve_t, halve_phi] = sides_to_halve(t, p);
        if (side_t > kMinDtheta && halve_t) split_t = true;
        if (p1 - p0 > kMinDphi && halve_phi) split_phi = true;
    }

    /// A sub-rectangle not split (yet): its 3×3 value and its error estimate.
    struct Cell {
        ThetaRange t;
        PhiRange p;
        int depth, peak_depth;
        double weight;
        Rgbd value;
        double error;           ///< |3×3 − degree-3| (largest channel)
        double weighted_error;  ///< error × weight: the split order
    };

    /// Splits the rectangle towards the peaks inside it (forced splits, which do not count as
    /// depth) and adds its leaves to cells_; `known` is its rule's result when already evaluated.
    void add_cells(const ThetaRange& t, const PhiRange& p, int depth, int peak_depth,
                   const std::pair<Rgbd, Rgbd>* known = nullptr) {
        bool split_t = false, split_phi = false;
        if (peak_depth < o_.peak_depth) peak_split(t, p, peak_depth, split_t, split_phi);
        if (split_t || split_phi) {
            split(t, p, split_t, split_phi, depth, peak_depth + 1);
            return;
        }
        const auto [i2, i3] = known ? *known : rule(t, p);
        const double weight = measure(t, p);
        const double error = max_abs(i3 - i2);
        cells_.push_back({t, p, depth, peak_depth, weight, i3, error, weight * error});
    }

    /// The children of [t] × [p], halved in θ, φ or both, added by add_cells.
    void split(const ThetaRange& t, const PhiRange& p, bool split_t, bool split_phi, int depth,
               int peak_depth) {
        if (split_t) {
            const double tm = 0.5 * (t.lo + t.hi), sin_tm = std::sin(tm);
            const ThetaRange lower = theta_range(t.lo, tm, t.sin_lo, sin_tm);
            const ThetaRange upper = theta_range(tm, t.hi, sin_tm, t.sin_hi);
            if (split_phi) {
                const double pm = 0.5 * (p.lo + p.hi);
                const PhiRange left = phi_range(p.lo, pm), right = phi_range(pm, p.hi);
                add_cells(lower, left, depth, peak_depth);
                add_cells(upper, left, depth, peak_depth);
                add_cells(lower, right, depth, peak_depth);
                add_cells(upper, right, depth, peak_depth);
            } else {
                add_cells(lower, p, depth, peak_depth);
                add_cells(upper, p, depth, peak_depth);
            }
        } else {
            const double pm = 0.5 * (p.lo + p.hi);
            add_cells(t, phi_range(p.lo, pm), depth, peak_depth);
            add_cells(t, phi_range(pm, p.hi), depth, peak_depth);
        }
    }

    /// The rectangle's average by adaptive bisection, best first: a leaf whose error estimate
    /// exceeds tol is bisected in both coordinates (up to max_depth), the one with the largest
    /// weighted error first, until every leaf is within tol or the evaluation budget is spent.
    /// Within the budget the leaves are those of depth-first bisection (the criterion is each
    /// leaf's own); where the budget binds — the integrand jumps along a curve, where the error
    /// of the cells along it does not shrink as they do — it has been spent evenly along the
    /// curve, from the largest cells down, rather than on one part of it to max_depth.
    Rgbd refine(const ThetaRange& t, const PhiRange& p, double tol,
                const std::pair<Rgbd, Rgbd>* known = nullptr) {
        cells_.clear();
        add_cells(t, p, 0, 0, known);
        const double total_weight = measure(t, p);
        // A max-heap of the leaves to split by weighted error (ties to the earlier cell, so the
        // order is fixed), over indices into cells_; a split leaf's weight becomes 0.
        auto before = [this](std::size_t a, std::size_t b) {
            const double ea = cells_[a].weighted_error, eb = cells_[b].weighted_error;
            return ea < eb || (ea == eb && a > b);
        };
        heap_.clear();
        auto push_from = [&](std::size_t first) {
            for (std::size_t k = first; k < cells_.size(); ++k)
                if (cells_[k].depth < o_.max_depth && cells_[k].error > tol) {
                    heap_.push_back(k);
                    std::push_heap(heap_.begin(), heap_.end(), before);
                }
        };
        push_from(0);
        while (!heap_.empty() && double(evals_) < budget_) {
            std::pop_heap(heap_.begin(), heap_.end(), before);
            const std::size_t k = heap_.back();
            heap_.pop_back();
            const Cell cell = cells_[k];
            cells_[k].weight = 0;  // replaced by its children
            const std::size_t first = cells_.size();
            // Halved across its longer side on the sphere (sides_to_halve): a bin near the normal
            // (1° × 2° at θ < 1°) is a sliver ~30 times longer in θ, and halving it in φ too spent
            // the budget on resolution nothing needed.
            const auto [halve_t, halve_phi] = sides_to_halve(cell.t, cell.p);
            split(cell.t, cell.p, halve_t, halve_phi, cell.depth + 1, cell.peak_depth);
            push_from(first);
        }
        if (cells_.size() == 1) return cells_.front().value;
        // Leaves combined with their exact weights (fractions of ∫ |cos θ| dω), in creation order.
        Rgbd sum(0.0);
        for (const Cell& c : cells_)
            if (c.weight > 0) sum += c.value * c.weight;
        return total_weight > 0 ? sum / total_weight : cells_.front().value;
    }

    const IncidentEvaluator& f_;
    bool transmission_;
    std::vector<Peak> peaks_;
    BinnedOptions o_;
    long evals_ = 0;
    double budget_ = 0;  ///< evaluations for this rectangle (eval_budget scaled to its size)
    std::vector<Cell> cells_;
    std::vector<std::size_t> heap_;
};

/// The peaks on `side` in the rectangles' coordinates: φ folded into [0, π], or unfolded in
/// [0, 2π] (a peak at φ = 0 also at 2π, the edge of the last bin).
std::vector<Peak> peaks_on_side(const std::vector<Vec3d>& dirs, Side side, bool unfolded = false) {
    std::vector<Peak> out;
    for (const Vec3d& d : dirs) {
        if ((d.z > 0) != (side == Side::Reflection)) continue;
        const double theta = theta_of(d);
        const bool pole = theta <= kPoleTheta;
        if (!unfolded) {
            out.push_back({theta, std::atan2(std::abs(d.y), d.x), pole});
            continue;
        }
        const double phi = phi_of(d);
        out.push_back({theta, phi, pole});
        if (phi == 0) out.push_back({theta, 2 * kPi<double>, pole});
    }
    return out;
}

// ---- The shared-node pass of bin_model ------------------------------------------------------
// Neighbouring bins of the grid share their edges, and a rule whose nodes lie on them shares its
// evaluations: on the lattice of half-bin steps in θ and φ a bin owns about 4 nodes, against the
// 9 interior nodes of its own 3×3 Gauss–Legendre rule. Two embedded product rules on it, per
// coordinate, in units of the bin's width:
//   - Simpson's rule on the bin's own nodes 0, ½, 1 (weights 1/6, 4/6, 1/6; degree 3;
//     Abramowitz & Stegun, 25.4.5);
//   - the interpolatory rule on the 5 nodes −½ … 3/2 (half a bin into each neighbour), weights
//     −1/180, 17/90, 19/30, 17/90, −1/180 (solved from the moments ∫₀¹ xᵏ dx = 1/(k + 1),
//     k = 0…4; degree 5 by its symmetry about the bin's centre, as the 3×3 Gauss–Legendre rule).
// Each is normalized by itself applied to the weight sin θ cos θ (constants exact), as
// RectIntegrator's. Along one coordinate their difference is the fourth difference of the 5 nodes
// over 180 (weights −1, 4, −6, 4, −1): about Simpson's error where the integrand is smooth, where
// the 5-node value is far better. The bin takes the 5-node value when kLatticeMargin times the
// difference is within the bin's tolerance τ = rel_tol·|value| + abs_tol and no peak direction
// forces a split of the bin; otherwise RectIntegrator's adaptive rule from scratch. Unlike
// RectIntegrator's pair, whose difference sees only the mixed variation of the integrand (on a
// function of θ alone its two rules agree), this pair's difference sees variation along either
// coordinate. The lattice continues smoothly past the pole (θ < 0 is the direction at φ + π) and
// past both ends of φ (the model's own values there), but not past the horizon: the last row of
// bins takes RectIntegrator's rule.
constexpr double kLattice5[5] = {-1.0 / 180, 17.0 / 90, 19.0 / 30, 17.0 / 90, -1.0 / 180};
constexpr double kSimpson[3] = {1.0 / 6, 4.0 / 6, 1.0 / 6};
/// Where the integrand is not smooth the difference understates the 5-node rule's error: by up to
/// 19 times for a jump anywhere in the 5 nodes' span, and without bound for a kink at the one
/// position where the fourth difference of |x − c| vanishes. Models interpolate tables (lamina-1,
/// the production coats' albedo tables) and have kinks. Against a 12 × 12 composite
/// Gauss–Legendre rule per bin (7 of the study's configurations × every model, θi 0.5°, 30° and
/// 75°, one bin in 9), with the margin 32 the bins off by more than τ are those RectIntegrator's
/// rule alone leaves off (lamina-1 on the frosted metal α 0.5/0.001: 80 against 77 of 2666), at
/// 8 more (205), at 1 many more (283; Blender's principled coat 176 against 0).
constexpr double kLatticeMargin = 32;
/// Rows per work unit: a unit of B rows evaluates 2B + 3 lattice lines, of which it shares 3 with
/// the next (9 % more evaluations at 16 rows, 19 % at 8), against the 6 units per (incidence,
/// side) of the 90-row grid to share out between the threads. The values do not depend on it.
constexpr int kLatticeBlockRows = 16;

/// Rows [t_begin, t_end) of one side's lobe: the shared-node pass, and RectIntegrator's rule
/// where it does not settle a bin. The lattice lines are those at half-bin steps k (θ = k·Δθ/2,
/// φ = k·Δφ/2, from the grid's own span so that the folded grid's and the unfolded grid's nodes
/// coincide bit for bit); the nodes depend on the grid alone, so any partition into units gives
/// the same values.
void bin_rows(const IncidentEvaluator& f, Side side, const HemisphereGrid& grid,
              const std::vector<PhiRange>& columns, RectIntegrator& integrator, int t_begin,
              int t_end, const BinnedOptions& options, BinnedLobe& lobe) {
    const int n_theta = grid.n_theta(), n_phi = grid.n_phi();
    const bool transmission = side == Side::Transmission;
    // Rows with a 5-node θ rule: not the horizon's.
    const int t_lattice_end = std::min(t_end, n_theta - 1);
    std::vector<Rgbd> g;  // f·sin 2θ on lines k_theta ∈ [2 t_begin − 1, 2 t_lattice_end + 1]
    std::vector<double> weight;  // sin 2θ on those lines
    const int k_theta0 = 2 * t_begin - 1;
    const int n_lines = t_lattice_end > t_begin ? 2 * (t_lattice_end - t_begin) + 3 : 0;
    const int n_nodes_phi = 2 * n_phi + 3;  // k_phi ∈ [−1, 2 n_phi + 1]
    g.resize(std::size_t(n_lines) * n_nodes_phi);
    weight.resize(std::size_t(n_lines));
    std::vector<double> cos_phi(static_cast<std::size_t>(n_nodes_phi)),
        sin_phi(static_cast<std::size_t>(n_nodes_phi));
    for (int q = 0; q < n_nodes_phi; ++q) {
        const double phi = grid.phi_span() * (q - 1) / (2 * n_phi);
        cos_phi[std::size_t(q)] = std::cos(phi);
        sin_phi[std::size_t(q)] = std::sin(phi);
    }
    for (int l = 0; l < n_lines; ++l) {
        const double theta = kPi<double> / 2 * (k_theta0 + l) / (2 * n_theta);
        const double sin_theta = std::sin(theta), z = std::cos(theta);
        const double w = std::sin(2 * theta);
        weight[std::size_t(l)] = w;
        for (int q = 0; q < n_nodes_phi; ++q)
            g[std::size_t(l) * n_nodes_phi + q] =
                f.eval(Vec3d(sin_theta * cos_phi[std::size_t(q)],
                             sin_theta * sin_phi[std::size_t(q)], transmission ? -z : z)) *
                w;
    }
    for (int t = t_begin; t < t_end; ++t) {
        const ThetaRange row = theta_range(grid.theta_lo(t), grid.theta_hi(t));
        // The row's lines: l0 … l0 + 4 for the 5-node rule, l0 + 1 … l0 + 3 for Simpson's.
        const int l0 = 2 * (t - t_begin);
        double w5 = 0, w3 = 0;
        if (t < t_lattice_end) {
            for (int a = 0; a < 5; ++a)
                w5 += kLattice5[a] * weight[std::size_t(l0 + a)];
            for (int a = 0; a < 3; ++a)
                w3 += kSimpson[a] * weight[std::size_t(l0 + 1 + a)];
        }
        for (int p = 0; p < n_phi; ++p) {
            Rgbd& out = lobe.f[std::size_t(t) * n_phi + p];
            const PhiRange& column = columns[std::size_t(p)];
            if (t < t_lattice_end && w5 > 0 && w3 > 0 && !integrator.forced_split(row, column)) {
                // Node (l, q) of the bin: lines l0 + a, columns 2p + b (q counts from k = −1).
                Rgbd i5(0.0), i3(0.0);
                for (int a = 0; a < 5; ++a) {
                    Rgbd line(0.0);
                    const Rgbd* gl = &g[std::size_t(l0 + a) * n_nodes_phi + 2 * p];
                    for (int b = 0; b < 5; ++b)
                        line += gl[b] * kLattice5[b];
                    i5 += line * kLattice5[a];
                    if (a >= 1 && a <= 3) {
                        Rgbd simpson(0.0);
                        for (int b = 0; b < 3; ++b)
                            simpson += gl[b + 1] * kSimpson[b];
                        i3 += simpson * kSimpson[a - 1];
                    }
                }
                const Rgbd value = i5 / w5;
                const Rgbd diff = value - i3 / w3;
                const double tol = options.rel_tol * max_abs(value) + options.abs_tol;
                if (kLatticeMargin * max_abs(diff) <= tol) {
                    out = value;
                    continue;
                }
            }
            out = integrator.average(row, column);
        }
    }
}
}  // namespace

Rgbd cos_weighted_average(const IncidentEvaluator& f, Side side, double theta0, double theta1,
                          double phi0, double phi1, const std::vector<Vec3d>& peaks,
                          const BinnedOptions& options) {
    RectIntegrator integrator(f, side, peaks_on_side(peaks, side), options);
    return integrator.average(theta_range(theta0, theta1), phi_range(phi0, phi1));
}

Rgbd model_albedo(const Model& model, const Vec3d& wi, Side side, const BinnedOptions& options) {
    const auto evaluator = model.prepare(wi);
    const std::vector<Vec3d> peaks = model.peak_directions(wi);
    // ∫ f |cos θ| dω over the hemisphere = 2 Σ (rectangle average × its weight) over [0, π/2] ×
    // [0, π] (symmetry φ ↔ −φ), or Σ over [0, π/2] × [0, 2π) without the symmetry. A fixed
    // 16 × 16 partition of each half first, so that no large rectangle is accepted on an
    // accidental agreement of its two rules.
    const bool full = options.full_azimuth || wi.y != 0;
    constexpr int kN = 16;
    const int n_phi = full ? 2 * kN : kN;
    const double dt = kPi<double> / 2 / kN, dp = kPi<double> / kN;
    const double copies = full ? 1 : 2;
    const std::vector<Peak> side_peaks = peaks_on_side(peaks, side, full);
    Rgbd albedo(0.0);
    for (int a = 0; a < kN; ++a)
        for (int b = 0; b < n_phi; ++b) {
            RectIntegrator integrator(*evaluator, side, side_peaks, options);
            albedo += integrator.average(theta_range(a * dt, (a + 1) * dt),
                                         phi_range(b * dp, (b + 1) * dp)) *
                      (copies * measure(a * dt, (a + 1) * dt, b * dp, (b + 1) * dp));
        }
    for (const DeltaLobe& d : model.delta_lobes(wi))
        if ((d.direction.z > 0) == (side == Side::Reflection)) albedo += d.energy;
    return albedo;
}

BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, const BinnedOptions& options) {
    return bin_model(model, grid, theta_i_deg, 0.0, options);
}

BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, double phi_i_deg,
                      const BinnedOptions& options) {
    LAMINA_CHECK(phi_i_deg == 0 || grid.is_unfolded());
    const Support support = model.support();
    BinnedTable table = BinnedTable::zeros(grid, theta_i_deg, support.brdf, support.btdf);
    const std::size_t n_inc = theta_i_deg.size();
    std::vector<Vec3d> wi(n_inc);
    std::vector<std::unique_ptr<IncidentEvaluator>> evaluators(n_inc);
    std::vector<std::vector<Vec3d>> peaks(n_inc);
    for (std::size_t i = 0; i < n_inc; ++i) {
        wi[i] = direction_from_angles(deg_to_rad(theta_i_deg[i]), deg_to_rad(phi_i_deg));
        evaluators[i] = model.prepare(wi[i]);  // forward variants: lobe statistics, once
        peaks[i] = model.peak_directions(wi[i]);
    }
    std::vector<Side> sides;
    if (support.brdf) sides.push_back(Side::Reflection);
    if (support.btdf) sides.push_back(Side::Transmission);
    std::vector<PhiRange> columns;
    for (int p = 0; p < grid.n_phi(); ++p)
        columns.push_back(phi_range(grid.phi_lo(p), grid.phi_hi(p)));
    const int n_blocks = (grid.n_theta() + kLatticeBlockRows - 1) / kLatticeBlockRows;
    const long n_units = long(n_inc) * long(sides.size()) * n_blocks;
#pragma omp parallel for schedule(dynamic, 1)
    for (long unit = 0; unit < n_units; ++unit) {
        const int block = int(unit % n_blocks);
        const long rest = unit / n_blocks;
        const Side side = sides[rest % long(sides.size())];
        const std::size_t i = std::size_t(rest / long(sides.size()));
        const std::unique_ptr<IncidentEvaluator> local = evaluators[i]->for_one_thread();
        const IncidentEvaluator& f = local ? *local : *evaluators[i];
        RectIntegrator integrator(f, side, peaks_on_side(peaks[i], side, grid.is_unfolded()),
                                  options);
        bin_rows(f, side, grid, columns, integrator, block * kLatticeBlockRows,
                 std::min(grid.n_theta(), (block + 1) * kLatticeBlockRows), options,
                 table.lobe(i, side));
    }
    // Delta lobes: energy / Ω⊥ of the bin they hit (docs/physics.md §5).
    for (std::size_t i = 0; i < n_inc; ++i) {
        for (const DeltaLobe& d : model.delta_lobes(wi[i])) {
            const Side side = d.direction.z > 0 ? Side::Reflection : Side::Transmission;
            if (side == Side::Reflection ? !support.brdf : !support.btdf) continue;
            const std::size_t j = grid.bin_of(d.direction);
            table.lobe(i, side).f[j] += d.energy / grid.projected_solid_angle(j);
        }
    }
    return table;
}

}  // namespace lamina

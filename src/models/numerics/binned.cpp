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
        const std::pair<Rgbd, Rgbd> whole = rule(t, p);
        const Rgbd coarse = whole.second;
        tol_ = o_.rel_tol * max_abs(coarse) + o_.abs_tol;
        // The top level reuses the coarse rule's nodes: the same values, not evaluated twice.
        const Rgbd first = rect(t, p, 0, 0, &whole);
        // A narrow lobe missed by the coarse nodes made τ far too strict: redo with the real size.
        if (max_abs(first) > 10 * max_abs(coarse)) {
            evals_ = 0;
            tol_ = o_.rel_tol * max_abs(first) + o_.abs_tol;
            return rect(t, p, 0, 0);
        }
        return first;
    }

  private:
    static double max_abs(const Rgbd& v) {
        return std::max({std::abs(v[0]), std::abs(v[1]), std::abs(v[2])});
    }

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

    /// Which coordinates must be split to approach a peak inside the (closed) rectangle.
    void peak_split(double t0, double t1, double p0, double p1, bool& split_t,
                    bool& split_phi) const {
        split_t = split_phi = false;
        for (const Peak& pk : peaks_) {
            if (pk.pole) {
                if (t0 <= kPoleTheta && t1 - t0 > kMinDtheta) split_t = true;
                continue;
            }
            if (pk.theta < t0 || pk.theta > t1 || pk.phi < p0 || pk.phi > p1) continue;
            if (t1 - t0 > kMinDtheta) split_t = true;
            if (p1 - p0 > kMinDphi) split_phi = true;
        }
    }

    Rgbd rect(const ThetaRange& t, const PhiRange& p, int depth, int peak_depth,
              const std::pair<Rgbd, Rgbd>* known = nullptr) {
        const auto [i2, i3] = known ? *known : rule(t, p);
        bool split_t = false, split_phi = false;
        if (peak_depth < o_.peak_depth) peak_split(t.lo, t.hi, p.lo, p.hi, split_t, split_phi);
        const bool forced = split_t || split_phi;
        if (!forced && depth < o_.max_depth && evals_ < o_.eval_budget && max_abs(i3 - i2) > tol_)
            split_t = split_phi = true;
        if (!split_t && !split_phi) return i3;
        const int nd = forced ? depth : depth + 1;
        const int np = forced ? peak_depth + 1 : peak_depth;
        // Children are combined with their exact weights (fractions of ∫ |cos θ| dω).
        auto part = [&](const ThetaRange& a, const PhiRange& b) {
            return rect(a, b, nd, np) * measure(a, b);
        };
        Rgbd sum(0.0);
        if (split_t) {
            const double tm = 0.5 * (t.lo + t.hi), sin_tm = std::sin(tm);
            const ThetaRange lower = theta_range(t.lo, tm, t.sin_lo, sin_tm);
            const ThetaRange upper = theta_range(tm, t.hi, sin_tm, t.sin_hi);
            if (split_phi) {
                const double pm = 0.5 * (p.lo + p.hi);
                const PhiRange left = phi_range(p.lo, pm), right = phi_range(pm, p.hi);
                sum =
                    part(lower, left) + part(upper, left) + part(lower, right) + part(upper, right);
            } else {
                sum = part(lower, p) + part(upper, p);
            }
        } else {
            const double pm = 0.5 * (p.lo + p.hi);
            sum = part(t, phi_range(p.lo, pm)) + part(t, phi_range(pm, p.hi));
        }
        const double m = measure(t, p);
        return m > 0 ? sum / m : i3;
    }

    const IncidentEvaluator& f_;
    bool transmission_;
    std::vector<Peak> peaks_;
    BinnedOptions o_;
    long evals_ = 0;
    double tol_ = 0;
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
    const long n_rows = long(n_inc) * long(sides.size()) * grid.n_theta();
#pragma omp parallel for schedule(dynamic, 1)
    for (long row = 0; row < n_rows; ++row) {
        const int t = int(row % grid.n_theta());
        const long rest = row / grid.n_theta();
        const Side side = sides[rest % long(sides.size())];
        const std::size_t i = std::size_t(rest / long(sides.size()));
        const std::unique_ptr<IncidentEvaluator> local = evaluators[i]->for_one_thread();
        RectIntegrator integrator(local ? *local : *evaluators[i], side,
                                  peaks_on_side(peaks[i], side, grid.is_unfolded()), options);
        BinnedLobe& lobe = table.lobe(i, side);
        const ThetaRange row_range = theta_range(grid.theta_lo(t), grid.theta_hi(t));
        for (int p = 0; p < grid.n_phi(); ++p)
            lobe.f[std::size_t(t) * grid.n_phi() + p] =
                integrator.average(row_range, columns[std::size_t(p)]);
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

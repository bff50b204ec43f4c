#include "models/binned.h"

#include "core/math.h"
#include "core/spherical.h"

#include <cmath>

namespace lamina {

namespace {

// Gauss–Legendre on [0, 1]: 2 points at ½ ± 1/(2√3), weights ½; 3 points at ½, ½ ± √(3/5)/2,
// weights 8/18, 5/18 (Abramowitz & Stegun, Table 25.4).
constexpr double kG2[2] = {0.5 - 0.28867513459481287, 0.5 + 0.28867513459481287};
constexpr double kG3[3] = {0.5 - 0.3872983346207417, 0.5, 0.5 + 0.3872983346207417};
constexpr double kW3[3] = {5.0 / 18, 8.0 / 18, 5.0 / 18};
constexpr double kMinDu = 1e-10, kMinDphi = 1e-8;
constexpr double kPoleU = 1e-12;

struct Peak {
    double u, phi;
    bool pole;  ///< at the normal: every φ
};

class RectIntegrator {
  public:
    RectIntegrator(const IncidentEvaluator& f, Side side, std::vector<Peak> peaks,
                   const BinnedOptions& o)
        : f_(f), transmission_(side == Side::Transmission), peaks_(std::move(peaks)), o_(o) {}

    Rgbd average(double u0, double u1, double p0, double p1) {
        evals_ = 0;
        return rect(u0, u1, p0, p1, 0, 0);
    }

  private:
    Rgbd at(double u, double phi) {
        ++evals_;
        const double s = std::sqrt(u), z = safe_sqrt(1 - u);
        return f_.eval(Vec3d(s * std::cos(phi), s * std::sin(phi), transmission_ ? -z : z));
    }

    /// Which coordinates must be split to approach a peak inside the (closed) rectangle.
    void peak_split(double u0, double u1, double p0, double p1, bool& split_u,
                    bool& split_phi) const {
        split_u = split_phi = false;
        for (const Peak& pk : peaks_) {
            if (pk.pole) {
                if (u0 <= kPoleU && u1 - u0 > kMinDu) split_u = true;
                continue;
            }
            if (pk.u < u0 || pk.u > u1 || pk.phi < p0 || pk.phi > p1) continue;
            if (u1 - u0 > kMinDu) split_u = true;
            if (p1 - p0 > kMinDphi) split_phi = true;
        }
    }

    Rgbd rect(double u0, double u1, double p0, double p1, int depth, int peak_depth) {
        const double du = u1 - u0, dp = p1 - p0;
        Rgbd i2(0.0), i3(0.0);
        for (int a = 0; a < 2; ++a)
            for (int b = 0; b < 2; ++b)
                i2 += at(u0 + du * kG2[a], p0 + dp * kG2[b]) * 0.25;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b)
                i3 += at(u0 + du * kG3[a], p0 + dp * kG3[b]) * (kW3[a] * kW3[b]);
        bool split_u = false, split_phi = false;
        if (peak_depth < o_.peak_depth) peak_split(u0, u1, p0, p1, split_u, split_phi);
        const bool forced = split_u || split_phi;
        if (!forced && depth < o_.max_depth && evals_ < o_.eval_budget) {
            for (int c = 0; c < 3; ++c)
                if (std::abs(i3[c] - i2[c]) > o_.rel_tol * std::abs(i3[c]) + o_.abs_tol) {
                    split_u = split_phi = true;
                    break;
                }
        }
        if (!split_u && !split_phi) return i3;
        const int next_depth = forced ? depth : depth + 1;
        const int next_peak = forced ? peak_depth + 1 : peak_depth;
        const double um = 0.5 * (u0 + u1), pm = 0.5 * (p0 + p1);
        if (split_u && split_phi)
            return (rect(u0, um, p0, pm, next_depth, next_peak) +
                    rect(um, u1, p0, pm, next_depth, next_peak) +
                    rect(u0, um, pm, p1, next_depth, next_peak) +
                    rect(um, u1, pm, p1, next_depth, next_peak)) *
                   0.25;
        if (split_u)
            return (rect(u0, um, p0, p1, next_depth, next_peak) +
                    rect(um, u1, p0, p1, next_depth, next_peak)) *
                   0.5;
        return (rect(u0, u1, p0, pm, next_depth, next_peak) +
                rect(u0, u1, pm, p1, next_depth, next_peak)) *
               0.5;
    }

    const IncidentEvaluator& f_;
    bool transmission_;
    std::vector<Peak> peaks_;
    BinnedOptions o_;
    long evals_ = 0;
};

std::vector<Peak> peaks_on_side(const std::vector<Vec3d>& dirs, Side side) {
    std::vector<Peak> out;
    for (const Vec3d& d : dirs) {
        if ((d.z > 0) != (side == Side::Reflection)) continue;
        const double u = clamp(d.x * d.x + d.y * d.y, 0.0, 1.0);
        double phi = std::atan2(std::abs(d.y), d.x);  // folded into [0, π]
        out.push_back({u, phi, u <= kPoleU});
    }
    return out;
}

}  // namespace

Rgbd cos_weighted_average(const IncidentEvaluator& f, Side side, double u0, double u1, double phi0,
                          double phi1, const std::vector<Vec3d>& peaks,
                          const BinnedOptions& options) {
    RectIntegrator integrator(f, side, peaks_on_side(peaks, side), options);
    return integrator.average(u0, u1, phi0, phi1);
}

Rgbd model_albedo(const Model& model, const Vec3d& wi, Side side, const BinnedOptions& options) {
    const auto evaluator = model.prepare(wi);
    const std::vector<Vec3d> peaks = model.peak_directions(wi);
    // ∫ f |cos θ| dω over the hemisphere = 2 · ∫₀^π ∫₀¹ f ½ du dφ (symmetry φ ↔ −φ): the sum of
    // the rectangles' averages × their areas. A fixed 16 × 16 partition first, so that no large
    // rectangle is accepted on an accidental agreement of its two rules.
    constexpr int kN = 16;
    Rgbd albedo(0.0);
    for (int a = 0; a < kN; ++a)
        for (int b = 0; b < kN; ++b)
            albedo += cos_weighted_average(*evaluator, side, double(a) / kN, double(a + 1) / kN,
                                           kPi<double> * b / kN, kPi<double> * (b + 1) / kN, peaks,
                                           options);
    albedo *= kPi<double> / (kN * kN);
    for (const DeltaLobe& d : model.delta_lobes(wi))
        if ((d.direction.z > 0) == (side == Side::Reflection)) albedo += d.energy;
    return albedo;
}

BinnedTable bin_model(const Model& model, const HemisphereGrid& grid,
                      const std::vector<double>& theta_i_deg, const BinnedOptions& options) {
    const Support support = model.support();
    BinnedTable table = BinnedTable::zeros(grid, theta_i_deg, support.brdf, support.btdf);
    const std::size_t n_inc = theta_i_deg.size();
    std::vector<Vec3d> wi(n_inc);
    std::vector<std::unique_ptr<IncidentEvaluator>> evaluators(n_inc);
    std::vector<std::vector<Vec3d>> peaks(n_inc);
    for (std::size_t i = 0; i < n_inc; ++i) {
        wi[i] = incident_direction(deg_to_rad(theta_i_deg[i]));
        evaluators[i] = model.prepare(wi[i]);  // forward variants: lobe statistics, once
        peaks[i] = model.peak_directions(wi[i]);
    }
    std::vector<Side> sides;
    if (support.brdf) sides.push_back(Side::Reflection);
    if (support.btdf) sides.push_back(Side::Transmission);
    const long n_rows = long(n_inc) * long(sides.size()) * grid.n_theta();
    // Bin edges in u = sin²θ, exactly as the grid defines Ω⊥.
    std::vector<double> u_edge(grid.n_theta() + 1);
    for (int t = 0; t <= grid.n_theta(); ++t)
        u_edge[t] = sqr(std::sin(grid.theta_lo(t)));
    u_edge.back() = 1.0;
#pragma omp parallel for schedule(dynamic, 1)
    for (long row = 0; row < n_rows; ++row) {
        const int t = int(row % grid.n_theta());
        const long rest = row / grid.n_theta();
        const Side side = sides[rest % long(sides.size())];
        const std::size_t i = std::size_t(rest / long(sides.size()));
        RectIntegrator integrator(*evaluators[i], side, peaks_on_side(peaks[i], side), options);
        BinnedLobe& lobe = table.lobe(i, side);
        for (int p = 0; p < grid.n_phi(); ++p)
            lobe.f[std::size_t(t) * grid.n_phi() + p] =
                integrator.average(u_edge[t], u_edge[t + 1], grid.phi_lo(p), grid.phi_hi(p));
    }
    // Delta lobes: energy / Ω⊥ of the bin they hit (physics.md §5).
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

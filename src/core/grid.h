#pragma once
// The goniophotometer's bins on a hemisphere (docs/physics.md §5), shared by the reference (which
// tallies particles into them) and the models (which are averaged over them).
//
// θ ∈ [0°, 90°] in n_theta equal bins (measured from +z for reflection, from −z for transmission);
// φ ∈ [0°, 180°] in n_phi equal bins, folding φ and −φ (an isotropic stack is symmetric about the
// plane of incidence, whose light sits at φ = 0). Bin j = theta_bin · n_phi + phi_bin.
// Its projected solid angle, both folded halves: Ω⊥ = ∫_bin |cos θ| dω = (φ1 − φ0)(sin²θ1 − sin²θ0)
// (the half-hemisphere's (φ1 − φ0)(sin²θ1 − sin²θ0)/2, counted twice).

#include "core/math.h"
#include "core/vec.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace lamina {

class HemisphereGrid {
  public:
    /// n_theta, n_phi ≥ 1 (checked by parse_grid for user input).
    HemisphereGrid(int n_theta = 90, int n_phi = 90);

    int n_theta() const { return n_theta_; }
    int n_phi() const { return n_phi_; }
    std::size_t size() const { return std::size_t(n_theta_) * std::size_t(n_phi_); }

    /// Bin edges in radians.
    double theta_lo(int t) const { return kPi<double> / 2 * t / n_theta_; }
    double theta_hi(int t) const { return kPi<double> / 2 * (t + 1) / n_theta_; }
    double phi_lo(int p) const { return kPi<double> * p / n_phi_; }
    double phi_hi(int p) const { return kPi<double> * (p + 1) / n_phi_; }

    /// Projected solid angle of bin (t, p), both folded halves (sr).
    double projected_solid_angle(int t, int p) const;
    double projected_solid_angle(std::size_t j) const {
        return projected_solid_angle(int(j) / n_phi_, int(j) % n_phi_);
    }

    /// Bin of a direction (either hemisphere: |w.z| is used), without inverse trigonometry: a
    /// lookup table gives a first guess that is corrected against the exact bin edges in cos θ and
    /// cos φ. w must be a unit vector; w.z = 0 falls in the last θ bin.
    template <typename T>
    std::size_t bin_of(const Vec3<T>& w) const {
        return std::size_t(theta_bin(double(std::abs(w.z)))) * std::size_t(n_phi_) +
               std::size_t(phi_bin(double(w.x), double(w.y)));
    }

    /// The grid's rule: the bin of x among the decreasing edges (bin b holds edge[b] ≥ x >
    /// edge[b + 1], the last bin also its lower edge), from any first guess b.
    static int refine_bin(double x, int b, const std::vector<double>& edges) {
        const int n = int(edges.size()) - 1;
        b = std::clamp(b, 0, n - 1);
        while (b > 0 && x > edges[std::size_t(b)])
            --b;
        while (b < n - 1 && x <= edges[std::size_t(b) + 1])
            ++b;
        return b;
    }

    int theta_bin(double cos_theta) const;
    /// The exact edges bin_of compares with (vectorized binning follows the same rule): cos θ
    /// (decreasing, n_theta + 1, the last 0) and the folded cos φ (decreasing, n_phi + 1, the last
    /// −1); bin b holds edge[b] ≥ x > edge[b + 1], the last bin also x = its lower edge.
    const std::vector<double>& cos_theta_edges() const { return cos_theta_edge_; }
    const std::vector<double>& cos_phi_edges() const { return cos_phi_edge_; }
    int phi_bin(double x, double y) const;

    /// "90x90"-style description, and its parser (InputError naming `option` on bad text).
    std::string to_string() const;
    static HemisphereGrid parse(const std::string& text, const std::string& option = "--grid");

    bool operator==(const HemisphereGrid& o) const {
        return n_theta_ == o.n_theta_ && n_phi_ == o.n_phi_;
    }

  private:
    int n_theta_, n_phi_;
    std::vector<double> cos_theta_edge_;        ///< cos of θ edges, decreasing, size n_theta + 1
    std::vector<double> cos_phi_edge_;          ///< cos of φ edges, decreasing, size n_phi + 1
    std::vector<int> theta_guess_, phi_guess_;  ///< first guesses indexed by cos quantized
};

}  // namespace lamina

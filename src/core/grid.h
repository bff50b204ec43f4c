#pragma once
// The goniophotometer's bins on a hemisphere (docs/physics.md §5), shared by the reference (which
// tallies particles into them) and the models (which are averaged over them).
//
// θ ∈ [0°, 90°] in n_theta equal bins (measured from +z for reflection, from −z for transmission);
// φ ∈ [0°, 180°] in n_phi equal bins, folding φ and −φ (an isotropic stack is symmetric about the
// plane of incidence, whose light sits at φ = 0). Bin j = theta_bin · n_phi + phi_bin.
// Its projected solid angle, both folded halves: Ω⊥ = ∫_bin |cos θ| dω = (φ1 − φ0)(sin²θ1 − sin²θ0)
// (the half-hemisphere's (φ1 − φ0)(sin²θ1 − sin²θ0)/2, counted twice).
// The unfolded grid (unfolded(): an anisotropic stack, or light from φi ≠ 0, has no mirror
// symmetry about the plane φ = 0) covers φ ∈ [0°, 360°) in twice as many bins of the same width,
// each one patch: Ω⊥ = (φ1 − φ0)(sin²θ1 − sin²θ0)/2. Its bins p < n_phi/2 are the folded grid's
// bins over y ≥ 0; bin n_phi − 1 − p is the mirror image (y < 0) of bin p.

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
    /// n_theta, n_phi ≥ 1 (checked by parse_grid for user input): the folded grid.
    HemisphereGrid(int n_theta = 90, int n_phi = 90);

    /// The unfolded grid of the same bin width over φ ∈ [0°, 360°) (2 n_phi bins); itself if
    /// already unfolded.
    HemisphereGrid unfolded() const;
    /// Whether φ covers [0°, 360°) (unfolded) or [0°, 180°] with φ and −φ folded.
    bool is_unfolded() const { return unfolded_; }
    /// The φ range the bins cover: π (folded) or 2π (unfolded), in radians.
    double phi_span() const { return unfolded_ ? 2 * kPi<double> : kPi<double>; }
    double phi_span_deg() const { return unfolded_ ? 360.0 : 180.0; }

    int n_theta() const { return n_theta_; }
    /// φ bins (2× the folded count when unfolded).
    int n_phi() const { return n_phi_; }
    std::size_t size() const { return std::size_t(n_theta_) * std::size_t(n_phi_); }

    /// Bin edges in radians.
    double theta_lo(int t) const { return kPi<double> / 2 * t / n_theta_; }
    double theta_hi(int t) const { return kPi<double> / 2 * (t + 1) / n_theta_; }
    double phi_lo(int p) const { return phi_span() * p / n_phi_; }
    double phi_hi(int p) const { return phi_span() * (p + 1) / n_phi_; }
    /// Bin edges in degrees, as the tables write them: 90 t / n_θ and 180 p / n_φ (360 unfolded)
    /// in one rounding, so an edge that is a whole or decimal number of degrees reads as one
    /// (11, not the 10.999999999999998 of the radians converted).
    double theta_lo_deg(int t) const { return 90.0 * t / n_theta_; }
    double theta_hi_deg(int t) const { return 90.0 * (t + 1) / n_theta_; }
    double phi_lo_deg(int p) const { return phi_span_deg() * p / n_phi_; }
    double phi_hi_deg(int p) const { return phi_span_deg() * (p + 1) / n_phi_; }

    /// Projected solid angle of bin (t, p), both folded halves (sr); one patch when unfolded.
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
    /// (decreasing, n_theta + 1, the last 0) and the folded cos φ (decreasing, n_phi + 1 of the
    /// folded grid, the last −1); bin b holds edge[b] ≥ x > edge[b + 1], the last bin also x = its
    /// lower edge. Unfolded, a direction with y < 0 takes bin n_phi − 1 − b.
    const std::vector<double>& cos_theta_edges() const { return cos_theta_edge_; }
    const std::vector<double>& cos_phi_edges() const { return cos_phi_edge_; }
    int phi_bin(double x, double y) const;

    /// "90x90"-style description (the folded grid's counts; an unfolded grid adds " unfolded"),
    /// and its parser of the folded form (InputError naming `option` on bad text).
    std::string to_string() const;
    static HemisphereGrid parse(const std::string& text, const std::string& option = "--grid");
    /// The folded grid of counts read from a file (a study's study.json): each in [1,
    /// kMaxCount], else InputError naming `where` and `field`.
    static HemisphereGrid checked(long long n_theta, long long n_phi, const std::string& where,
                                  const std::string& field);
    /// The most bins along θ or φ a grid may have.
    static constexpr int kMaxCount = 3600;

    bool operator==(const HemisphereGrid& o) const {
        return n_theta_ == o.n_theta_ && n_phi_ == o.n_phi_ && unfolded_ == o.unfolded_;
    }

  private:
    int n_theta_, n_phi_;
    bool unfolded_ = false;
    std::vector<double> cos_theta_edge_;  ///< cos of θ edges, decreasing, size n_theta + 1
    std::vector<double>
        cos_phi_edge_;  ///< cos of the folded φ edges, decreasing, size n_folded + 1
    std::vector<int> theta_guess_, phi_guess_;  ///< first guesses indexed by cos quantized
};

}  // namespace lamina

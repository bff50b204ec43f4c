#include "core/grid.h"

#include "core/error.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>

namespace lamina {

namespace {
constexpr int kGuessResolution = 4096;

// For each of kGuessResolution equal cells of x ∈ [−1, 1] (θ: only [0, 1] is used), the first bin
// whose decreasing edge list allows x; the search then only steps forward a few bins.
std::vector<int> make_guess(const std::vector<double>& edges, double x_min) {
    std::vector<int> guess(kGuessResolution + 1);
    const int n = int(edges.size()) - 1;
    int b = 0;  // x decreases with c, so the bin only moves forward: one pass
    for (int c = 0; c <= kGuessResolution; ++c) {
        const double x = x_min + (1.0 - x_min) * (kGuessResolution - c) / kGuessResolution;
        while (b < n - 1 && x < edges[b + 1])
            ++b;  // x at a cell's top: the smallest bin
        guess[c] = b;
    }
    return guess;
}
}  // namespace

HemisphereGrid HemisphereGrid::unfolded() const {
    if (unfolded_) return *this;
    HemisphereGrid g = *this;
    g.n_phi_ = 2 * n_phi_;
    g.unfolded_ = true;
    return g;
}

HemisphereGrid::HemisphereGrid(int n_theta, int n_phi) : n_theta_(n_theta), n_phi_(n_phi) {
    for (int t = 0; t <= n_theta_; ++t)
        cos_theta_edge_.push_back(std::cos(theta_lo(t)));
    cos_theta_edge_.back() = 0.0;
    for (int p = 0; p <= n_phi_; ++p)
        cos_phi_edge_.push_back(std::cos(phi_lo(p)));
    cos_phi_edge_.back() = -1.0;
    theta_guess_ = make_guess(cos_theta_edge_, 0.0);
    phi_guess_ = make_guess(cos_phi_edge_, -1.0);
}

double HemisphereGrid::projected_solid_angle(int t, int p) const {
    const double folded =
        (phi_hi(p) - phi_lo(p)) * (sqr(std::sin(theta_hi(t))) - sqr(std::sin(theta_lo(t))));
    return unfolded_ ? folded / 2 : folded;
}

int HemisphereGrid::theta_bin(double cos_theta) const {
    cos_theta = clamp(cos_theta, 0.0, 1.0);
    // The guess never overshoots: refine_bin only steps forward.
    return refine_bin(cos_theta, theta_guess_[int((1.0 - cos_theta) * kGuessResolution)],
                      cos_theta_edge_);
}

int HemisphereGrid::phi_bin(double x, double y) const {
    const double r = std::sqrt(x * x + y * y);
    if (r == 0) return 0;
    const double cos_phi = clamp(x / r, -1.0, 1.0);  // folded: φ and −φ share a bin
    const int folded = refine_bin(
        cos_phi, phi_guess_[int((1.0 - cos_phi) * 0.5 * kGuessResolution)], cos_phi_edge_);
    return unfolded_ && y < 0 ? n_phi_ - 1 - folded : folded;
}

std::string HemisphereGrid::to_string() const {
    if (unfolded_) return fmt::format("{}x{} unfolded", n_theta_, n_phi_ / 2);
    return fmt::format("{}x{}", n_theta_, n_phi_);
}

HemisphereGrid HemisphereGrid::parse(const std::string& text, const std::string& option) {
    const auto x = text.find('x');
    int n_theta = 0, n_phi = 0;
    auto parse_int = [](const std::string& s, int& out) {
        auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), out);
        return ec == std::errc() && ptr == s.data() + s.size();
    };
    if (x == std::string::npos || !parse_int(text.substr(0, x), n_theta) ||
        !parse_int(text.substr(x + 1), n_phi) || n_theta < 1 || n_phi < 1 || n_theta > kMaxCount ||
        n_phi > kMaxCount)
        throw InputError("command line", option,
                         fmt::format("'{}' is not a grid: expected NTHETAxNPHI with each count in "
                                     "[1, {}], e.g. 90x90",
                                     text, kMaxCount));
    return HemisphereGrid(n_theta, n_phi);
}

HemisphereGrid HemisphereGrid::checked(long long n_theta, long long n_phi, const std::string& where,
                                       const std::string& field) {
    if (n_theta < 1 || n_phi < 1 || n_theta > kMaxCount || n_phi > kMaxCount)
        throw InputError(where, field,
                         fmt::format("{} × {} bins: allowed counts in [1, {}] along θ and φ",
                                     n_theta, n_phi, kMaxCount));
    return HemisphereGrid(int(n_theta), int(n_phi));
}

}  // namespace lamina

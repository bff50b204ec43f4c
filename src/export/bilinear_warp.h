#pragma once
// The sample warp of the RGL .bsdf format (Dupuy & Jakob 2018, §5): a density on [0, 1]² that
// bilinearly interpolates values at an nx × ny grid of nodes (node (i, j) at (i/(nx−1), j/(ny−1)),
// x fastest in memory), warped by inverting its exact cumulative distributions: first the
// marginal in y, M(y) = ∫₀^y ∫₀¹ p dx dy', then the conditional in x at that y,
// F(x | y) = ∫₀^x p(x', y) dx' / ∫₀¹ p(x', y) dx'. Both are piecewise quadratic, so the warp and
// its inverse are closed forms. pbrt-v4 and Mitsuba 3 invert this map (u_wm → sample) when they
// evaluate a .bsdf; the writer uses sample() to place its values (rgl_bsdf.h).

#include <array>
#include <vector>

namespace lamina {

class BilinearWarp {
  public:
    /// values: nx·ny ≥ 0 with a positive total (nx, ny ≥ 2).
    BilinearWarp(std::vector<double> values, int nx, int ny);

    /// The (normalized) density at x ∈ [0, 1]².
    double eval(std::array<double, 2> x) const;
    /// Uniforms u ∈ [0, 1]² → x with density eval(x).
    std::array<double, 2> sample(std::array<double, 2> u) const;
    /// x → u, the inverse of sample (the readers' map).
    std::array<double, 2> invert(std::array<double, 2> x) const;

    /// The three masses invert() is made of, each a fraction of the total: `left` of the row
    /// through x left of x, that `row` (a density in y), and `below` of the row (u_y). invert(x) is
    /// (left / row, below). A reader that interpolates between warps (pbrt-v4 and Mitsuba 3
    /// between incidences) interpolates these masses, not the inverted coordinates.
    struct Masses {
        double left, row, below;
    };
    Masses masses(std::array<double, 2> x) const;

  private:
    double v(int i, int j) const { return values_[std::size_t(j) * nx_ + i]; }
    double cond(int i, int j) const { return cond_[std::size_t(j) * nx_ + i]; }

    std::vector<double> values_;  ///< normalized to ∫ p = 1 over [0, 1]²
    std::vector<double> cond_;    ///< ∫₀^{x_i} p(x', y_j) dx'
    std::vector<double> marg_;    ///< M(y_j)
    int nx_, ny_;
};

}  // namespace lamina

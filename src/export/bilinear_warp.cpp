#include "export/bilinear_warp.h"

#include "core/check.h"

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {
/// The t ∈ [0, 1] with t·(a + t·(b − a)/2) = target: the inverse of the integral of a linear
/// function from a (at 0) to b (at 1); stable in both the constant and the steep case.
double solve_linear_cdf(double a, double b, double target) {
    if (target <= 0) return 0;
    const double disc = std::max(0.0, a * a + 2 * (b - a) * target);
    const double denom = a + std::sqrt(disc);
    const double t = denom > 0 ? 2 * target / denom : 0;
    return std::clamp(t, 0.0, 1.0);
}
}  // namespace

BilinearWarp::BilinearWarp(std::vector<double> values, int nx, int ny)
    : values_(std::move(values)), nx_(nx), ny_(ny) {
    LAMINA_CHECK(nx >= 2 && ny >= 2 && values_.size() == std::size_t(nx) * std::size_t(ny));
    const double dx = 1.0 / (nx - 1), dy = 1.0 / (ny - 1);
    // Trapezoids are exact for the piecewise-linear rows and the linear-in-y row totals.
    cond_.assign(values_.size(), 0.0);
    for (int j = 0; j < ny; ++j)
        for (int i = 1; i < nx; ++i)
            cond_[std::size_t(j) * nx + i] = cond(i - 1, j) + 0.5 * dx * (v(i - 1, j) + v(i, j));
    marg_.assign(ny, 0.0);
    for (int j = 1; j < ny; ++j)
        marg_[j] = marg_[j - 1] + 0.5 * dy * (cond(nx - 1, j - 1) + cond(nx - 1, j));
    const double total = marg_.back();
    LAMINA_CHECK(total > 0);
    for (double& x : values_)
        x /= total;
    for (double& x : cond_)
        x /= total;
    for (double& x : marg_)
        x /= total;
}

double BilinearWarp::eval(std::array<double, 2> x) const {
    const double gx = std::clamp(x[0], 0.0, 1.0) * (nx_ - 1),
                 gy = std::clamp(x[1], 0.0, 1.0) * (ny_ - 1);
    const int i = std::min(int(gx), nx_ - 2), j = std::min(int(gy), ny_ - 2);
    const double s = gx - i, t = gy - j;
    return (1 - t) * ((1 - s) * v(i, j) + s * v(i + 1, j)) +
           t * ((1 - s) * v(i, j + 1) + s * v(i + 1, j + 1));
}

BilinearWarp::Masses BilinearWarp::masses(std::array<double, 2> x) const {
    const double dx = 1.0 / (nx_ - 1), dy = 1.0 / (ny_ - 1);
    const double gx = std::clamp(x[0], 0.0, 1.0) * (nx_ - 1),
                 gy = std::clamp(x[1], 0.0, 1.0) * (ny_ - 1);
    const int i = std::min(int(gx), nx_ - 2), j = std::min(int(gy), ny_ - 2);
    const double s = gx - i, t = gy - j;
    // Row totals at the patch's edges and at y; M(y) = M_j + ∫ over the partial patch.
    const double r0 = cond(nx_ - 1, j), r1 = cond(nx_ - 1, j + 1);
    const double row = (1 - t) * r0 + t * r1;
    const double below = marg_[j] + dy * t * (r0 + 0.5 * t * (r1 - r0));
    // p(·, y) between columns i and i+1, and its integral up to x.
    const double c0 = (1 - t) * v(i, j) + t * v(i, j + 1);
    const double c1 = (1 - t) * v(i + 1, j) + t * v(i + 1, j + 1);
    const double left =
        (1 - t) * cond(i, j) + t * cond(i, j + 1) + dx * s * (c0 + 0.5 * s * (c1 - c0));
    return {left, row, below};
}

std::array<double, 2> BilinearWarp::invert(std::array<double, 2> x) const {
    const Masses m = masses(x);
    const double u_x = m.row > 0 ? m.left / m.row : 0;
    return {std::clamp(u_x, 0.0, 1.0), std::clamp(m.below, 0.0, 1.0)};
}

std::array<double, 2> BilinearWarp::sample(std::array<double, 2> u) const {
    const double dx = 1.0 / (nx_ - 1), dy = 1.0 / (ny_ - 1);
    const double uy = std::clamp(u[1], 0.0, 1.0), ux = std::clamp(u[0], 0.0, 1.0);
    // The row: the last j with M_j ≤ u_y.
    int j = int(std::upper_bound(marg_.begin(), marg_.end(), uy) - marg_.begin()) - 1;
    j = std::clamp(j, 0, ny_ - 2);
    const double r0 = cond(nx_ - 1, j), r1 = cond(nx_ - 1, j + 1);
    const double t = solve_linear_cdf(r0, r1, (uy - marg_[j]) / dy);
    const double row = (1 - t) * r0 + t * r1;
    const double target = ux * row;
    // The column: the last i with the interpolated partial integral ≤ target.
    int lo = 0, hi = nx_ - 1;
    while (hi - lo > 1) {
        const int mid = (lo + hi) / 2;
        ((1 - t) * cond(mid, j) + t * cond(mid, j + 1) <= target ? lo : hi) = mid;
    }
    const int i = lo;
    const double c0 = (1 - t) * v(i, j) + t * v(i, j + 1);
    const double c1 = (1 - t) * v(i + 1, j) + t * v(i + 1, j + 1);
    const double base = (1 - t) * cond(i, j) + t * cond(i, j + 1);
    const double s = solve_linear_cdf(c0, c1, (target - base) / dx);
    return {(i + s) * dx, (j + t) * dy};
}

}  // namespace lamina

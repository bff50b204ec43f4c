#include "models/tables/slope_sum_table.h"

#include "core/math.h"
#include "models/tables/table_cache.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lamina {

namespace {

constexpr const char* kCodeVersion = "slope-sum-v2";
constexpr int kNq = 4001;     // Simpson nodes in q (odd)
constexpr double kQmax = 40;  // in units of 1/σ: every φ(a_j q) product is below e^{-40} beyond

/// φ(z) = z K₁(z), the characteristic function of a GGX slope of unit scale at |q| = z (φ(0) = 1).
double phi(double z) {
    return z > 0 ? z * std::cyl_bessel_k(1.0, z) : 1.0;
}

/// The GGX slope density of scale σ at radius r.
double ggx_slope_density(double r, double sigma) {
    return sqr(sigma) * kInvPi<double> / sqr(sqr(sigma) + sqr(r));
}

/// The three scales of the shares (x, y), for σ = 1.
std::array<double, 3> scales(double x, double y) {
    return {std::sqrt(x), std::sqrt((1 - x) * y), std::sqrt((1 - x) * (1 - y))};
}

/// R(ρ) − 1 for scales a (Σ a² = 1) by the Hankel transform of Π φ(a_j q) − φ(q): the q² ln q
/// terms of the two (the heavy tails) cancel, so the difference decays quickly in r and the
/// integral keeps its accuracy where the densities themselves are tiny.
double ratio_minus_one(double rho, const std::array<double, 3>& a, int n, double q_max) {
    const double h = q_max / (n - 1);
    double sum = 0;
    for (int i = 0; i < n; ++i) {
        const double q = i * h;
        const double w = (i == 0 || i == n - 1) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
        const double g = phi(a[0] * q) * phi(a[1] * q) * phi(a[2] * q) - phi(q);
        sum += w * g * std::cyl_bessel_j(0.0, q * rho) * q;
    }
    const double integral = sum * h / 3 / (2 * kPi<double>);
    return integral / ggx_slope_density(rho, 1.0);
}

double x_node(int i) {
    return 0.5 * (1 - std::cos(kPi<double> * double(i) / (SlopeSumTable::kNx - 1)));
}
double y_node(int j) {
    return 0.5 * sqr(double(j) / (SlopeSumTable::kNy - 1));
}
double u_node(int k) {
    return double(k) / (SlopeSumTable::kNu - 1);
}

std::vector<float> compute_slope_sum() {
    using T = SlopeSumTable;
    std::vector<float> v(std::size_t(T::kNx) * T::kNy * T::kNu, 1.0f);
    // J₀(q ρ) at every (ρ node, q node), shared by all the shares.
    const double h = kQmax / (kNq - 1);
    std::vector<double> j0(std::size_t(T::kNu) * kNq);
#pragma omp parallel for schedule(static)
    for (int k = 0; k < T::kNu - 1; ++k) {
        const double rho = u_node(k) / (1 - u_node(k));
        for (int i = 0; i < kNq; ++i)
            j0[std::size_t(k) * kNq + i] = std::cyl_bessel_j(0.0, i * h * rho);
    }
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ix = 0; ix < T::kNx; ++ix)
        for (int iy = 0; iy < T::kNy; ++iy) {
            const auto a = scales(x_node(ix), y_node(iy));
            std::vector<double> g(kNq);
            for (int i = 0; i < kNq; ++i) {
                const double q = i * h;
                g[i] = (phi(a[0] * q) * phi(a[1] * q) * phi(a[2] * q) - phi(q)) * q *
                       ((i == 0 || i == kNq - 1) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0));
            }
            // The last u node is ρ = ∞, where R = 1 (the fill value).
            for (int k = 0; k < T::kNu - 1; ++k) {
                const double rho = u_node(k) / (1 - u_node(k));
                double sum = 0;
                for (int i = 0; i < kNq; ++i)
                    sum += g[i] * j0[std::size_t(k) * kNq + i];
                const double integral = sum * h / 3 / (2 * kPi<double>);
                v[(std::size_t(ix) * T::kNy + iy) * T::kNu + k] =
                    float(1 + integral / ggx_slope_density(rho, 1.0));
            }
        }
    return v;
}

}  // namespace

SlopeSumTable::SlopeSumTable() {
    const TableKey key{
        "slope-sum",
        fmt::format("{} x{} y{} u{} q{}:{}", kCodeVersion, kNx, kNy, kNu, kNq, kQmax),
        {kNx, kNy, kNu}};
    values_ = cached_table(key, compute_slope_sum);
}

const SlopeSumTable& SlopeSumTable::get() {
    static const SlopeSumTable table;
    return table;
}

SlopeSumTable::Shares SlopeSumTable::locate(double x, double y) {
    return lamina1::SlopeSumFormat::locate(x, y);
}

double SlopeSumTable::ratio(double rho, const Shares& at) const {
    return lamina1::SlopeSumFormat::ratio(values_.data(), rho, at);
}

double SlopeSumTable::density(double r, double a1, double a2, double a3) const {
    const double s2 = sqr(a1) + sqr(a2) + sqr(a3);
    if (!(s2 > 0)) return 0;
    const double sigma = std::sqrt(s2);
    const double rest = sqr(a2) + sqr(a3);
    const double x = sqr(a1) / s2, y = rest > 0 ? sqr(a2) / rest : 0.0;
    return ggx_slope_density(r, sigma) * ratio(r / sigma, x, y);
}

double SlopeSumTable::direct(double r, double a1, double a2, double a3, int n, double q_max) {
    const double s2 = sqr(a1) + sqr(a2) + sqr(a3);
    if (!(s2 > 0)) return 0;
    const double sigma = std::sqrt(s2);
    if (n % 2 == 0) ++n;
    const std::array<double, 3> a{a1 / sigma, a2 / sigma, a3 / sigma};
    const double rho = r / sigma;
    return ggx_slope_density(r, sigma) * (1 + ratio_minus_one(rho, a, n, q_max));
}

}  // namespace lamina

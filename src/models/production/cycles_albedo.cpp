#include "models/production/cycles_albedo.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {

/// The first node of each of Cycles' unit axes (r, μ, z), and the last of z
/// (cycles_precompute clamps the node coordinates so).
constexpr double kFirstNode = 1e-4, kLastZ = 0.99;

/// The node of a unit axis (Cycles' cycles_precompute: x/(n − 1), at least 10⁻⁴).
double unit_axis_node(int i, int n) {
    return std::max(double(i) / (n - 1), kFirstNode);
}

/// Cycles' reading of a coordinate on an axis of n nodes (kernel/util/lookup_table.h): the
/// coordinate clamped to [0, 1] and scaled by n − 1; the node below and the weight of the next.
std::pair<int, double> cycles_bracket(double x, int n) {
    x = clamp(x, 0.0, 1.0) * (n - 1);
    const int i = std::min(int(x), n - 1);
    return {i, x - i};
}
int next_node(int i, int n) {
    return std::min(i + 1, n - 1);
}

/// The relative index of Cycles' node z: F0 = z⁴ (cycles_precompute's ior_parametrization, its
/// F0 clamped to 0.99).
double eta_of_z(double z) {
    const double sqrt_f0 = std::sqrt(std::min(sqr(sqr(z)), 0.99));
    return (1 + sqrt_f0) / (1 - sqrt_f0);
}

}  // namespace

CyclesWhiteAlbedo::CyclesWhiteAlbedo(double r) {
    const auto [i, t] = cycles_bracket(r, kN);
    t_r_ = t;
    const int columns[2] = {i, next_node(i, kN)};
    static const QuadratureRule q = gauss_legendre(32);
    double averages[2] = {0, 0};
    for (int b = 0; b < 2; ++b) {
        const double alpha = sqr(unit_axis_node(columns[b], kN));
        for (int k = 0; k < kN; ++k)
            albedo_[b * kN + k] = correlated_ggx_albedo_white(unit_axis_node(k, kN), alpha);
        for (std::size_t n = 0; n < q.x.size(); ++n)
            averages[b] += 2 * q.w[n] * q.x[n] * correlated_ggx_albedo_white(q.x[n], alpha);
    }
    average_ = mix(averages[0], averages[1], t_r_);
}

double CyclesWhiteAlbedo::albedo(double mu) const {
    const auto [k, t] = cycles_bracket(mu, kN);
    const int k1 = next_node(k, kN);
    auto at = [&](int b) { return mix(albedo_[b * kN + k], albedo_[b * kN + k1], t); };
    // Cycles interpolates in r first, then in μ: the same bilinear value.
    return mix(at(0), at(1), t_r_);
}

double CyclesFresnelFactor::unit_node(int i) {
    return unit_axis_node(i, kN);
}

double CyclesFresnelFactor::eta_node(int k) {
    return eta_of_z(std::min(unit_axis_node(k, kN), kLastZ));
}

CyclesFresnelFactor::CyclesFresnelFactor(double r, double eta) {
    const auto [i, tr] = cycles_bracket(r, kN);
    const auto [k, tz] = cycles_bracket(std::sqrt(std::abs((eta - 1) / (eta + 1))), kN);
    t_r_ = tr;
    t_z_ = tz;
    const int columns[2] = {i, next_node(i, kN)}, slices[2] = {k, next_node(k, kN)};
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int m = 0; m < kN; ++m)
                factor_[(a * 2 + b) * kN + m] = cycles_fresnel_factor(
                    unit_node(m), sqr(unit_node(columns[b])), eta_node(slices[a]));
}

double CyclesFresnelFactor::factor(double mu) const {
    const auto [m, t] = cycles_bracket(mu, kN);
    const int m1 = next_node(m, kN);
    auto at = [&](int a, int b) {
        const double* row = &factor_[(a * 2 + b) * kN];
        return mix(row[m], row[m1], t);
    };
    return mix(mix(at(0, 0), at(0, 1), t_r_), mix(at(1, 0), at(1, 1), t_r_), t_z_);
}

}  // namespace lamina

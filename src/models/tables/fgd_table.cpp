#include "models/tables/fgd_table.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/tables/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

namespace lamina {

namespace {

constexpr int kBins = lamina1::FgdFormat::kBins;  // x = wi·wm bins per (c, α)
constexpr int kTableNr = 48;  // Gauss–Legendre nodes in r (weight 2r) on Heitz's disk
constexpr int kTableNphi = 64;
constexpr double kCMin = lamina1::FgdFormat::kCMin;  // c = 0 is evaluated here (G1 → 0 at grazing)
constexpr double kAlphaMin = lamina1::FgdFormat::kAlphaMin;  // α = 0 here (the smooth limit)
constexpr const char* kCodeVersion = "fgd-v4";

// The axes' nodes (lamina1::FgdFormat, the table's format, which lamina-1's header reads).
using Format = lamina1::FgdFormat;
double c_node(int i) {
    return Format::c_node(i);
}
double alpha_node(int i) {
    return Format::alpha_node(i);
}

/// Calls visit(x = wi·wm, weight·G2/G1) for each node of the n_r × n_phi visible-normal rule.
template <typename Visit>
void visible_normal_rule(double c, double alpha, int n_r, int n_phi, Visit&& visit) {
    const Vec3d wi(safe_sqrt(1 - c * c), 0, c);
    const GGX<double> ggx{alpha};
    const QuadratureRule qr = gauss_legendre(n_r);
    const double G1i = ggx.G1(wi);
    for (int a = 0; a < n_r; ++a) {
        const double r = qr.x[a];
        const double wr = qr.w[a] * 2 * r;  // ∫ g du1 with u1 = r²
        for (int b = 0; b < n_phi; ++b) {
            const double u2 = (b + 0.5) / n_phi;  // trapezoid rule for the periodic φ
            const Vec3d wm = ggx.sample_visible_normal(wi, r * r, u2);
            const Vec3d wo = reflect(wi, wm);
            if (wo.z <= 0) continue;
            visit(dot(wi, wm), wr / n_phi * ggx.G2(wi, wo) / G1i);
        }
    }
}

double fresnel_any(double x, double eta, double k) {
    return Format::fresnel(x, eta, k);
}

/// The bins of x = wi·wm of the (c, α) node (ic, ia): the rule's weights and mean x of each
/// non-empty bin (FgdFormat::node sums the Fresnel factor over them).
void node_bins(int ic, int ia, std::vector<double>& w, std::vector<double>& x) {
    std::array<double, kBins> W{}, X{};
    visible_normal_rule(c_node(ic), alpha_node(ia), kTableNr, kTableNphi,
                        [&](double xm, double wm) {
                            const int b = std::min(kBins - 1, int(xm * kBins));
                            W[b] += wm;
                            X[b] += wm * xm;
                        });
    w.clear();
    x.clear();
    for (int b = 0; b < kBins; ++b)
        if (W[b] > 0) {
            w.push_back(W[b]);
            x.push_back(X[b] / W[b]);
        }
}

std::vector<float> compute_fgd() {
    using T = FgdTable;
    std::vector<float> v(std::size_t(T::kNc) * T::kNalpha * T::kNeta * T::kNk);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < T::kNc; ++ic) {
        for (int ia = 0; ia < T::kNalpha; ++ia) {
            std::vector<double> w, x;
            node_bins(ic, ia, w, x);
            // Stored as the residual from w(α)·F(c), the smooth limit (a control variate that
            // fades out with roughness): the lookup adds the exact w(α)F(c) back, so the
            // step-like kink of F at the critical angle (η < 1) is not interpolated where the
            // lobe is narrow enough to keep it.
            for (int ie = 0; ie < T::kNeta; ++ie)
                for (int ik = 0; ik < T::kNk; ++ik)
                    v[Format::index(ic, ia, ie, ik)] =
                        Format::node(w.data(), x.data(), int(w.size()), ic, ia,
                                     Format::eta_node(ie), Format::k_node(ik));
        }
    }
    return v;
}

std::vector<float> compute_ggx_albedo() {
    using T = FgdTable;
    std::vector<float> v(std::size_t(T::kNc) * T::kNalpha);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < T::kNc; ++ic)
        for (int ia = 0; ia < T::kNalpha; ++ia) {
            double sum = 0;
            visible_normal_rule(c_node(ic), alpha_node(ia), kTableNr, kTableNphi,
                                [&](double, double w) { sum += w; });
            v[std::size_t(ic) * T::kNalpha + ia] = float(sum);
        }
    return v;
}

}  // namespace

double GgxAlbedoTable::direct(double c, double alpha, int n_r, int n_phi) {
    if (alpha <= 0) return 1.0;
    double sum = 0;
    visible_normal_rule(std::max(c, kCMin), alpha, n_r, n_phi, [&](double, double w) { sum += w; });
    return sum;
}

GgxAlbedoTable::GgxAlbedoTable() {
    using T = FgdTable;
    const TableKey key{"ggx-albedo",
                       fmt::format("ggx-albedo-v1 c{} a{} nr{} nphi{} cmin{} amin{}", T::kNc,
                                   T::kNalpha, kTableNr, kTableNphi, kCMin, kAlphaMin),
                       {T::kNc, T::kNalpha}};
    values_ = cached_table(key, compute_ggx_albedo);
}

const GgxAlbedoTable& GgxAlbedoTable::get() {
    static const GgxAlbedoTable table;
    return table;
}

double GgxAlbedoTable::operator()(double c, double alpha) const {
    if (alpha <= 0) return 1.0;
    using T = FgdTable;
    const double fc = std::sqrt(lamina1::table_axis(c, 0.0, 1.0)) * (T::kNc - 1);
    const double fa = std::sqrt(lamina1::table_axis(alpha, 0.0, 1.0)) * (T::kNalpha - 1);
    const int ic = std::min(int(fc), T::kNc - 2), ia = std::min(int(fa), T::kNalpha - 2);
    const double tc = fc - ic, ta = fa - ia;
    const float* row = values_.data() + std::size_t(ic) * T::kNalpha + ia;
    const double v0 = (1 - ta) * row[0] + ta * row[1];
    const double v1 = (1 - ta) * row[T::kNalpha] + ta * row[T::kNalpha + 1];
    return clamp((1 - tc) * v0 + tc * v1, 0.0, 1.0);
}

double FgdTable::direct(double c, double alpha, double eta, double k, int n_r, int n_phi) {
    if (alpha <= 0) return fresnel_any(c, eta, k);
    double sum = 0;
    visible_normal_rule(std::max(c, kCMin), alpha, n_r, n_phi,
                        [&](double x, double w) { sum += w * fresnel_any(x, eta, k); });
    return sum;
}

FgdTable::FgdTable() {
    const TableKey key{"fgd",
                       fmt::format("{} c{} a{} e{}:{}:{} k{}:{} bins{} nr{} nphi{} cmin{} amin{}",
                                   kCodeVersion, kNc, kNalpha, kNeta, kLog2EtaMin, kLog2EtaMax, kNk,
                                   kKMax, kBins, kTableNr, kTableNphi, kCMin, kAlphaMin),
                       {kNc, kNalpha, kNeta, kNk}};
    values_ = cached_table(key, compute_fgd);
    data_ = values_.data();
}

const FgdTable& FgdTable::get() {
    static const FgdTable table;  // thread-safe initialization (C++11 magic statics)
    return table;
}

FgdTable::Index FgdTable::locate(double eta, double k) {
    return Format::locate(eta, k);
}

double FgdTable::operator()(double c, double alpha, double eta, double k) const {
    return (*this)(c, alpha, locate(eta, k));
}

Rgbd FgdTable::rgb(double c, double alpha, const std::array<Index, 3>& at) const {
    const lamina1::Rgb f = Format::interpolate_rgb(
        [&](int ic, int ia, int i) { return data_ + Format::index(ic, ia, at[i].ie, at[i].ik); },
        kNk, c, alpha, at);
    return {f[0], f[1], f[2]};
}

double FgdTable::operator()(double c, double alpha, const Index& at) const {
    return Format::interpolate(
        [&](int ic, int ia) { return data_ + Format::index(ic, ia, at.ie, at.ik); }, kNk, c, alpha,
        at);
}

lamina1::FgdBins FgdTable::bins() {
    lamina1::FgdBins out;
    std::vector<std::vector<double>> w(std::size_t(kNc) * kNalpha), x(w.size());
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < kNc; ++ic)
        for (int ia = 0; ia < kNalpha; ++ia)
            node_bins(ic, ia, w[std::size_t(ic) * kNalpha + ia], x[std::size_t(ic) * kNalpha + ia]);
    out.offset.push_back(0);
    for (std::size_t i = 0; i < w.size(); ++i) {
        out.w.insert(out.w.end(), w[i].begin(), w[i].end());
        out.x.insert(out.x.end(), x[i].begin(), x[i].end());
        out.offset.push_back(std::uint32_t(out.w.size()));
    }
    return out;
}

}  // namespace lamina

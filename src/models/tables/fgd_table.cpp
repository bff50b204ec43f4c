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

constexpr int kBins = 64;     // x = wi·wm bins per (c, α)
constexpr int kTableNr = 48;  // Gauss–Legendre nodes in r (weight 2r) on Heitz's disk
constexpr int kTableNphi = 64;
constexpr double kCMin = 1e-4;      // c = 0 is evaluated at this cosine (G1 → 0 at grazing)
constexpr double kAlphaMin = 1e-5;  // α = 0 is evaluated at this roughness (the smooth limit)
constexpr const char* kCodeVersion = "fgd-v4";

// c and α are tabulated on squared axes (node = s², s uniform): the shadowing at grazing varies
// on the scale c ~ α, which needs dense nodes near 0 on both axes.
double c_node(int i) {
    return std::max(kCMin, sqr(double(i) / (FgdTable::kNc - 1)));
}
double alpha_node(int i) {
    return std::max(kAlphaMin, sqr(double(i) / (FgdTable::kNalpha - 1)));
}
double eta_node(int i) {
    return std::exp2(FgdTable::kLog2EtaMin +
                     (FgdTable::kLog2EtaMax - FgdTable::kLog2EtaMin) * i / (FgdTable::kNeta - 1));
}
double k_node(int i) {
    return FgdTable::kKMax * sqr(double(i) / (FgdTable::kNk - 1));
}

/// x limited to [lo, hi] for a table coordinate, NaN going to lo: an index computed from NaN would
/// be undefined behaviour and read outside the table.
double axis(double x, double lo, double hi) {
    return x >= lo ? (x <= hi ? x : hi) : lo;
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

/// Weight of the control variate F(c): 1 for smooth interfaces, fading out by α ≈ 0.1.
double smooth_weight(double alpha) {
    return std::exp(-alpha / 0.03);
}

double fresnel_any(double x, double eta, double k) {
    return k == 0 ? fresnel_dielectric(x, eta) : fresnel_complex_fast(x, eta, k);
}

std::vector<float> compute_fgd() {
    using T = FgdTable;
    std::vector<float> v(std::size_t(T::kNc) * T::kNalpha * T::kNeta * T::kNk);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < T::kNc; ++ic) {
        for (int ia = 0; ia < T::kNalpha; ++ia) {
            std::array<double, kBins> W{}, X{};
            visible_normal_rule(c_node(ic), alpha_node(ia), kTableNr, kTableNphi,
                                [&](double x, double w) {
                                    const int b = std::min(kBins - 1, int(x * kBins));
                                    W[b] += w;
                                    X[b] += w * x;
                                });
            int nb = 0;
            std::array<double, kBins> Wc{}, Xc{};
            for (int b = 0; b < kBins; ++b)
                if (W[b] > 0) {
                    Wc[nb] = W[b];
                    Xc[nb] = X[b] / W[b];
                    ++nb;
                }
            for (int ie = 0; ie < T::kNeta; ++ie) {
                const double eta = eta_node(ie);
                for (int ik = 0; ik < T::kNk; ++ik) {
                    const double k = k_node(ik);
                    double sum = 0;
                    for (int b = 0; b < nb; ++b)
                        sum += Wc[b] * fresnel_any(Xc[b], eta, k);
                    // Stored as the residual from w(α)·F(c), the smooth limit (a control variate
                    // that fades out with roughness): the lookup adds the exact w(α)F(c) back, so
                    // the step-like kink of F at the critical angle (η < 1) is not interpolated
                    // where the lobe is narrow enough to keep it.
                    sum -= smooth_weight(alpha_node(ia)) * fresnel_any(c_node(ic), eta, k);
                    v[((std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie) * T::kNk + ik] =
                        float(sum);
                }
            }
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
    const double fc = std::sqrt(axis(c, 0.0, 1.0)) * (T::kNc - 1);
    const double fa = std::sqrt(axis(alpha, 0.0, 1.0)) * (T::kNalpha - 1);
    const int ic = std::min(int(fc), T::kNc - 2), ia = std::min(int(fa), T::kNalpha - 2);
    const double tc = fc - ic, ta = fa - ia;
    const float* row = values_.data() + std::size_t(ic) * T::kNalpha + ia;
    const double v0 = (1 - ta) * row[0] + ta * row[1];
    const double v1 = (1 - ta) * row[T::kNalpha] + ta * row[T::kNalpha + 1];
    return clamp((1 - tc) * v0 + tc * v1, 0.0, 1.0);
}

double fresnel_complex_fast(double cos_theta, double eta, double k) {
    cos_theta = clamp(cos_theta, 0.0, 1.0);
    const double cos2 = cos_theta * cos_theta;
    const double sin2 = 1 - cos2;
    const double eta2 = eta * eta, k2 = k * k;
    const double t0 = eta2 - k2 - sin2;
    const double a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta2 * k2);
    const double t1 = a2_plus_b2 + cos2;
    const double a = safe_sqrt(0.5 * (a2_plus_b2 + t0));
    const double t2 = 2 * cos_theta * a;
    if (t1 + t2 <= 0) return 1;  // grazing onto an index-matched interface: the limit c → 0
    // t1 − t2 and t3 − t4 are sums of squares (physics/fresnel.h, fresnel_conductor): clamped at 0
    // against the rounding that makes them slightly negative near η = 1, κ = 0.
    const double rs = max0(t1 - t2) / (t1 + t2);
    const double t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    const double t4 = t2 * sin2;
    const double rp = rs * max0(t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

Rgbd fresnel_complex_rgb(double cos_theta, const Rgbd& eta, const Rgbd& k) {
    cos_theta = clamp(cos_theta, 0.0, 1.0);
    const double cos2 = cos_theta * cos_theta;
    const double sin2 = 1 - cos2;
    alignas(32) double e[4] = {eta[0], eta[1], eta[2], 1.5}, kk[4] = {k[0], k[1], k[2], 0.0};
    alignas(32) double out[4];
    // PBR 3rd ed., §8.2.1 (FrConductor), lane by lane.
    for (int c = 0; c < 4; ++c) {
        const double eta2 = e[c] * e[c], k2 = kk[c] * kk[c];
        const double t0 = eta2 - k2 - sin2;
        const double a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta2 * k2);
        const double t1 = a2_plus_b2 + cos2;
        const double a = std::sqrt(std::max(0.5 * (a2_plus_b2 + t0), 0.0));
        const double t2 = 2 * cos_theta * a;
        // Non-negative numerators (sums of squares; see fresnel_complex_fast), clamped at 0.
        const double rs = std::max(t1 - t2, 0.0) / std::max(t1 + t2, 1e-300);
        const double t3 = cos2 * a2_plus_b2 + sin2 * sin2;
        const double t4 = t2 * sin2;
        const double rp = rs * std::max(t3 - t4, 0.0) / std::max(t3 + t4, 1e-300);
        out[c] = t1 + t2 > 0 ? 0.5 * (rp + rs) : 1.0;
    }
    return {out[0], out[1], out[2]};
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
    const double fe = (axis(std::log2(eta), kLog2EtaMin, kLog2EtaMax) - kLog2EtaMin) /
                      (kLog2EtaMax - kLog2EtaMin) * (kNeta - 1);
    const double fk = std::sqrt(axis(k, 0.0, kKMax) / kKMax) * (kNk - 1);
    Index at;
    at.eta = eta;
    at.k = k;
    at.ie = std::min(int(fe), kNeta - 2);
    at.ik = std::min(int(fk), kNk - 2);
    at.te = fe - at.ie;
    at.tk = fk - at.ik;
    return at;
}

double FgdTable::operator()(double c, double alpha, double eta, double k) const {
    return (*this)(c, alpha, locate(eta, k));
}

Rgbd FgdTable::rgb(double c, double alpha, const std::array<Index, 3>& at) const {
    const Rgbd eta(at[0].eta, at[1].eta, at[2].eta), k(at[0].k, at[1].k, at[2].k);
    if (alpha <= 0) return fresnel_complex_rgb(c, eta, k);
    const double fc = std::sqrt(axis(c, 0.0, 1.0)) * (kNc - 1);
    const double fa = std::sqrt(axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2);
    const double tc = fc - ic, ta = fa - ia;
    Rgbd out(0.0);
    for (int dc = 0; dc < 2; ++dc) {
        const double wc = dc ? tc : 1 - tc;
        for (int da = 0; da < 2; ++da) {
            const double wa = wc * (da ? ta : 1 - ta);
            const float* block = data_ + (std::size_t(ic + dc) * kNalpha + (ia + da)) * kNeta * kNk;
            for (int i = 0; i < 3; ++i) {
                const float* row = block + std::size_t(at[i].ie) * kNk + at[i].ik;
                const double tk = at[i].tk, te = at[i].te;
                const double v0 = (1 - tk) * row[0] + tk * row[1];
                const double v1 = (1 - tk) * row[kNk] + tk * row[kNk + 1];
                out[i] += wa * ((1 - te) * v0 + te * v1);
            }
        }
    }
    if (alpha < 0.5) out += fresnel_complex_rgb(c, eta, k) * smooth_weight(alpha);
    for (int i = 0; i < 3; ++i)
        out[i] = clamp(out[i], 0.0, 1.0);
    return out;
}

double FgdTable::operator()(double c, double alpha, const Index& at) const {
    if (alpha <= 0) return fresnel_any(c, at.eta, at.k);  // the smooth limit is exact Fresnel
    const double fc = std::sqrt(axis(c, 0.0, 1.0)) * (kNc - 1);
    const double fa = std::sqrt(axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2);
    const double tc = fc - ic, ta = fa - ia, te = at.te, tk = at.tk;
    double sum = 0;
    for (int dc = 0; dc < 2; ++dc) {
        const double wc = dc ? tc : 1 - tc;
        for (int da = 0; da < 2; ++da) {
            const double wa = wc * (da ? ta : 1 - ta);
            const float* row =
                data_ + ((std::size_t(ic + dc) * kNalpha + (ia + da)) * kNeta + at.ie) * kNk +
                at.ik;
            const double v0 = (1 - tk) * row[0] + tk * row[1];
            const double v1 = (1 - tk) * row[kNk] + tk * row[kNk + 1];
            sum += wa * ((1 - te) * v0 + te * v1);
        }
    }
    // The control variate w(α)F(c) (see compute_fgd); below 6e-8 beyond α = 0.5, skipped there.
    if (alpha < 0.5) sum += smooth_weight(alpha) * fresnel_any(c, at.eta, at.k);
    return clamp(sum, 0.0, 1.0);
}

}  // namespace lamina

#pragma once
// The generic tables lamina-1 reads, as formats: their axes, their layouts and their
// interpolation, over arrays of floats (lamina computes the values and caches them; a renderer
// reads them from the data file, lamina1/tables.h). Four tables, each over generic axes:
//
//   T(c, α, η)       a rough dielectric's directional transmittance (Walter et al. 2007, Eq. 21),
//                    one table per refraction masking;
//   FGD(c, α, η, κ)  the directional albedo of one GGX reflection with exact Fresnel (Belcour
//                    2018's "FGD"), its nodes as the sum of per-(c, α) bins of x = wi·wm, whose
//                    weights do not depend on the index (FgdBins);
//   R(ρ; x, y)       the density of a sum of three GGX slopes relative to one GGX (lamina-1's
//                    shaped first-order lobe);
//   s(μ, α, η), ΔE   how a rough dielectric's scattering orders ≥ 2 split between reflection and
//                    transmission, and a white conductor's orders ≥ 2 (microsurface=multiple).
//
// lamina's docs/models.md describes how each is computed and how accurate it is.

#include "lamina1/math.h"
#include "lamina1/physics.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace lamina1 {

/// x limited to [lo, hi] for a table coordinate, NaN going to lo (an index computed from NaN would
/// read outside the table).
inline double table_axis(double x, double lo, double hi) {
    return x >= lo ? (x <= hi ? x : hi) : lo;
}

/// The cosine of total internal reflection μc(η) = √(1 − η²) for a relative index η < 1 (light
/// from the denser side), 0 where there is none (η ≥ 1).
inline double critical_cosine(double eta) {
    return eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;
}

/// The axes of a table f(c, α, η) that steps at the critical cosine of total internal reflection
/// (a rough interface's transmittance), and its interpolation.
///
/// c in two pieces split at the critical cosine μc(η) = √(1 − η²) (μc = 0 for η ≥ 1): c = μc (1 −
/// y²) below it (n_below nodes uniform in y) and c = μc + (1 − μc) x² above it (n_c nodes uniform
/// in x; for η ≥ 1, c = x²), so that the (smoothed) step lies on one node line at every η and the
/// nodes crowd towards it from both sides; α = s² (n_alpha nodes, s uniform in [0, 1]); η in two
/// halves meeting at the node η = 1, uniform in log2 η up to 2^log2_eta_max above and uniform in
/// μc(η) down to η = 2^log2_eta_min below (n_eta nodes in all; μc moves fastest with η near 1).
/// Arguments outside are clamped.
///
/// A table on these axes stores the residual f − w(α) f0(c, η) from the smooth limit f0 (the
/// value at α = 0, a step or a kink at μc), w(α) = e^{−α/0.03}: a control variate for the nodes
/// of small α, where f is nearly the step itself. The lookup interpolates the residual
/// multilinearly at the query's own μc — the table at every η node holds f at the same fractions
/// of the pieces below and above μc, so the step is never interpolated across — and adds w f0 back
/// (the weight interpolated in α as the residual is). Layout: ((ic n_alpha + ia) n_eta + ie)
/// components + k, ic over both pieces of c (n_below + n_c).
struct CriticalCosineAxes {
    int n_below, n_c, n_alpha, n_eta;
    double log2_eta_min, log2_eta_max;
    double c_min, alpha_min;  ///< the smallest c and α nodes (their exact 0 is singular)
    /// w(α) at the α nodes (filled by the constructor).
    std::vector<double> alpha_weights;

    CriticalCosineAxes(int n_below_, int n_c_, int n_alpha_, int n_eta_, double log2_eta_min_,
                       double log2_eta_max_, double c_min_, double alpha_min_)
        : n_below(n_below_),
          n_c(n_c_),
          n_alpha(n_alpha_),
          n_eta(n_eta_),
          log2_eta_min(log2_eta_min_),
          log2_eta_max(log2_eta_max_),
          c_min(c_min_),
          alpha_min(alpha_min_) {
        for (int i = 0; i < n_alpha; ++i)
            alpha_weights.push_back(smooth_weight(alpha_node(i)));
    }

    int c_count() const { return n_below + n_c; }
    std::size_t count(int components = 1) const {
        return std::size_t(c_count()) * n_alpha * n_eta * components;
    }
    std::size_t index(int ic, int ia, int ie, int components = 1, int k = 0) const {
        return ((std::size_t(ic) * n_alpha + ia) * n_eta + ie) * components + k;
    }

    /// The cosine of node i of the c axis at η.
    double c_node(int i, double eta) const {
        const double mu_c = critical_cosine(eta);
        double c;
        if (i < n_below) {
            const double y = 1 - double(i) / (n_below - 1);
            c = mu_c * (1 - y * y);
        } else {
            const double x = double(i - n_below) / (n_c - 1);
            c = mu_c + (1 - mu_c) * x * x;
        }
        return std::max(c_min, c);
    }
    /// True for a node of the lower piece (c ≤ μc).
    bool below(int i) const { return i < n_below; }
    double alpha_node(int i) const { return std::max(alpha_min, sqr(double(i) / (n_alpha - 1))); }
    int eta_one() const { return (n_eta - 1) / 2; }
    double max_critical_cosine() const { return critical_cosine(std::exp2(log2_eta_min)); }
    double eta_node(int i) const {
        if (i >= eta_one())
            return std::exp2(log2_eta_max * (i - eta_one()) / (n_eta - 1 - eta_one()));
        const double mu_c = max_critical_cosine() * (eta_one() - i) / eta_one();
        return std::sqrt(1 - mu_c * mu_c);
    }
    /// The fractional node index of η (clamped to the axis).
    double eta_index(double eta) const {
        if (eta >= 1)
            return eta_one() +
                   std::min(std::log2(eta) / log2_eta_max, 1.0) * (n_eta - 1 - eta_one());
        return eta_one() * (1 - std::min(critical_cosine(eta) / max_critical_cosine(), 1.0));
    }

    /// The control variate's weight w(α) = e^{−α/0.03}.
    static double smooth_weight(double alpha) { return std::exp(-alpha / 0.03); }

    /// Interpolated component k of a table of these axes holding the residual from w(α) f0: c ∈
    /// [0, 1], α ∈ (0, 1], η clamped here; limit = f0 at the query (for a step, its value on the
    /// query's side: c < μc is the lower piece).
    double interpolate(const float* values, int components, int k, double c, double alpha,
                       double eta, double limit) const {
        eta = clamp(eta, std::exp2(log2_eta_min), std::exp2(log2_eta_max));
        const double mu_c = critical_cosine(eta);
        double fc;
        if (c < mu_c) {
            fc = (1 - std::sqrt(std::max(0.0, 1 - c / mu_c))) * (n_below - 1);
        } else {
            fc = n_below + std::sqrt(mu_c < 1 ? (c - mu_c) / (1 - mu_c) : 0.0) * (n_c - 1);
        }
        const double fa = std::sqrt(clamp(alpha, 0.0, 1.0)) * (n_alpha - 1);
        const double fe = eta_index(eta);
        const int ic_max = c < mu_c ? n_below - 2 : n_below + n_c - 2;
        const int ic = std::min(int(fc), ic_max), ia = std::min(int(fa), n_alpha - 2),
                  ie = std::min(int(fe), n_eta - 2);
        const double tc = fc - ic, ta = fa - ia, te = fe - ie;
        // The weight interpolated as the residual is (exact at the α nodes): the weight itself at
        // the query's α would add its own curvature in α to the interpolation error (2e-3 at
        // α = 0.05, η = 1.5, on a rough interface's transmittance, nearly constant there).
        const double weight = (1 - ta) * alpha_weights[ia] + ta * alpha_weights[ia + 1];
        double sum = 0;
        for (int dc = 0; dc < 2; ++dc)
            for (int da = 0; da < 2; ++da) {
                const double w = (dc ? tc : 1 - tc) * (da ? ta : 1 - ta);
                const float* row = values + index(ic + dc, ia + da, ie, components, k);
                sum += w * ((1 - te) * row[0] + te * row[components]);
            }
        if (weight > 0) sum += weight * limit;
        return sum;
    }
};

/// The transmittance table T(c, α, η): its axes (CriticalCosineAxes: 33 + 49 cosines, 33
/// roughnesses, 41 indices over log2 η ∈ [−2, 2]) and its lookup.
struct TransmittanceFormat {
    static constexpr int kNbelow = 33, kNc = 49, kNalpha = 33, kNeta = 41;
    static constexpr double kLog2EtaMin = -2, kLog2EtaMax = 2;
    static constexpr double kCMin = 1e-4, kAlphaMin = 1e-5;
    static const CriticalCosineAxes& axes() {
        static const CriticalCosineAxes a(kNbelow, kNc, kNalpha, kNeta, kLog2EtaMin, kLog2EtaMax,
                                          kCMin, kAlphaMin);
        return a;
    }
    static std::size_t size() { return axes().count(); }
    /// Interpolated T of the table `values`: c ∈ [0, 1], α ∈ [0, 1], η > 0 (clamped to the axes);
    /// α = 0 gives 1 − F(c) exactly.
    static double lookup(const float* values, double c, double alpha, double eta) {
        c = clamp(c, 0.0, 1.0);
        if (alpha <= 0) return 1 - fresnel_dielectric(c, eta);
        eta = clamp(eta, std::exp2(kLog2EtaMin), std::exp2(kLog2EtaMax));
        return clamp(
            axes().interpolate(values, 1, 0, c, alpha, eta, 1 - fresnel_dielectric(c, eta)), 0.0,
            1.0);
    }
};

/// The FGD table: c = s² (41 nodes, s uniform in [0, 1]), α = s² (33), log2 η ∈ [−5, 3] (81, η = 1
/// a node), κ = 10 s² (21); outside, the arguments are clamped. Its nodes hold the residual from
/// w(α) F(c) (the smooth limit, a control variate that fades out with roughness); multilinear
/// interpolation, α = 0 the exact Fresnel factor.
struct FgdFormat {
    static constexpr int kNc = 41, kNalpha = 33, kNeta = 81, kNk = 21;
    static constexpr double kLog2EtaMin = -5, kLog2EtaMax = 3, kKMax = 10;
    static constexpr double kCMin = 1e-4;      ///< c = 0 is computed at this cosine
    static constexpr double kAlphaMin = 1e-5;  ///< α = 0 is computed at this roughness
    static constexpr int kBins = 64;           ///< x = wi·wm bins per (c, α)
    static std::size_t size() { return std::size_t(kNc) * kNalpha * kNeta * kNk; }
    static std::size_t index(int ic, int ia, int ie, int ik) {
        return ((std::size_t(ic) * kNalpha + ia) * kNeta + ie) * kNk + ik;
    }

    // c and α are tabulated on squared axes (node = s², s uniform): the shadowing at grazing
    // varies on the scale c ~ α, which needs dense nodes near 0 on both axes.
    static double c_node(int i) { return std::max(kCMin, sqr(double(i) / (kNc - 1))); }
    static double alpha_node(int i) { return std::max(kAlphaMin, sqr(double(i) / (kNalpha - 1))); }
    static double eta_node(int i) {
        return std::exp2(kLog2EtaMin + (kLog2EtaMax - kLog2EtaMin) * i / (kNeta - 1));
    }
    static double k_node(int i) { return kKMax * sqr(double(i) / (kNk - 1)); }
    /// Weight of the control variate F(c): 1 for smooth interfaces, fading out by α ≈ 0.1.
    static double smooth_weight(double alpha) { return std::exp(-alpha / 0.03); }
    static double fresnel(double x, double eta, double k) {
        return k == 0 ? fresnel_dielectric(x, eta) : fresnel_complex(x, eta, k);
    }

    /// The node (c_node(ic), alpha_node(ia), η, κ) from the bins of x = wi·wm of its (c, α): the
    /// visible-normal rule's weights w_b (with G2/G1) and mean cosines x̄_b, FGD = Σ w_b F(x̄_b),
    /// less the control variate.
    static float node(const double* w, const double* x, int bins, int ic, int ia, double eta,
                      double k) {
        double sum = 0;
        for (int b = 0; b < bins; ++b)
            sum += w[b] * fresnel(x[b], eta, k);
        sum -= smooth_weight(alpha_node(ia)) * fresnel(c_node(ic), eta, k);
        return float(sum);
    }

    /// The (η, κ) part of a lookup, located once per interface.
    struct Index {
        double eta = 1, k = 0;
        int ie = 0, ik = 0;
        double te = 0, tk = 0;
    };
    static Index locate(double eta, double k) {
        const double fe = (table_axis(std::log2(eta), kLog2EtaMin, kLog2EtaMax) - kLog2EtaMin) /
                          (kLog2EtaMax - kLog2EtaMin) * (kNeta - 1);
        const double fk = std::sqrt(table_axis(k, 0.0, kKMax) / kKMax) * (kNk - 1);
        Index at;
        at.eta = eta;
        at.k = k;
        at.ie = std::min(int(fe), kNeta - 2);
        at.ik = std::min(int(fk), kNk - 2);
        at.te = fe - at.ie;
        at.tk = fk - at.ik;
        return at;
    }

    /// Interpolated FGD at (c, α) for the located index `at`. block(ic, ia) points to the nodes
    /// (ic, ia, at.ie, at.ik), whose neighbours in κ follow at +1 and in η at +eta_stride.
    template <typename Block>
    static double interpolate(Block&& block, int eta_stride, double c, double alpha,
                              const Index& at) {
        if (alpha <= 0) return fresnel(c, at.eta, at.k);  // the smooth limit is exact Fresnel
        const double fc = std::sqrt(table_axis(c, 0.0, 1.0)) * (kNc - 1);
        const double fa = std::sqrt(table_axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
        const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2);
        const double tc = fc - ic, ta = fa - ia, te = at.te, tk = at.tk;
        double sum = 0;
        for (int dc = 0; dc < 2; ++dc) {
            const double wc = dc ? tc : 1 - tc;
            for (int da = 0; da < 2; ++da) {
                const double wa = wc * (da ? ta : 1 - ta);
                const float* row = block(ic + dc, ia + da);
                const double v0 = (1 - tk) * row[0] + tk * row[1];
                const double v1 = (1 - tk) * row[eta_stride] + tk * row[eta_stride + 1];
                sum += wa * ((1 - te) * v0 + te * v1);
            }
        }
        // The control variate w(α)F(c); below 6e-8 beyond α = 0.5, skipped there.
        if (alpha < 0.5) sum += smooth_weight(alpha) * fresnel(c, at.eta, at.k);
        return clamp(sum, 0.0, 1.0);
    }

    /// Three channels at once (a conductor), sharing the (c, α) part; block(ic, ia, channel).
    template <typename Block, typename Indices>
    static Rgb interpolate_rgb(Block&& block, int eta_stride, double c, double alpha,
                               const Indices& at) {
        const Rgb eta(at[0].eta, at[1].eta, at[2].eta), k(at[0].k, at[1].k, at[2].k);
        if (alpha <= 0) return fresnel_complex_rgb(c, eta, k);
        const double fc = std::sqrt(table_axis(c, 0.0, 1.0)) * (kNc - 1);
        const double fa = std::sqrt(table_axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
        const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2);
        const double tc = fc - ic, ta = fa - ia;
        Rgb out(0.0);
        for (int dc = 0; dc < 2; ++dc) {
            const double wc = dc ? tc : 1 - tc;
            for (int da = 0; da < 2; ++da) {
                const double wa = wc * (da ? ta : 1 - ta);
                for (int i = 0; i < 3; ++i) {
                    const float* row = block(ic + dc, ia + da, i);
                    const double tk = at[i].tk, te = at[i].te;
                    const double v0 = (1 - tk) * row[0] + tk * row[1];
                    const double v1 = (1 - tk) * row[eta_stride] + tk * row[eta_stride + 1];
                    out[i] += wa * ((1 - te) * v0 + te * v1);
                }
            }
        }
        if (alpha < 0.5) out += fresnel_complex_rgb(c, eta, k) * smooth_weight(alpha);
        for (int i = 0; i < 3; ++i)
            out[i] = clamp(out[i], 0.0, 1.0);
        return out;
    }
};

/// The bins of the FGD table's visible-normal rule, per (c, α) node: weights and mean x = wi·wm
/// of the non-empty bins (FgdFormat::node), at offset[ic · kNalpha + ia] .. offset[… + 1].
struct FgdBins {
    std::vector<std::uint32_t> offset;
    std::vector<double> w, x;
};

/// The slope-sum table R(ρ; x, y): x the first scale's share of the variance (25 nodes, x = (1 −
/// cos πs)/2), y the second's share of the rest (13 nodes in [0, 1/2], y = s²/2; R is symmetric in
/// y ↔ 1 − y), ρ = r/σ on u = ρ/(1 + ρ) (33 nodes); trilinear in (s_x, s_y, u).
struct SlopeSumFormat {
    static constexpr int kNx = 25, kNy = 13, kNu = 33;
    static std::size_t size() { return std::size_t(kNx) * kNy * kNu; }

    /// The (x, y) part of a lookup, located once for every radius of one lobe.
    struct Shares {
        int ix = 0, iy = 0;
        double tx = 0, ty = 0;
    };
    /// x, y clamped to [0, 1] (NaN to 0; y folded to [0, 1/2]).
    static Shares locate(double x, double y) {
        x = table_axis(x, 0.0, 1.0);
        y = table_axis(y, 0.0, 1.0);
        if (y > 0.5) y = 1 - y;
        const double fx = std::acos(1 - 2 * x) * kInvPi * (kNx - 1);
        const double fy = std::sqrt(2 * y) * (kNy - 1);
        Shares at;
        at.ix = std::min(int(fx), kNx - 2);
        at.iy = std::min(int(fy), kNy - 2);
        at.tx = clamp(fx - at.ix, 0.0, 1.0);
        at.ty = clamp(fy - at.iy, 0.0, 1.0);
        return at;
    }

    /// R(ρ; x, y) of the table `values` at ρ ≥ 0 (NaN and negative read ρ = 0; ∞ the last node).
    static double ratio(const float* values, double rho, const Shares& at) {
        rho = table_axis(rho, 0.0, HUGE_VAL);
        const double u = std::isfinite(rho) ? rho / (1 + rho) : 1.0;
        const double fu = u * (kNu - 1);
        const int iu = std::min(int(fu), kNu - 2);
        const double tu = fu - iu;
        double sum = 0;
        for (int dx = 0; dx < 2; ++dx)
            for (int dy = 0; dy < 2; ++dy) {
                const double wxy = (dx ? at.tx : 1 - at.tx) * (dy ? at.ty : 1 - at.ty);
                const float* row =
                    values + (std::size_t(at.ix + dx) * kNy + (at.iy + dy)) * kNu + iu;
                sum += wxy * ((1 - tu) * row[0] + tu * row[1]);
            }
        return sum;
    }
};

/// The multiple-scattering albedo table: μ = s² (17 nodes, the first at 10⁻³), α = s² (17),
/// log2 η ∈ [−2, 2] (25); [μ][α][η] the split s = ΔR/(ΔR + ΔT) of a dielectric's orders ≥ 2,
/// then [μ][α] a white conductor's ΔE. Multilinear; arguments clamped.
struct MultipleScatteringFormat {
    static constexpr int kNmu = 17, kNalpha = 17, kNeta = 25;
    static constexpr double kLog2EtaMin = -2, kLog2EtaMax = 2, kMuMin = 1e-3;
    static std::size_t size() { return std::size_t(kNmu) * kNalpha * (kNeta + 1); }
    static std::size_t dielectric_index(int im, int ia, int ie) {
        return (std::size_t(im) * kNalpha + ia) * kNeta + ie;
    }
    static std::size_t conductor_index(int im, int ia) {
        return std::size_t(kNmu) * kNalpha * kNeta + std::size_t(im) * kNalpha + ia;
    }
    static double mu_node(int i) { return std::max(kMuMin, sqr(double(i) / (kNmu - 1))); }
    static double alpha_node(int i) { return sqr(double(i) / (kNalpha - 1)); }
    static double eta_node(int i) {
        return std::exp2(kLog2EtaMin + (kLog2EtaMax - kLog2EtaMin) * i / (kNeta - 1));
    }
    /// Position of f on an axis of n nodes: the cell's first node and the weight of the next.
    static void locate(double f, int n, int& i, double& t) {
        f = clamp(f, 0.0, double(n - 1));
        i = std::min(int(f), n - 2);
        t = f - i;
    }

    struct Dielectric {
        double reflected = 0;    ///< ΔR
        double transmitted = 0;  ///< ΔT
    };
    /// A rough dielectric's orders ≥ 2: the table's split of what single scattering loses,
    /// 1 − fgd − transmittance (the single-scattering albedos FGD(μ, α, η) and T(μ, α, η) with the
    /// Smith masking, which the caller looks up). α > 0, η > 0, else nothing.
    static Dielectric dielectric(const float* values, double mu, double alpha, double eta,
                                 double fgd, double transmittance) {
        Dielectric out;
        if (!(alpha > 0) || !(eta > 0)) return out;
        int im, ia, ie;
        double tm, ta, te;
        locate(std::sqrt(clamp(mu, 0.0, 1.0)) * (kNmu - 1), kNmu, im, tm);
        locate(std::sqrt(clamp(alpha, 0.0, 1.0)) * (kNalpha - 1), kNalpha, ia, ta);
        locate((clamp(std::log2(eta), kLog2EtaMin, kLog2EtaMax) - kLog2EtaMin) /
                   (kLog2EtaMax - kLog2EtaMin) * (kNeta - 1),
               kNeta, ie, te);
        double split = 0;
        for (int dm = 0; dm < 2; ++dm)
            for (int da = 0; da < 2; ++da)
                for (int de = 0; de < 2; ++de)
                    split += (dm ? tm : 1 - tm) * (da ? ta : 1 - ta) * (de ? te : 1 - te) *
                             values[dielectric_index(im + dm, ia + da, ie + de)];
        // What single scattering loses (the walk's orders ≥ 2 carry exactly it).
        const double lost = std::max(0.0, 1 - fgd - transmittance);
        out.reflected = split * lost;
        out.transmitted = (1 - split) * lost;
        return out;
    }
    /// A rough white conductor's orders ≥ 2, ΔE(μ, α); 0 for α = 0.
    static double conductor(const float* values, double mu, double alpha) {
        if (!(alpha > 0)) return 0;
        int im, ia;
        double tm, ta;
        locate(std::sqrt(clamp(mu, 0.0, 1.0)) * (kNmu - 1), kNmu, im, tm);
        locate(std::sqrt(clamp(alpha, 0.0, 1.0)) * (kNalpha - 1), kNalpha, ia, ta);
        double sum = 0;
        for (int dm = 0; dm < 2; ++dm)
            for (int da = 0; da < 2; ++da)
                sum += (dm ? tm : 1 - tm) * (da ? ta : 1 - ta) *
                       values[conductor_index(im + dm, ia + da)];
        return sum;
    }
};

}  // namespace lamina1

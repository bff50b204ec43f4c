#pragma once
// lamina-1's building blocks: its rules' sizes, the per-material curves over a cosine, and one
// facet's exact refraction turn (the shaped first-order lobe's tails).

#include "lamina1/math.h"
#include "lamina1/physics.h"
#include "lamina1/quadrature.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace lamina1 {

constexpr int kNmu = 65;   // nodes of the per-material curves over a cosine, μ = s²
constexpr int kNx = 33;    // nodes of X(μ), μ = s²
constexpr int kNloss = 9;  // nodes on each side of μc of a dense-side interface's loss L(μ)
constexpr int kYnr = 6;    // the rule of the transmitted light's mean direction: Gauss–Legendre
constexpr int kYnphi = 8;  // in r × midpoint in φ over the half disk
// The rule of Y and X: their integrands step at the coat's critical angle (total internal
// reflection returns everything beyond it). A plain 6 × 8 rule in r put that step on one heavy
// node (Y = 0.27 instead of 0.17 at normal incidence on α1 = 0.4 under an η0 = 1.2 smooth coat,
// and the stack 7% more light than the goniophotometer); 24 × 16 nodes still moved by 2% from one
// rule to the next. The rule splits the radius of each φ node at the step instead (and, for a
// slab's Y, at its bottom's own total reflection) and integrates it in u = √(1 − r)
// (integrate_visible_split, lamina1/quadrature.h): 5 Gauss–Legendre nodes
// per piece, 6 in φ; on the study's slabs, paints and frosted metals its albedos are within 1.0e-3
// (mean 5e-5) of a 16 × 32 rule, where 6 × 8 nodes in r were within 3.1e-3.
constexpr int kSplitNr = 5, kSplitNphi = 6, kSplitBisections = 14;
constexpr int kNormNr = 8, kNormNphi = 8;  // the base lobe's normalization N (its rule) ...
constexpr int kNnorm = 17;                 // ... on this many cosines (μ = s²)
/// Energies (fractions of the incident light) below this are taken as zero where a lobe is
/// normalized by them: far below anything a goniophotometer could measure.
constexpr double kNegligibleEnergy = 1e-12;
constexpr int kGauss = 24;  // Gauss–Legendre nodes per piece of the hemispherical integrals
// The slab's transmission curves (precompute_slab): nodes over a cosine (the first order, the
// later orders), and the split visible-normal rule of their integrals (r nodes per piece, φ
// nodes, bisections).
constexpr int kNfirst = 17, kNslab = 17;
constexpr int kSlabNr = 4, kSlabNphi = 8, kSlabBisections = 8;
// The slab's inside light in cosine bins (slab-orders=bins): the bins, the nodes per segment of
// their entry curves (SegmentCurve), and the rule of the interfaces' transfer between bins (r × φ
// nodes over the half disk of visible normals on one side of the plane of incidence, which the
// isotropic interface mirrors; sub-directions on each side of a bin's centre). Fewer nodes make
// the curves bumpy: 8 × 8 moved the quick study's slab errors by < 0.1 point but put the RGL
// export of a slab 2.3 % off in albedo (its goal 2 %).
constexpr int kNbins = 12, kBinPer = 4;
constexpr int kBinNr = 12, kBinNphi = 12, kBinSub = 3;

/// f(wm, weight) over the normals visible from w (w in the xz-plane) by GGX's visible-normal map
/// (Heitz 2018, "Sampling the GGX distribution of visible normals", JCGT 7(4)), kNr Gauss–Legendre
/// nodes in u1 = r² times kNphi midpoints in φ over the half disk on one side of the plane of
/// incidence, which an isotropic interface mirrors; the weights sum to 1. For histograms (the
/// slab's bins), whose integrands step everywhere: integrate_visible_split where they step once.
template <int kNr, int kNphi, typename F>
void for_visible_normals(const GGX& ggx, const Vec3& w, F&& f) {
    static const QuadratureRule q = gauss_legendre(kNr);
    for (int a = 0; a < kNr; ++a)
        for (int b = 0; b < kNphi; ++b) {
            const double r = q.x[a];
            f(ggx.sample_visible_normal(w, r * r, 0.5 * (b + 0.5) / kNphi - 0.25),
              q.w[a] * 2 * r / kNphi);
        }
}

/// A curve over a cosine μ ∈ [0, 1] on nodes μ = s² (dense at grazing), linear in s.
template <typename V, int kN = kNmu>
struct CosineCurve {
    std::array<V, kN> v{};
    template <typename F>
    void fill(F&& f) {
        for (int i = 0; i < kN; ++i)
            v[i] = f(sqr(double(i) / (kN - 1)));
    }
    /// Where μ falls: between nodes i and i + 1, t the weight of node i + 1.
    struct Place {
        int i;
        double t;
    };
    static Place locate(double mu) {
        const double s = std::sqrt(clamp(mu, 0.0, 1.0)) * (kN - 1);
        const int i = std::min(int(s), kN - 2);
        return {i, s - i};
    }
    V operator()(double mu) const {
        const Place p = locate(mu);
        return v[p.i] * (1 - p.t) + v[p.i + 1] * p.t;
    }
};

/// A curve over an inside cosine with a jump at the critical cosine μc (total internal reflection
/// at a smooth coat): linear on nodes uniform in [0, μc) and in [μc, 1], each piece on its own.
/// kSqrtEdge: a square-root edge there instead (a rough interface's transmittance from inside,
/// which rises as √(μ − μc) above it when nearly smooth, its step smoothed over a width ~α on
/// both sides): the nodes crowd towards μc from both sides, μ = μc (1 − (1 − t)²) below and
/// μ = μc + (1 − μc) t² above (t uniform), as integrate_split01 (lamina1/quadrature.h)
/// places its upper nodes.
template <int kN, typename V = Rgb, bool kSqrtEdge = false>
struct SplitCurve {
    double split = 0;
    std::array<V, kN> below{}, above{};
    /// The cosine of node i below the split (lower) or above it.
    double node(int i, bool lower) const {
        const double t = double(i) / (kN - 1);
        return lower
                   ? std::min(split * (kSqrtEdge ? 1 - sqr(1 - t) : t), std::nextafter(split, 0.0))
                   : split + (1 - split) * (kSqrtEdge ? t * t : t);
    }
    template <typename F>
    void fill(double mu_split, F&& f) {
        split = clamp(mu_split, 0.0, 1.0);
        for (int i = 0; i < kN; ++i) {
            if (split > 0) below[i] = f(node(i, true));  // else never read
            above[i] = f(node(i, false));
        }
    }
    /// Where μ falls: on which side of the split, between nodes i and i + 1 of it, t the weight
    /// of node i + 1.
    struct Place {
        bool lower;
        int i;
        double t;
    };
    Place locate(double mu) const {
        const bool lower = mu < split;
        const double a = lower ? 0 : split, b = lower ? split : 1;
        double x = b > a ? clamp((mu - a) / (b - a), 0.0, 1.0) : 0;
        if (kSqrtEdge) x = lower ? 1 - std::sqrt(1 - x) : std::sqrt(x);
        x *= kN - 1;
        const int i = std::min(int(x), kN - 2);
        return {lower, i, x - i};
    }
    V operator()(double mu) const {
        const Place p = locate(mu);
        const auto& v = p.lower ? below : above;
        return v[p.i] * (1 - p.t) + v[p.i + 1] * p.t;
    }
};

/// The square-root-edge curve (SplitCurve with kSqrtEdge).
template <int kN>
using EdgeCurve = SplitCurve<kN, double, true>;
/// The same per channel: the light a return trip keeps, whose Fresnel factors rise from total
/// reflection as √(μ − μc) just inside the critical cosine.
template <int kN>
using RgbEdgeCurve = SplitCurve<kN, Rgb, true>;

/// A curve over a cosine μ ∈ [0, 1] in segments between given cuts (where it may jump or bend:
/// the images of the bins' edges and centres under a smooth refraction), kPer nodes in each
/// segment from end to end (each end taken just inside it: the one-sided value), linear between
/// them: continuous within a segment, and across a cut where the function is.
template <typename V, int kPer>
struct SegmentCurve {
    static_assert(kPer >= 2, "a segment has its two ends");
    std::vector<double> cut;  ///< 0 = cut[0] < … < cut.back() = 1
    std::vector<V> v;         ///< kPer per segment
    template <typename F>
    void fill(std::vector<double> cuts, F&& f) {
        cut = std::move(cuts);
        const int n = int(cut.size()) - 1;
        v.assign(std::size_t(n) * kPer, V{});
        for (int g = 0; g < n; ++g)
            for (int i = 0; i < kPer; ++i) {
                double mu = cut[g] + (cut[g + 1] - cut[g]) * i / (kPer - 1);
                if (i == 0) mu = std::nextafter(cut[g], cut[g + 1]);
                if (i == kPer - 1) mu = std::nextafter(cut[g + 1], cut[g]);
                v[std::size_t(g) * kPer + i] = f(mu);
            }
    }
    V operator()(double mu) const {
        const int n = int(cut.size()) - 1;
        const int g = std::clamp(
            int(std::upper_bound(cut.begin() + 1, cut.end() - 1, mu) - (cut.begin() + 1)), 0,
            n - 1);
        const double span = cut[g + 1] - cut[g];
        const double x = span > 0 ? clamp((mu - cut[g]) / span, 0.0, 1.0) * (kPer - 1) : 0.0;
        const V* seg = v.data() + std::size_t(g) * kPer;
        const int i = std::min(int(x), kPer - 2);
        const double t = x - i;
        return seg[i] * (1 - t) + seg[i + 1] * t;
    }
    /// The outside cosine of node i of segment g (as fill places it).
    double node(int g, int i) const { return cut[g] + (cut[g + 1] - cut[g]) * i / (kPer - 1); }
};

/// N values of type T integrated and tabulated together (the curves above take it as V).
template <typename T, int N>
struct Multi {
    std::array<T, N> v{};
    Multi& operator+=(const Multi& o) {
        for (int i = 0; i < N; ++i)
            v[i] += o.v[i];
        return *this;
    }
    Multi operator+(const Multi& o) const { return Multi(*this) += o; }
    Multi operator*(double s) const {
        Multi r;
        for (int i = 0; i < N; ++i)
            r.v[i] = v[i] * s;
        return r;
    }
};

/// ∫_lo^hi f(μ) dμ by Gauss–Legendre (kGauss nodes).
template <typename V, typename F>
V integrate_range(F&& f, double lo, double hi) {
    static const QuadratureRule q = gauss_legendre(kGauss);
    V sum{};
    if (!(hi > lo)) return sum;
    for (int i = 0; i < kGauss; ++i)
        sum += f(lo + (hi - lo) * q.x[i]) * (q.w[i] * (hi - lo));
    return sum;
}

/// |1 − μ/(η μ')|: the rate at which a refracted direction turns with the tilt of the facet it
/// crosses (differentiate Snell's law sin(θ − δ) = η sin(θ' + Δ − δ) in δ at δ = 0, for a facet
/// tilted by δ in the plane of incidence: dΔ/dδ = 1 − cos θ/(η cos θ')). Belcour 2018, Eq. 10,
/// is the same first-order deflection. At normal incidence 1 − 1/η.
inline double deflection(double mu, double mu_in, double eta) {
    return std::abs(1 - mu / (eta * mu_in));
}

/// One facet's exact deflection of the refracted light at normal incidence (docs/models.md,
/// lamina-1, item 4), for the coat's spreads' tails: a facet tilted by δ turns the inside
/// direction by g(δ) — entering from outside, g = δ − asin(sin δ/η); leaving from inside, the
/// outside ray turns by ψ = asin(η sin δ) − δ, which the smooth refraction wo → wo' sees inside
/// as g = asin(sin ψ/η) (nothing beyond total internal reflection, δ ≥ asin(1/η)). Both have
/// g'(0) = k_n = 1 − 1/η. Tabulated inverse, over g ∈ [0, g_max] (129 nodes): sin δ and cos δ
/// (both smooth in g: an interpolated cos δ alone would make tan δ grow like √g at 0), and the
/// weight k_n w(δ)/g'(δ) (the Jacobian of the map, 1 at δ = 0) with w the facet's transmission
/// 1 − F(cos δ) times the refracted ray's Smith escape 1/(1 + Λ), relative to normal incidence.
struct FacetDeflection {
    static constexpr int kN = 129, kFine = 257;
    double g_max = 0;
    std::array<double, kN> sin_delta{}, cos_delta{}, weight{};

    void build(bool entering, double eta, double alpha0) {
        const GGX ggx{alpha0};
        const double k_n = 1 - 1 / eta;
        const double delta_max = entering ? 0.5 * kPi : std::asin(1 / eta);
        const double w0 = 1 - fresnel_dielectric(1.0, eta);
        // The forward map on a fine δ grid (g is increasing), then inverted node by node.
        std::array<double, kFine> g{}, sn{}, c{}, wt{};
        for (int j = 0; j < kFine; ++j) {
            const double delta = delta_max * j / (kFine - 1);
            const double sd = std::sin(delta), cd = std::cos(delta);
            double gj, dg, escape_cos;
            if (entering) {
                const double ct = safe_sqrt(1 - sqr(sd / eta));
                gj = delta - std::asin(std::min(sd / eta, 1.0));
                dg = 1 - cd / (eta * ct);
                escape_cos = std::cos(gj);
            } else {
                const double x = std::min(eta * sd, 1.0);
                const double psi = std::asin(x) - delta;
                gj = std::asin(std::sin(psi) / eta);
                const double root = safe_sqrt(1 - x * x);
                dg = root > 0 ? std::cos(psi) * (eta * cd / root - 1) / (eta * std::cos(gj))
                              : HUGE_VAL;
                escape_cos = std::cos(psi);
            }
            const double F =
                entering ? fresnel_dielectric(cd, eta) : fresnel_dielectric(cd, 1 / eta);
            const Vec3 w_ref(safe_sqrt(1 - sqr(escape_cos)), 0, std::max(escape_cos, 1e-9));
            const double w = (1 - F) / (1 + ggx.lambda(w_ref)) / w0;
            g[j] = gj;
            sn[j] = sd;
            c[j] = cd;
            wt[j] = j == 0 ? 1.0 : (dg > 0 && std::isfinite(dg) ? k_n * w / dg : 0.0);
        }
        g_max = g[kFine - 1];
        int j = 0;
        for (int i = 0; i < kN; ++i) {
            const double gi = g_max * i / (kN - 1);
            while (j < kFine - 2 && g[j + 1] < gi)
                ++j;
            const double span = g[j + 1] - g[j];
            const double t = span > 0 ? clamp((gi - g[j]) / span, 0.0, 1.0) : 0.0;
            sin_delta[i] = sn[j] + t * (sn[j + 1] - sn[j]);
            cos_delta[i] = c[j] + t * (c[j + 1] - c[j]);
            weight[i] = wt[j] + t * (wt[j + 1] - wt[j]);
        }
    }

    /// sin δ, cos δ and the weight at deflection g ≥ 0; false beyond g_max (no facet turns so far).
    bool lookup(double g, double& sin_d, double& cos_d, double& w) const {
        if (!(g < g_max)) return false;
        const double f = g / g_max * (kN - 1);
        const int i = std::min(int(f), kN - 2);
        const double t = f - i;
        sin_d = sin_delta[i] + t * (sin_delta[i + 1] - sin_delta[i]);
        cos_d = cos_delta[i] + t * (cos_delta[i + 1] - cos_delta[i]);
        w = weight[i] + t * (weight[i + 1] - weight[i]);
        return cos_d > 0 && w > 0;
    }
};

}  // namespace lamina1

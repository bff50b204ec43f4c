#include "models/tables/tir_table.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "models/tables/critical_cosine_axes.h"
#include "models/tables/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lamina {

namespace {
constexpr int kStrata = 32;  // per axis of the sampling square
constexpr double kCMin = 1e-4, kAlphaMin = 1e-5;
constexpr const char* kCodeVersion = "tir-v4";
constexpr int kSplit = 16;  // c nodes 0..kSplit cover [0, c_crit], the rest [c_crit, 1]

// The c axis is relative to the critical cosine of each η node and dense next to it on both
// sides (τ is a smoothed step there, of width ~α): node j ≤ kSplit sits at
// c_crit (1 − (1 − j/kSplit)²), node j ≥ kSplit at c_crit + (1 − c_crit)((j −
// kSplit)/(N−1−kSplit))².
double c_node(int j, double c_crit) {
    if (j <= kSplit) return std::max(kCMin, c_crit * (1 - sqr(1 - double(j) / kSplit)));
    return c_crit + (1 - c_crit) * sqr(double(j - kSplit) / (TirTable::kNc - 1 - kSplit));
}
/// Fractional node index of c for the η node whose critical cosine is c_crit.
double c_index(double c, double c_crit) {
    c = lamina1::table_axis(c, 0.0, 1.0);
    if (c >= c_crit)
        return kSplit + (TirTable::kNc - 1 - kSplit) * std::sqrt((c - c_crit) / (1 - c_crit));
    return kSplit * (1 - std::sqrt(1 - c / c_crit));
}
// α on a squared axis (dense at small α, where the step is sharp).
double alpha_node(int i) {
    return std::max(kAlphaMin, sqr(double(i) / (TirTable::kNalpha - 1)));
}
// η nodes uniform in the critical cosine c_crit = √(1 − η²) ∈ [0, √(1 − η_min²)]: c_crit, which
// places the step, moves fastest with η near 1.
double max_critical_cosine() {
    return critical_cosine(TirTable::kEtaMin);
}
double eta_node(int i) {
    const double cc = max_critical_cosine() * double(i) / (TirTable::kNeta - 1);
    return std::sqrt(1 - cc * cc);
}

std::vector<float> compute_tir() {
    using T = TirTable;
    std::vector<float> v(std::size_t(T::kNc) * T::kNalpha * T::kNeta);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < T::kNc; ++ic) {
        for (int ia = 0; ia < T::kNalpha; ++ia) {
            for (int ie = 0; ie < T::kNeta; ++ie) {
                const std::size_t index = (std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie;
                ParticleRng rng(0x7125, index, 0);
                int through = 0;
                for (int a = 0; a < kStrata; ++a)
                    for (int b = 0; b < kStrata; ++b) {
                        const double u1 = (a + rng.uniform_double()) / kStrata;
                        const double u2 = (b + rng.uniform_double()) / kStrata;
                        through += T::transmits(c_node(ic, critical_cosine(eta_node(ie))),
                                                alpha_node(ia), eta_node(ie), u1, u2);
                    }
                v[index] = float(double(through) / (kStrata * kStrata));
            }
        }
    }
    return v;
}
}  // namespace

bool TirTable::transmits(double c, double alpha, double eta, double u1, double u2) {
    // The interface seen from the denser side is the same point-symmetric microsurface, so the
    // arriving direction is written in the upper hemisphere with relative index eta.
    const Vec3d wi(safe_sqrt(1 - c * c), 0, std::max(c, kCMin));
    const Vec3d wm = GGX<double>{std::max(alpha, kAlphaMin)}.sample_visible_normal(wi, u1, u2);
    const auto wt = refract(wi, wm, eta);
    return wt && wt->z < 0;
}

double TirTable::direct_mc(double c, double alpha, double eta, std::uint64_t n,
                           std::uint64_t seed) {
    ParticleRng rng(seed, 0, 0);
    std::uint64_t through = 0;
    for (std::uint64_t i = 0; i < n; ++i) {
        const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
        through += transmits(c, alpha, eta, u1, u2);
    }
    return double(through) / double(n);
}

TirTable::TirTable() {
    const TableKey key{
        "tir",
        fmt::format("{} c{} a{} e{}:{} strata{} cmin{} amin{} seed7125", kCodeVersion, kNc, kNalpha,
                    kNeta, kEtaMin, kStrata, kCMin, kAlphaMin),
        {kNc, kNalpha, kNeta}};
    values_ = cached_table(key, compute_tir);
}

const TirTable& TirTable::get() {
    static const TirTable table;
    return table;
}

double TirTable::operator()(double c, double alpha, double eta) const {
    if (!(eta < 1)) return 1;  // η ≥ 1 (and NaN): no total internal reflection
    // Smooth interface: the exact step at the critical cosine (the table would blur it).
    if (alpha <= 0) return c > critical_cosine(eta) ? 1.0 : 0.0;
    const double fa = std::sqrt(lamina1::table_axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const double fe =
        lamina1::table_axis(critical_cosine(eta) / max_critical_cosine(), 0.0, 1.0) * (kNeta - 1);
    const int ia = std::min(int(fa), kNalpha - 2), ie = std::min(int(fe), kNeta - 2);
    const double ta = fa - ia, te = fe - ie;
    double sum = 0;
    for (int de = 0; de < 2; ++de) {
        // Each η node has its own c axis (relative to its critical cosine).
        const double fc = c_index(c, critical_cosine(eta_node(ie + de)));
        const int ic = std::min(int(fc), kNc - 2);
        const double tc = fc - ic;
        for (int dc = 0; dc < 2; ++dc)
            for (int da = 0; da < 2; ++da)
                sum += (de ? te : 1 - te) * (dc ? tc : 1 - tc) * (da ? ta : 1 - ta) *
                       values_[(std::size_t(ic + dc) * kNalpha + (ia + da)) * kNeta + ie + de];
    }
    return sum;
}

// ---- The lobe definitions (LobeFresnel, Lobe) ----

namespace {

constexpr int kLobeNr = 16;    // Gauss–Legendre nodes in u = √(1 − r) per piece
constexpr int kLobeNphi = 32;  // midpoint nodes in φ over the half disk (mirrored)
constexpr double kLobeCMin = 1e-4, kLobeAlphaMin = 1e-5;
constexpr const char* kLobeCodeVersion = "tir-lobe-v1";
constexpr int kLobeComponents = 2;  // LobeFresnel, Lobe

using L = LobeTirTable;

int component(TirDefinition definition) {
    return definition == TirDefinition::LobeFresnel ? 0 : 1;
}

const CriticalCosineAxes& lobe_axes() {
    static const CriticalCosineAxes a(L::kNbelow, L::kNc, L::kNalpha, L::kNeta, L::kLog2EtaMin,
                                      L::kLog2EtaMax, kLobeCMin, kLobeAlphaMin);
    return a;
}

/// The step limit of the Lobe definition on the side of μc a table piece holds (the lower piece
/// ends at μc from below).
double step(bool above) {
    return above ? 1.0 : 0.0;
}

/// Both lobe fractions at one point (α > 0, c ≥ kLobeCMin): the lobe of the incidence wi at
/// cosine c, D G1(wi) G1(wo)/(4 μi μo) μo dωo = D_wi(wm) G1(wo) dωm over the visible normals wm
/// (Heitz 2018), wo the reflection of wi about wm; the integrals of G1(wo) times 1 − F(μo; η),
/// times 1{μo > μc}, and alone (μo > 0 only), the rule split where μo crosses 0 and μc.
std::array<double, kLobeComponents> lobe_fractions(double c, double alpha, double eta, int n_r,
                                                   int n_phi) {
    const Vec3d wi(safe_sqrt(1 - c * c), 0, c);
    const GGX<double> ggx{alpha};
    const double mu_c = critical_cosine(eta);
    auto reflected = [&](const Vec3d& wm) { return 2 * dot(wi, wm) * wm - wi; };
    auto reflected_z = [&](const Vec3d& wm) { return reflected(wm).z; };
    const QuadratureRule q = gauss_legendre(n_r);
    const Vec3d sums = integrate_visible_split<Vec3d>(
        ggx, wi,
        [&](const Vec3d& wm) {
            const Vec3d wo = reflected(wm);
            if (!(wo.z > 0)) return Vec3d(0, 0, 0);
            const double g1 = ggx.G1(wo);
            return Vec3d(g1 * (1 - fresnel_dielectric(wo.z, eta)), wo.z > mu_c ? g1 : 0.0, g1);
        },
        q, n_phi, 1e-6, Crossing{reflected_z, 0.0}, Crossing{reflected_z, mu_c});
    return {sums.x / sums.z, sums.y / sums.z};
}

std::vector<float> compute_lobe() {
    const CriticalCosineAxes& a = lobe_axes();
    std::vector<float> v(a.count(kLobeComponents));
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < a.c_count(); ++ic)
        for (int ia = 0; ia < a.n_alpha; ++ia)
            for (int ie = 0; ie < a.n_eta; ++ie) {
                const double alpha = a.alpha_node(ia), eta = a.eta_node(ie);
                // Without total internal reflection the lower piece is the single cosine c_min:
                // computed once (ic = 0), copied after the loop.
                if (ic > 0 && a.below(ic) && critical_cosine(eta) == 0) continue;
                const double c = a.c_node(ic, eta);
                const auto f = lobe_fractions(c, alpha, eta, kLobeNr, kLobeNphi);
                const double w = CriticalCosineAxes::smooth_weight(alpha);
                v[a.index(ic, ia, ie, kLobeComponents, 0)] =
                    float(f[0] - w * L::smooth_limit(TirDefinition::LobeFresnel, c, eta));
                v[a.index(ic, ia, ie, kLobeComponents, 1)] = float(f[1] - w * step(!a.below(ic)));
            }
    for (int ic = 1; ic < a.n_below; ++ic)
        for (int ia = 0; ia < a.n_alpha; ++ia)
            for (int ie = 0; ie < a.n_eta; ++ie)
                if (critical_cosine(a.eta_node(ie)) == 0)
                    for (int k = 0; k < kLobeComponents; ++k)
                        v[a.index(ic, ia, ie, kLobeComponents, k)] =
                            v[a.index(0, ia, ie, kLobeComponents, k)];
    return v;
}

}  // namespace

double LobeTirTable::smooth_limit(TirDefinition definition, double c, double eta) {
    if (definition == TirDefinition::LobeFresnel) return 1 - fresnel_dielectric(c, eta);
    return step(c >= critical_cosine(eta));
}

double LobeTirTable::direct(TirDefinition definition, double c, double alpha, double eta, int n_r,
                            int n_phi) {
    c = clamp(c, 0.0, 1.0);
    if (alpha <= 0) return smooth_limit(definition, c, eta);
    return lobe_fractions(std::max(c, kLobeCMin), alpha, eta, n_r, n_phi)[component(definition)];
}

LobeTirTable::LobeTirTable() {
    const CriticalCosineAxes& a = lobe_axes();
    const TableKey key{"tir-lobe",
                       fmt::format("{} c{}+{} a{} e{}:{}:{} nr{} nphi{} cmin{} amin{}",
                                   kLobeCodeVersion, kNbelow, kNc, kNalpha, kNeta, kLog2EtaMin,
                                   kLog2EtaMax, kLobeNr, kLobeNphi, kLobeCMin, kLobeAlphaMin),
                       {std::uint32_t(a.c_count()), kNalpha, kNeta, kLobeComponents}};
    values_ = cached_table(key, compute_lobe);
}

const LobeTirTable& LobeTirTable::get() {
    static const LobeTirTable table;
    return table;
}

double LobeTirTable::operator()(TirDefinition definition, double c, double alpha,
                                double eta) const {
    c = clamp(c, 0.0, 1.0);
    if (alpha <= 0) return smooth_limit(definition, c, eta);
    if (definition == TirDefinition::Lobe && !(eta < 1)) return 1;  // no total reflection
    eta = clamp(eta, std::exp2(kLog2EtaMin), std::exp2(kLog2EtaMax));
    // The limit on the query's side of μc: the lookup's piece (c < μc: the lower one).
    const double limit = definition == TirDefinition::LobeFresnel
                             ? smooth_limit(definition, c, eta)
                             : step(!(c < critical_cosine(eta)));
    return clamp(lobe_axes().interpolate(values_.data(), kLobeComponents, component(definition), c,
                                         alpha, eta, limit),
                 0.0, 1.0);
}

double tir_fraction(TirDefinition definition, double c, double alpha, double eta) {
    if (definition == TirDefinition::Microfacet) return TirTable::get()(c, alpha, eta);
    return LobeTirTable::get()(definition, c, alpha, eta);
}

void tir_table_prepare(TirDefinition definition) {
    if (definition == TirDefinition::Microfacet)
        TirTable::get();
    else
        LobeTirTable::get();
}

}  // namespace lamina

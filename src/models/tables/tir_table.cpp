#include "models/tables/tir_table.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/tables/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {
constexpr int kStrata = 32;  // per axis of the sampling square
constexpr double kCMin = 1e-4, kAlphaMin = 1e-5;
constexpr const char* kCodeVersion = "tir-v3";
constexpr int kSplit = 16;  // c nodes 0..kSplit cover [0, c_crit], the rest [c_crit, 1]

/// x limited to [lo, hi] for a table coordinate, NaN going to lo (an index computed from NaN would
/// be undefined behaviour and read outside the table).
double axis(double x, double lo, double hi) {
    return x >= lo ? (x <= hi ? x : hi) : lo;
}

/// Critical cosine of relative index η < 1: below it a smooth interface reflects totally.
double critical_cosine(double eta) {
    return std::sqrt(std::max(0.0, 1 - eta * eta));
}

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
    c = axis(c, 0.0, 1.0);
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
    const double fa = std::sqrt(axis(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const double fe = axis(critical_cosine(eta) / max_critical_cosine(), 0.0, 1.0) * (kNeta - 1);
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

}  // namespace lamina

#include "models/tir_table.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace lamina {

namespace {
constexpr int kStrata = 32;  // per axis of the sampling square
constexpr double kCMin = 1e-4, kAlphaMin = 1e-5;
constexpr const char* kCodeVersion = "tir-v1";

double c_node(int i) {
    return std::max(kCMin, double(i) / (TirTable::kNc - 1));
}
double alpha_node(int i) {
    return std::max(kAlphaMin, double(i) / (TirTable::kNalpha - 1));
}
double eta_node(int i) {
    return TirTable::kEtaMin + (1 - TirTable::kEtaMin) * double(i) / (TirTable::kNeta - 1);
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
                        through += T::transmits(c_node(ic), alpha_node(ia), eta_node(ie), u1, u2);
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
    if (eta >= 1) return 1;
    // Smooth interface: the exact step at the critical cosine (the table would blur it).
    if (alpha <= 0) return c > std::sqrt(1 - eta * eta) ? 1.0 : 0.0;
    const double fc = clamp(c, 0.0, 1.0) * (kNc - 1);
    const double fa = clamp(alpha, 0.0, 1.0) * (kNalpha - 1);
    const double fe = (clamp(eta, kEtaMin, 1.0) - kEtaMin) / (1 - kEtaMin) * (kNeta - 1);
    const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2),
              ie = std::min(int(fe), kNeta - 2);
    const double tc = fc - ic, ta = fa - ia, te = fe - ie;
    double sum = 0;
    for (int dc = 0; dc < 2; ++dc)
        for (int da = 0; da < 2; ++da) {
            const float* row =
                values_.data() + (std::size_t(ic + dc) * kNalpha + (ia + da)) * kNeta + ie;
            sum += (dc ? tc : 1 - tc) * (da ? ta : 1 - ta) * ((1 - te) * row[0] + te * row[1]);
        }
    return sum;
}

}  // namespace lamina

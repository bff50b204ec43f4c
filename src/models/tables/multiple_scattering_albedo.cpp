#include "models/tables/multiple_scattering_albedo.h"

#include "core/math.h"
#include "core/rng.h"
#include "models/tables/coat_transmittance.h"
#include "models/tables/fgd_table.h"
#include "models/tables/table_cache.h"
#include "physics/microsurface_walk.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

namespace {

using Table = MultipleScatteringAlbedo;

constexpr const char* kCodeVersion = "ms-albedo-v2";
constexpr std::uint64_t kSeed = 0x6d73616c62656431ull;  // fixed: the table is deterministic
constexpr int kMaxOrder = 100;                          // the goniophotometer's facet cap

// The axes, the layout and the lookups are the table's format (include/lamina1/table_lookups.h,
// MultipleScatteringFormat), which lamina-1's header reads too.
using Format = lamina1::MultipleScatteringFormat;
double mu_node(int i) {
    return Format::mu_node(i);
}
double alpha_node(int i) {
    return Format::alpha_node(i);
}
double eta_node(int i) {
    return Format::eta_node(i);
}
Vec3d incident(double mu) {
    mu = clamp(mu, Table::kMuMin, 1.0);
    return {safe_sqrt(1 - mu * mu), 0, mu};
}

std::size_t dielectric_index(int im, int ia, int ie) {
    return Format::dielectric_index(im, ia, ie);
}
std::size_t conductor_index(int im, int ia) {
    return Format::conductor_index(im, ia);
}

}  // namespace

Table::Dielectric Table::walk_dielectric(double mu, double alpha, double eta, int walks,
                                         unsigned stream) {
    Dielectric out;
    if (alpha <= 0 || walks <= 0) return out;
    const GGX<double> ggx{alpha};
    const Vec3d wi = incident(mu);
    std::uint64_t reflected = 0, transmitted = 0;
    ParticleRng rng(kSeed, stream, 0);  // one generator per node: its walks in sequence
    auto uniform = [&] { return rng.uniform_double(); };
    for (int n = 0; n < walks; ++n) {
        const auto exit = walk_rough_dielectric(ggx, eta, wi, uniform, kMaxOrder);
        if (!exit || !exit->escaped || exit->order < 2) continue;
        (exit->wo.z > 0 ? reflected : transmitted) += 1;
    }
    out.reflected = double(reflected) / walks;
    out.transmitted = double(transmitted) / walks;
    return out;
}

double Table::walk_conductor(double mu, double alpha, int walks, unsigned stream) {
    if (alpha <= 0 || walks <= 0) return 0;
    const GGX<double> ggx{alpha};
    const Vec3d wi = incident(mu);
    auto white = [](double) { return Rgbd(1.0); };
    std::uint64_t later = 0;
    ParticleRng rng(kSeed, stream, 0);
    auto uniform = [&] { return rng.uniform_double(); };
    for (int n = 0; n < walks; ++n) {
        const auto exit = walk_rough_conductor(ggx, white, wi, uniform, kMaxOrder);
        if (exit && exit->escaped && exit->order >= 2) ++later;
    }
    return double(later) / walks;
}

MultipleScatteringAlbedo::MultipleScatteringAlbedo() {
    const TableKey key{"ms-albedo",
                       fmt::format("{} mu{}:{} a{} e{}:{}:{} walks{}:{} order{} seed{}",
                                   kCodeVersion, kNmu, kMuMin, kNalpha, kNeta, kLog2EtaMin,
                                   kLog2EtaMax, kWalksSplit, kWalksConductor, kMaxOrder, kSeed),
                       {std::uint32_t(kNmu * kNalpha * kNeta + kNmu * kNalpha)}};
    values_ = cached_table(key, [] {
        std::vector<float> v(std::size_t(kNmu) * kNalpha * kNeta + kNmu * kNalpha);
        // One stream per node: each node's walks are the same whatever the thread count.
#pragma omp parallel for schedule(dynamic) collapse(2)
        for (int im = 0; im < kNmu; ++im)
            for (int ia = 0; ia < kNalpha; ++ia) {
                for (int ie = 0; ie < kNeta; ++ie) {
                    const unsigned stream = unsigned(dielectric_index(im, ia, ie));
                    const Dielectric d = walk_dielectric(mu_node(im), alpha_node(ia), eta_node(ie),
                                                         kWalksSplit, stream);
                    const double total = d.reflected + d.transmitted;
                    v[dielectric_index(im, ia, ie)] = float(total > 0 ? d.reflected / total : 0);
                }
                v[conductor_index(im, ia)] =
                    float(walk_conductor(mu_node(im), alpha_node(ia), kWalksConductor,
                                         unsigned(conductor_index(im, ia))));
            }
        return v;
    });
}

const MultipleScatteringAlbedo& MultipleScatteringAlbedo::get() {
    static const MultipleScatteringAlbedo table;
    return table;
}

Table::Dielectric MultipleScatteringAlbedo::dielectric(double mu, double alpha, double eta) const {
    if (!(alpha > 0) || !(eta > 0)) return {};
    // What single scattering loses, from its own tables (the walk's orders ≥ 2 carry exactly it).
    return Format::dielectric(
        values_.data(), mu, alpha, eta, FgdTable::get()(mu, alpha, eta, 0.0),
        CoatTransmittanceTable::get(TransmissionMasking::Smith)(mu, alpha, eta));
}

double MultipleScatteringAlbedo::conductor(double mu, double alpha) const {
    return Format::conductor(values_.data(), mu, alpha);
}

}  // namespace lamina

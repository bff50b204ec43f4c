#include "models/production/uncorrelated_albedo.h"

#include "models/production/ggx_albedo.h"

#include "core/check.h"
#include "core/math.h"
#include "layers/data_files.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

namespace lamina {

namespace {

using Grid = OpenPbrBsdfEnergyGrid;

/// E over the visible normals of wi: ∫ D_wi(h) F(wi·h) G1(wo) dh (Heitz 2018).
template <typename Fresnel>
double albedo(double mu, double alpha, Fresnel&& fresnel, int n_r, int n_phi) {
    return reflection_over_visible_normals(
        mu, alpha,
        [&](const GGX<double>& ggx, const Vec3d&, const Vec3d& wo, double cos_h) {
            return fresnel(cos_h) * ggx.G1(wo);
        },
        n_r, n_phi);
}

}  // namespace

double uncorrelated_ggx_albedo(double mu, double alpha, double eta, int n_r, int n_phi) {
    auto fresnel = [eta](double c) { return eta == 1 ? 0.0 : fresnel_dielectric(c, eta); };
    if (alpha <= 0) return fresnel(clamp(mu, 0.0, 1.0));
    const bool tir = eta < 1;
    return albedo(mu, alpha, fresnel, n_r > 0 ? n_r : (tir ? 96 : 24),
                  n_phi > 0 ? n_phi : (tir ? 400 : 48));
}

double uncorrelated_ggx_albedo_white(double mu, double alpha, int n_r, int n_phi) {
    if (alpha <= 0) return 1;
    return albedo(
        mu, alpha, [](double) { return 1.0; }, n_r > 0 ? n_r : 24, n_phi > 0 ? n_phi : 48);
}

// --- openpbr-bsdf's grid ----------------------------------------------------------------------
// The axes as openpbr-bsdf's openpbr_microfacet_multiple_scattering_data.h reads them: the η
// index runs 16 → 31 over η ∈ [1, 2.5] and 15 → 0 over 1/η ∈ [1, 2.5]; r = √α and μ are uniform
// over the 32 nodes. Indices are clamped to [0, 31]; past η = 2.5 (or below 1/2.5) the complement
// read at the end node is scaled by 1 − (F0(η) − F0(2.5))/(1 − F0(2.5)).

double Grid::eta_index(double eta) {
    constexpr int kHalf = kN / 2;
    const double index = eta < 1 ? (kHalf - 1) - (1 / eta - 1) / (kEtaMax - 1) * (kHalf - 1)
                                 : kHalf + (eta - 1) / (kEtaMax - 1) * (kHalf - 1);
    return clamp(index, 0.0, double(kN - 1));
}
double Grid::alpha_index(double alpha) {
    return clamp(std::sqrt(std::max(alpha, 0.0)) * (kN - 1), 0.0, double(kN - 1));
}
double Grid::mu_index(double mu) {
    return clamp(mu * (kN - 1), 0.0, double(kN - 1));
}
double Grid::eta_node(int i) {
    constexpr int kHalf = kN / 2;
    if (i >= kHalf) return 1 + (kEtaMax - 1) * (i - kHalf) / (kHalf - 1);
    return 1 / (1 + (kEtaMax - 1) * (kHalf - 1 - i) / (kHalf - 1));
}
double Grid::alpha_node(int j) {
    return sqr(double(j) / (kN - 1));
}

namespace {
/// The lower node of a fractional index and the weight of the upper one (the upper node is the
/// lower one at the end of the axis).
std::pair<int, double> bracket(double index) {
    const int i0 = std::min(int(std::floor(index)), Grid::kN - 1);
    return {i0, index - i0};
}
int upper(int i0) {
    return std::min(i0 + 1, Grid::kN - 1);
}
double f0_of(double eta) {
    return fresnel_dielectric_normal(eta);
}
}  // namespace

namespace {
/// openpbr-bsdf's tables of 1 − E (data/production/README.md): the dielectric lobe's
/// [η][α][μ], the white lobe's [α][μ] and its average's [α], each node unorm16 / 65535 as
/// openpbr-bsdf decodes it.
struct ShippedTables {
    std::vector<double> coat, white, white_average;
    ShippedTables()
        : coat(read("production/openpbr_bsdf_coat_energy_complement.csv", 2)),
          white(read("production/openpbr_bsdf_white_energy_complement.csv", 1)),
          white_average(read("production/openpbr_bsdf_white_average_energy_complement.csv", 1)) {
        LAMINA_CHECK(coat.size() == std::size_t(Grid::kN * Grid::kN * Grid::kN) &&
                     white.size() == std::size_t(Grid::kN * Grid::kN) &&
                     white_average.size() == std::size_t(Grid::kN));
    }
    /// The values of every row after its `keys` index columns, rows in file order.
    static std::vector<double> read(std::string_view path, std::size_t keys) {
        std::vector<double> out;
        for (const auto& row : data_file_rows(path))
            for (std::size_t c = keys; c < row.size(); ++c)
                out.push_back(std::stoi(row[c]) / 65535.0);
        return out;
    }
};
const ShippedTables& shipped() {
    static const ShippedTables tables;
    return tables;
}
}  // namespace

Grid Grid::dielectric(double eta, double alpha) {
    Grid g;
    const auto [ie, te] = bracket(eta_index(eta));
    const auto [ja, ta] = bracket(alpha_index(alpha));
    g.t_eta_ = te;
    g.t_alpha_ = ta;
    const int etas[2] = {ie, upper(ie)}, alphas[2] = {ja, upper(ja)};
    for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
            for (int k = 0; k < kN; ++k)
                g.complement_[(a * 2 + b) * kN + k] =
                    shipped().coat[std::size_t((etas[a] * kN + alphas[b]) * kN + k)];
    if (eta > kEtaMax || eta < 1 / kEtaMax) {
        const double f0_max = f0_of(kEtaMax);
        g.extrapolation_ = 1 - (f0_of(eta) - f0_max) / (1 - f0_max);
    }
    return g;
}

Grid Grid::white(double alpha) {
    Grid g;
    const auto [ja, ta] = bracket(alpha_index(alpha));
    g.t_alpha_ = ta;
    const int alphas[2] = {ja, upper(ja)};
    for (int b = 0; b < 2; ++b) {
        for (int k = 0; k < kN; ++k) {
            // Both η slots hold the white lobe: the η weight is 0.
            g.complement_[b * kN + k] = g.complement_[(2 + b) * kN + k] =
                shipped().white[std::size_t(alphas[b] * kN + k)];
        }
        g.average_complement_[b] = shipped().white_average[std::size_t(alphas[b])];
    }
    return g;
}

double Grid::complement(double mu) const {
    const auto [k, tk] = bracket(mu_index(mu));
    const int k1 = upper(k);
    auto at = [&](int a, int b) {
        const double* row = &complement_[(a * 2 + b) * kN];
        return mix(row[k], row[k1], tk);
    };
    const double value =
        mix(mix(at(0, 0), at(0, 1), t_alpha_), mix(at(1, 0), at(1, 1), t_alpha_), t_eta_);
    return extrapolation_ * value;
}

double Grid::average_complement() const {
    return mix(average_complement_[0], average_complement_[1], t_alpha_);
}

}  // namespace lamina

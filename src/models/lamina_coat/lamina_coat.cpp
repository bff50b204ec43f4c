#include "models/lamina_coat/lamina_coat.h"

#include "core/math.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace lamina {

namespace {

// docs/lamina-coat/tables.csv, row by row (scripts/lamina_coat_fit.py tables): value/65535.
constexpr std::uint16_t kTable[][32] = {
#include "models/lamina_coat/lamina_coat_table.inc"
};
constexpr int kRowAlbedo = 0, kRowWhite = 512, kRowAverage = 544, kRowWhiteAverage = 560,
              kRowInternal = 561;
constexpr double kEtaFirst = 1.1, kEtaStep = 0.1, kEtaLast = 2.6;
static_assert(sizeof(kTable) / sizeof(kTable[0]) == 577, "577 rows of 32");

double texel(int row, int column) {
    return kTable[row][column] * (1.0 / 65535.0);
}

/// x ∈ [0, 1] on 32 nodes: the lower node and the weight of the upper one.
struct Node {
    int i;
    double w;
};
Node node(double x, int nodes) {
    const double s = clamp(x, 0.0, 1.0) * (nodes - 1);
    const int i = std::min(int(s), nodes - 2);
    return {i, s - i};
}

/// Bilinear along a row (column x) between rows row and row + stride (weight y).
double bilinear(int row, int stride, Node x, Node y) {
    const auto along = [&](int r) {
        return texel(r, x.i) + x.w * (texel(r, x.i + 1) - texel(r, x.i));
    };
    const double lo = along(row), hi = along(row + stride);
    return lo + y.w * (hi - lo);
}

Node eta_node(double eta) {
    return node((eta - kEtaFirst) / (kEtaLast - kEtaFirst), 16);
}

}  // namespace

LaminaCoatFit lamina_coat_fit() {
    // scripts/lamina_coat_fit.py fit on the study's fitting configurations (docs/lamina-coat.md).
    return {0.0, 0.125, 0.1};
}

double lamina_coat_albedo(double mu, double r, double eta) {
    const Node x = node(mu, 32), y = node(r, 32), z = eta_node(eta);
    const double lo = bilinear(kRowAlbedo + z.i * 32 + y.i, 1, x, y);
    const double hi = bilinear(kRowAlbedo + (z.i + 1) * 32 + y.i, 1, x, y);
    return lo + z.w * (hi - lo);
}

double lamina_coat_white_albedo(double mu, double r) {
    const Node y = node(r, 32);
    return bilinear(kRowWhite + y.i, 1, node(mu, 32), y);
}

double lamina_coat_average_albedo(double r, double eta) {
    const Node z = eta_node(eta);
    return bilinear(kRowAverage + z.i, 1, node(r, 32), z);
}

double lamina_coat_white_average_albedo(double r) {
    return bilinear(kRowWhiteAverage, 0, node(r, 32), Node{0, 0.0});
}

double lamina_coat_internal_absorption(double tau, double eta) {
    const Node z = eta_node(eta);
    return bilinear(kRowInternal + z.i, 1, node(tau / (1 + tau), 32), z);
}

LaminaCoatPrepared lamina_coat_prepare(const LaminaCoatMaterial& m) {
    const LaminaCoatFit fit = lamina_coat_fit();
    LaminaCoatPrepared p;
    p.m = m;
    p.r = std::sqrt(m.alpha_coat);
    const double white_average = lamina_coat_white_average_albedo(p.r);
    if (white_average < 1 - 1e-6) p.white_norm = fit.grazing / (kPi<double> * (1 - white_average));
    p.tau_path = m.tau * (1 + fit.tint_path * p.r);
    if (m.conductor) {
        p.alpha_base = std::sqrt(sqr(m.alpha_base) + fit.roughening * sqr(m.alpha_coat));
    } else {
        // What the coat returns to the base from inside: 1 − (1 − Ē)/η² of light arriving
        // evenly (by reciprocity with what it transmits from outside), under absorption.
        const double average =
            lamina_coat_average_albedo(p.r, m.eta) + fit.grazing * (1 - white_average);
        const double K0 = 1 - (1 - average) / sqr(m.eta);
        for (int c = 0; c < 3; ++c) {
            const double K = K0 * lamina_coat_internal_absorption(p.tau_path[c], m.eta);
            p.lambert[c] = m.albedo[c] / (kPi<double> * (1 - m.albedo[c] * K));
        }
    }
    return p;
}

double lamina_coat_transmittance(const LaminaCoatPrepared& p, double mu) {
    const double reflected = lamina_coat_albedo(mu, p.r, p.m.eta) +
                             lamina_coat_fit().grazing * (1 - lamina_coat_white_albedo(mu, p.r));
    return std::max(0.0, 1 - reflected);
}

Rgbd lamina_coat_eval(const LaminaCoatPrepared& p, const Vec3d& wi, const Vec3d& wo) {
    if (wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
    const double eta = p.m.eta;
    double coat = 0;
    if (p.m.alpha_coat > 0) {
        const GGX<double> ggx{p.m.alpha_coat};
        const Vec3d h = normalize(wi + wo);
        coat = fresnel_dielectric(dot(wi, h), eta) * ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
    }
    coat += p.white_norm * (1 - lamina_coat_white_albedo(wi.z, p.r)) *
            (1 - lamina_coat_white_albedo(wo.z, p.r));
    // The refracted directions (Snell at the mean surface) and the paths' transmittance.
    const auto refracted = [eta](const Vec3d& w) {
        return Vec3d{w.x / eta, w.y / eta, std::sqrt(1 - (1 - w.z * w.z) / (eta * eta))};
    };
    const Vec3d wi_in = refracted(wi), wo_in = refracted(wo);
    const double t = lamina_coat_transmittance(p, wi.z) * lamina_coat_transmittance(p, wo.z);
    const Rgbd tint = exp_rgb(p.tau_path * -(1 / wi_in.z + 1 / wo_in.z));
    Rgbd base = p.lambert;
    if (p.m.conductor) {
        if (p.alpha_base <= 0) return Rgbd(coat);  // a smooth base: a delta lobe
        const GGX<double> ggx{p.alpha_base};
        const Vec3d h = normalize(wi_in + wo_in);
        const double lobe = ggx.D(h) * ggx.G2(wi_in, wo_in) / (4 * wi_in.z * wo_in.z);
        const double cos_h = dot(wi_in, h);
        for (int c = 0; c < 3; ++c)
            base[c] = fresnel_conductor(cos_h, p.m.base_eta[c], p.m.base_k[c]) * lobe;
    }
    return Rgbd(coat) + base * tint * (t / (eta * eta));
}

namespace {

class LaminaCoat final : public Model {
  public:
    explicit LaminaCoat(const Stack& stack) {
        CoatedStack coat;
        std::string why;
        if (!coated_stack(stack, coat, why)) {
            support_.reason = fmt::format("lamina-coat {}", why);
            return;
        }
        if (coat.tau_s.max() > 0) {
            support_.reason = "lamina-coat has no scattering coat (a clear or absorbing one)";
            return;
        }
        if (coat.base_type == InterfaceType::Dielectric) {
            support_.reason =
                "lamina-coat has an opaque base (Lambertian or conductor): a dielectric base "
                "with light passing below it (a slab) has no counterpart";
            return;
        }
        if (!(coat.eta0 >= kEtaFirst && coat.eta0 <= kEtaLast)) {
            support_.reason = fmt::format(
                "lamina-coat's tables hold coat indices 1.1 to 2.6; this coat's is {}", coat.eta0);
            return;
        }
        support_.brdf = true;
        LaminaCoatMaterial m;
        m.eta = coat.eta0;
        m.alpha_coat = coat.alpha0;
        m.tau = coat.tau_a;
        m.conductor = coat.base_type == InterfaceType::Conductor;
        m.albedo = coat.albedo;
        m.base_eta = coat.base_eta;
        m.base_k = coat.base_k;
        m.alpha_base = coat.base_alpha;
        p_ = lamina_coat_prepare(m);
    }

    std::string name() const override { return "lamina-coat"; }
    Support support() const override { return support_; }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf) return Rgbd(0.0);
        return lamina_coat_eval(p_, wi, wo);
    }

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> lobes;
        if (!support_.brdf || wi.z <= 0) return lobes;
        const Vec3d wr = mirror_direction(wi);
        if (p_.m.alpha_coat == 0) lobes.push_back({wr, Rgbd(fresnel_dielectric(wi.z, p_.m.eta))});
        if (p_.m.conductor && p_.alpha_base == 0) {
            // The base's mirror through the coat: t(μi)² e^(−2 s τ/μt) F(μt); the radiance
            // compression 1/η² and the solid angle's η² cancel for a delta lobe.
            const double mu_t = std::sqrt(1 - (1 - wi.z * wi.z) / sqr(p_.m.eta));
            const Rgbd tint = exp_rgb(p_.tau_path * (-2 / mu_t));
            Rgbd F;
            for (int c = 0; c < 3; ++c)
                F[c] = fresnel_conductor(mu_t, p_.m.base_eta[c], p_.m.base_k[c]);
            lobes.push_back({wr, F * tint * sqr(lamina_coat_transmittance(p_, wi.z))});
        }
        return lobes;
    }

  private:
    Support support_;
    LaminaCoatPrepared p_;
};

}  // namespace

std::vector<OptionSpec> lamina_coat_options() {
    return {};
}

std::unique_ptr<Model> make_lamina_coat(const Stack& stack, const ModelOptions&) {
    return std::make_unique<LaminaCoat>(stack);
}

}  // namespace lamina

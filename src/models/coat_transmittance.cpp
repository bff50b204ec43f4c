#include "models/coat_transmittance.h"

#include "core/math.h"
#include "models/quadrature.h"
#include "models/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/smith_masking.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

namespace {

constexpr int kTableNr = 32;    // Gauss–Legendre nodes in r on Heitz's disk
constexpr int kTableNphi = 32;  // midpoint nodes in φ over the half disk (mirrored)
constexpr double kCMin = 1e-4;
constexpr double kAlphaMin = 1e-5;
constexpr const char* kCodeVersion = "coat-t-v3";

using T = CoatTransmittanceTable;

double c_node(int i) {
    return std::max(kCMin, sqr(double(i) / (T::kNc - 1)));
}
double alpha_node(int i) {
    return std::max(kAlphaMin, sqr(double(i) / (T::kNalpha - 1)));
}
double eta_node(int i) {
    return std::exp2(T::kLog2EtaMin + (T::kLog2EtaMax - T::kLog2EtaMin) * i / (T::kNeta - 1));
}
double smooth_weight(double alpha) {
    return std::exp(-alpha / 0.03);
}

double integrate(double c, double alpha, double eta, RefractionMasking masking, int n_r,
                 int n_phi) {
    if (alpha <= 0) return 1 - fresnel_dielectric(c, eta);
    const Vec3d wi(safe_sqrt(1 - c * c), 0, c);
    const GGX<double> ggx{alpha};
    const double lambda_i = ggx.lambda(wi);
    const QuadratureRule qr = gauss_legendre(n_r);
    double sum = 0;
    for (int a = 0; a < n_r; ++a) {
        const double r = qr.x[a];
        const double w_r = qr.w[a] * 2 * r;  // ∫ g du1 with u1 = r²
        for (int b = 0; b < n_phi; ++b) {
            // φ ∈ [−π/2, π/2): the half disk p1 ≥ 0; its mirror image p1 → −p1 (the normal's
            // y → −y) gives the same integrand, wi lying in the xz plane.
            const double u2 = 0.5 * (b + 0.5) / n_phi - 0.25;
            const Vec3d wm = ggx.sample_visible_normal(wi, r * r, u2);
            const FresnelDielectric<double> fr = fresnel_dielectric_full(dot(wi, wm), eta);
            if (fr.reflectance >= 1) continue;  // total internal reflection
            const auto wt = refract(wi, wm, eta);
            if (!wt || wt->z >= 0) continue;  // masked: the single-scattering surface loses it
            const double g = refraction_escape(masking, lambda_i, ggx.lambda(*wt));
            sum += w_r / n_phi * (1 - fr.reflectance) * g;
        }
    }
    return sum;
}

std::vector<float> compute(RefractionMasking masking) {
    std::vector<float> v(std::size_t(T::kNc) * T::kNalpha * T::kNeta);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < T::kNc; ++ic)
        for (int ia = 0; ia < T::kNalpha; ++ia)
            for (int ie = 0; ie < T::kNeta; ++ie) {
                const double c = c_node(ic), alpha = alpha_node(ia), eta = eta_node(ie);
                const double t = integrate(c, alpha, eta, masking, kTableNr, kTableNphi);
                v[(std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie] =
                    float(t - smooth_weight(alpha) * (1 - fresnel_dielectric(c, eta)));
            }
    return v;
}

const char* masking_name(RefractionMasking m) {
    return m == RefractionMasking::SmithBeta ? "smith-beta" : "walter";
}

}  // namespace

double refraction_escape(RefractionMasking masking, double lambda_i, double lambda_t) {
    // The escape fractions of physics/smith_masking.h, from the Smith roots r = 1 + 2Λ.
    const double r_i = 1 + 2 * lambda_i, r_t = 1 + 2 * lambda_t;
    if (masking == RefractionMasking::Walter) return smith_reflection_escape(r_i, r_t);
    return smith_refraction_escape(r_i, r_t);
}

double CoatTransmittanceTable::direct(double c, double alpha, double eta, RefractionMasking masking,
                                      int n_r, int n_phi) {
    return integrate(std::max(c, kCMin), alpha, eta, masking, n_r, n_phi);
}

CoatTransmittanceTable::CoatTransmittanceTable(RefractionMasking masking) {
    const TableKey key{
        "coat-t",
        fmt::format("{} {} c{} a{} e{}:{}:{} nr{} nphi{} cmin{} amin{}", kCodeVersion,
                    masking_name(masking), kNc, kNalpha, kNeta, kLog2EtaMin, kLog2EtaMax, kTableNr,
                    kTableNphi, kCMin, kAlphaMin),
        {kNc, kNalpha, kNeta}};
    values_ = cached_table(key, [&] { return compute(masking); });
}

const CoatTransmittanceTable& CoatTransmittanceTable::get(RefractionMasking masking) {
    // Thread-safe initialization (C++11 magic statics), one per masking.
    if (masking == RefractionMasking::Walter) {
        static const CoatTransmittanceTable walter(RefractionMasking::Walter);
        return walter;
    }
    static const CoatTransmittanceTable beta(RefractionMasking::SmithBeta);
    return beta;
}

double CoatTransmittanceTable::operator()(double c, double alpha, double eta) const {
    c = clamp(c, 0.0, 1.0);
    if (alpha <= 0) return 1 - fresnel_dielectric(c, eta);
    const double fc = std::sqrt(c) * (kNc - 1);
    const double fa = std::sqrt(clamp(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const double fe = (clamp(std::log2(eta), kLog2EtaMin, kLog2EtaMax) - kLog2EtaMin) /
                      (kLog2EtaMax - kLog2EtaMin) * (kNeta - 1);
    const int ic = std::min(int(fc), kNc - 2), ia = std::min(int(fa), kNalpha - 2),
              ie = std::min(int(fe), kNeta - 2);
    const double tc = fc - ic, ta = fa - ia, te = fe - ie;
    double sum = 0;
    for (int dc = 0; dc < 2; ++dc)
        for (int da = 0; da < 2; ++da) {
            const double w = (dc ? tc : 1 - tc) * (da ? ta : 1 - ta);
            const float* row =
                values_.data() + ((std::size_t(ic + dc) * kNalpha + ia + da) * kNeta + ie);
            sum += w * ((1 - te) * row[0] + te * row[1]);
        }
    if (alpha < 0.5) sum += smooth_weight(alpha) * (1 - fresnel_dielectric(c, eta));
    return clamp(sum, 0.0, 1.0);
}

}  // namespace lamina

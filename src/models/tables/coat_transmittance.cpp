#include "models/tables/coat_transmittance.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "models/tables/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/smith_masking.h"

#include <fmt/format.h>

#include <array>
#include <cmath>

namespace lamina {

namespace {

constexpr int kTableNr = 16;    // Gauss–Legendre nodes in u = √(1 − r) per piece
constexpr int kTableNphi = 32;  // midpoint nodes in φ over the half disk (mirrored)
constexpr double kCMin = 1e-4;
constexpr double kAlphaMin = 1e-5;
constexpr const char* kCodeVersion = "coat-t-v6";

using T = CoatTransmittanceTable;

/// The cosine of total internal reflection (η < 1), 0 where there is none.
double critical_cosine(double eta) {
    return eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;
}
/// The cosine of node i of the c axis at η: below the critical cosine μc (i < kNbelow)
/// c = μc (1 − y²), y = 1 − i/(kNbelow − 1); above it c = μc + (1 − μc) x², x = j/(kNc − 1).
double c_node(int i, double eta) {
    const double mu_c = critical_cosine(eta);
    double c;
    if (i < T::kNbelow) {
        const double y = 1 - double(i) / (T::kNbelow - 1);
        c = mu_c * (1 - y * y);
    } else {
        const double x = double(i - T::kNbelow) / (T::kNc - 1);
        c = mu_c + (1 - mu_c) * x * x;
    }
    return std::max(kCMin, c);
}
double alpha_node(int i) {
    return std::max(kAlphaMin, sqr(double(i) / (T::kNalpha - 1)));
}
// The η axis in two halves meeting at η = 1 (node kEtaOne): above, uniform in log2 η up to
// kLog2EtaMax; below, uniform in the critical cosine μc(η) = √(1 − η²) up to μc(2^kLog2EtaMin),
// which places the step of total internal reflection and moves fastest with η near 1 (uniform in
// log2 η, T at a fixed fraction of the way past the step went from its value at μc(0.933) to
// its grazing value at μc(1) = 0 within one interval: 0.27 off at η = 0.95).
constexpr int kEtaOne = (T::kNeta - 1) / 2;
double max_critical_cosine() {
    return critical_cosine(std::exp2(T::kLog2EtaMin));
}
double eta_node(int i) {
    if (i >= kEtaOne) return std::exp2(T::kLog2EtaMax * (i - kEtaOne) / (T::kNeta - 1 - kEtaOne));
    const double mu_c = max_critical_cosine() * (kEtaOne - i) / kEtaOne;
    return std::sqrt(1 - mu_c * mu_c);
}
/// The fractional node index of η (clamped to the axis).
double eta_index(double eta) {
    if (eta >= 1)
        return kEtaOne + std::min(std::log2(eta) / T::kLog2EtaMax, 1.0) * (T::kNeta - 1 - kEtaOne);
    return kEtaOne * (1 - std::min(critical_cosine(eta) / max_critical_cosine(), 1.0));
}
double smooth_weight(double alpha) {
    return std::exp(-alpha / 0.03);
}

/// T by the visible normals of wi, n_r Gauss–Legendre nodes in u = √(1 − r) on each side of the
/// facets' total internal reflection (η < 1: w·wm below the critical cosine; the rule splits the
/// radius there per φ node, integrate_visible_split; unsplit, 32 nodes in r across that step at
/// normal incidence were 1.4e-2 low at α = 0.3) × n_phi midpoint nodes in φ over the half disk
/// p1 ≥ 0, whose mirror image (the normal's y → −y) gives the same integrand, wi lying in the xz
/// plane.
double integrate(double c, double alpha, double eta, TransmissionMasking masking, int n_r,
                 int n_phi) {
    if (alpha <= 0) return 1 - fresnel_dielectric(c, eta);
    const Vec3d wi(safe_sqrt(1 - c * c), 0, c);
    const GGX<double> ggx{alpha};
    const double lambda_i = ggx.lambda(wi);
    const QuadratureRule qr = gauss_legendre(n_r);
    return integrate_visible_split<double>(
        ggx, wi, critical_cosine(eta), [&](const Vec3d& wm) { return dot(wi, wm); },
        [&](const Vec3d& wm) {
            const FresnelDielectric<double> fr = fresnel_dielectric_full(dot(wi, wm), eta);
            if (fr.reflectance >= 1) return 0.0;  // total internal reflection
            const auto wt = refract(wi, wm, eta);
            if (!wt || wt->z >= 0) return 0.0;  // masked: the single-scattering surface loses it
            return (1 - fr.reflectance) * refraction_escape(masking, lambda_i, ggx.lambda(*wt));
        },
        qr, n_phi, 1e-6);
}

std::vector<float> compute(TransmissionMasking masking) {
    constexpr int kNcAll = T::kNbelow + T::kNc;
    std::vector<float> v(std::size_t(kNcAll) * T::kNalpha * T::kNeta);
#pragma omp parallel for schedule(dynamic) collapse(2)
    for (int ic = 0; ic < kNcAll; ++ic)
        for (int ia = 0; ia < T::kNalpha; ++ia)
            for (int ie = 0; ie < T::kNeta; ++ie) {
                const double alpha = alpha_node(ia), eta = eta_node(ie);
                // Without total internal reflection the lower piece is the single cosine kCMin:
                // computed once (ic = 0), copied after the loop.
                if (ic > 0 && ic < T::kNbelow && critical_cosine(eta) == 0) continue;
                const double c = c_node(ic, eta);
                const double t = integrate(c, alpha, eta, masking, kTableNr, kTableNphi);
                v[(std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie] =
                    float(t - smooth_weight(alpha) * (1 - fresnel_dielectric(c, eta)));
            }
    for (int ic = 1; ic < T::kNbelow; ++ic)
        for (int ia = 0; ia < T::kNalpha; ++ia)
            for (int ie = 0; ie < T::kNeta; ++ie)
                if (critical_cosine(eta_node(ie)) == 0)
                    v[(std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie] =
                        v[(std::size_t(0) * T::kNalpha + ia) * T::kNeta + ie];
    return v;
}

const char* masking_name(TransmissionMasking m) {
    return m == TransmissionMasking::Smith ? "smith-beta" : "walter";
}

}  // namespace

double refraction_escape(TransmissionMasking masking, double lambda_i, double lambda_t) {
    // The escape fractions of physics/smith_masking.h, from the Smith roots r = 1 + 2Λ.
    const double r_i = 1 + 2 * lambda_i, r_t = 1 + 2 * lambda_t;
    if (masking == TransmissionMasking::Pbrt) return smith_reflection_escape(r_i, r_t);
    return smith_refraction_escape(r_i, r_t);
}

double CoatTransmittanceTable::direct(double c, double alpha, double eta,
                                      TransmissionMasking masking, int n_r, int n_phi) {
    return integrate(std::max(c, kCMin), alpha, eta, masking, n_r, n_phi);
}

CoatTransmittanceTable::CoatTransmittanceTable(TransmissionMasking masking) {
    const TableKey key{
        "coat-t",
        fmt::format("{} {} c{}+{} a{} e{}:{}:{} nr{} nphi{} cmin{} amin{}", kCodeVersion,
                    masking_name(masking), kNbelow, kNc, kNalpha, kNeta, kLog2EtaMin, kLog2EtaMax,
                    kTableNr, kTableNphi, kCMin, kAlphaMin),
        {kNbelow + kNc, kNalpha, kNeta}};
    values_ = cached_table(key, [&] { return compute(masking); });
}

const CoatTransmittanceTable& CoatTransmittanceTable::get(TransmissionMasking masking) {
    // Thread-safe initialization (C++11 magic statics), one per masking.
    if (masking == TransmissionMasking::Pbrt) {
        static const CoatTransmittanceTable walter(TransmissionMasking::Pbrt);
        return walter;
    }
    static const CoatTransmittanceTable beta(TransmissionMasking::Smith);
    return beta;
}

double CoatTransmittanceTable::operator()(double c, double alpha, double eta) const {
    c = clamp(c, 0.0, 1.0);
    if (alpha <= 0) return 1 - fresnel_dielectric(c, eta);
    eta = clamp(eta, std::exp2(kLog2EtaMin), std::exp2(kLog2EtaMax));
    // The c axis of the query's own critical cosine: the table at every η node holds T at the
    // same fractions of the pieces below and above it, so the smoothed step of total internal
    // reflection lies on one node line for every η and is never interpolated across.
    const double mu_c = critical_cosine(eta);
    double fc;
    if (c < mu_c) {
        fc = (1 - std::sqrt(std::max(0.0, 1 - c / mu_c))) * (kNbelow - 1);
    } else {
        fc = kNbelow + std::sqrt(mu_c < 1 ? (c - mu_c) / (1 - mu_c) : 0.0) * (kNc - 1);
    }
    const double fa = std::sqrt(clamp(alpha, 0.0, 1.0)) * (kNalpha - 1);
    const double fe = eta_index(eta);
    const int ic_max = c < mu_c ? kNbelow - 2 : kNbelow + kNc - 2;
    const int ic = std::min(int(fc), ic_max), ia = std::min(int(fa), kNalpha - 2),
              ie = std::min(int(fe), kNeta - 2);
    const double tc = fc - ic, ta = fa - ia, te = fe - ie;
    // The control variate's weight interpolated as the residual is (exact at the α nodes): the
    // weight itself at the query's α would add its own curvature in α to the interpolation error
    // (2e-3 at α = 0.05, η = 1.5, where T is nearly constant).
    static const std::array<double, kNalpha> weights = [] {
        std::array<double, kNalpha> w{};
        for (int i = 0; i < kNalpha; ++i)
            w[i] = smooth_weight(alpha_node(i));
        return w;
    }();
    const double weight = (1 - ta) * weights[ia] + ta * weights[ia + 1];
    double sum = 0;
    for (int dc = 0; dc < 2; ++dc)
        for (int da = 0; da < 2; ++da) {
            const double w = (dc ? tc : 1 - tc) * (da ? ta : 1 - ta);
            const float* row =
                values_.data() + ((std::size_t(ic + dc) * kNalpha + ia + da) * kNeta + ie);
            sum += w * ((1 - te) * row[0] + te * row[1]);
        }
    if (weight > 0) sum += weight * (1 - fresnel_dielectric(c, eta));
    return clamp(sum, 0.0, 1.0);
}

}  // namespace lamina

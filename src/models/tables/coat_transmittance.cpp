#include "models/tables/coat_transmittance.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "models/tables/critical_cosine_axes.h"
#include "models/tables/table_cache.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/smith_masking.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

namespace {

constexpr int kTableNr = 16;    // Gauss–Legendre nodes in u = √(1 − r) per piece
constexpr int kTableNphi = 32;  // midpoint nodes in φ over the half disk (mirrored)
constexpr double kCMin = lamina1::TransmittanceFormat::kCMin;
constexpr double kAlphaMin = lamina1::TransmittanceFormat::kAlphaMin;
constexpr const char* kCodeVersion = "coat-t-v7";

using T = CoatTransmittanceTable;

// The c, α, η axes and their interpolation (the table's format is lamina-1's header library's,
// include/lamina1/table_lookups.h, which reads this table too).
const CriticalCosineAxes& axes() {
    return lamina1::TransmittanceFormat::axes();
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
                const double alpha = axes().alpha_node(ia), eta = axes().eta_node(ie);
                // Without total internal reflection the lower piece is the single cosine kCMin:
                // computed once (ic = 0), copied after the loop.
                if (ic > 0 && ic < T::kNbelow && critical_cosine(eta) == 0) continue;
                const double c = axes().c_node(ic, eta);
                const double t = integrate(c, alpha, eta, masking, kTableNr, kTableNphi);
                v[(std::size_t(ic) * T::kNalpha + ia) * T::kNeta + ie] =
                    float(t - CriticalCosineAxes::smooth_weight(alpha) *
                                  (1 - fresnel_dielectric(c, eta)));
            }
    for (int ic = 1; ic < T::kNbelow; ++ic)
        for (int ia = 0; ia < T::kNalpha; ++ia)
            for (int ie = 0; ie < T::kNeta; ++ie)
                if (critical_cosine(axes().eta_node(ie)) == 0)
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
    return lamina1::TransmittanceFormat::lookup(values_.data(), c, alpha, eta);
}

}  // namespace lamina

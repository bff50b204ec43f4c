#pragma once
// lamina-1's importance sampling: a mixture of its lobes, each drawn by its own distribution,
// with probabilities from the lobes' approximate energies at wi (lamina's docs/models.md,
// lamina-1, "Sampling"). pdf is the same mixture evaluated at wo; the weight is
// eval·|cos θo|/pdf.

#include "lamina1/bsdf.h"

namespace lamina1 {

inline Bsdf::Mixture Bsdf::mixture(const Incident& in) const {
    Mixture m;
    if (!in.ok) return m;
    m.wi_in = in.wi_in;
    m.wi_mean = in.wi_mean;
    const double a = in.a.mean();
    if (alpha0_ > 0) m.p[0] = fresnel_dielectric(in.wi.z, eta0_);
    const double E_b = base_albedo(in.wi_in.z).mean();
    if (layers_.base == Base::Lambertian) {
        m.p[1] = in.T * a * E_b;
    } else {
        // The base lobe is drawn with its incident-side widening on both sides (k_o ≈ k_i).
        m.base = widened_ggx(in.k_top, in.k_top);
        if (m.base.alpha > 0) m.p[1] = in.T * a * E_b;
    }
    if (series_on_) m.p[2] = (in.X * K_ * X_bar_).mean();
    if (bins_) m.p[2] = in.bins.v[6 * kNbins].mean();
    m.p[2] += in.dR;  // the coat's separable multiple-scattering lobe, also cosine-distributed
    // A scattering medium's light: broad (its single scattering) or separable (the rest), both
    // drawn with the cosine lobe.
    if (scatters_) {
        if (single_on_) m.p[2] += single_energy_(in.wi.z).mean();
        if (orders_on_) m.p[2] += orders_(in.wi.z).mean();
    }
    if (support_.btdf) {
        m.bottom_sampled = bottom_lobe_ && in.u_bottom >= 0.5;
        m.beta = m.bottom_sampled ? in.alpha_b : transmission_roughness(in.k_top, in.k_bottom);
        if (m.beta > 0)
            m.p[3] = bottom_lobe_ ? in.first_E.mean() : in.T * a * std::max(0.0, 1 - E_b);
        if (bins_)
            m.p[4] = in.bins.v[6 * kNbins + 1].mean();
        else if (series_btdf_)
            m.p[4] = (in.X * inv_one_minus_Er_).mean() * 0.5;
        if (orders_on_) m.p[4] += orders_t_(in.wi.z).mean();
        if (scatters_ && back_on_) m.p[4] += single_energy_t_(in.wi.z).mean();
    }
    double total = 0;
    for (double p : m.p)
        total += p;
    if (!(total > 0)) return Mixture{};
    for (double& p : m.p)
        p /= total;
    return m;
}

inline double Bsdf::pdf_with(const Incident& in, const Mixture& m, const Vec3& wo) const {
    if (!in.ok || wo.z == 0) return 0;
    double pdf = 0;
    if (wo.z > 0) {
        if (m.p[0] > 0) {
            const Vec3 h = normalize(in.wi + wo);
            pdf += m.p[0] * coat_ggx_.D_visible(in.wi, h) / (4 * std::abs(dot(wo, h)));
        }
        if (m.p[1] > 0) {
            if (layers_.base == Base::Lambertian) {
                pdf += m.p[1] * wo.z * kInvPi;
            } else {
                // Drawn inside the coat: dω'/dω = μo/(η0² μo') (Snell's law of solid angles).
                // (A wo refracted onto the horizon, wo' = 0 by rounding, is never drawn: density
                // 0.)
                const Vec3 wo_in = refract_in(wo, inv_eta0_);
                if (wo_in.z > 0) {
                    const Vec3 h = normalize(m.wi_in + wo_in);
                    const double pdf_in =
                        m.base.D_visible(m.wi_in, h) / (4 * std::abs(dot(wo_in, h)));
                    pdf += m.p[1] * pdf_in * wo.z / (sqr(eta0_) * wo_in.z);
                }
            }
        }
        if (m.p[2] > 0) pdf += m.p[2] * wo.z * kInvPi;
        return pdf;
    }
    if (m.p[3] > 0 && m.bottom_sampled) {
        // Refracted through the visible normals of α_b at the mean inside direction (Walter et
        // al. 2007, Eq. 17: dωm/dωo = η_o² |wo·wm| / (η_i wi·wm + η_o wo·wm)², η_o/η_i = η_b).
        const RoughDielectric bottom = bottom_btdf(m.beta);
        if (const auto wm = bottom.half_vector(m.wi_mean, wo)) {
            const double denom = sqr(dot(m.wi_mean, *wm) + eta_b_ * dot(wo, *wm));
            const double jacobian = sqr(eta_b_) * std::abs(dot(wo, *wm)) / denom;
            // A nearly index-matched bottom straight through: the half vector is rounding noise.
            if (denom > 0 && std::isfinite(jacobian))
                pdf += m.p[3] * GGX{m.beta}.D_visible(m.wi_mean, *wm) * jacobian;
        }
    } else if (m.p[3] > 0) {
        const Vec3 v(wo.x, wo.y, -wo.z);
        if (const auto v_in = refract_in_checked(v, 1 / eta_s_)) {
            const Vec3 h = normalize(m.wi_mean + *v_in);
            const double pdf_in =
                GGX{m.beta}.D_visible(m.wi_mean, h) / (4 * std::abs(dot(*v_in, h)));
            pdf += m.p[3] * pdf_in * v.z / (sqr(eta_s_) * v_in->z);
        }
    }
    if (m.p[4] > 0) pdf += m.p[4] * -wo.z * kInvPi;
    return pdf;
}

inline std::optional<Sample> Bsdf::sample(const Vec3& wi, const Vec3& u) const {
    if (!support_.brdf || wi.z <= 0) return std::nullopt;
    const Incident in = incident(wi);
    const Mixture m = mixture(in);
    // u.x picks the lobe, (u.y, u.z) draw its direction.
    int lobe = 0;
    double c = m.p[0];
    while (lobe < 4 && u.x >= c)
        c += m.p[++lobe];
    if (m.p[lobe] <= 0) return std::nullopt;
    Vec3 wo;
    switch (lobe) {
        case 0: {
            const Vec3 wm = coat_ggx_.sample_visible_normal(wi, u.y, u.z);
            wo = reflect(wi, wm);
            if (wo.z <= 0) return std::nullopt;  // shadowed by the coat's microsurface
            break;
        }
        case 1:
            if (layers_.base == Base::Lambertian) {
                wo = sample_cosine_hemisphere(u.y, u.z);
            } else {
                const Vec3 wm = m.base.sample_visible_normal(m.wi_in, u.y, u.z);
                const Vec3 wo_in = reflect(m.wi_in, wm);
                const double s2 = sqr(eta0_) * (1 - sqr(wo_in.z));
                if (wo_in.z <= 0 || s2 >= 1) return std::nullopt;  // shadowed, or totally reflected
                wo = Vec3(wo_in.x * eta0_, wo_in.y * eta0_, std::sqrt(1 - s2));
            }
            break;
        case 2:
            wo = sample_cosine_hemisphere(u.y, u.z);
            break;
        case 3: {
            const Vec3 wm = GGX{m.beta}.sample_visible_normal(m.wi_mean, u.y, u.z);
            if (m.bottom_sampled) {
                const auto wt = refract(m.wi_mean, wm, eta_b_);
                if (!wt || wt->z >= 0) return std::nullopt;  // totally reflected by the facet
                wo = *wt;
                break;
            }
            const Vec3 v_in = reflect(m.wi_mean, wm);
            const double s2 = sqr(eta_s_) * (1 - sqr(v_in.z));
            if (v_in.z <= 0 || s2 >= 1) return std::nullopt;
            wo = Vec3(v_in.x * eta_s_, v_in.y * eta_s_, -std::sqrt(1 - s2));
            break;
        }
        default: {
            const Vec3 w = sample_cosine_hemisphere(u.y, u.z);
            wo = Vec3(w.x, w.y, -w.z);
        }
    }
    if (wo.z == 0 || (wo.z < 0 && !support_.btdf)) return std::nullopt;
    const double pdf = pdf_with(in, m, wo);
    if (!(pdf > 0)) return std::nullopt;
    const Rgb weight = eval_with(in, wo) * (std::abs(wo.z) / pdf);
    // A direction drawn where the density underflows (a denormal pdf at the horizon, u at 1):
    // its weight would overflow; it is rejected, as a direction of zero density is.
    if (!std::isfinite(weight.max())) return std::nullopt;
    return Sample{wo, weight, pdf};
}

inline double Bsdf::pdf(const Vec3& wi, const Vec3& wo) const {
    if (!support_.brdf || wi.z <= 0) return 0;
    const Incident in = incident(wi);
    return pdf_with(in, mixture(in), wo);
}

}  // namespace lamina1

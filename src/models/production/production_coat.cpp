#include "models/production/production_coat.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/tables/fgd_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lamina {

namespace {

/// (1 − c)⁵ of Schlick 1994, "An inexpensive BRDF model for physically-based rendering", Eq. 15.
double schlick_weight(double c) {
    const double m = clamp(1 - c, 0.0, 1.0), m2 = m * m;
    return m2 * m2 * m;
}

double schlick(double c, double f0) {
    return f0 + (1 - f0) * schlick_weight(c);
}

constexpr double kF82Cos = 1.0 / 7.0;  // μ̄ of the F82-tint model (OpenPBR 1.1, "Metal")

class ProductionCoat final : public Model {
  public:
    ProductionCoat(const Stack& stack, const CoatRecipe& recipe) : r_(recipe) {
        std::string why;
        if (!coated_stack(stack, coat_, why)) {
            support_.reason = fmt::format("{} {}", r_.name, why);
            return;
        }
        if (coat_.tau_s.max() > 0) {
            support_.reason = fmt::format(
                "{} has no scattering coat (its coat is a clear or absorbing dielectric)", r_.name);
            return;
        }
        if (coat_.base_type == InterfaceType::Dielectric) {
            support_.reason = fmt::format(
                "{} has an opaque base (diffuse or metal) under its coat: a dielectric base with "
                "light passing below it (a slab, BTDF) has no counterpart",
                r_.name);
            return;
        }
        if (r_.coat_ior_fixed && std::abs(coat_.eta0 - 1.5) > 1e-9) {
            support_.reason = fmt::format(
                "{}'s coat has a fixed IOR of 1.5 (F0 = 0.04); this coat's relative index is {}",
                r_.name, coat_.eta0);
            return;
        }
        support_.brdf = true;
        eta0_ = coat_.eta0;
        switch (r_.coat_fresnel) {
            case CoatRecipe::Fresnel::Exact:
                break;
            case CoatRecipe::Fresnel::SchlickIor:
                coat_f0_ = sqr((eta0_ - 1) / (eta0_ + 1));
                break;
            case CoatRecipe::Fresnel::Schlick004:
                coat_f0_ = 0.04;
                break;
        }
        // Roughness: every engine's α is its parameter squared, α = r².
        double r_coat = std::sqrt(coat_.alpha0);
        if (r_.coat_min_roughness > 0) r_coat = std::max(r_coat, r_.coat_min_roughness);
        alpha_coat_ = sqr(r_coat);
        eta_index_ = FgdTable::locate(eta0_, 0);

        // The base.
        is_metal_ = coat_.base_type == InterfaceType::Conductor;
        if (is_metal_) {
            const double r_base = std::sqrt(coat_.base_alpha);
            double r_prime = r_base;
            switch (r_.roughening) {
                case CoatRecipe::Roughening::None:
                    break;
                case CoatRecipe::Roughening::OpenPBR:  // OpenPBR 1.1, "Roughening"
                    r_prime =
                        std::pow(std::min(1.0, sqr(sqr(r_base)) + 2 * sqr(sqr(r_coat))), 0.25);
                    break;
                case CoatRecipe::Roughening::Adobe: {  // openpbr-bsdf, openpbr_bsdf.h
                    const double factor = 1 - (eta0_ >= 1 ? 1 / eta0_ : eta0_);
                    r_prime =
                        std::pow(std::min(1.0, sqr(sqr(r_base)) + factor * sqr(sqr(r_coat))), 0.25);
                    break;
                }
                case CoatRecipe::Roughening::Max:  // Filament, base no glossier than the coat
                    r_prime = std::max(r_base, r_coat);
                    break;
                case CoatRecipe::Roughening::StandardSurface:  // coat_affect_roughness = 1
                    r_prime = r_base + (1 - r_base) * r_coat;
                    break;
            }
            alpha_base_ = sqr(r_prime);
            for (int c = 0; c < 3; ++c) {
                const double e = coat_.base_eta[c], k = coat_.base_k[c];
                f0_[c] = fresnel_conductor(1.0, e, k);
                switch (r_.metal_fresnel) {
                    case CoatRecipe::MetalFresnel::Exact:
                    case CoatRecipe::MetalFresnel::Schlick:
                        break;
                    case CoatRecipe::MetalFresnel::F82Tint:
                        // The edge tint that makes F82(μ̄) the exact F(μ̄), within the
                        // parameter's range [0, 1] (the model cannot brighten the edge).
                        tint82_[c] = clamp(
                            fresnel_conductor(kF82Cos, e, k) / schlick(kF82Cos, f0_[c]), 0.0, 1.0);
                        break;
                    case CoatRecipe::MetalFresnel::SchlickFilament:
                        // The artist's F0 is the metal's against air; Filament converts it.
                        f0_[c] = filament_f0_clear_coat_to_surface(
                            fresnel_conductor(1.0, e * eta0_, k * eta0_));
                        break;
                }
            }
        } else {
            albedo_ = r_.affect_color ? coat_.albedo * coat_.albedo : coat_.albedo;
        }
        tau_ = coat_.tau_a;
        has_tau_ = tau_.max() > 0;
        if (r_.attenuation == CoatRecipe::Attenuation::KullaConty) {
            // E_avg = 2 ∫ E(μ) μ dμ (Kulla & Conty 2017), Gauss–Legendre over μ.
            const QuadratureRule q = gauss_legendre(32);
            double e_avg = 0;
            for (std::size_t i = 0; i < q.x.size(); ++i)
                e_avg += 2 * q.w[i] * q.x[i] * coat_albedo(q.x[i]);
            kc_norm_ = 1 / std::max(1e-9, 1 - e_avg);
        }
        setup_darkening();
    }

    std::string name() const override { return r_.name; }
    Support support() const override { return support_; }

    /// What depends on wi alone.
    struct Incident {
        Vec3d wi;
        double E_i = 0;     ///< E_coat(μi)
        double F_i = 0;     ///< the coat's Fresnel at μi (its own form)
        double mu_t_i = 1;  ///< refracted cosine
        double lambda_coat = 0, lambda_base = 0;
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || wi.z <= 0) return in;
        in.E_i = uses_albedo() ? coat_albedo(wi.z) : 0;
        in.F_i = coat_fresnel(wi.z);
        in.mu_t_i = refracted_cos(wi.z);
        if (alpha_coat_ > 0) in.lambda_coat = GGX<double>{alpha_coat_}.lambda(wi);
        if (is_metal_ && alpha_base_ > 0) in.lambda_base = GGX<double>{alpha_base_}.lambda(wi);
        return in;
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        return eval_with(incident(wi), wo);
    }

    Rgbd eval_with(const Incident& in, const Vec3d& wo) const {
        const Vec3d& wi = in.wi;
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        const Vec3d h = normalize(wi + wo);
        const double cos_h = dot(wi, h);
        double f_coat = 0;
        if (alpha_coat_ > 0) {
            const GGX<double> ggx{alpha_coat_};
            const double F = coat_fresnel(r_.coat_fresnel_at_n ? wo.z : cos_h);
            if (r_.coat_visibility == CoatRecipe::Visibility::Smith) {
                const double G = 1 / (1 + in.lambda_coat + ggx.lambda(wo));
                f_coat = F * ggx.D(h) * G / (4 * wi.z * wo.z);
            } else {
                f_coat = F * ggx.D(h) / (4 * cos_h * cos_h);
            }
        }
        Rgbd base(0.0);
        if (is_metal_) {
            if (alpha_base_ <= 0) return Rgbd(f_coat);  // a smooth base: a delta lobe
            const GGX<double> ggx{alpha_base_};
            const double G = 1 / (1 + in.lambda_base + ggx.lambda(wo));
            base = metal_fresnel(cos_h) * (ggx.D(h) * G / (4 * wi.z * wo.z));
        } else {
            base = albedo_ * kInvPi<double>;
        }
        return Rgbd(f_coat) + base * base_scale(in, wo.z, cos_h);
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> lobes;
        if (!support_.brdf || wi.z <= 0) return lobes;
        const Vec3d wr = mirror_direction(wi);
        // At the mirror pair h = n: wi·h = μi = μo, and the smooth limit of either visibility
        // term leaves the lobe's energy equal to its Fresnel factor.
        if (alpha_coat_ == 0) lobes.push_back({wr, Rgbd(coat_fresnel(wi.z))});
        if (is_metal_ && alpha_base_ == 0) {
            const Incident in = incident(wi);
            lobes.push_back({wr, metal_fresnel(wi.z) * base_scale(in, wi.z, wi.z)});
        }
        return lobes;
    }

    /// Importance sampling: the coat lobe's visible normals (Heitz 2018) with probability p_c,
    /// else the base (its GGX visible normals, or the cosine for a Lambertian). p_c is the coat's
    /// Fresnel at μi (clamped to [0.1, 0.9]), 0 when the coat is smooth (a delta lobe, not
    /// sampled here), 1 when the base is a smooth metal.
    bool has_sampling() const override { return support_.brdf && sampled_lobes() > 0; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!has_sampling() || wi.z <= 0) return std::nullopt;
        const double p_c = coat_probability(wi);
        Vec3d wo;
        if (u.z < p_c) {
            const GGX<double> ggx{alpha_coat_};
            wo = reflect(wi, ggx.sample_visible_normal(wi, u.x, u.y));
        } else if (is_metal_) {
            const GGX<double> ggx{alpha_base_};
            wo = reflect(wi, ggx.sample_visible_normal(wi, u.x, u.y));
        } else {
            wo = sample_cosine_hemisphere(u.x, u.y);
        }
        if (wo.z <= 0) return std::nullopt;
        const double density = pdf(wi, wo);
        if (!(density > 0)) return std::nullopt;
        return ModelSample{wo, eval(wi, wo) * (wo.z / density), density};
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!has_sampling() || wi.z <= 0 || wo.z <= 0) return 0;
        const double p_c = coat_probability(wi);
        const Vec3d h = normalize(wi + wo);
        const double jacobian = 1 / (4 * dot(wo, h));  // dωh/dωo for reflection
        double p = 0;
        if (p_c > 0) p += p_c * GGX<double>{alpha_coat_}.pdf_visible_normal(wi, h) * jacobian;
        if (p_c < 1) {
            if (is_metal_)
                p += (1 - p_c) * GGX<double>{alpha_base_}.pdf_visible_normal(wi, h) * jacobian;
            else
                p += (1 - p_c) * pdf_cosine_hemisphere(wo);
        }
        return p;
    }

  private:
    int sampled_lobes() const { return int(alpha_coat_ > 0) + int(!is_metal_ || alpha_base_ > 0); }

    double coat_probability(const Vec3d& wi) const {
        if (alpha_coat_ <= 0) return 0;
        if (is_metal_ && alpha_base_ <= 0) return 1;
        return clamp(coat_fresnel(wi.z), 0.1, 0.9);
    }

    bool uses_albedo() const {
        using A = CoatRecipe::Attenuation;
        return r_.attenuation == A::AlbedoView || r_.attenuation == A::AlbedoReciprocal ||
               r_.attenuation == A::KullaConty;
    }

    /// E_coat(μ): the directional albedo of the coat lobe with exact Fresnel and Smith G2
    /// (lamina's FGD table; the models that scale by an albedo all use the exact Fresnel).
    double coat_albedo(double mu) const { return FgdTable::get()(mu, alpha_coat_, eta_index_); }

    double coat_fresnel(double c) const {
        if (r_.coat_fresnel == CoatRecipe::Fresnel::Exact) return fresnel_dielectric(c, eta0_);
        return schlick(c, coat_f0_);
    }

    /// μt = √(1 − (1 − μ²)/η0²) (OpenPBR 1.1, "View-dependent absorption").
    double refracted_cos(double mu) const { return safe_sqrt(1 - (1 - mu * mu) / (eta0_ * eta0_)); }

    Rgbd metal_fresnel(double c) const {
        Rgbd F;
        for (int i = 0; i < 3; ++i) {
            switch (r_.metal_fresnel) {
                case CoatRecipe::MetalFresnel::Exact:
                    F[i] = fresnel_conductor(c, coat_.base_eta[i], coat_.base_k[i]);
                    break;
                case CoatRecipe::MetalFresnel::Schlick:
                case CoatRecipe::MetalFresnel::SchlickFilament:
                    F[i] = schlick(c, f0_[i]);
                    break;
                case CoatRecipe::MetalFresnel::F82Tint:
                    F[i] = f82_tint_fresnel(c, f0_[i], tint82_[i]);
                    break;
            }
        }
        return F;
    }

    /// A · T · Δ: the base's scale for the pair (in.wi, wo) with cos_h = wi·h.
    Rgbd base_scale(const Incident& in, double mu_o, double cos_h) const {
        using A = CoatRecipe::Attenuation;
        double a = 1;
        switch (r_.attenuation) {
            case A::AlbedoView:
                a = 1 - coat_albedo(mu_o);
                break;
            case A::AlbedoReciprocal:
                a = (1 - in.E_i) * (1 - coat_albedo(mu_o));
                break;
            case A::KullaConty:
                a = (1 - in.E_i) * (1 - coat_albedo(mu_o)) * kc_norm_;
                break;
            case A::FresnelView:
                a = 1 - coat_fresnel(mu_o);
                break;
            case A::FresnelHalf:
                a = 1 - coat_fresnel(cos_h);
                break;
            case A::FresnelMax:
                a = 1 - std::max(in.F_i, coat_fresnel(mu_o));
                break;
        }
        Rgbd s(a);
        if (has_tau_) {
            switch (r_.tint) {
                case CoatRecipe::Tint::TwoWay:
                    s *= beer_lambert(tau_, 1 / in.mu_t_i + 1 / refracted_cos(mu_o));
                    break;
                case CoatRecipe::Tint::ViewOnly:
                    s *= beer_lambert(tau_, 2 / refracted_cos(mu_o));
                    break;
                case CoatRecipe::Tint::Constant:
                    s *= exp_rgb(tau_ * -2.0);
                    break;
            }
        }
        if (r_.darkening == CoatRecipe::Darkening::Spec && is_metal_) {
            // K = lerp(K_s, K_r, r_b) with K_s = F(μo; η0): a darkening that depends on wo.
            const double K_s = fresnel_dielectric(mu_o, eta0_);
            const double K = K_s + (K_r_ - K_s) * r_b_;
            for (int c = 0; c < 3; ++c)
                s[c] *= coat_darkening(K, E_b_[c]);
        } else {
            s *= darkening_;
        }
        return s;
    }

    void setup_darkening() {
        using D = CoatRecipe::Darkening;
        if (r_.darkening == D::None) return;
        // OpenPBR 1.1, "Darkening": Δ = (1 − K)/(1 − E_b K), K_r = 1 − (1 − E_F(η_c))/η_c².
        const double E_F = r_.darkening == D::Spec ? openpbr_average_fresnel_fit(eta0_)
                                                   : kulla_conty_average_fresnel_fit(eta0_);
        K_r_ = 1 - (1 - E_F) / (eta0_ * eta0_);
        double K = K_r_;  // a diffuse base: r_b = 1 (no specular of its own)
        if (is_metal_) {
            if (r_.darkening == D::Spec) {
                // E_b: the base's normal-incidence albedo (lamina's FGD of the conductor);
                // r_b = the metal's roughness parameter (K depends on wo: base_scale).
                std::array<FgdTable::Index, 3> at;
                for (int c = 0; c < 3; ++c)
                    at[c] = FgdTable::locate(coat_.base_eta[c], coat_.base_k[c]);
                E_b_ = FgdTable::get().rgb(1.0, alpha_base_, at);
                r_b_ = std::sqrt(coat_.base_alpha);
                return;
            }
            // Adobe: E_b = the metal's average Fresnel 2∫F μ dμ (its own metal Fresnel; a
            // Gauss–Legendre rule, exact for F82's polynomial), r_b = the roughened r,
            // K_s = E_F.
            const QuadratureRule q = gauss_legendre(16);
            E_b_ = Rgbd(0.0);
            for (std::size_t i = 0; i < q.x.size(); ++i)
                E_b_ += metal_fresnel(q.x[i]) * (2 * q.w[i] * q.x[i]);
            const double r_b = std::sqrt(alpha_base_);
            K = E_F + (K_r_ - E_F) * r_b;
        } else {
            E_b_ = albedo_;
        }
        for (int c = 0; c < 3; ++c)
            darkening_[c] = coat_darkening(K, E_b_[c]);
    }

    /// The darkening (1 − K)/(1 − E_b K) (OpenPBR 1.1, "Coat darkening"): 0 where the coat
    /// reflects everything (K = 1: a coat less dense than the ambient medium past its critical
    /// angle), never 0/0 with a perfect base (E_b = 1).
    static double coat_darkening(double K, double E_b) {
        if (!(K < 1)) return 0.0;
        return (1 - K) / (1 - E_b * K);
    }

    CoatRecipe r_;
    CoatedStack coat_;
    Support support_;
    double eta0_ = 1.5;
    double coat_f0_ = 0;
    double alpha_coat_ = 0, alpha_base_ = 0;
    FgdTable::Index eta_index_;
    bool is_metal_ = false;
    Rgbd f0_{0.0}, tint82_{1.0};
    Rgbd albedo_{0.0};
    Rgbd tau_{0.0};
    bool has_tau_ = false;
    double kc_norm_ = 1;
    // Darkening: Δ for a wo-independent K, else K_r, r_b and E_b for the spec's K(μo).
    Rgbd darkening_{1.0};
    Rgbd E_b_{0.0};
    double K_r_ = 0, r_b_ = 1;
};

std::unique_ptr<IncidentEvaluator> ProductionCoat::prepare(const Vec3d& wi) const {
    return std::make_unique<SplitIncidentEvaluator<ProductionCoat>>(*this, wi);
}

}  // namespace

double openpbr_average_fresnel_fit(double eta) {
    // The fit holds over the relative indices a stack file may give (docs/stack-format.md,
    // "Ranges": [1/5, 5]); past η ≈ 6 it exceeds 1 and past 13.2 its denominator changes sign (a
    // NaN for stacks built in code with absurd indices, found by tests/fuzz): η is kept in
    // [1/5, 5] and the average in [0, 1].
    eta = std::clamp(eta, 0.2, 5.0);
    if (eta < 1) return 1 - eta * eta * (1 - openpbr_average_fresnel_fit(1 / eta));
    // OpenPBR 1.1, footnote avg_fresnel (d'Eon 2021): ln((10893η − 1438.2)/(−774.4η² + 10212η +
    // 1)).
    return std::clamp(std::log((10893 * eta - 1438.2) / (-774.4 * eta * eta + 10212 * eta + 1)),
                      0.0, 1.0);
}

double kulla_conty_average_fresnel_fit(double eta) {
    // Kulla & Conty 2017, slide 18, as openpbr-bsdf's openpbr_average_fresnel ships it.
    if (eta > 1) return (eta - 1) / (4.08567 + 1.00071 * eta);
    return 0.997118 + 0.1014 * eta - 0.965241 * eta * eta - 0.130607 * eta * eta * eta;
}

double filament_f0_clear_coat_to_surface(double f0) {
    // Filament documentation, "Clear coat" (f0ClearCoatToSurface): a fit of the F0 of an
    // interface against IOR 1.5 from its F0 against air.
    return clamp(f0 * (f0 * (0.941892 - 0.263008 * f0) + 0.346479) - 0.0285998, 0.0, 1.0);
}

double f82_tint_fresnel(double cos_theta, double f0, double tint) {
    const double mu = clamp(cos_theta, 0.0, 1.0);
    const double one_minus_bar = 1 - kF82Cos;
    const double bar6 = std::pow(one_minus_bar, 6);
    const double b = schlick(kF82Cos, f0) * (1 - tint) / (kF82Cos * bar6);
    return clamp(schlick(mu, f0) - b * mu * std::pow(1 - mu, 6), 0.0, 1.0);
}

OptionSpec leaves_option() {
    return {"leaves",
            {"shipped", "exact"},
            "shipped",
            "the leaf BSDFs: as the model ships them, or lamina's exact ones (exact Fresnel of "
            "coat and metal, height-correlated Smith GGX, no roughness clamp)"};
}

void use_exact_leaves(CoatRecipe& r) {
    r.coat_fresnel = CoatRecipe::Fresnel::Exact;
    r.coat_visibility = CoatRecipe::Visibility::Smith;
    r.coat_min_roughness = 0;
    r.metal_fresnel = CoatRecipe::MetalFresnel::Exact;
}

std::unique_ptr<Model> make_production_coat(const Stack& stack, const CoatRecipe& recipe) {
    return std::make_unique<ProductionCoat>(stack, recipe);
}

}  // namespace lamina

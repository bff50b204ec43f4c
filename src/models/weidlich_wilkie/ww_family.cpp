#include "models/weidlich_wilkie/ww_family.h"

#include "core/math.h"
#include "models/tables/fgd_table.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <cmath>
#include <optional>

namespace lamina {

namespace {

/// An interface's GGX distribution as the stack gives it: α, or α_x, α_y along its tangent.
GGX<double> interface_distribution(const InterfaceSpec& s) {
    return s.is_anisotropic()
               ? GGX<double>::anisotropic(s.alpha, s.alpha_b(), deg_to_rad(s.tangent_deg))
               : GGX<double>{s.alpha};
}

/// The root mean square √((α_x² + α_y²)/2) of an interface's roughnesses (α when isotropic): what
/// "rougher" means between two interfaces whose tangents may differ.
double rms_alpha(const InterfaceSpec& s) {
    return s.is_anisotropic() ? std::sqrt((sqr(s.alpha) + sqr(s.alpha_b())) / 2) : s.alpha;
}

class WWModel final : public Model {
  public:
    WWModel(std::string name, const Stack& stack, const WWChoices& choices)
        : name_(std::move(name)), choices_(choices) {
        std::string why;
        if (!coated_stack(stack, coat_, why)) {
            support_.reason = fmt::format("{} {}", name_, why);
            return;
        }
        if (coat_.tau_s.max() > 0) {
            support_.reason = fmt::format("{} has no scattering medium", name_);
            return;
        }
        const InterfaceSpec &coat_spec = stack.layers[0].interface,
                            &base_spec = stack.layers[1].interface;
        if (coat_.base_type == InterfaceType::Dielectric && base_spec.is_anisotropic()) {
            support_.reason = fmt::format(
                "{} has no anisotropic dielectric base (a slab's anisotropic bottom interface)",
                name_);
            return;
        }
        support_.brdf = true;
        if (coat_.base_type == InterfaceType::Dielectric)
            support_.reason = fmt::format("{} gives only the slab's reflection (no BTDF)", name_);
        // The lobes' distributions: anisotropic where the stack's interfaces are (lamina's
        // extension of the family: the same terms with the anisotropic D and Λ, each interface in
        // its own frame). Elek 2010, Algorithm 1: the base is at least as rough as the coat; with
        // anisotropic interfaces, the rougher by the root mean square of α_x, α_y, whose
        // distribution (and tangent) the base then takes.
        coat_ggx_ = interface_distribution(coat_spec);
        base_ggx_ = interface_distribution(base_spec);
        coat_.alpha0 = rms_alpha(coat_spec);
        coat_.base_alpha = rms_alpha(base_spec);
        base_alpha_ = coat_.base_alpha;
        if (choices_.max_roughness && coat_.alpha0 > coat_.base_alpha &&
            coat_.base_type != InterfaceType::Lambertian) {
            base_alpha_ = coat_.alpha0;
            base_ggx_ = coat_ggx_;
        }
        has_absorption_ = coat_.tau_a.max() > 0;
        gray_tau_ = coat_.tau_a.min() == coat_.tau_a.max();
        inv_eta0_ = 1 / coat_.eta0;
        inv_eta0_sq_ = inv_eta0_ * inv_eta0_;
        for (int c = 0; c < 3; ++c) {
            base_eta_f_[c] = float(coat_.base_eta[c]);
            base_k_f_[c] = float(coat_.base_k[c]);
        }
    }

    std::string name() const override { return name_; }
    Support support() const override { return support_; }

    /// What depends on wi alone (cached by prepare: the per-incidence path of the study).
    struct Incident {
        Vec3d wi;
        double lambda0 = 0;      ///< Λ_α0(wi)
        bool in_ok = false;      ///< wi refracted about n exists
        Vec3d wi_in;             ///< wi refracted about n
        Rgbd att{1.0};           ///< exp(−τ/μi') about n
        double lambda1 = 0;      ///< Λ_α1(wi') of the base, about n
        double lambda1_out = 0;  ///< Λ_α1(wi) of the base (f_base at the outside directions)
        double T01_n = 0;        ///< 1 − F(μi)
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || wi.z <= 0) return in;
        if (coat_.alpha0 > 0) in.lambda0 = coat_ggx_.lambda(wi);
        if (base_alpha_ > 0) in.lambda1_out = base_ggx_.lambda(wi);
        in.T01_n = 1 - fresnel_coat(wi.z);
        if (const auto w = refract_in_n(wi)) {
            in.in_ok = true;
            in.wi_in = *w;
            in.att = attenuation(w->z);
            if (base_alpha_ > 0) in.lambda1 = base_ggx_.lambda(*w);
        }
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
        const double cos_h = dot(wi, h);  // = wo·h
        Rgbd f(0.0);
        double G0 = 1;
        if (coat_.alpha0 > 0) {
            // Top reflection (docs/models.md; Walter et al. 2007, Eq. 20; height-correlated G2,
            // Heitz 2014, Eq. 99); a delta lobe when smooth.
            G0 = 1 / (1 + in.lambda0 + coat_ggx_.lambda(wo));
            f = Rgbd(fresnel_coat(cos_h) * coat_ggx_.D(h) * G0 / (4 * wi.z * wo.z));
        }
        if (base_is_delta()) return f;
        if (choices_.refract_about_h) {
            const std::optional<Rgbd> base = base_term_about_h(in, wo, h, cos_h, G0);
            return base ? f + *base : f;
        }
        // Refraction about n: the incident half is cached in `in`.
        if (!in.in_ok) return f;
        const auto wo_in = refract_in_n(wo);
        if (!wo_in) return f;
        // Fresnel transmittances at h (wi·h = wo·h: T01 = T10) or at n.
        const double T01 = choices_.fresnel_at_h ? 1 - fresnel_coat(cos_h) : in.T01_n;
        const double T10 = choices_.fresnel_at_h ? T01 : 1 - fresnel_coat(wo.z);
        // Weidlich & Wilkie 2007, §4.2: t = (1 − G) + T10·G.
        const double t = choices_.exit_t_term ? (1 - G0) + T10 * G0 : T10;
        const Rgbd fb = choices_.base_at_outside ? base_brdf_in(wi, wo, in.lambda1_out)
                                                 : base_brdf_in(in.wi_in, *wo_in, in.lambda1);
        double scale = T01 * t;
        if (choices_.eta2_factor) scale *= inv_eta0_sq_;  // Hanrahan & Krueger 1993, Eq. 8
        return f + fb * (in.att * attenuation(wo_in->z)) * scale;
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> lobes;
        if (!support_.brdf || wi.z <= 0) return lobes;
        const Vec3d wr = mirror_direction(wi);
        if (coat_.alpha0 == 0) lobes.push_back({wr, Rgbd(fresnel_dielectric(wi.z, coat_.eta0))});
        if (base_is_delta()) {
            // A smooth base under the coat: its mirror lobe leaves along wr. In the delta limit
            // f_base = F_b δ(wo* − r(wi*)) / μo*; with f_base at the refracted directions the
            // delta is in the coat's solid angle, and ∫ ... μo dωo = η0² ∫ ... μo' dωo' (Snell's
            // law of solid angles, η0² μo' dωo' = μo dωo) gives the factor η0² that the 1/η0² of
            // WW' cancels. At the mirror pair h = n, so every variant's T01, T10 and refractions
            // are the normal-incidence ones of wi.
            const double G0 = coat_.alpha0 > 0 ? coat_ggx_.G2(wi, wr) : 1.0;
            const Vec3d n(0, 0, 1);
            const auto in = refract_in(wi, n);
            if (in) {
                const Vec3d wb = choices_.base_at_outside ? wi : *in;
                const Rgbd Fb = base_fresnel(wb.z);
                const double T01 = 1 - fresnel_dielectric(wi.z, coat_.eta0);
                const double T10 = T01;  // Fresnel is the same from both sides of one pair
                const double t = choices_.exit_t_term ? (1 - G0) + T10 * G0 : T10;
                const Rgbd a = absorption(in->z, in->z);
                double scale = T01 * t;
                if (choices_.eta2_factor) scale /= sqr(coat_.eta0);
                if (!choices_.base_at_outside) scale *= sqr(coat_.eta0);
                lobes.push_back({wr, Fb * a * scale});
            }
        }
        return lobes;
    }

  private:
    /// F(c; η0) for light arriving from outside, c ∈ [0, 1] (the same as fresnel_dielectric,
    /// with 1/η0² precomputed: this is the hot path of the study).
    double fresnel_coat(double c) const {
        const double sin2_t = (1 - c * c) * inv_eta0_sq_;
        if (sin2_t >= 1) return 1;
        const double ct = std::sqrt(1 - sin2_t), e = coat_.eta0;
        const double r_par = (e * c - ct) / (e * c + ct);
        const double r_perp = (c - e * ct) / (c + e * ct);
        return 0.5 * (r_par * r_par + r_perp * r_perp);
    }

    /// "Refract w about n" for n the macro normal: (w.x/η0, w.y/η0, cos θ') inside the coat.
    std::optional<Vec3d> refract_in_n(const Vec3d& w) const {
        const double sin2_t = (1 - w.z * w.z) * inv_eta0_sq_;
        if (sin2_t >= 1) return std::nullopt;
        return Vec3d(w.x * inv_eta0_, w.y * inv_eta0_, std::sqrt(1 - sin2_t));
    }

    /// Beer–Lambert along one refracted path: exp(−τ/μ').
    Rgbd attenuation(double mu) const {
        if (!has_absorption_) return Rgbd(1.0);
        if (gray_tau_) return Rgbd(std::exp(-coat_.tau_a[0] / mu));
        return beer_lambert(coat_.tau_a, 1 / mu);
    }

    /// f_base with Λ of its incident direction cached.
    Rgbd base_brdf_in(const Vec3d& wi, const Vec3d& wo, double lambda_i) const {
        if (coat_.base_type != InterfaceType::Conductor) return base_brdf(wi, wo);
        if (base_alpha_ <= 0) return Rgbd(0.0);
        // Walter et al. 2007, Eq. 20, conductor Fresnel per channel.
        const Vec3d h = normalize(wi + wo);
        const double G = 1 / (1 + lambda_i + base_ggx_.lambda(wo));
        return base_fresnel(dot(wi, h)) * (base_ggx_.D(h) * G / (4 * wi.z * wo.z));
    }

    bool base_is_delta() const {
        return coat_.base_type != InterfaceType::Lambertian && base_alpha_ == 0;
    }

    /// "Refract w about m" (docs/models.md): the direction inside the coat, pointing away from the
    /// base, whose refraction through the top interface is w; nothing if it does not exist.
    std::optional<Vec3d> refract_in(const Vec3d& w, const Vec3d& m) const {
        const auto t = refract(w, m, coat_.eta0);  // points down, into the coat
        if (!t || t->z >= 0) return std::nullopt;
        return -*t;
    }

    /// Beer–Lambert along both refracted paths: a = exp(−τ (1/μi' + 1/μo')).
    Rgbd absorption(double mu_i, double mu_o) const {
        if (!has_absorption_) return Rgbd(1.0);
        return beer_lambert(coat_.tau_a, 1 / mu_i + 1 / mu_o);
    }

    Rgbd base_fresnel(double cos_theta) const {
        if (coat_.base_type == InterfaceType::Conductor) {
            // The base's conductor Fresnel in float (physics/fresnel.h, exact equations; ~1e-7
            // relative rounding, far below any model's own error): three independent float
            // chains of square roots and divisions are about a third faster than the double
            // ones, and this factor is a third of a WW evaluation.
            const float c = float(cos_theta);
            return {double(fresnel_conductor(c, base_eta_f_[0], base_k_f_[0])),
                    double(fresnel_conductor(c, base_eta_f_[1], base_k_f_[1])),
                    double(fresnel_conductor(c, base_eta_f_[2], base_k_f_[2]))};
        }
        return Rgbd(fresnel_dielectric(cos_theta, coat_.base_eta[0]));
    }

    /// The base's own BRDF (relative indices against the coat), rough or Lambertian.
    Rgbd base_brdf(const Vec3d& wi, const Vec3d& wo) const {
        switch (coat_.base_type) {
            case InterfaceType::Lambertian:
                return coat_.albedo * kInvPi<double>;
            case InterfaceType::Conductor: {
                // Walter et al. 2007, Eq. 20 with the conductor Fresnel factor per channel (the
                // closed form of fresnel_complex_fast: ConductorInterface::eval's std::complex
                // path costs 3× more here).
                if (base_alpha_ <= 0 || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
                const Vec3d h = normalize(wi + wo);
                return base_fresnel(dot(wi, h)) *
                       (base_ggx_.D(h) * base_ggx_.G2(wi, wo) / (4 * wi.z * wo.z));
            }
            case InterfaceType::Dielectric:
                return Rgbd(
                    DielectricInterface<double>{coat_.base_eta[0], base_alpha_}.eval(wi, wo));
        }
        return Rgbd(0.0);
    }

    /// The base term when the directions are refracted about h (WW09): wi·h = wo·h, so both
    /// refractions share their cosines.
    std::optional<Rgbd> base_term_about_h(const Incident& in, const Vec3d& wo, const Vec3d& h,
                                          double cos_h, double G0) const {
        const Vec3d& wi = in.wi;
        const double sin2_t = (1 - cos_h * cos_h) * inv_eta0_sq_;
        if (sin2_t >= 1) return std::nullopt;
        // "Refract w about h": the inside direction w/η0 − h (cos/η0 − cos θt), pointing away
        // from the base (the negative of physics' refract(w, h, η0)).
        const double k = cos_h * inv_eta0_ - std::sqrt(1 - sin2_t);
        const Vec3d in_i = wi * inv_eta0_ - h * k, in_o = wo * inv_eta0_ - h * k;
        if (in_i.z <= 0 || in_o.z <= 0) return std::nullopt;
        // Fresnel transmittances; leaving through m from inside equals entering along wo
        // (Fresnel reflectance is the same from both sides of one refraction pair).
        const double T01 = choices_.fresnel_at_h ? 1 - fresnel_coat(cos_h) : in.T01_n;
        const double T10 = choices_.fresnel_at_h ? T01 : 1 - fresnel_coat(wo.z);
        // Weidlich & Wilkie 2007, §4.2: t = (1 − G) + T10·G lets shadowed light through
        // unattenuated.
        const double t = choices_.exit_t_term ? (1 - G0) + T10 * G0 : T10;
        const Rgbd fb =
            choices_.base_at_outside ? base_brdf_in(wi, wo, in.lambda1_out) : base_brdf(in_i, in_o);
        double scale = T01 * t;
        if (choices_.eta2_factor) scale *= inv_eta0_sq_;  // Hanrahan & Krueger 1993, Eq. 8
        return fb * absorption(in_i.z, in_o.z) * scale;
    }

    std::string name_;
    WWChoices choices_;
    CoatedStack coat_;
    Support support_;
    double base_alpha_ =
        0;  ///< the base's α (root mean square when anisotropic), after max-roughness
    GGX<double> coat_ggx_{0.0}, base_ggx_{0.0};
    bool has_absorption_ = false;
    bool gray_tau_ = true;
    double inv_eta0_ = 1, inv_eta0_sq_ = 1;
    float base_eta_f_[3] = {1, 1, 1}, base_k_f_[3] = {0, 0, 0};
};

std::unique_ptr<IncidentEvaluator> WWModel::prepare(const Vec3d& wi) const {
    return std::make_unique<SplitIncidentEvaluator<WWModel>>(*this, wi);
}

}  // namespace

const ModelOptionTable<WWChoices>& ww_option_table() {
    using C = WWChoices;
    static const ModelOptionTable<C> table({
        member_option<C, bool>(
            "fresnel-normal", &C::fresnel_at_h, {{"h", true}, {"n", false}},
            "normal of the Fresnel transmittances T01, T10: half vector h or macro normal n"),
        member_option<C, bool>("refraction-normal", &C::refract_about_h,
                               {{"h", true}, {"n", false}},
                               "normal the directions are refracted about"),
        member_option<C, bool>("base-directions", &C::base_at_outside,
                               {{"outside", true}, {"refracted", false}},
                               "directions f_base is evaluated at"),
        member_option<C, bool>(
            "exit", &C::exit_t_term, {{"t", true}, {"T10", false}},
            "exit factor: t = (1 - G) + T10 G (Weidlich & Wilkie) or the exit transmission T10"),
        on_off_member<C>("eta2", &C::eta2_factor,
                         "the 1/eta0^2 solid-angle compression factor on the base term"),
        on_off_member<C>("max-roughness", &C::max_roughness,
                         "alpha1 <- max(alpha0, alpha1) (Elek 2010)"),
    });
    return table;
}

WWChoices ww_variant(const std::string& variant) {
    WWChoices c;
    if (variant == "ww09") {
        // Weidlich & Wilkie's SIGGRAPH Asia 2009 course code (docs/models.md table, row WW09):
        // T01 and the refractions at the half vector h; the base BRDF at the *outside* directions
        // (wi, wo), which looks like a bug but is what the code did, so lamina keeps it;
        // t = (1 − G) + T10·G (Weidlich & Wilkie 2007, §4.2).
        c.fresnel_at_h = true;
        c.refract_about_h = true;
        c.base_at_outside = true;
        c.exit_t_term = true;
    } else if (variant == "ele10") {
        // Elek 2010, "Layered materials in real-time rendering", CESCG, Algorithm 1: T01 and t at
        // h; refraction about the macro normal n; the base at the refracted directions with
        // α1 ← max(α0, α1); no 1/η0² factor.
        c.fresnel_at_h = true;
        c.exit_t_term = true;
        c.max_roughness = true;
    } else {
        // WW', the 2019 study's correction: f = f_top + T01(μi) · f_base(wi', wo') · a / η0² ·
        // T10(μo), Fresnel and refraction about n, the exit transmission T10 instead of t, the
        // solid-angle compression 1/η0² (Hanrahan & Krueger 1993, Eq. 8) and α1 ← max(α0, α1).
        // For a smooth coat over a Lambertian base with τ = 0 it is the first term of the exact
        // series (docs/physics.md §6.3).
        LAMINA_CHECK(variant == "ww-prime");
        c.eta2_factor = true;
        c.max_roughness = true;
    }
    return c;
}

std::unique_ptr<Model> make_ww_model(const std::string& name, const Stack& stack,
                                     const WWChoices& choices) {
    return std::make_unique<WWModel>(name, stack, choices);
}

}  // namespace lamina

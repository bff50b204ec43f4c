#include "models/ddb22.h"

#include "core/math.h"
#include "models/belcour.h"
#include "models/coat_transmittance.h"
#include "models/factories.h"
#include "models/fgd_table.h"
#include "models/quadrature.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

namespace lamina {

NormalLobeMoments ggx_normal_lobe_moments(double alpha, int n) {
    if (!(alpha > 0)) return {1.0, 0.0};
    const GGX<double> ggx{alpha};
    const Vec3d normal{0, 0, 1};
    const QuadratureRule q = gauss_legendre(n);
    // Visible normals at normal incidence (Heitz 2018, JCGT 7(4); G1(n) = 1): the density
    // D(h) cos θh over dωh has the CDF u = t/(α² + t) in t = tan²θh, so ∫ g μo dωo =
    // ∫ D(h) G2(n, wo) cos θh dωh = ∫ G2(n, wo(t)) du, wo = 2 cos θh h − n, cos θo = cos 2θh =
    // (1 − t)/(1 + t) > 0 for t < 1. Two pieces: u ∈ [0, u(¼)] (Gauss in u, where the mass is),
    // then t ∈ [¼, 1] with du = α²/(α² + t)² dt (Gauss in t, where G2 falls to 0 at grazing: in
    // u that piece shrinks to a width ~α² next to u = 1).
    constexpr double kTSplit = 0.25;
    const double a2 = alpha * alpha, u_split = kTSplit / (a2 + kTSplit);
    double albedo = 0, moment = 0;
    const auto add = [&](double t, double weight) {
        const double cos_o = (1 - t) / (1 + t);
        const double sin2_o = 4 * t / sqr(1 + t);
        const Vec3d wo{std::sqrt(sin2_o), 0, cos_o};
        const double w = weight * ggx.G2(normal, wo);
        albedo += w;
        moment += w * sin2_o;
    };
    for (int i = 0; i < n; ++i) {
        const double u = u_split * q.x[i];
        add(a2 * u / (1 - u), q.w[i] * u_split);
        const double t = kTSplit + (1 - kTSplit) * q.x[i];
        add(t, q.w[i] * (1 - kTSplit) * a2 / sqr(a2 + t));
    }
    return {albedo, albedo > 0 ? moment / albedo : 0.0};
}

GgxNormalLobeTable::GgxNormalLobeTable() {
    for (int i = 0; i < kN; ++i) {
        const NormalLobeMoments m = ggx_normal_lobe_moments(sqr(double(i) / (kN - 1)));
        albedo_[i] = m.albedo;
        variance_[i] = m.variance;
    }
}

const GgxNormalLobeTable& GgxNormalLobeTable::get() {
    static const GgxNormalLobeTable table;
    return table;
}

namespace {

/// Linear interpolation in s = √α on the table's nodes.
double lerp_sqrt_alpha(const std::array<double, GgxNormalLobeTable::kN>& v, double alpha) {
    constexpr int kN = GgxNormalLobeTable::kN;
    const double s = std::sqrt(clamp(alpha, 0.0, 1.0)) * (kN - 1);
    const int i = std::min(int(s), kN - 2);
    const double t = s - i;
    return v[i] * (1 - t) + v[i + 1] * t;
}

}  // namespace

double GgxNormalLobeTable::albedo(double alpha) const {
    return lerp_sqrt_alpha(albedo_, alpha);
}
double GgxNormalLobeTable::variance(double alpha) const {
    return lerp_sqrt_alpha(variance_, alpha);
}

double GgxNormalLobeTable::alpha_of_variance(double v) const {
    if (!(v > 0)) return 0;
    if (v >= variance_[kN - 1]) return 1;
    // The node interval holding v (V increases along the nodes), then the inverse of the same
    // linear interpolation in s = √α that variance() uses.
    const int i =
        int(std::upper_bound(variance_.begin(), variance_.end(), v) - variance_.begin()) - 1;
    const double t = (v - variance_[i]) / (variance_[i + 1] - variance_[i]);
    return sqr((i + t) / (kN - 1));
}

namespace {

constexpr int kGauss = 32;  // Gauss–Legendre nodes per piece of the hemispherical integrals

/// ∫₀¹ f(μ) dμ by Gauss–Legendre in two pieces split at a critical cosine (where the coat's
/// smooth-limit transmittance has a square-root edge); the upper piece in t with μ = split +
/// (1 − split) t², which makes that edge smooth.
template <typename V, typename F>
V integrate_split01(F&& f, double split) {
    static const QuadratureRule q = gauss_legendre(kGauss);
    V sum{};
    split = clamp(split, 0.0, 1.0);
    for (int i = 0; i < kGauss; ++i) {
        if (split > 0) sum += f(split * q.x[i]) * (q.w[i] * split);
        const double t = q.x[i], d = 1 - split;
        if (d > 0) sum += f(split + d * t * t) * (q.w[i] * 2 * d * t);
    }
    return sum;
}

/// The cosine of the macro refraction of a direction of cosine mu into a medium of relative index
/// eta (0 past total reflection).
double refracted_cosine(double mu, double eta) {
    return fresnel_dielectric_full(mu, eta).cos_theta_t;
}

/// The critical cosine of light arriving from the side where the relative index is eta < 1 (0 when
/// eta ≥ 1: no total reflection).
double critical_cosine(double eta) {
    return eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;
}

}  // namespace

bool ddb22_stack(const Stack& stack, const Ddb22Choices& ch, Ddb22Stack& out, std::string& why) {
    if (!coated_stack(stack, out.coat, why)) {
        why = fmt::format("ddb22 {}", why);
        return false;
    }
    const CoatedStack& c = out.coat;
    if (c.base_type != InterfaceType::Lambertian) {
        why =
            "ddb22 covers a Lambertian base only (the paper's rough-coated Lambertian); conductor "
            "and dielectric bases are Bel18's and Bel''s";
        return false;
    }
    if (c.tau_s.max() > 0) {
        why = "ddb22 has no scattering medium (the paper's coat is clear; lamina adds absorption)";
        return false;
    }
    const double log2_eta = std::log2(c.eta0);
    if (!(log2_eta >= CoatTransmittanceTable::kLog2EtaMin &&
          log2_eta <= CoatTransmittanceTable::kLog2EtaMax)) {
        why = fmt::format(
            "ddb22's coat transmittance table covers a relative coat index in [0.25, 4] (eta0 = "
            "{:.4g})",
            c.eta0);
        return false;
    }
    const CoatTransmittanceTable& coat_t =
        CoatTransmittanceTable::get(RefractionMasking::SmithBeta);
    const FgdTable& fgd = FgdTable::get();
    const double eta0 = c.eta0, inv_eta0 = 1 / c.eta0, alpha0 = c.alpha0;
    const Rgbd tau = c.tau_a;

    // The light the base reflects, seen from inside the coat (docs/models.md, "ddb22"): a
    // Lambertian emits a cosine-weighted flux over the inside directions μ' whatever the incidence;
    // each ray is attenuated by a(μ') on its way up, leaves with T10(μ') or is reflected back down
    // with R10(μ') (attenuated once more at the same cosine: exact for a smooth coat, lamina's
    // approximation for a rough one) and re-diffused by the base.
    const double split_in = critical_cosine(inv_eta0);
    out.T_bar = integrate_split01<Rgbd>(
        [&](double mu) {
            return beer_lambert(tau, 1 / mu) * (2 * mu * coat_t(mu, alpha0, inv_eta0));
        },
        split_in);
    out.r_bar = integrate_split01<Rgbd>(
        [&](double mu) {
            return beer_lambert(tau, 2 / mu) * (2 * mu * fgd(mu, alpha0, inv_eta0, 0.0));
        },
        split_in);
    for (int k = 0; k < 3; ++k) {
        const double rho = c.albedo[k];
        // 1 − ρ r̄ > 0: r̄ < 1 whenever anything leaves; kept ≥ 1e-9 (a white base under a coat
        // that lets nothing out returns nothing either: K = 0).
        out.K[k] = rho * out.T_bar[k] / std::max(1 - rho * out.r_bar[k], 1e-9);
    }

    // The directions of that light once outside: by reciprocity a uniform radiance inside leaves
    // with radiance ∝ T01(μo), attenuated along the macro refraction μo' of wo (the same
    // approximation as a above); flux ∝ W(μo) μo dωo, azimuthally symmetric about the normal, so
    // its mean direction is the normal and its projected variance V = ∫ W μ (1 − μ²) dμ / ∫ W μ dμ.
    const auto weight = [&](double mu) {
        const double mu_in = refracted_cosine(mu, eta0);
        return beer_lambert(tau, mu_in > 0 ? 1 / mu_in : std::numeric_limits<double>::infinity())
                   .mean() *
               coat_t(mu, alpha0, eta0) * mu;
    };
    const double split_out = critical_cosine(eta0);
    const double flux = integrate_split01<double>(weight, split_out);
    const double moment =
        integrate_split01<double>([&](double mu) { return weight(mu) * (1 - mu * mu); }, split_out);
    // Nothing leaves (an opaque absorbing coat): the lobe carries no energy; any width will do.
    out.v_exit = flux > 0 ? moment / flux : 0.5;
    out.beta = ch.matched_variance
                   ? GgxNormalLobeTable::get().alpha_of_variance(out.v_exit)
                   : belcour_alpha_of_variance(out.v_exit / (1 - out.v_exit), false);
    return true;
}

namespace {

class Ddb22 final : public Model {
  public:
    Ddb22(const Stack& stack, const Ddb22Choices& choices) : ch_(choices) {
        std::string why;
        if (!ddb22_stack(stack, ch_, s_, why)) {
            support_.reason = why;
            return;
        }
        support_.brdf = true;
        eta0_ = s_.coat.eta0;
        alpha0_ = s_.coat.alpha0;
        tau_ = s_.coat.tau_a;
        beta_ = s_.beta;
        albedo_beta_ = GgxNormalLobeTable::get().albedo(beta_);
        coat_t_ = &CoatTransmittanceTable::get(RefractionMasking::SmithBeta);
        if (!ch_.lobe_at_normal) GgxAlbedoTable::get();
    }

    std::string name() const override { return "ddb22"; }
    Support support() const override { return support_; }

    /// Everything that depends on wi alone: the indirect lobe's energy E_ind(μi) (RGB).
    struct Incident {
        Vec3d wi;
        Rgbd e_ind{0.0};
        double lobe_norm = 0;  ///< 1/albedo of the indirect lobe's shape
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || !(wi.z > 0)) return in;
        const double mu_i = std::min(wi.z, 1.0);
        const double mu_in = refracted_cosine(mu_i, eta0_);
        const Rgbd a =
            beer_lambert(tau_, mu_in > 0 ? 1 / mu_in : std::numeric_limits<double>::infinity());
        in.e_ind = a * s_.K * (*coat_t_)(mu_i, alpha0_, eta0_);
        const double albedo =
            ch_.lobe_at_normal ? albedo_beta_ : GgxAlbedoTable::get()(mu_i, beta_);
        in.lobe_norm = albedo > 0 ? 1 / albedo : 0.0;
        return in;
    }

    Rgbd eval_with(const Incident& in, const Vec3d& wo) const {
        if (!support_.brdf || !(in.wi.z > 0) || !(wo.z > 0)) return Rgbd(0.0);
        const Vec3d& wi = in.wi;
        const Vec3d h = normalize(wi + wo);
        Rgbd f(0.0);
        // The direct lobe: the coat's reflection, F(wi·h) D G2/(4 μi μo) (Walter et al. 2007,
        // Eq. 20); a smooth coat's is a delta lobe (delta_lobes).
        if (alpha0_ > 0)
            f += Rgbd(fresnel_dielectric(dot(wi, h), eta0_) * ggx_lobe_shape(alpha0_, wi, wo, h));
        if (in.e_ind.max() > 0) {
            double shape;
            if (ch_.lobe_at_normal) {
                const Vec3d normal{0, 0, 1};
                shape = ggx_lobe_shape(beta_, normal, wo, normalize(normal + wo));
            } else {
                shape = ggx_lobe_shape(beta_, wi, wo, h);
            }
            f += in.e_ind * (shape * in.lobe_norm);
        }
        return f;
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || !(wi.z > 0) || !(wo.z > 0)) return Rgbd(0.0);
        return eval_with(incident(wi), wo);
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override {
        return std::make_unique<SplitIncidentEvaluator<Ddb22>>(*this, wi);
    }

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        if (!support_.brdf || !(wi.z > 0) || alpha0_ > 0) return {};
        return {{mirror_direction(wi), Rgbd(fresnel_dielectric(std::min(wi.z, 1.0), eta0_))}};
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        return {mirror_direction(wi), Vec3d{0, 0, 1}};
    }

    // Importance sampling: a two-lobe mixture. The direct lobe (rough coats only: a smooth coat's
    // is a delta lobe, left out here as model.h says) by the visible normals of GGX α0 seen from
    // wi (Heitz 2018, JCGT 7(4)), wo its mirror about them; the indirect lobe by the visible
    // normals of GGX β seen from the lobe's own incidence (the normal, or wi with
    // indirect-lobe=mirror). Each lobe is chosen with its share of the energy, the direct lobe's
    // being the coat's FGD(μi, α0, η0). A draw leaving below the surface is a failed sample.
    bool has_sampling() const override { return support_.brdf; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!support_.brdf || !(wi.z > 0)) return std::nullopt;
        const Incident in = incident(wi);
        const double p_dir = direct_probability(in);
        Vec3d wo;
        if (u.x < p_dir) {
            const GGX<double> ggx{alpha0_};
            wo = reflect(wi, ggx.sample_visible_normal(wi, u.y, u.z));
        } else {
            const Vec3d from = indirect_incidence(wi);
            const GGX<double> ggx{sampled_beta()};
            wo = reflect(from, ggx.sample_visible_normal(from, u.y, u.z));
        }
        if (!(wo.z > 0)) return std::nullopt;
        const double density = pdf_with(in, p_dir, wo);
        if (!(density > 0)) return std::nullopt;
        return ModelSample{wo, eval_with(in, wo) * (wo.z / density), density};
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || !(wi.z > 0) || !(wo.z > 0)) return 0.0;
        const Incident in = incident(wi);
        return pdf_with(in, direct_probability(in), wo);
    }

  private:
    /// The direct lobe's share of the energy (0 for a smooth coat).
    double direct_probability(const Incident& in) const {
        if (!(alpha0_ > 0)) return 0.0;
        const double e_dir = FgdTable::get()(std::min(in.wi.z, 1.0), alpha0_, eta0_, 0.0);
        const double sum = e_dir + in.e_ind.mean();
        return sum > 0 ? e_dir / sum : 1.0;
    }
    Vec3d indirect_incidence(const Vec3d& wi) const {
        return ch_.lobe_at_normal ? Vec3d{0, 0, 1} : wi;
    }
    /// β for the sampler (kept ≥ the smallest roughness a stack file may hold, 1e-4: the visible
    /// normals of α = 0 are not a density).
    double sampled_beta() const { return std::max(beta_, 1e-4); }

    /// Density of the mixture at wo (solid angle): p D_w(h)/(4 |w·h|) per lobe, the reflection
    /// Jacobian of Walter et al. 2007, Eq. 14.
    double pdf_with(const Incident& in, double p_dir, const Vec3d& wo) const {
        double density = 0;
        if (p_dir > 0) {
            const GGX<double> ggx{alpha0_};
            const Vec3d h = normalize(in.wi + wo);
            const double c = dot(in.wi, h);
            if (c > 0) density += p_dir * ggx.D_visible(in.wi, h) / (4 * c);
        }
        if (p_dir < 1) {
            const Vec3d from = indirect_incidence(in.wi);
            const GGX<double> ggx{sampled_beta()};
            const Vec3d h = normalize(from + wo);
            const double c = dot(from, h);
            if (c > 0) density += (1 - p_dir) * ggx.D_visible(from, h) / (4 * c);
        }
        return density;
    }

    Ddb22Choices ch_;
    Ddb22Stack s_;
    Support support_;
    double eta0_ = 1.5, alpha0_ = 0, beta_ = 1, albedo_beta_ = 1;
    Rgbd tau_{0.0};
    const CoatTransmittanceTable* coat_t_ = nullptr;
};

}  // namespace

std::vector<OptionSpec> ddb22_option_specs() {
    return {
        {"variance-mapping",
         {"matched", "belcour"},
         "matched",
         "indirect lobe roughness: the GGX lobe with the same projected variance (matched) or "
         "Belcour 2018's a^1.1/(1-a^1.1) read as V/(1-V)"},
        {"indirect-lobe",
         {"normal", "mirror"},
         "normal",
         "indirect lobe centred on the normal (the mean of the light the base returns) or a GGX "
         "reflection lobe of wi"},
    };
}

Ddb22Choices ddb22_choices(const ModelOptions& o) {
    Ddb22Choices c;
    c.matched_variance = option_value(o, "variance-mapping") == "matched";
    c.lobe_at_normal = option_value(o, "indirect-lobe") == "normal";
    return c;
}

std::vector<OptionSpec> ddb22_options() {
    return ddb22_option_specs();
}

std::unique_ptr<Model> make_ddb22(const Stack& stack, const ModelOptions& options) {
    return std::make_unique<Ddb22>(stack, ddb22_choices(options));
}

}  // namespace lamina

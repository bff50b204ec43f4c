#include "models/ddb22/ddb22.h"

#include "core/math.h"
#include "models/belcour/belcour.h"
#include "models/numerics/quadrature.h"
#include "models/tables/coat_transmittance.h"
#include "models/tables/critical_cosine_axes.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
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

/// The cosine of the macro refraction of a direction of cosine mu into a medium of relative index
/// eta (0 past total reflection).
double refracted_cosine(double mu, double eta) {
    return fresnel_dielectric_full(mu, eta).cos_theta_t;
}

/// Belcour's adding (models/belcour/belcour.h) as Bel18 forward runs it — μ-dependent statistics,
/// the author's transmission variances, the power mapping — but with a TIR step that is exact for
/// smooth coats: once below the top interface, with the microfacet definition of τ_TIR (no
/// Fresnel; the author's table counts the top's Fresnel a second time).
BelcourChoices adding_choices() {
    BelcourChoices c;
    c.tir = BelcourTir::TopInterface;
    c.tir_table = TirDefinition::Microfacet;
    c.tir_across_media = true;
    return c;
}
const BelcourChoices kAdding = adding_choices();

const CoatTransmittanceTable& coat_table() {
    return CoatTransmittanceTable::get(TransmissionMasking::Smith);
}

bool in_coat_table(double eta) {
    const double log2_eta = std::log2(eta);
    return log2_eta >= CoatTransmittanceTable::kLog2EtaMin &&
           log2_eta <= CoatTransmittanceTable::kLog2EtaMax;
}

/// Beer–Lambert along a refracted mean direction of cosine mu (0: past total reflection, an
/// infinite path).
Rgbd attenuation(const Rgbd& tau, double mu) {
    return beer_lambert(tau, mu > 0 ? 1 / mu : std::numeric_limits<double>::infinity());
}

/// What reaches the base, from the statistics of the downward adding run (layered stacks).
Rgbd down_from_stats(const Ddb22Stack& s, const BelcourStats& st) {
    if (!st.transmits) return Rgbd(0.0);
    return st.transmitted * attenuation(s.tau_base, st.cos_t);
}

/// The light leaving the base's medium upwards at cosine mu: transmitted out of the top (T) and
/// reflected back down to the base (R), before the medium above the base.
void transmittance_up(const Ddb22Stack& s, double mu, Rgbd& T, Rgbd& R) {
    if (!s.layered()) {
        T = Rgbd(coat_table()(mu, s.alpha0, 1 / s.eta0));
        R = Rgbd(FgdTable::get()(mu, s.alpha0, 1 / s.eta0, 0.0));
        return;
    }
    const BelcourStats st = belcour_adding(s.up, mu, kAdding);
    R = Rgbd(0.0);
    for (int k = 0; k < st.n_lobes; ++k)
        R += st.lobes[k].energy;
    T = st.transmits ? st.transmitted : Rgbd(0.0);
}

BelcourOperator coat_operator(double n12, double alpha) {
    BelcourOperator op;
    op.kind = BelcourOperator::Dielectric;
    op.n12 = n12;
    op.eta = Rgbd(n12);
    op.alpha = alpha;
    return op;
}

BelcourOperator absorbing_operator(const Rgbd& tau_a) {
    BelcourOperator op;
    op.kind = BelcourOperator::Medium;
    op.tau_a = tau_a;
    return op;
}

}  // namespace

Rgbd ddb22_transmittance_down(const Ddb22Stack& s, double mu) {
    if (s.layered()) return down_from_stats(s, belcour_adding(s.down, mu, kAdding));
    return coat_table()(mu, s.alpha0, s.eta0) *
           attenuation(s.tau_base, refracted_cosine(mu, s.eta0));
}

bool ddb22_stack(const Stack& stack, const Ddb22Choices& ch, Ddb22Stack& out, std::string& why) {
    out = Ddb22Stack{};
    const std::size_t n = stack.layers.size();
    if (n < 2) {
        why = fmt::format(
            "ddb22 needs one or more dielectric coats over a Lambertian base, the stack has {} "
            "interface",
            n);
        return false;
    }
    if (stack.base().type != InterfaceType::Lambertian) {
        why =
            "ddb22 covers a Lambertian base only (the paper's rough-coated Lambertian); conductor "
            "and dielectric bases are Bel18's and Bel''s";
        return false;
    }
    const std::size_t coats = n - 1;
    if (coats > std::size_t(BelcourStats::kMaxLobes)) {
        why = fmt::format("ddb22 needs 1 to {} coats over the Lambertian, the stack has {}",
                          int(BelcourStats::kMaxLobes), coats);
        return false;
    }
    std::vector<double> n12(coats);
    for (std::size_t i = 0; i < coats; ++i) {
        const Layer& layer = stack.layers[i];
        if (layer.interface.type != InterfaceType::Dielectric) {
            why = "ddb22: every interface above the Lambertian must be a dielectric coat";
            return false;
        }
        if (layer.has_medium && layer.medium.scatters()) {
            why =
                "ddb22 has no scattering medium (the paper's coat is clear; lamina adds "
                "absorption)";
            return false;
        }
        n12[i] = model_relative_eta(layer.interface.eta / stack.eta_above(i));
        if (!in_coat_table(n12[i])) {
            why = fmt::format(
                "ddb22's coat tables cover a relative index in [0.25, 4] at each coat (interface "
                "{}: {:.4g})",
                i, n12[i]);
            return false;
        }
    }
    const auto medium_tau = [&](std::size_t i) {
        const Layer& layer = stack.layers[i];
        return layer.has_medium ? layer.medium.tau_a : Rgbd(0.0);
    };
    out.eta0 = n12[0];
    out.alpha0 = stack.layers[0].interface.alpha;
    out.tau_base = medium_tau(coats - 1);
    out.albedo = stack.base().albedo;
    if (coats > 1) {
        // Lamina's reading of the Lambertian interface in Bel18's adding (docs/models.md): the
        // coats' energies from Belcour's scheme, down from the top for the light that reaches
        // the base, up from the base (indices inverted, order reversed) for the light it returns.
        for (std::size_t i = 0; i < coats; ++i) {
            out.down.push_back(coat_operator(n12[i], stack.layers[i].interface.alpha));
            if (i + 1 < coats && medium_tau(i).max() > 0)
                out.down.push_back(absorbing_operator(medium_tau(i)));
        }
        for (std::size_t j = coats; j-- > 0;) {
            out.up.push_back(coat_operator(1 / n12[j], stack.layers[j].interface.alpha));
            if (j > 0 && medium_tau(j - 1).max() > 0)
                out.up.push_back(absorbing_operator(medium_tau(j - 1)));
        }
        precompute_variances(out.down, kAdding.quadratic_mapping);
        precompute_variances(out.up, kAdding.quadratic_mapping);
    }
    // The critical cosines where the integrands have square-root edges: seen from the base's
    // medium, total reflection sets in where the least dense medium above stops the light
    // (Snell's invariant η sin θ); from outside, where a coat less dense than the ambient does.
    const double eta_base_medium = stack.layers[coats - 1].interface.eta;
    double eta_min_above = stack.ambient_eta, eta_min_coats = eta_base_medium;
    for (std::size_t i = 0; i + 1 < coats; ++i)
        eta_min_above = std::min(eta_min_above, stack.layers[i].interface.eta);
    for (std::size_t i = 0; i < coats; ++i)
        eta_min_coats = std::min(eta_min_coats, stack.layers[i].interface.eta);
    const double split_in = critical_cosine(eta_min_above / eta_base_medium);
    const double split_out = critical_cosine(eta_min_coats / stack.ambient_eta);

    // The light the base reflects, seen from the base's medium (docs/models.md, "ddb22"): a
    // Lambertian emits a cosine-weighted flux over the directions μ' whatever the incidence; each
    // ray is attenuated by a(μ') on its way up, leaves with T(μ') or is reflected back down with
    // R(μ') (attenuated once more at the same cosine: exact for smooth coats, lamina's
    // approximation for rough ones) and re-diffused by the base.
    const auto up = [&](double mu, bool transmitted) {
        Rgbd T, R;
        transmittance_up(out, mu, T, R);
        return transmitted ? beer_lambert(out.tau_base, 1 / mu) * T * (2 * mu)
                           : beer_lambert(out.tau_base, 2 / mu) * R * (2 * mu);
    };
    if (out.layered()) {
        // Several coats: the light leaving the top is taken from the downward run by reciprocity
        // (Snell's invariant maps μ outside to μ' at the base, μ' dμ' = (η_amb/η_b)² μ dμ):
        // T̄ = (η_amb/η_b)² ∫ 2μ T_down(μ) dμ. Bel18's adding from the base stops at an interface
        // whose mean direction is totally reflected and drops what the rough facets transmit
        // there, so its upward T would lose that light; its upward R (what returns to the base)
        // is kept.
        out.T_bar = integrate_split01<kGauss, Rgbd>(
                        [&](double mu) { return ddb22_transmittance_down(out, mu) * (2 * mu); },
                        split_out) *
                    sqr(stack.ambient_eta / eta_base_medium);
    } else {
        out.T_bar =
            integrate_split01<kGauss, Rgbd>([&](double mu) { return up(mu, true); }, split_in);
    }
    out.r_bar = integrate_split01<kGauss, Rgbd>([&](double mu) { return up(mu, false); }, split_in);
    for (int k = 0; k < 3; ++k) {
        const double rho = out.albedo[k];
        // 1 − ρ r̄ > 0: r̄ < 1 whenever anything leaves; kept ≥ 1e-9 (a white base under coats
        // that let nothing out returns nothing either: K = 0).
        out.K[k] = rho * out.T_bar[k] / std::max(1 - rho * out.r_bar[k], 1e-9);
    }

    // The directions of that light once outside: by reciprocity a uniform radiance at the base
    // leaves with radiance ∝ the coats' downward transmittance at μo (attenuated along the mean
    // refracted direction, the same approximation as a above); flux ∝ W(μo) μo dωo,
    // azimuthally symmetric about the normal, so its mean direction is the normal and its
    // projected variance V = ∫ W μ (1 − μ²) dμ / ∫ W μ dμ.
    const auto weight = [&](double mu) { return ddb22_transmittance_down(out, mu).mean() * mu; };
    const double flux = integrate_split01<kGauss, double>(weight, split_out);
    const double moment = integrate_split01<kGauss, double>(
        [&](double mu) { return weight(mu) * (1 - mu * mu); }, split_out);
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
        eta0_ = s_.eta0;
        alpha0_ = s_.alpha0;
        beta_ = s_.beta;
        albedo_beta_ = GgxNormalLobeTable::get().albedo(beta_);
        if (!ch_.lobe_at_normal) GgxAlbedoTable::get();
        if (s_.layered()) tir_table_prepare(kAdding.tir_table);
    }

    std::string name() const override { return "ddb22"; }
    Support support() const override { return support_; }

    /// Everything that depends on wi alone: the indirect lobe's energy E_ind(μi) (RGB) and, for
    /// several coats, the lobes of the coats below the top from Bel18's adding.
    struct Incident {
        Vec3d wi;
        Rgbd e_ind{0.0};
        double lobe_norm = 0;  ///< 1/albedo of the indirect lobe's shape
        BelcourStats coats;    ///< layered stacks: lobe k ≥ 1 is coat k's (lobe 0: the exact top)
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || !(wi.z > 0)) return in;
        const double mu_i = std::min(wi.z, 1.0);
        if (s_.layered()) {
            in.coats = belcour_adding(s_.down, mu_i, kAdding);
            in.e_ind = down_from_stats(s_, in.coats) * s_.K;
        } else {
            in.e_ind = ddb22_transmittance_down(s_, mu_i) * s_.K;
        }
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
        // The direct lobe: the top coat's reflection, F(wi·h) D G2/(4 μi μo) (Walter et al.
        // 2007, Eq. 20); a smooth coat's is a delta lobe (delta_lobes).
        if (alpha0_ > 0)
            f += Rgbd(fresnel_dielectric(dot(wi, h), eta0_) * ggx_lobe_shape(alpha0_, wi, wo, h));
        // The coats below the top (several coats): Bel18's GGX lobes (Belcour 2018, Eq. 1).
        for (int k = 1; k < in.coats.n_lobes; ++k)
            f += in.coats.lobes[k].energy * ggx_lobe_shape(in.coats.lobes[k].alpha, wi, wo, h);
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
        std::vector<DeltaLobe> out;
        if (!support_.brdf || !(wi.z > 0)) return out;
        const double mu_i = std::min(wi.z, 1.0);
        if (!(alpha0_ > 0))
            out.push_back({mirror_direction(wi), Rgbd(fresnel_dielectric(mu_i, eta0_))});
        if (s_.layered()) {
            const BelcourStats st = belcour_adding(s_.down, mu_i, kAdding);
            for (int k = 1; k < st.n_lobes; ++k)
                if (st.lobes[k].alpha == 0 && st.lobes[k].energy.max() > 0)
                    out.push_back({mirror_direction(wi), st.lobes[k].energy});
        }
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        return {mirror_direction(wi), Vec3d{0, 0, 1}};
    }

    // Importance sampling: a mixture of the lobes. The direct lobes (rough ones only: a smooth
    // lobe is a delta lobe, left out here as model.h says) by the visible normals of their GGX seen
    // from wi (Heitz 2018, JCGT 7(4)), wo their mirror about them; the indirect lobe by the
    // visible normals of GGX β seen from the lobe's own incidence (the normal, or wi with
    // indirect-lobe=mirror). Each lobe is chosen with its share of the energy, the top lobe's
    // being the coat's FGD(μi, α0, η0). A draw leaving below the surface is a failed sample.
    bool has_sampling() const override { return support_.brdf; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!support_.brdf || !(wi.z > 0)) return std::nullopt;
        const Incident in = incident(wi);
        const Mixture m = mixture(in);
        int pick = 0;
        double below = 0;
        while (pick + 1 < m.n && u.x >= below + m.p[pick])
            below += m.p[pick++];
        const Vec3d from = m.from_normal[pick] ? Vec3d{0, 0, 1} : wi;
        const GGX<double> ggx{m.alpha[pick]};
        const Vec3d wo = reflect(from, ggx.sample_visible_normal(from, u.y, u.z));
        if (!(wo.z > 0)) return std::nullopt;
        const double density = pdf_with(in, m, wo);
        if (!(density > 0)) return std::nullopt;
        return ModelSample{wo, eval_with(in, wo) * (wo.z / density), density};
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || !(wi.z > 0) || !(wo.z > 0)) return 0.0;
        const Incident in = incident(wi);
        return pdf_with(in, mixture(in), wo);
    }

  private:
    /// The sampled lobes for one incidence: probability, roughness, seen from wi or the normal.
    struct Mixture {
        static constexpr int kMax = BelcourStats::kMaxLobes + 1;
        int n = 0;
        std::array<double, kMax> p{}, alpha{};
        std::array<bool, kMax> from_normal{};
    };

    Mixture mixture(const Incident& in) const {
        Mixture m;
        const auto add = [&](double energy, double alpha, bool from_normal) {
            if (!(energy > 0) || !(alpha > 0) || m.n == Mixture::kMax) return;
            m.p[m.n] = energy;
            // ≥ the smallest roughness a stack file may hold, 1e-4: the visible normals of α = 0
            // are not a density.
            m.alpha[m.n] = std::max(alpha, 1e-4);
            m.from_normal[m.n++] = from_normal;
        };
        const double mu_i = std::min(in.wi.z, 1.0);
        add(FgdTable::get()(mu_i, alpha0_, eta0_, 0.0), alpha0_, false);
        for (int k = 1; k < in.coats.n_lobes; ++k)
            add(in.coats.lobes[k].energy.mean(), in.coats.lobes[k].alpha, false);
        add(in.e_ind.mean(), beta_, ch_.lobe_at_normal);
        // Nothing but delta lobes carries energy: sample the indirect lobe's shape (eval is 0).
        if (m.n == 0) {
            m.n = 1;
            m.p[0] = 1;
            m.alpha[0] = std::max(beta_, 1e-4);
            m.from_normal[0] = ch_.lobe_at_normal;
        }
        double sum = 0;
        for (int i = 0; i < m.n; ++i)
            sum += m.p[i];
        for (int i = 0; i < m.n; ++i)
            m.p[i] /= sum;
        return m;
    }

    /// Density of the mixture at wo (solid angle): p D_w(h)/(4 |w·h|) per lobe, the reflection
    /// Jacobian of Walter et al. 2007, Eq. 14.
    double pdf_with(const Incident& in, const Mixture& m, const Vec3d& wo) const {
        double density = 0;
        for (int i = 0; i < m.n; ++i) {
            const Vec3d from = m.from_normal[i] ? Vec3d{0, 0, 1} : in.wi;
            const GGX<double> ggx{m.alpha[i]};
            const Vec3d h = normalize(from + wo);
            const double c = dot(from, h);
            if (c > 0) density += m.p[i] * ggx.D_visible(from, h) / (4 * c);
        }
        return density;
    }

    Ddb22Choices ch_;
    Ddb22Stack s_;
    Support support_;
    double eta0_ = 1.5, alpha0_ = 0, beta_ = 1, albedo_beta_ = 1;
};

}  // namespace

const ModelOptionTable<Ddb22Choices>& ddb22_option_table() {
    using C = Ddb22Choices;
    static const ModelOptionTable<C> table({
        member_option<C, bool>("variance-mapping", &C::matched_variance,
                               {{"matched", true}, {"belcour", false}},
                               "indirect lobe roughness: the GGX lobe with the same projected "
                               "variance (matched) or Belcour 2018's a^1.1/(1-a^1.1) read as "
                               "V/(1-V)"),
        member_option<C, bool>("indirect-lobe", &C::lobe_at_normal,
                               {{"normal", true}, {"mirror", false}},
                               "indirect lobe centred on the normal (the mean of the light the "
                               "base returns) or a GGX reflection lobe of wi"),
    });
    return table;
}

std::unique_ptr<Model> make_ddb22_model(const std::string&, const Stack& stack,
                                        const Ddb22Choices& choices) {
    return std::make_unique<Ddb22>(stack, choices);
}

}  // namespace lamina

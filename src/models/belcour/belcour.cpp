#include "models/belcour/belcour.h"

#include "core/math.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

// Roughness ↔ variance (Belcour 2018, §5.1 and the author's code): σ(α) = α^1.1 / (1 − α^1.1),
// α(σ) = (σ / (1 + σ))^(1/1.1); α clamped below 1 (σ(1) is infinite). The quadratic alternative
// σ = α²/(1 − α²) is lamina's ablation (the exponent of a slope variance).
double belcour_variance_of_alpha(double alpha, bool quadratic, double alpha_max) {
    const double a = std::min(alpha, alpha_max);
    if (a <= 0) return 0;
    const double p = quadratic ? a * a : std::pow(a, 1.1);
    return p / (1 - p);
}
double belcour_alpha_of_variance(double sigma, bool quadratic) {
    if (!(sigma > 0)) return 0;
    const double s = 1 / (1 + 1 / sigma);  // σ/(1 + σ), also for σ = ∞ (→ 1)
    return quadratic ? std::sqrt(s) : std::pow(s, 1 / 1.1);
}

namespace {

// Henyey–Greenstein lobe variance (Belcour 2018, §5.3 and code): σ_HG(g) = ((1 − g)/g)^0.8 / (1 +
// g). Infinite as g → 0⁺ (a subnormal g gives ∞) and undefined for g ≤ 0 (reached only through
// medium-variance=every-medium on an absorbing medium): capped at the variance of the roughest
// lobe, σ(kBelcourAlphaMax), which α(σ) maps to the same clamped roughness; an infinite variance
// would reach the adding sums as ∞ · 0.
double variance_hg(double g) {
    const double cap = belcour_variance_of_alpha(kBelcourAlphaMax, false);
    if (!(g > 0)) return cap;
    return std::min(std::pow((1 - g) / g, 0.8) / (1 + g), cap);
}

// Belcour 2018, §6, as the author's code applies it ("decoupling approximation"): of the energy
// going up through the stack above, the fraction τ leaves; the rest is totally internally
// reflected back down: Ri0 ← min(Ri0 + (1 − τ) Ti0, 1), Ti0 ← τ Ti0 (the code clamps Ri0 to 1).
void total_internal_reflection(double tau, Rgbd& Ri0, Rgbd& Ti0) {
    for (int k = 0; k < 3; ++k) {
        Ri0[k] = std::min(Ri0[k] + (1 - tau) * Ti0[k], 1.0);
        Ti0[k] *= tau;
    }
}

double mean(const Rgbd& x) {
    return x.mean();
}

}  // namespace

namespace {

// The variance of the adding scheme as a number (Belcour 2018: one scalar per lobe) or as a 2×2
// covariance in the surface's frame (Weier & Belcour 2020); the scheme is the same loop for both
// (adding_impl), which reads the per-operator variances through these.
struct ScalarVariance {
    using V = double;
    bool q;
    V zero() const { return 0.0; }
    V of_alpha(const BelcourOperator& op, double (*scale)(double, double, double), double a1,
               double a2) const {
        return belcour_variance_of_alpha(scale(op.alpha, a1, a2), q);
    }
    V reflection(const BelcourOperator& op) const { return op.sigma_r; }
    V t12(const BelcourOperator& op) const { return op.sigma_t12; }
    V t21(const BelcourOperator& op) const { return op.sigma_t21; }
    V isotropic(double v) const { return v; }
    double scalar(V v) const { return v; }
    /// Nothing accumulated above: the interface's own (clamped) α is the roughness it reads.
    bool reads_own_alpha(V v) const { return v == 0; }
    void set_lobe(BelcourStats::Lobe& lobe, V v, double alpha) const {
        lobe.alpha = alpha;
        lobe.covariance = {v, v, 0};
    }
};

struct CovarianceVariance {
    using V = BelcourCovariance;
    bool q;
    double dx, dy;  ///< the incident azimuth (unit), along which the FGD tables read a roughness
    V zero() const { return {}; }
    V of_alpha(const BelcourOperator& op, double (*scale)(double, double, double), double a1,
               double a2) const {
        return BelcourCovariance::of_axes(belcour_variance_of_alpha(scale(op.alpha, a1, a2), q),
                                          belcour_variance_of_alpha(scale(op.alpha_b, a1, a2), q),
                                          op.tangent_cos, op.tangent_sin);
    }
    V reflection(const BelcourOperator& op) const { return op.cov_r; }
    V t12(const BelcourOperator& op) const { return op.cov_t12; }
    V t21(const BelcourOperator& op) const { return op.cov_t21; }
    V isotropic(double v) const { return {v, v, 0}; }
    bool mean;  ///< read the mean over azimuths instead (energy-roughness=mean)
    double scalar(const V& v) const { return mean ? 0.5 * (v.xx + v.yy) : v.along(dx, dy); }
    /// An anisotropic interface reads the roughness along the incident azimuth, never its α.
    bool reads_own_alpha(const V&) const { return false; }
    void set_lobe(BelcourStats::Lobe& lobe, const V& v, double) const {
        lobe.covariance = v;
        lobe.alpha = belcour_alpha_of_variance(std::max(v.xx, v.yy), q);
    }
};

double scale_identity(double alpha, double, double) {
    return alpha;
}
// α scalings of the transmission variances (a1, a2 their angle or index terms).
double scale_paper(double alpha, double ratio, double) {
    return alpha * 0.5 * std::abs(1 - ratio);  // Belcour 2018, Eq. 10 as lamina reads it
}
double scale_t12_code(double alpha, double n12, double) {
    return alpha * 0.5 * std::abs(n12 - 1) / n12;
}
double scale_t21_code(double alpha, double n12, double) {
    return alpha * 0.5 * std::abs(1 - n12);
}

// Kept in one piece (about 150 lines): Belcour 2018's adding of lobe statistics is one loop over
// the operators whose steps (paper §4–6 and the author's code: the interface's statistics, the TIR
// step, the adding sums, the medium) read best in the order the paper gives them.
template <typename Var>
BelcourStats adding_impl(const std::vector<BelcourOperator>& ops, double c0,
                         const BelcourChoices& ch, const Var& var) {
    using V = typename Var::V;
    const FgdTable& fgd = FgdTable::get();
    BelcourStats out;
    const bool q = ch.quadratic_mapping;
    // Initial state (docs/models.md "Adding"): nothing reflected, everything transmitted.
    Rgbd R0i(0.0), Ri0(0.0), T0i(1.0), Ti0(1.0);
    V sR0i = var.zero(), sRi0 = var.zero(), sT0i = var.zero(), sTi0 = var.zero();
    double J0i = 1, Ji0 = 1;
    double c = std::max(c0, 1e-6);
    bool first_interface = true;
    bool last_was_dielectric = false, last_transmits = false;
    // The index ratio η_above/η_below of the interface above the current layer, as light going up
    // sees it (tir=each-interface); 1: no step (the top, or a medium in between, as the author's
    // code has it unless tir_across_media).
    double eta_up = 1;
    for (std::size_t index = 0; index < ops.size(); ++index) {
        const BelcourOperator& op = ops[index];
        Rgbd R12(0.0), T12(0.0);
        V sR12 = var.zero(), sT12 = var.zero(), sT21 = var.zero();
        double J12 = 1, ct = c;
        bool transmits = false;
        double alpha_eff = 0;
        const bool is_interface = op.kind != BelcourOperator::Medium;
        if (is_interface) {
            const bool pre = op.precomputed && op.precomputed_quadratic == q;
            sR12 = pre ? var.reflection(op) : var.of_alpha(op, scale_identity, 0, 0);
            // Roughness the lobe sees: what was accumulated above plus this interface's own
            // (nothing above: α itself, α(σ(α)) = α).
            alpha_eff = pre && var.reads_own_alpha(sT0i)
                            ? op.alpha_clamped
                            : belcour_alpha_of_variance(var.scalar(sT0i + sR12), q);
            if (op.kind == BelcourOperator::Dielectric) {
                // Snell's law on the mean direction; TIR: no transmission.
                const double sin2_t = (1 - c * c) / sqr(op.n12);
                transmits = sin2_t < 1;
                if (transmits) ct = std::max(std::sqrt(1 - sin2_t), 1e-6);
                R12 =
                    Rgbd(pre ? fgd(c, alpha_eff, op.fgd_index[0]) : fgd(c, alpha_eff, op.n12, 0.0));
                if (transmits) {
                    T12 = Rgbd(1.0) - R12;
                    J12 = op.n12 * ct / c;  // Jacobian of the refracted variance
                    if (ch.sigma_t_paper) {
                        // Belcour 2018, Eq. 10 as lamina reads it: the first-order deflection of
                        // a refracted ray by a microfacet tilt, |1 − η_i cos θi / (η_t cos θt)|/2.
                        sT12 = var.of_alpha(op, scale_paper, c / (op.n12 * ct), 0);
                        sT21 = var.of_alpha(op, scale_paper, op.n12 * ct / c, 0);
                    } else {
                        // The author's code (docs/models.md): angle-independent scalings.
                        sT12 = pre ? var.t12(op) : var.of_alpha(op, scale_t12_code, op.n12, 0);
                        sT21 = pre ? var.t21(op) : var.of_alpha(op, scale_t21_code, op.n12, 0);
                    }
                }
            } else {
                if (pre) {
                    R12 = fgd.rgb(c, alpha_eff, op.fgd_index);
                } else {
                    for (int i = 0; i < 3; ++i)
                        R12[i] = fgd(c, alpha_eff, op.eta[i], op.k[i]);
                }
            }
        } else {
            // Medium (docs/models.md "Per medium"): unscattered plus once forward-scattered light,
            // T = (1 + τs L) e^{−(τa+τs) L}, L = 1/c; no reflection; the scattered part widens
            // the lobe by σ_HG(g) (only when the medium scatters, unless every medium does).
            const double L = 1 / c;
            const Rgbd tau_t = op.tau_a + op.tau_s;
            T12 = (Rgbd(1.0) + op.tau_s * L) * exp_rgb(tau_t * -L);
            sT12 = sT21 = var.isotropic(
                op.tau_s.max() > 0 || ch.medium_variance_every_medium ? variance_hg(op.g) : 0.0);
            transmits = true;
        }
        if (is_interface && ch.tir == BelcourTir::EachInterface && eta_up != 1) {
            // The author's placement: before this interface's sums, for the interface above it,
            // at the cosine in the layer between and the roughness this interface reads its FGD
            // at — the spread of the light coming back up (the decoupling approximation).
            total_internal_reflection(tir_fraction(ch.tir_table, c, alpha_eff, eta_up), Ri0, Ti0);
        }
        const Rgbd R21 = R12, T21 = T12;
        const V sR21 = sR12;
        const double J21 = 1 / J12;

        // Adding (docs/models.md): Dn = 1 − Ri0·R12 sums the inter-reflections between this
        // operator and everything above.
        Rgbd Dn = Rgbd(1.0) - Ri0 * R12;
        for (int i = 0; i < 3; ++i)
            Dn[i] = std::max(Dn[i], 1e-9);  // two perfect mirrors facing
        const Rgbd E = T0i * R12 * Ti0 / Dn;
        const double rr = mean(Ri0 * R12 / Dn);
        if (is_interface && out.n_lobes < BelcourStats::kMaxLobes) {
            // The lobe variance uses J0i before this layer, as the author's code does.
            const V sigma_k = sTi0 + J0i * (sT0i + sR12 + rr * (sR12 + sRi0));
            const bool only_own = op.precomputed && op.precomputed_quadratic == q &&
                                  sigma_k == sR12;  // nothing accumulated: α itself
            BelcourStats::Lobe& lobe = out.lobes[out.n_lobes++];
            lobe.energy = E;
            var.set_lobe(
                lobe, sigma_k,
                only_own ? op.alpha_clamped : belcour_alpha_of_variance(var.scalar(sigma_k), q));
            const double w_old = mean(R0i), w_new = mean(E);
            if (w_old + w_new > 0) sR0i = (w_old * sR0i + w_new * sigma_k) / (w_old + w_new);
        }
        R0i += E;
        const Rgbd through = T21 * Ri0 * T12 / Dn;
        const Rgbd new_T0i = T0i * T12 / Dn;
        const Rgbd new_Ri0 = R21 + through;
        const Rgbd new_Ti0 = T21 * Ti0 / Dn;
        const V new_sT0i = J12 * sT0i + sT12 + J12 * (sR12 + sRi0) * rr;
        const double norm = mean(new_Ri0);
        const V new_sRi0 =
            norm > 0 ? (mean(R21) * sR21 +
                        mean(through) * (sT12 + J12 * (sT21 + sRi0 + rr * (sR12 + sRi0)))) /
                           norm
                     : var.zero();
        const V new_sTi0 = Ji0 * sT21 + sTi0 + Ji0 * (sR12 + sRi0) * rr;
        T0i = new_T0i;
        Ri0 = new_Ri0;
        Ti0 = new_Ti0;
        sT0i = new_sT0i;
        sRi0 = new_sRi0;
        sTi0 = new_sTi0;
        const bool medium_below =
            index + 1 < ops.size() && ops[index + 1].kind == BelcourOperator::Medium;
        if (is_interface && first_interface && op.kind == BelcourOperator::Dielectric &&
            transmits && ch.tir == BelcourTir::TopInterface &&
            (ch.tir_across_media || !medium_below)) {
            // lamina's former placement: right after the top interface, at its refracted cosine
            // and its own roughness.
            total_internal_reflection(tir_fraction(ch.tir_table, ct, alpha_eff, 1 / op.n12), Ri0,
                                      Ti0);
        }
        if (is_interface) first_interface = false;
        if (op.kind == BelcourOperator::Dielectric)
            eta_up = 1 / op.n12;
        else if (op.kind == BelcourOperator::Medium && !ch.tir_across_media)
            eta_up = 1;
        c = ct;
        J0i *= J12;
        Ji0 *= J21;
        last_was_dielectric = op.kind == BelcourOperator::Dielectric;
        last_transmits = transmits;
        if (op.kind == BelcourOperator::Conductor || (is_interface && !transmits)) break;
    }
    (void)sR0i;  // the reflected variance, tracked as docs/models.md writes it; no lobe uses it
    if (last_was_dielectric && last_transmits) {
        out.transmits = true;
        out.transmitted = T0i;
        out.alpha_t = belcour_alpha_of_variance(var.scalar(sT0i), q);
        out.covariance_t = BelcourCovariance(sT0i);
        out.cos_t = c;
    }
    return out;
}

}  // namespace

BelcourStats belcour_adding(const std::vector<BelcourOperator>& ops, double c0,
                            const BelcourChoices& ch) {
    return adding_impl(ops, c0, ch, ScalarVariance{ch.quadratic_mapping});
}

BelcourStats belcour_adding_anisotropic(const std::vector<BelcourOperator>& ops, double c0,
                                        const BelcourChoices& ch, double dir_x, double dir_y) {
    return adding_impl(
        ops, c0, ch,
        CovarianceVariance{ch.quadratic_mapping, dir_x, dir_y, ch.energy_roughness_mean});
}

void precompute_variances(std::vector<BelcourOperator>& ops, bool q) {
    for (BelcourOperator& op : ops) {
        op.precomputed = true;
        op.precomputed_quadratic = q;
        op.alpha_clamped = belcour_alpha_of_variance(belcour_variance_of_alpha(op.alpha, q), q);
        op.sigma_r = belcour_variance_of_alpha(op.alpha, q);
        op.sigma_t12 = belcour_variance_of_alpha(op.alpha * 0.5 * std::abs(op.n12 - 1) / op.n12, q);
        op.sigma_t21 = belcour_variance_of_alpha(op.alpha * 0.5 * std::abs(1 - op.n12), q);
        const CovarianceVariance cov{q, 1, 0, false};
        op.cov_r = cov.of_alpha(op, scale_identity, 0, 0);
        op.cov_t12 = cov.of_alpha(op, scale_t12_code, op.n12, 0);
        op.cov_t21 = cov.of_alpha(op, scale_t21_code, op.n12, 0);
        for (int i = 0; i < 3; ++i)
            op.fgd_index[i] = op.kind == BelcourOperator::Conductor
                                  ? FgdTable::locate(op.eta[i], op.k[i])
                                  : FgdTable::locate(op.n12, 0.0);
    }
}

double ggx_lobe_shape(double alpha, const Vec3d& wi, const Vec3d& wo, const Vec3d& h) {
    if (alpha <= 0) return 0;
    // Interfaces within rounding of index matching give accumulated lobes of roughness 1e-17 or
    // less, whose peak 1/(πα²) overflows (found by the fuzz test). Below the smallest roughness a
    // stack file may hold, 1e-4, a lobe is a mirror for every purpose: it is evaluated with that
    // roughness (the same energy, a finite peak).
    constexpr double kAlphaMin = 1e-4;
    const GGX<double> ggx{std::max(alpha, kAlphaMin)};
    return ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
}

BelcourAnisotropicLobe belcour_lobe_of_covariance(const BelcourCovariance& c, bool q) {
    // Eigen-decomposition of the symmetric 2×2 covariance: λ = m ± r, m the mean of the diagonal,
    // r = √(((xx − yy)/2)² + xy²); the major axis at ψ = atan2(2 xy, xx − yy)/2.
    const double m = 0.5 * (c.xx + c.yy), d = 0.5 * (c.xx - c.yy);
    const double r = std::hypot(d, c.xy);
    BelcourAnisotropicLobe lobe;
    lobe.alpha_x = belcour_alpha_of_variance(m + r, q);
    lobe.alpha_y = belcour_alpha_of_variance(m - r, q);
    lobe.psi = r > 0 ? 0.5 * std::atan2(c.xy, d) : 0.0;
    return lobe;
}

namespace {

double lobe_shape(double alpha, const Vec3d& wi, const Vec3d& wo, const Vec3d& h) {
    return ggx_lobe_shape(alpha, wi, wo, h);
}

// Weier & Belcour 2020: a lobe as the anisotropic GGX of its covariance, D G2 / (4 μi μo) with
// the energy factored out; the isotropic lobe (ggx_lobe_shape) when its axes are equal.
double anisotropic_lobe_shape(const BelcourCovariance& cov, bool q, const Vec3d& wi,
                              const Vec3d& wo, const Vec3d& h) {
    const BelcourAnisotropicLobe l = belcour_lobe_of_covariance(cov, q);
    if (l.alpha_x <= 0) return 0;
    if (l.alpha_y == l.alpha_x) return ggx_lobe_shape(l.alpha_x, wi, wo, h);
    constexpr double kAlphaMin = 1e-4;  // as ggx_lobe_shape: a finite peak for a mirror axis
    const GGX<double> ggx = GGX<double>::anisotropic(std::max(l.alpha_x, kAlphaMin),
                                                     std::max(l.alpha_y, kAlphaMin), l.psi);
    return ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
}

class BelcourModel final : public Model {
  public:
    BelcourModel(std::string name, const Stack& stack, const BelcourChoices& ch)
        : name_(std::move(name)), ch_(ch) {
        int interfaces = 0;
        for (std::size_t i = 0; i < stack.layers.size(); ++i) {
            const InterfaceSpec& s = stack.layers[i].interface;
            const double above = stack.eta_above(i);
            BelcourOperator op;
            op.alpha = s.alpha;
            op.alpha_b = s.alpha_b();
            op.tangent_cos = std::cos(deg_to_rad(s.tangent_deg));
            op.tangent_sin = std::sin(deg_to_rad(s.tangent_deg));
            switch (s.type) {
                case InterfaceType::Lambertian:
                    support_.reason = fmt::format("{} has no Lambertian base", name_);
                    return;
                case InterfaceType::Dielectric:
                    op.kind = BelcourOperator::Dielectric;
                    op.n12 = model_relative_eta(s.eta / above);
                    op.eta = Rgbd(op.n12);
                    break;
                case InterfaceType::Conductor:
                    op.kind = BelcourOperator::Conductor;
                    op.eta = model_relative_eta(s.eta_rgb / above);
                    op.k = model_relative_k(s.k / above);
                    op.n12 = op.eta.mean();
                    break;
            }
            ops_.push_back(op);
            ++interfaces;
            if (stack.layers[i].has_medium && !stack.layers[i].medium.is_empty()) {
                const MediumSpec& m = stack.layers[i].medium;
                BelcourOperator med;
                med.kind = BelcourOperator::Medium;
                med.tau_a = m.tau_a;
                med.tau_s = m.tau_s;
                med.g = m.g.mean();
                if (m.scatters() && !(med.g > 0)) {
                    support_.reason = fmt::format(
                        "{} scatters only forwards (its medium operator needs HG g > 0, the stack "
                        "has g = {})",
                        name_, med.g);
                    return;
                }
                ops_.push_back(med);
            }
        }
        if (interfaces == 0 || interfaces > BelcourStats::kMaxLobes) {
            support_.reason =
                fmt::format("{} needs 1 to {} interfaces", name_, int(BelcourStats::kMaxLobes));
            return;
        }
        support_.brdf = true;
        if (stack.transmits()) {
            support_.btdf = ch_.btdf;
            if (!ch_.btdf) support_.reason = fmt::format("{} gives no BTDF (Bel' does)", name_);
        }
        precompute_variances(ops_, ch_.quadratic_mapping);
        // Build (or load) the tables now, outside any parallel region of the callers: a first
        // use inside one would compute them with a single thread.
        FgdTable::get();
        if (ch_.tir != BelcourTir::Off) tir_table_prepare(ch_.tir_table);
        top_ = ops_.front();
    }

    std::string name() const override { return name_; }
    Support support() const override { return support_; }

    BelcourStats stats(double c0, const Vec3d& wi) const {
        if (!ch_.anisotropic) return belcour_adding(ops_, c0, ch_);
        // The incident azimuth, along which the energies read their roughness (any at normal
        // incidence, where an anisotropic lobe has no preferred azimuth).
        const double s = std::hypot(wi.x, wi.y);
        return s > 0 ? belcour_adding_anisotropic(ops_, c0, ch_, wi.x / s, wi.y / s)
                     : belcour_adding_anisotropic(ops_, c0, ch_, 1, 0);
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z == 0) return Rgbd(0.0);
        if (wo.z > 0) {
            const Vec3d h = normalize(wi + wo);
            const double c0 = ch_.symmetric ? std::abs(dot(wi, h)) : wi.z;
            return eval_with(stats(c0, wi), wi, wo);
        }
        if (!support_.btdf) return Rgbd(0.0);
        return eval_with(stats(wi.z, wi), wi, wo);
    }

    /// Sum of the lobes for precomputed statistics (forward: depend only on wi).
    Rgbd eval_with(const BelcourStats& st, const Vec3d& wi, const Vec3d& wo) const {
        if (wo.z < 0) return eval_btdf(st, wi, wo);
        const Vec3d h = normalize(wi + wo);
        Rgbd f(0.0);
        for (int k = 0; k < st.n_lobes; ++k) {
            if (k == 0 && ch_.exact_top) {
                f += exact_top(wi, wo, h);
                continue;
            }
            f += st.lobes[k].energy *
                 (ch_.anisotropic ? anisotropic_lobe_shape(st.lobes[k].covariance,
                                                           ch_.quadratic_mapping, wi, wo, h)
                                  : lobe_shape(st.lobes[k].alpha, wi, wo, h));
        }
        return f;
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> out;
        if (!support_.brdf || wi.z <= 0) return out;
        const BelcourStats st = stats(wi.z, wi);  // at the mirror pair |wi·h| = μi: both variants
        const Vec3d wr = mirror_direction(wi);
        for (int k = 0; k < st.n_lobes; ++k) {
            if (k == 0 && ch_.exact_top) {
                if (top_.alpha == 0) out.push_back({wr, top_fresnel(wi.z)});
                continue;
            }
            if (st.lobes[k].alpha == 0 && st.lobes[k].energy.max() > 0)
                out.push_back({wr, st.lobes[k].energy});
        }
        if (support_.btdf && st.transmits && st.alpha_t == 0 && st.transmitted.max() > 0)
            out.push_back({transmitted_direction(wi, st.cos_t), st.transmitted});
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> peaks{mirror_direction(wi)};
        if (support_.btdf) {
            const BelcourStats st = stats(wi.z, wi);
            if (st.transmits) peaks.push_back(transmitted_direction(wi, st.cos_t));
        }
        return peaks;
    }

  private:
    /// The straight-through direction with cosine cos_t below the surface, opposite wi's azimuth.
    static Vec3d transmitted_direction(const Vec3d& wi, double cos_t) {
        const double s = std::hypot(wi.x, wi.y);
        const double sin_t = safe_sqrt(1 - cos_t * cos_t);
        if (s == 0) return {0, 0, -1};
        return {-sin_t * wi.x / s, -sin_t * wi.y / s, -cos_t};
    }

    Rgbd top_fresnel(double cos_theta) const {
        if (top_.kind == BelcourOperator::Conductor)
            return fresnel_complex_rgb(cos_theta, top_.eta, top_.k);
        return Rgbd(fresnel_dielectric(cos_theta, top_.n12));
    }

    /// Bel': the exact reflection of the top interface, F(wi·h) D G2 / (4 μi μo) (Walter et al.
    /// 2007, Eq. 20).
    Rgbd exact_top(const Vec3d& wi, const Vec3d& wo, const Vec3d& h) const {
        if (top_.alpha <= 0) return Rgbd(0.0);
        return top_fresnel(dot(wi, h)) * lobe_shape(top_.alpha, wi, wo, h);
    }

    /// Bel' BTDF: a GGX reflection lobe of energy T0i and roughness α(sT0i) for the virtual
    /// incidence wv at the transmitted mean cosine, mirrored through z = 0, so that its peak is
    /// the refracted mean direction (docs/models.md; lamina's documented choice).
    Rgbd eval_btdf(const BelcourStats& st, const Vec3d& wi, const Vec3d& wo) const {
        if (!support_.btdf || !st.transmits || st.alpha_t <= 0) return Rgbd(0.0);
        const Vec3d wt = transmitted_direction(wi, st.cos_t);
        const Vec3d wv = mirror_direction(flip_z(wt));  // virtual incidence above the surface
        const Vec3d wo_up = flip_z(wo);
        const Vec3d h = normalize(wv + wo_up);
        return st.transmitted * lobe_shape(st.alpha_t, wv, wo_up, h);
    }

    std::string name_;
    BelcourChoices ch_;
    std::vector<BelcourOperator> ops_;
    BelcourOperator top_;
    Support support_;
};

class BelcourForwardEvaluator final : public IncidentEvaluator {
  public:
    BelcourForwardEvaluator(const BelcourModel& model, const Vec3d& wi)
        : model_(model), wi_(wi), stats_(model.stats(wi.z, wi)) {}
    Rgbd eval(const Vec3d& wo) const override {
        if (wi_.z <= 0 || wo.z == 0) return Rgbd(0.0);
        return model_.eval_with(stats_, wi_, wo);
    }

  private:
    const BelcourModel& model_;
    Vec3d wi_;
    BelcourStats stats_;
};

std::unique_ptr<IncidentEvaluator> BelcourModel::prepare(const Vec3d& wi) const {
    if (ch_.symmetric || !support_.brdf) return Model::prepare(wi);
    return std::make_unique<BelcourForwardEvaluator>(*this, wi);
}

}  // namespace

namespace {

std::vector<ModelOption<BelcourChoices>> belcour_options() {
    using C = BelcourChoices;
    return {
        member_option<C, bool>(
            "cosine", &C::symmetric, {{"forward", false}, {"symmetric", true}},
            "cosine fed to the adding scheme: mu_i (forward) or |wi.h| (symmetric, reciprocal)"),
        enum_member<C>("tir", &C::tir,
                       "total-internal-reflection step: while adding each interface below the "
                       "top, for the one above, at the roughness of the light coming back (the "
                       "author's code); once below the top interface at its own roughness; or "
                       "none"),
        enum_member<C>("tir-table", &C::tir_table,
                       "what the step's fraction holds: a flat interface's Fresnel transmittance "
                       "over the light's GGX lobe (the author's table), that lobe's part inside "
                       "the escape cone, or what a rough interface's microfacets refract of "
                       "collimated light"),
        member_option<C, bool>("tir-media", &C::tir_across_media,
                               {{"skip", false}, {"cross", true}},
                               "a medium between two interfaces: no step for the interface above "
                               "it (the author's code) or the step across it"),
        member_option<C, bool>("sigma-t", &C::sigma_t_paper, {{"code", false}, {"paper", true}},
                               "transmission variance: the author's code or the paper's Eq. 10"),
        member_option<C, bool>("variance-mapping", &C::quadratic_mapping,
                               {{"power", false}, {"quadratic", true}},
                               "roughness <-> variance: a^1.1/(1-a^1.1) (Belcour) or a^2/(1-a^2)"),
        member_option<C, bool>("medium-variance", &C::medium_variance_every_medium,
                               {{"scattering", false}, {"every-medium", true}},
                               "a medium widens the lobes by the HG variance of its g when it "
                               "scatters, or every medium by its g (the author's operator with "
                               "the stack's g)"),
    };
}

}  // namespace

const ModelOptionTable<BelcourChoices>& belcour_option_table() {
    static const ModelOptionTable<BelcourChoices> table(belcour_options());
    return table;
}

const ModelOptionTable<BelcourChoices>& wb20_option_table() {
    using C = BelcourChoices;
    static const ModelOptionTable<C> table([] {
        std::vector<ModelOption<C>> options = belcour_options();
        options.push_back(member_option<C, bool>(
            "energy-roughness", &C::energy_roughness_mean, {{"incident", false}, {"mean", true}},
            "roughness the FGD and TIR tables read for a covariance: along the incident azimuth "
            "or its mean over azimuths"));
        return options;
    }());
    return table;
}

BelcourChoices belcour_variant(const std::string& variant) {
    BelcourChoices c;
    if (variant == "bel18-symmetric") {
        // c0 = |wi·h| = |wo·h| (paper §7, "reciprocity"): the lobe statistics are recomputed for
        // every pair (table lookups only) and the BRDF is reciprocal by construction.
        c.symmetric = true;
    } else if (variant == "bel-prime") {
        // Bel', the 2019 study's correction (docs/models.md): Bel18 forward with lobe 0 replaced
        // by the exact microfacet reflection of the top interface (Walter et al. 2007, Eq. 20),
        // and the slab's BTDF as one transmitted GGX lobe of energy T0i, roughness α(sT0i) and
        // the refracted mean direction, evaluated as the mirror image through z = 0 of a
        // reflection lobe with those statistics.
        c.exact_top = true;
        c.btdf = true;
    } else if (variant == "wb20") {
        // Weier & Belcour 2020, "Rendering layered materials with anisotropic interfaces", JCGT
        // 9(2): Bel18 forward with each variance a 2×2 covariance (docs/models.md, "WB20").
        c.anisotropic = true;
    } else {
        // Bel18 forward: the adding scheme fed the incident direction's own cosine c0 = μi (as in
        // the author's renderer); the lobe statistics then depend only on wi, so the study
        // computes them once per incidence (prepare). Not reciprocal.
        LAMINA_CHECK(variant == "bel18-forward");
    }
    return c;
}

std::unique_ptr<Model> make_belcour_model(const std::string& name, const Stack& stack,
                                          const BelcourChoices& choices) {
    return std::make_unique<BelcourModel>(name, stack, choices);
}

}  // namespace lamina

#include "models/transfer_matrix.h"

#include "core/math.h"
#include "models/belcour.h"
#include "models/tir_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

double tm_hg_from_ggx(double alpha) {
    if (alpha <= 0) return 1.0;
    const double a = std::min(alpha, 1.0);
    return clamp(-0.085 + 1.085 / (1 + std::pow(a / 0.5, 1.3)), 0.0, 1.0);
}

double tm_ggx_from_hg(double g) {
    const double gc = std::max(clamp(g, -1.0, 1.0), 0.2);
    return clamp(0.5 * std::pow(1.085 / (gc + 0.085) - 1, 1 / 1.3), 1e-4, 1.0);
}

double tm_hg_refract(double g, double eta) {
    return std::min(safe_sqrt(1 - (1 - g * g) * std::pow(eta, 0.75)), 1.0);
}

namespace {

const char* on_off(bool b) {
    return b ? "on" : "off";
}

/// Optical paths are clamped as in the released code (TM_EXP_ARG_MAX): 1/T stays finite.
constexpr double kMaxOpticalPath = 45;
/// Below this a transmission factor is treated as zero (the matrix needs 1/t).
constexpr double kTinyT = 1e-12;

Rgbd max_of(const Rgbd& a, const Rgbd& b) {
    return {std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2])};
}

/// A 2×2 transfer matrix with entries of type T (Rgbd for energies, double for asymmetries).
template <typename T>
struct Matrix2 {
    T m11, m12, m21, m22;
    static Matrix2 identity() { return {T(1.0), T(0.0), T(0.0), T(1.0)}; }
    /// The matrix of a component with downward (r, t) and upward (rp, tp) factors
    /// (Randrianandrasana et al. 2021; tm.h energy_matrix).
    static Matrix2 component(const T& r, const T& t, const T& rp, const T& tp) {
        const T t_inv = T(1.0) / t;
        return {t_inv, T(0.0) - rp * t_inv, r * t_inv, (t * tp - r * rp) * t_inv};
    }
    Matrix2 operator*(const Matrix2& b) const {
        return {m11 * b.m11 + m12 * b.m21, m11 * b.m12 + m12 * b.m22, m21 * b.m11 + m22 * b.m21,
                m21 * b.m12 + m22 * b.m22};
    }
    T reflectance() const { return m21 / m11; }
    T transmittance() const { return T(1.0) / m11; }
    /// Reflectance over an opaque base of reflectance rb.
    /// Reflectance over an opaque base of reflectance rb; the denominator m11 (1 − r′ r_b) is kept
    /// ≥ 1e−9 m11, as Belcour's adding keeps 1 − R R ≥ 1e−9 (two perfect mirrors facing).
    T reflectance_over(const T& rb) const {
        return (m21 + m22 * rb) / max_of(m11 + m12 * rb, m11 * 1e-9);
    }
};

/// The transfer factors of one component at the mean direction of the light reaching it.
struct Factors {
    Rgbd r{0.0}, t{1.0}, rp{0.0}, tp{1.0};
    double gr = 0, gt = 1, grp = 0, gtp = 1;
    double c_above = 1, c_below = 1;
    bool skip = false;    ///< an index-matched dielectric: no component at all
    bool opaque = false;  ///< conductor, or a dielectric that reflects the mean direction totally
};

Rgbd max_rgb(const Rgbd& x, double lo) {
    return {std::max(x[0], lo), std::max(x[1], lo), std::max(x[2], lo)};
}

/// A lobe's asymmetry from its g-weighted energy: g = weighted/energy (≤ 1), RGB means for the
/// released scheme (one g per lobe), else per channel; α = α(g).
void set_asymmetry(TmLobes::Lobe& lobe, const Rgbd& weighted, bool per_channel) {
    const auto ratio = [](double w, double e) { return e > 0 ? std::min(w / e, 1.0) : 0.0; };
    if (!per_channel) {
        lobe.g = ratio(weighted.mean(), lobe.energy.mean());
        lobe.alpha = tm_ggx_from_hg(lobe.g);
        lobe.alpha_rgb = Rgbd(lobe.alpha);
        return;
    }
    for (int c = 0; c < 3; ++c)
        lobe.alpha_rgb[c] = tm_ggx_from_hg(ratio(weighted[c], lobe.energy[c]));
    lobe.g = ratio(weighted.mean(), lobe.energy.mean());
    lobe.alpha = tm_ggx_from_hg(lobe.g);
}

}  // namespace

TmLobes tm_lobes(const std::vector<TmComponent>& comps, double c0, const TmChoices& ch) {
    const FgdTable& fgd = FgdTable::get();
    TmLobes out;
    const int n = int(comps.size());
    std::array<Factors, 2 * TmLobes::kMaxLobes> f{};

    // 1. Transfer factors along the refracted mean direction (tm.h dielectric_transfer_factors,
    //    conductor_transfer_factors; media: lamina's absorbing layer, below).
    double c = std::max(c0, 1e-6);
    int n_used = n;
    for (int i = 0; i < n; ++i) {
        const TmComponent& k = comps[i];
        Factors& x = f[i];
        if (k.kind == TmComponent::Dielectric) {
            if (std::abs(k.eta - 1) < 1e-5) {
                x.skip = true;
                continue;
            }
            x.gr = x.grp = tm_hg_from_ggx(k.alpha);
            x.c_above = c;
            const double r = std::abs(k.eta - 1) < 1e-3 ? 0.0 : fgd(c, k.alpha, k.fgd_index[0]);
            x.r = x.rp = Rgbd(r);
            const double sin2_t = (1 - c * c) / sqr(k.eta);
            if (sin2_t >= 1) {  // the mean direction is totally reflected: nothing goes on
                x.opaque = true;
                n_used = i + 1;
                break;
            }
            const double ct = std::max(std::sqrt(1 - sin2_t), 1e-6);
            // Rough transmission as a GGX lobe of roughness ½ s α (tm.h: "fake rough
            // transmissions scaling factors"), s from the mean directions above and below.
            const double s_down = std::abs(c / (k.eta * ct) - 1);
            const double s_up = std::abs(1 - k.eta * ct / c);
            x.gt = tm_hg_from_ggx(0.5 * s_down * k.alpha);
            x.gtp = tm_hg_from_ggx(0.5 * s_up * k.alpha);
            if (ch.upward_fgd) x.rp = Rgbd(fgd(ct, k.alpha, 1 / k.eta, 0.0));
            x.t = Rgbd(1.0) - x.r;
            x.tp = Rgbd(1.0) - x.rp;
            x.c_below = ct;
            c = ct;
        } else if (k.kind == TmComponent::Medium) {
            // An absorbing layer: r = r′ = 0, t = t′ = exp(−τa/μ) along the mean direction, its
            // asymmetry unchanged (g = 1, the primary-flux block of the released tm6 medium).
            const Rgbd path = k.tau_a * (1 / c);
            for (int ch3 = 0; ch3 < 3; ++ch3)
                x.t[ch3] = x.tp[ch3] = std::exp(-std::min(path[ch3], kMaxOpticalPath));
            x.c_above = x.c_below = c;
        } else {
            x.r = fgd.rgb(c, k.alpha, k.fgd_index);
            x.gr = tm_hg_from_ggx(k.alpha);
            x.c_above = c;
            x.opaque = true;
            n_used = i + 1;
            break;
        }
    }

    // 2. First-order asymmetries, TIR, matrix products and one lobe per interface
    //    (tm2.cpp / tm2_dielectric.cpp outgoing_lobes).
    auto E = Matrix2<Rgbd>::identity();
    auto G = Matrix2<Rgbd>::identity();
    Rgbd e_above(0.0);
    Rgbd g_above(0.0);
    // The weights of the asymmetry matrices: the released RGB means, or each channel's own.
    const auto weight = [&](const Rgbd& x) { return ch.per_channel_g ? x : Rgbd(x.mean()); };
    double g_T = 1;  // asymmetry of the light transmitted down to the current component
    bool smooth = true;
    bool opaque_end = false;
    for (int i = 0; i < n_used; ++i) {
        const TmComponent& k = comps[i];
        Factors x = f[i];
        if (x.skip) continue;
        if (k.kind == TmComponent::Medium) {
            E = E * Matrix2<Rgbd>::component(x.r, x.t, x.rp, x.tp);
            G = G * Matrix2<Rgbd>::component(Rgbd(0.0), weight(x.t), Rgbd(0.0), weight(x.tp));
            continue;
        }
        smooth = smooth && k.alpha <= 0;
        Rgbd R;
        Rgbd Rg;
        double g_T_next = g_T;
        if (!x.opaque) {
            // The asymmetry of the light refracted down, reflected by the next interface and
            // refracted back up, to first order; the factors' g are the ratios of these.
            g_T_next = tm_hg_refract(g_T, 1 / k.eta) * x.gt;
            double g_next_r = 1.0;  // the slab's last interface: nothing below reflects
            for (int j = i + 1; j < n_used; ++j)
                if (!f[j].skip && comps[j].kind != TmComponent::Medium) {
                    g_next_r = f[j].gr;
                    break;
                }
            const double g_TR = g_T_next * g_next_r;
            const double g_TRT = tm_hg_refract(g_TR, k.eta) * x.gtp;
            x.gt = g_T != 0 ? g_T_next / g_T : 0.0;
            x.gtp = g_TR != 0 ? g_TRT / g_TR : 0.0;
            if (ch.tir) {
                const TirTable& tir = TirTable::get();
                if (k.eta < 1) {
                    // Downward TIR (into a lower index), at the roughness of the arriving light.
                    const double a = g_T >= 1 ? 0.0 : tm_ggx_from_hg(g_T);
                    const Rgbd moved = x.t * (1 - tir(x.c_above, a, k.eta));
                    x.r += moved;
                    x.t = x.t - moved;
                } else if (!ch.upward_fgd) {
                    // Upward TIR of the light coming back from below.
                    const double a = g_TR >= 1 ? 0.0 : tm_ggx_from_hg(g_TR);
                    const Rgbd moved = x.tp * (1 - tir(x.c_below, a, 1 / k.eta));
                    x.rp += moved;
                    x.tp = x.tp - moved;
                }
            }
            for (int ch3 = 0; ch3 < 3; ++ch3) {
                x.t[ch3] = std::max(x.t[ch3], kTinyT);
                x.tp[ch3] = std::max(x.tp[ch3], 0.0);
            }
            E = E * Matrix2<Rgbd>::component(x.r, x.t, x.rp, x.tp);
            G = G * Matrix2<Rgbd>::component(weight(x.r) * x.gr,
                                             max_rgb(weight(x.t) * x.gt, kTinyT),
                                             weight(x.rp) * x.grp, weight(x.tp) * x.gtp);
            R = E.reflectance();
            Rg = G.reflectance();
        } else {
            R = E.reflectance_over(x.r);
            Rg = G.reflectance_over(weight(x.r) * x.gr);
            opaque_end = true;
        }
        if (out.n_lobes < TmLobes::kMaxLobes) {
            TmLobes::Lobe& lobe = out.lobes[out.n_lobes++];
            // Clamped at 0 (as the released tm6 does): where a channel is absorbed the difference
            // is 0 up to rounding (≈ −1e−17 otherwise).
            lobe.energy = max_of(R - e_above, Rgbd(0.0));
            set_asymmetry(lobe, Rg - g_above, ch.per_channel_g);
            lobe.delta = smooth;
            lobe.component = i;
        }
        e_above = R;
        g_above = Rg;
        g_T = g_T_next;
        if (x.opaque) break;
    }
    if (ch.slab && !opaque_end) {
        out.transmits = true;
        out.transmitted.energy = max_of(E.transmittance(), Rgbd(0.0));
        set_asymmetry(out.transmitted, G.transmittance(), ch.per_channel_g);
        out.transmitted.delta = smooth;
        out.cos_t = c;
    }
    return out;
}

namespace {

/// The straight-through direction with cosine cos_t below the surface, opposite wi's azimuth.
Vec3d transmitted_direction(const Vec3d& wi, double cos_t) {
    const double s = std::hypot(wi.x, wi.y);
    const double sin_t = safe_sqrt(1 - cos_t * cos_t);
    if (s == 0) return {0, 0, -1};
    return {-sin_t * wi.x / s, -sin_t * wi.y / s, -cos_t};
}

/// The virtual incidence above the surface whose GGX reflection lobe, mirrored through z = 0, is
/// the transmitted lobe (tm2_dielectric.cpp: lobes_wi = reflectZ(t.mean), evaluated with |z|).
Vec3d virtual_incidence(const Vec3d& wi, double cos_t) {
    return mirror_direction(flip_z(transmitted_direction(wi, cos_t)));
}

class TmModel final : public Model {
  public:
    TmModel(std::string name, const Stack& stack, const TmChoices& ch)
        : name_(std::move(name)), ch_(ch) {
        int interfaces = 0;
        for (std::size_t i = 0; i < stack.layers.size(); ++i) {
            const InterfaceSpec& s = stack.layers[i].interface;
            const double above = stack.eta_above(i);
            TmComponent k;
            k.alpha = s.alpha;
            switch (s.type) {
                case InterfaceType::Lambertian:
                    support_.reason = fmt::format(
                        "{} has no Lambertian interface (its components are dielectric and "
                        "conductor interfaces and media)",
                        name_);
                    return;
                case InterfaceType::Dielectric:
                    k.kind = TmComponent::Dielectric;
                    k.eta = model_relative_eta(s.eta / above);  // model.h: finite for any stack
                    k.eta_rgb = Rgbd(k.eta);
                    k.fgd_index.fill(FgdTable::locate(k.eta, 0.0));
                    break;
                case InterfaceType::Conductor:
                    k.kind = TmComponent::Conductor;
                    k.eta_rgb = model_relative_eta(s.eta_rgb / above);
                    k.k = model_relative_k(s.k / above);
                    k.eta = k.eta_rgb.mean();
                    for (int c = 0; c < 3; ++c)
                        k.fgd_index[c] = FgdTable::locate(k.eta_rgb[c], k.k[c]);
                    break;
            }
            comps_.push_back(k);
            ++interfaces;
            if (stack.layers[i].has_medium && !stack.layers[i].medium.is_empty()) {
                const MediumSpec& m = stack.layers[i].medium;
                if (m.scatters()) {
                    support_.reason = fmt::format(
                        "{} has no scattering media (its two-flux matrices carry no scattered "
                        "flux; the released tm6 does)",
                        name_);
                    return;
                }
                TmComponent med;
                med.kind = TmComponent::Medium;
                med.tau_a = m.tau_a;
                comps_.push_back(med);
            }
        }
        if (interfaces > TmLobes::kMaxLobes) {
            support_.reason =
                fmt::format("{} needs 1 to {} interfaces", name_, int(TmLobes::kMaxLobes));
            return;
        }
        ch_.slab = stack.transmits();
        ch_.exact_top =
            ch_.top == TmChoices::Top::Exact || (ch_.top == TmChoices::Top::Released && !ch_.slab);
        support_.brdf = true;
        support_.btdf = ch_.slab;
        top_ = comps_.front();
        FgdTable::get();
        if (ch_.tir) TirTable::get();
    }

    std::string name() const override { return name_; }
    Support support() const override { return support_; }

    TmLobes lobes(double c0) const { return tm_lobes(comps_, c0, ch_); }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z == 0) return Rgbd(0.0);
        if (wo.z < 0 && !support_.btdf) return Rgbd(0.0);
        return eval_with(lobes(wi.z), wi, wo);
    }

    Rgbd eval_with(const TmLobes& st, const Vec3d& wi, const Vec3d& wo) const {
        if (wi.z <= 0 || wo.z == 0) return Rgbd(0.0);
        if (wo.z < 0) {
            const TmLobes::Lobe& t = st.transmitted;
            if (!support_.btdf || !st.transmits || t.delta) return Rgbd(0.0);
            const Vec3d wv = virtual_incidence(wi, st.cos_t);
            const Vec3d wo_up = flip_z(wo);
            return lobe_value(t, wv, wo_up, normalize(wv + wo_up));
        }
        const Vec3d h = normalize(wi + wo);
        Rgbd f(0.0);
        for (int k = 0; k < st.n_lobes; ++k) {
            if (st.lobes[k].component == 0 && ch_.exact_top) {
                f += exact_top(wi, wo, h);
                continue;
            }
            const TmLobes::Lobe& l = st.lobes[k];
            if (l.delta) continue;
            f += lobe_value(l, wi, wo, h);
        }
        return f;
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> out;
        if (!support_.brdf || wi.z <= 0) return out;
        const TmLobes st = lobes(wi.z);
        const Vec3d wr = mirror_direction(wi);
        for (int k = 0; k < st.n_lobes; ++k) {
            if (st.lobes[k].component == 0 && ch_.exact_top) {
                if (top_.alpha <= 0) out.push_back({wr, top_fresnel(wi.z)});
                continue;
            }
            const TmLobes::Lobe& l = st.lobes[k];
            if (l.delta && l.energy.max() > 0) out.push_back({wr, l.energy});
        }
        if (support_.btdf && st.transmits && st.transmitted.delta &&
            st.transmitted.energy.max() > 0)
            out.push_back({transmitted_direction(wi, st.cos_t), st.transmitted.energy});
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> peaks{mirror_direction(wi)};
        if (support_.btdf) {
            const TmLobes st = lobes(wi.z);
            if (st.transmits) peaks.push_back(transmitted_direction(wi, st.cos_t));
        }
        return peaks;
    }

    // Importance sampling: the energy-weighted mixture of the lobes' visible-normal densities
    // (tm2.cpp sample/pdf: weights = RGB-mean lobe energies, lobe 0 at the top's roughness when
    // exact), delta lobes left out.
    bool has_sampling() const override { return support_.brdf; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!support_.brdf || wi.z <= 0) return std::nullopt;
        const TmLobes st = lobes(wi.z);
        const Mixture mix = mixture(st, wi);
        if (mix.total <= 0) return std::nullopt;
        double pick = u.x * mix.total;
        int k = 0;
        while (k + 1 < mix.n && pick >= mix.w[k]) {
            pick -= mix.w[k];
            ++k;
        }
        // The lobe is chosen by u.x; its direction comes from u.y, u.z.
        const GGX<double> ggx{mix.alpha[k]};
        const Vec3d wm = ggx.sample_visible_normal(mix.wi[k], u.y, u.z);
        Vec3d wo = reflect(mix.wi[k], wm);
        if (wo.z <= 0) return std::nullopt;
        if (mix.below[k]) wo = flip_z(wo);
        const double p = mixture_pdf(mix, wo);
        if (!(p > 0)) return std::nullopt;
        ModelSample s;
        s.wo = wo;
        s.pdf = p;
        s.weight = eval_with(st, wi, wo) * (std::abs(wo.z) / p);
        return s;
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z == 0) return 0.0;
        const TmLobes st = lobes(wi.z);
        return mixture_pdf(mixture(st, wi), wo);
    }

  private:
    /// energy · D G2/(4 μi μo) at the lobe's roughness (one per channel with
    /// asymmetry=per-channel).
    Rgbd lobe_value(const TmLobes::Lobe& l, const Vec3d& wi, const Vec3d& wo,
                    const Vec3d& h) const {
        if (!ch_.per_channel_g) return l.energy * ggx_lobe_shape(l.alpha, wi, wo, h);
        Rgbd f;
        for (int c = 0; c < 3; ++c)
            f[c] = l.energy[c] * ggx_lobe_shape(l.alpha_rgb[c], wi, wo, h);
        return f;
    }

    struct Mixture {
        static constexpr int kMax = TmLobes::kMaxLobes + 1;
        std::array<double, kMax> w{}, alpha{};
        std::array<Vec3d, kMax> wi{};
        std::array<bool, kMax> below{};
        int n = 0;
        double total = 0;
    };

    Mixture mixture(const TmLobes& st, const Vec3d& wi) const {
        Mixture m;
        auto add = [&](double w, double alpha, const Vec3d& w_in, bool below) {
            if (!(w > 0) || alpha <= 0) return;
            m.w[m.n] = w;
            m.alpha[m.n] = alpha;
            m.wi[m.n] = w_in;
            m.below[m.n] = below;
            ++m.n;
            m.total += w;
        };
        for (int k = 0; k < st.n_lobes; ++k) {
            const TmLobes::Lobe& l = st.lobes[k];
            if (st.lobes[k].component == 0 && ch_.exact_top)
                add(l.energy.mean(), top_.alpha, wi, false);
            else if (!l.delta)
                add(l.energy.mean(), l.alpha, wi, false);
        }
        if (support_.btdf && st.transmits && !st.transmitted.delta)
            add(st.transmitted.energy.mean(), st.transmitted.alpha, virtual_incidence(wi, st.cos_t),
                true);
        return m;
    }

    /// Σ_k w_k G1(wi_k) D_k(h_k) / (4 μ_k) / Σ w: the visible-normal reflection densities.
    static double mixture_pdf(const Mixture& m, const Vec3d& wo) {
        if (m.total <= 0) return 0.0;
        double p = 0;
        for (int k = 0; k < m.n; ++k) {
            if (m.below[k] != (wo.z < 0)) continue;
            const Vec3d wo_up = m.below[k] ? flip_z(wo) : wo;
            const Vec3d h = normalize(m.wi[k] + wo_up);
            const GGX<double> ggx{m.alpha[k]};
            p += m.w[k] * ggx.G1(m.wi[k]) * ggx.D(h) / (4 * m.wi[k].z);
        }
        return p / m.total;
    }

    Rgbd top_fresnel(double cos_theta) const {
        if (top_.kind == TmComponent::Conductor)
            return fresnel_complex_rgb(cos_theta, top_.eta_rgb, top_.k);
        return Rgbd(fresnel_dielectric(cos_theta, top_.eta));
    }

    /// The exact reflection of the top interface, F(wi·h) D G2 / (4 μi μo) (Walter et al. 2007,
    /// Eq. 20), the released tm2's "top reflection correction".
    Rgbd exact_top(const Vec3d& wi, const Vec3d& wo, const Vec3d& h) const {
        if (top_.alpha <= 0) return Rgbd(0.0);
        return top_fresnel(dot(wi, h)) * ggx_lobe_shape(top_.alpha, wi, wo, h);
    }

    std::string name_;
    TmChoices ch_;
    std::vector<TmComponent> comps_;
    TmComponent top_;
    Support support_;
};

class TmEvaluator final : public IncidentEvaluator {
  public:
    TmEvaluator(const TmModel& model, const Vec3d& wi)
        : model_(model), wi_(wi), lobes_(model.lobes(std::max(wi.z, 1e-6))) {}
    Rgbd eval(const Vec3d& wo) const override {
        if (wo.z < 0 && !model_.support().btdf) return Rgbd(0.0);
        return model_.eval_with(lobes_, wi_, wo);
    }

  private:
    const TmModel& model_;
    Vec3d wi_;
    TmLobes lobes_;
};

std::unique_ptr<IncidentEvaluator> TmModel::prepare(const Vec3d& wi) const {
    if (!support_.brdf || wi.z <= 0) return Model::prepare(wi);
    return std::make_unique<TmEvaluator>(*this, wi);
}

}  // namespace

std::vector<OptionSpec> tm_option_specs() {
    const TmChoices d;
    return {
        {"top",
         {"released", "exact", "lobe"},
         "released",
         "lobe 0: as released (exact over a conductor, from the matrices for a slab), the exact "
         "top reflection, or the matrices' FGD-weighted lobe"},
        {"upward-fgd",
         {"same-cosine", "refracted"},
         d.upward_fgd ? "refracted" : "same-cosine",
         "upward reflectance r': r at the incident cosine (released) or FGD(mu_t, alpha, 1/eta)"},
        {"tir", {"on", "off"}, on_off(d.tir), "the TIR-table steps of the released code"},
        {"asymmetry",
         {"rgb-mean", "per-channel"},
         d.per_channel_g ? "per-channel" : "rgb-mean",
         "lobe asymmetry g from RGB-mean weights, one per lobe (released), or per channel"},
    };
}

TmChoices tm_choices(const ModelOptions& o) {
    TmChoices c;
    const std::string& top = option_value(o, "top");
    c.top = top == "exact"  ? TmChoices::Top::Exact
            : top == "lobe" ? TmChoices::Top::Lobe
                            : TmChoices::Top::Released;
    c.upward_fgd = option_value(o, "upward-fgd") == "refracted";
    c.tir = option_value(o, "tir") == "on";
    c.per_channel_g = option_value(o, "asymmetry") == "per-channel";
    return c;
}

std::unique_ptr<Model> make_tm_model(std::string model_name, const Stack& stack,
                                     const TmChoices& choices) {
    return std::make_unique<TmModel>(std::move(model_name), stack, choices);
}

}  // namespace lamina

#pragma once
// lamina-1's construction and the coat's per-material curves: the interfaces' transmittances,
// the widened base lobe's normalization, the multiple-scattering lobes, the hemispherical albedos
// and the inter-reflection series (items 1–4 of lamina-1 in lamina's docs/models.md).

#include "lamina1/bsdf.h"

namespace lamina1 {

inline Bsdf::Bsdf(const Layers& layers, const Tables& tables, const Options& options)
    : tables_(&tables), ch_(options), layers_(layers) {
    if (!(layers_.eta0 >= 1)) {
        support_.reason = "lamina-1 needs a coat at least as dense as the ambient medium";
        return;
    }
    const bool coat_aniso = layers_.alpha0_y >= 0;
    const bool base_aniso = layers_.alpha1_y >= 0 && layers_.base != Base::Lambertian;
    ms_ = ch_.microsurface == Options::Microsurface::Multiple ||
          (ch_.microsurface == Options::Microsurface::Auto && !coat_aniso && !base_aniso);
    if (!tables.complete(ch_.masking, ms_)) {
        support_.reason = "lamina-1's tables lack what these options read";
        return;
    }
    if ((coat_aniso && !(layers_.alpha0 > 0 && layers_.alpha0_y > 0)) ||
        (base_aniso && !(layers_.alpha1 > 0 && layers_.alpha1_y > 0))) {
        support_.reason = "lamina-1 needs both roughnesses of an anisotropic interface above 0";
        return;
    }
    if ((coat_aniso || base_aniso) && ch_.microsurface == Options::Microsurface::Multiple) {
        // The orders ≥ 2 are energies of the isotropic tables: at the rms roughness they restore
        // what an isotropic interface loses, far more than an anisotropic one loses along its
        // smooth axis (23 % too much light at 80° under a coat of 0.05 × 0.4).
        support_.reason =
            "lamina-1 does not represent the multiple-scattering orders (microsurface=multiple) "
            "of an anisotropic interface";
        return;
    }
    if ((coat_aniso || base_aniso) && layers_.base == Base::Dielectric) {
        support_.reason =
            "lamina-1 does not represent a slab with an anisotropic interface (its transmission "
            "lobes are isotropic)";
        return;
    }
    support_.brdf = true;
    support_.btdf = layers_.base == Base::Dielectric;
    eta0_ = layers_.eta0;
    inv_eta0_ = 1 / eta0_;
    alpha0_ = layers_.alpha0;
    alpha1_ = layers_.alpha1;
    aniso_ = coat_aniso || base_aniso;
    if (aniso_) {
        // Each interface's slope covariance; the terms 1-D in α read the root mean square.
        auto rms = [](double a_x, double a_y) { return std::sqrt(0.5 * (sqr(a_x) + sqr(a_y))); };
        sigma0_ = coat_aniso ? SlopeCovariance::of_axes(alpha0_, layers_.alpha0_y, layers_.tangent0)
                             : SlopeCovariance::isotropic(alpha0_);
        sigma1_ = base_aniso ? SlopeCovariance::of_axes(alpha1_, layers_.alpha1_y, layers_.tangent1)
                             : SlopeCovariance::isotropic(alpha1_);
        if (coat_aniso) alpha0_ = rms(alpha0_, layers_.alpha0_y);
        if (base_aniso) alpha1_ = rms(alpha1_, layers_.alpha1_y);
    }
    coat_ggx_ = coat_aniso ? GGX::anisotropic_of(sigma0_) : GGX{alpha0_};
    // The unscattered light is attenuated by extinction, τt = τa + τs (τa itself, bitwise,
    // without scattering).
    tau_t_ = layers_.tau_a + layers_.tau_s;
    has_absorption_ = tau_t_.max() > 0;
    scatters_ = layers_.tau_s.max() > 0;
    if (layers_.base == Base::Dielectric) {
        eta_b_ = layers_.base_eta[0];  // η_below/η_coat
        eta_s_ = 1 / eta_b_;           // the coat seen from below: η_coat/η_below
    }
    fgd_top_in_.table = FgdView(tables, alpha0_, inv_eta0_, 0.0);
    precompute_dense_side(fgd_top_in_, alpha0_, inv_eta0_);
    if (layers_.base == Base::Conductor)
        fgd_base_ = FgdView(tables, alpha1_, layers_.base_eta, layers_.base_k);
    if (layers_.base == Base::Dielectric) {
        fgd_base_in_.table = FgdView(tables, alpha1_, eta_b_, 0.0);
        precompute_dense_side(fgd_base_in_, alpha1_, eta_b_);
    }
    if (ms_) {
        fgd_top_ = FgdView(tables, alpha0_, eta0_, 0.0);
        if (support_.btdf) fgd_bottom_ = FgdView(tables, alpha1_, eta_s_, 0.0);
    }
    // A slab's later orders in bins (slab-orders=bins) take the place of the separable series
    // and of the first order's round trips (precompute_series); with both interfaces smooth the
    // exact delta series is summed instead; an index-matched bottom has no later orders (the
    // coat's interface alone: eval_btdf).
    bins_ = support_.btdf && ch_.slab_bins && ch_.inter_reflection &&
            !(alpha0_ == 0 && alpha1_ == 0) && !bottom_matched();
    precompute();
    // The slab's bins before the medium's curves: a slab's scattered remainders are weighed by
    // the bins' entry (precompute_scattering_curves).
    precompute_slab();
    precompute_polarization();
    if (scatters_) precompute_scattering();
}

inline void Bsdf::precompute() {
    inside_exit_ = ch_.inside_exit && alpha0_ > 0 && ch_.directional_transmittance &&
                   layers_.base != Base::Lambertian;
    precompute_lobe_normalization();
    setup_transmittances();
    precompute_coat_attenuation();
    precompute_multiple_scattering();
    const RgbEdgeCurve<33> g_curve = precompute_albedos();
    precompute_mean_direction();
    precompute_series(g_curve);
}

inline void Bsdf::precompute_dense_side(DenseSideFgd& fgd, double alpha, double eta) const {
    // DenseSideFgd: where the table steps (near μc, under α < 0.2).
    fgd.weight = eta < 1 && alpha > 0 ? clamp((0.2 - alpha) / 0.1, 0.0, 1.0) : 0.0;
    if (!(fgd.weight > 0)) return;
    fgd.transmittance = tables_->transmittance(ch_.masking);
    fgd.alpha = alpha;
    fgd.eta = eta;
    fgd.mu_crit = std::sqrt(1 - eta * eta);
    fgd.width = std::max(3 * alpha, 0.08);
    // L(μ) = ∫ D_w(wm) [F (1 − G2/G1(w, wr)) + (1 − F)(1 − G2/G1(w, wt))] dwm over the normals
    // visible from w (Heitz 2014, Eq. 38; the escapes as the tables take them: the height-
    // correlated reflection, the refraction's refraction_escape), w on the dense side, wr its
    // reflection and wt its refraction about wm. F has a kink where the facet cosine w·wm reaches
    // the critical one (total reflection below it): the rule is split there.
    const GGX ggx{alpha};
    const double x_crit = fgd.mu_crit;
    fgd.loss.fill(x_crit, [&](double mu) {
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-6));
        const double lambda_w = ggx.lambda(w);
        auto facet_cosine = [&](const Vec3& wm) { return dot(w, wm); };
        return integrate_visible_split<double, kSplitNr, kSplitNphi, kSplitBisections>(
            ggx, w, x_crit, facet_cosine, [&](const Vec3& wm) {
                const double F = fresnel_dielectric(dot(w, wm), eta);
                const Vec3 wr = reflect(w, wm);
                const double escape_r =
                    wr.z > 0 ? reflection_escape(lambda_w, ggx.lambda(wr)) : 0.0;
                double lost = F * (1 - escape_r);
                if (F < 1) {
                    const std::optional<Vec3> wt = refract(w, wm, eta);
                    const double escape_t =
                        wt && wt->z < 0 ? refraction_escape(ch_.masking, lambda_w, ggx.lambda(*wt))
                                        : 0.0;
                    lost += (1 - F) * (1 - escape_t);
                }
                return lost;
            });
    });
}

/// T(μ) of the coat from outside and inside, and of a slab's bottom from below and inside: the
/// table (or 1 − F with coat-transmittance=fresnel) resampled per material, with the orders ≥ 2
/// of multiple scattering.
inline void Bsdf::setup_transmittances() {
    const float* table = tables_->transmittance(ch_.masking);
    const bool ms = ms_;
    auto setup = [&](Transmittance& t, double alpha, double eta, const auto& fgd) {
        t.eta = eta;
        t.exact = alpha == 0 || (!ch_.directional_transmittance && !ms);
        if (!t.exact)
            t.curve.fill(eta < 1 ? std::sqrt(1 - eta * eta) : 0.0, [&](double mu) {
                const double tr = ch_.directional_transmittance
                                      ? TransmittanceFormat::lookup(table, mu, alpha, eta)
                                      : 1 - fresnel_dielectric(mu, eta);
                return ms ? tr + ms_dielectric(fgd, mu, alpha, eta).transmitted : tr;
            });
    };
    setup(T_top_, alpha0_, eta0_, fgd_top_);
    setup(T_top_in_, alpha0_, inv_eta0_, fgd_top_in_);
    if (support_.btdf) {
        setup(T_bot_, alpha1_, eta_s_, fgd_bottom_);
        setup(T_bot_in_, alpha1_, eta_b_, fgd_base_in_);
    }
}

/// The base lobe's width follows wo through k_o, so the lobe is not normalized: its energy over
/// the exit cone exceeds that of the lobe of fixed width α_e(k_i, k_i) by N(μi') (up to 2× in
/// the tails under rough, low-index coats). Divided out reciprocally, by √N(μi') √N(μo'). N by the
/// fixed lobe's visible normals (Heitz 2018), the varying lobe weighted by its ratio.
inline void Bsdf::precompute_lobe_normalization() {
    shaped_lobe_ = ch_.first_order_lobe != Options::FirstOrderLobe::Ggx && alpha0_ > 0 &&
                   eta0_ > 1 && layers_.base != Base::Lambertian &&
                   ch_.spread != Options::Spread::Off;
    if (shaped_lobe_ && ch_.first_order_lobe == Options::FirstOrderLobe::Compressed) {
        entering_.build(true, eta0_, alpha0_);
        leaving_.build(false, eta0_, alpha0_);
    }
    lobe_norm_on_ = ch_.lobe_normalization && alpha0_ > 0 && layers_.base != Base::Lambertian &&
                    ch_.spread == Options::Spread::Angular;
    if (!lobe_norm_on_) return;
    static const QuadratureRule qn = gauss_legendre(kNormNr);
    const double mu_crit_in = std::sqrt(1 - sqr(inv_eta0_));
    lobe_norm_.fill([&](double mu) {
        const double mu_in = std::max(mu, mu_crit_in + 1e-6);
        const Vec3 w(safe_sqrt(1 - mu_in * mu_in), 0, mu_in);
        const double mu_out_i = safe_sqrt(1 - (1 - mu_in * mu_in) * sqr(eta0_));
        const double k_i = spread_factor(mu_out_i, mu_in, eta0_);
        const double alpha_f = effective_alpha(k_i, k_i);
        if (alpha_f <= 0) return 1.0;
        const GGX fixed{alpha_f};
        double sum_fixed = 0, sum_var = 0;
        for (int a = 0; a < kNormNr; ++a)
            for (int b = 0; b < kNormNphi; ++b) {
                const double r = qn.x[a], w_r = qn.w[a] * 2 * r / kNormNphi;
                const Vec3 wm =
                    fixed.sample_visible_normal(w, r * r, 0.5 * (b + 0.5) / kNormNphi - 0.25);
                const Vec3 wo = reflect(w, wm);
                if (wo.z <= mu_crit_in) continue;  // beyond the exit cone (or below)
                const double mu_out = safe_sqrt(1 - (1 - wo.z * wo.z) * sqr(eta0_));
                const double k_o = spread_factor(mu_out, wo.z, eta0_);
                const GGX var{effective_alpha(k_i, k_o)};
                const double g_fixed = fixed.G2(w, wo) / fixed.G1(w);
                sum_fixed += w_r * g_fixed;
                // f_var / f_fixed = D_var G2_var / (D_fixed G2_fixed) at the same half vector
                // (D_var the shaped lobe's where first-order-lobe shapes it).
                const double D_var =
                    shaped_lobe_ ? first_order_ndf(wm, k_i, k_o, false) : var.D(wm);
                sum_var += w_r * g_fixed * D_var * var.G2(w, wo) / (fixed.D(wm) * fixed.G2(w, wo));
            }
        return sum_fixed > 0 && sum_var > 0 ? std::sqrt(sum_fixed / sum_var) : 1.0;
    });
}

/// Multiple scattering's separable lobes: the coat's from outside, the base's from inside.
inline void Bsdf::precompute_multiple_scattering() {
    const bool ms = ms_;
    top_ms_ = ms && alpha0_ > 0;
    if (top_ms_) {
        dR_top_.fill(
            [&](double mu) { return ms_dielectric(fgd_top_, mu, alpha0_, eta0_).reflected; });
        dR_top_bar_ =
            integrate_split01<kGauss, double>([&](double mu) { return dR_top_(mu) * 2 * mu; }, 0.0);
        top_ms_ = dR_top_bar_ > 0;
    }
    base_ms_ = ms && alpha1_ > 0 && layers_.base != Base::Lambertian;
    if (!base_ms_) return;
    if (layers_.base == Base::Conductor) {
        dE_base_.fill([&](double mu) {
            return MultipleScatteringFormat::conductor(tables_->multiple_scattering(), mu, alpha1_);
        });
    } else {
        dE_base_.fill(
            [&](double mu) { return ms_dielectric(fgd_base_in_, mu, alpha1_, eta_b_).reflected; });
    }
    dE_base_bar_ =
        integrate_split01<kGauss, double>([&](double mu) { return dE_base_(mu) * 2 * mu; }, 0.0);
    base_ms_ = dE_base_bar_ > 0;
    if (base_ms_ && layers_.base == Base::Conductor) {
        // Each further facet multiplies by the conductor's Fresnel factor: with its hemispherical
        // average F̄ and the white surface's E_avg = 1 − ΔĒ, the orders ≥ 2 carry ΔE(μ) F̄² E_avg /
        // (1 − F̄ (1 − E_avg)) (Kulla & Conty 2017, "Revisiting physically based shading at
        // Imageworks", the F_ms factor: one more bounce F̄, then escape E_avg or another bounce).
        const Rgb F_avg = integrate_split01<kGauss, Rgb>(
            [&](double mu) {
                return fresnel_complex_rgb(mu, layers_.base_eta, layers_.base_k) * (2 * mu);
            },
            0.0);
        const double E_avg = 1 - dE_base_bar_;
        for (int c = 0; c < 3; ++c)
            F_ms_[c] = sqr(F_avg[c]) * E_avg / (1 - F_avg[c] * (1 - E_avg));
    }
}

/// A rough absorbing coat's Beer–Lambert factor for light crossing it from the outside cosine μ,
/// averaged over the directions the coat transmits it into: ∫ t(μ → w') exp(−τ/μ_w') dω' /
/// ∫ t(μ → w') dω' by the coat's visible-normal rule (weight (1 − F) G_t/G1, as X(μ) and its
/// transmittance table), the coat's orders ≥ 2 taken as cosine-distributed inside. By
/// reciprocity the same factor holds for light leaving towards μ. Over an opaque base without a
/// scattering medium (Options::coat_path_spread): a slab's first order takes its own directions
/// through the coat (lamina1/slab.h), and with a medium the adding balances the scattered light's
/// energy along the macro refractions (lamina1/media.h).
inline void Bsdf::precompute_coat_attenuation() {
    a_coat_on_ = ch_.coat_path_spread && alpha0_ > 0 && has_absorption_ && !scatters_ &&
                 !support_.btdf && ch_.directional_transmittance;
    if (!a_coat_on_) return;
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    const Rgb a_cosine =
        integrate_split01<kGauss, Rgb>([&](double m) { return attenuation(m) * (2 * m); }, mu_crit);
    a_coat_.fill([&](double mu) {
        // v[0]: the attenuated transmitted light, v[1]: the transmitted light.
        Multi<Rgb, 2> sum =
            over_coat_transmission<Multi<Rgb, 2>, kSplitNr, kSplitNphi, kSplitBisections>(
                mu, mu_crit, [&](const Vec3& wt, double F, double escape) {
                    const double weight = (1 - F) * escape;
                    Multi<Rgb, 2> r;
                    r.v[0] = attenuation(-wt.z) * weight;
                    r.v[1] = Rgb(weight);
                    return r;
                });
        if (ms_) {
            const double dT = ms_dielectric(fgd_top_, mu, alpha0_, eta0_).transmitted;
            sum.v[0] += a_cosine * dT;
            sum.v[1] += Rgb(dT);
        }
        Rgb a = attenuation(inside_cos(mu));
        for (int c = 0; c < 3; ++c)
            if (sum.v[1][c] > 0) a[c] = sum.v[0][c] / sum.v[1][c];
        return a;
    });
}

inline double Bsdf::returned_share(double mu) const {
    const double R_in = inside_reflectance(mu);
    if (!(alpha0_ > 0)) return R_in;
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    return std::max(0.0, R_in + T_top_in_(mu) - (mu > mu_crit ? first_order_exit(mu) : 0.0));
}

/// The hemispherical albedos r̄ (the coat's bottom, with the medium's round trip), Ē_b (the
/// base) and t̄ (the coat's diffuse exit); returns g(μ) = a(μ)² R_eff(μ), the light a return trip
/// base → coat → base keeps, tabulated for Y.
inline RgbEdgeCurve<33> Bsdf::precompute_albedos() {
    // The coat's bottom seen from inside: R_in(μ) = FGD(μ, α0, 1/η0) (total internal reflection
    // included), and g(μ) = a(μ)² R_in(μ) for a return trip base → coat → base.
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    r_bar_ = integrate_split01<kGauss, Rgb>(
        [&](double mu) {
            return attenuation(mu) * attenuation(mu) * (2 * mu * inside_reflectance(mu));
        },
        mu_crit);
    // What the first order does not send out is returned: light inside at μ'' within the exit
    // cone leaves in the first order with the outside transmittance T(μ) (exact for a locally
    // uniform inside radiance, by reciprocity), so the part returned to the base is
    // R_eff = 1 − loss − T(μ) = R_in + T_in − T(μ), where R_in + T_in + loss = 1 from inside. For
    // a smooth coat T_in = T and R_eff = R_in; for a rough one the facets' total internal
    // reflection makes T_in < T near the critical angle, and R_in alone would count that light
    // twice. Beyond the cone the first order lets nothing out (its lobe leaves through the
    // macro refraction), but a rough coat's tilted facets transmit part of that light, T_in > 0
    // (a third of it at μ' = 0.4 under η0 1.2, α0 0.4): it is not lost, it leaves with the
    // series, R_eff = R_in + T_in.
    auto g_direct = [&](double mu) {
        const Rgb a = attenuation(mu);
        return a * a * returned_share(mu);
    };
    // Tabulated once (Y's quadrature looks it up at every node); the node μ = 0 is taken at 1e-6,
    // where an index-matched coat's Fresnel factor is its limit 0 (not the 0/0 of grazing). Its
    // nodes crowd towards μc (RgbEdgeCurve): R_in falls from total reflection as √(μ − μc) just
    // inside the cone, and so does Y's (a slab's bottom reflects totally at the same angle when
    // the slab is in air); on nodes uniform in μ the nearly smooth slab's returned light at 80°
    // was 0.22 instead of 0.10 of the incident flux.
    RgbEdgeCurve<33> g_curve;
    g_curve.fill(mu_crit, [&](double mu) { return g_direct(std::max(mu, 1e-6)); });
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    E_bar_ = integrate_split01<kGauss, Rgb>([&](double mu) { return base_albedo(mu) * (2 * mu); },
                                            mu_crit_b);
    t_bar_ =
        integrate_split01<kGauss, Rgb>(
            [&](double mu) { return coat_attenuation(mu, inside_cos(mu)) * (2 * mu * T_top_(mu)); },
            0.0) *
        sqr(inv_eta0_);
    return g_curve;
}

/// The mean direction of the light a rough coat transmits (slab BTDF): the visible facets at
/// grazing incidence lean towards the light and turn the refracted light away from the normal (by
/// k δ per facet tilt δ, item 4 of lamina-1), so its mean lies beyond the macro refraction — near
/// grazing, beyond a slab's exit cone. By the coat's visible-normal rule. (With btdf-lobe=bottom
/// or shared, slab_entry computes it by its own rule, with the first order.)
inline void Bsdf::precompute_mean_direction() {
    mean_shift_ = support_.btdf && alpha0_ > 0 && ch_.directional_transmittance && ch_.mean_shift;
    if (!mean_shift_ || ch_.btdf_bottom_lobe) return;
    static const QuadratureRule q = gauss_legendre(kYnr);
    const GGX ggx0{alpha0_};
    mu_mean_.fill([&](double mu) {
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        double x = 0, z = 0;
        for (int a = 0; a < kYnr; ++a)
            for (int b = 0; b < kYnphi; ++b) {
                const double r = q.x[a], w_r = q.w[a] * 2 * r;
                const Vec3 wm =
                    ggx0.sample_visible_normal(w, r * r, 0.5 * (b + 0.5) / kYnphi - 0.25);
                const auto wt = refract(w, wm, eta0_);
                if (!wt || wt->z >= 0) continue;
                const double wgt = (1 - fresnel_dielectric(dot(w, wm), eta0_)) * w_r;
                x += wgt * wt->x;  // −wt: the inside direction pointing up, in −x
                z += wgt * -wt->z;
            }
        const double len = std::hypot(x, z);
        // Stored as the shift from the macro refraction (which the lookup adds back exactly): it
        // vanishes with α0, and so does its interpolation error under narrow lobes.
        return (len > 0 ? z / len : inside_cos(mu)) - inside_cos(mu);
    });
}

/// The share of the returned light that the round trips' lobe carries over a conductor (the rest
/// in the uniform series): what keeps its direction through a round trip. All of it where the
/// conductor is no rougher than the coat (α1 ≤ α0); none where it is rougher than 3 max(α0, 0.1),
/// whose reflections spread the returned light over the inside directions again; log-linear in α1
/// between, so that the model is continuous in α1. The bounds are measured against the exact
/// reference (docs/models.md, lamina-1, item 3: the lobe alone misplaced less light up to α1 0.1
/// over coats of α0 10⁻³–0.05, the series alone less from α1 0.3, and over conductors as rough as
/// the coat the series lost up to 5 % of the albedo under η0 2.5).
inline double round_trip_weight(double alpha0, double alpha1) {
    const double spread = 3 * std::max(alpha0, 0.1);
    if (alpha1 <= alpha0) return 1.0;
    if (alpha1 >= spread) return 0.0;
    return std::log(spread / alpha1) / std::log(spread / alpha0);
}

/// Which inter-reflections are summed (item 3 of lamina-1): the separable series where the base
/// re-diffuses the returned light, else the first order's round trips kept in its lobe.
inline void Bsdf::precompute_series(const RgbEdgeCurve<33>& g_curve) {
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    const bool smooth_base = layers_.base != Base::Lambertian && alpha1_ == 0;
    // "auto" leaves the series out under a conductor smoother than the coat only where the
    // microsurfaces are single scattering: the returned light, near grazing inside directions,
    // is then largely lost on the interfaces, as in the 2019 study's reference. With their orders
    // ≥ 2 restored nothing is lost, and each return through the rough coat spreads the light
    // again: the series is summed (a white mirror under a rough coat then keeps 0.985–1.010 of
    // the light up to 85°; 0.47 without, at 85° under η0 1.2, α0 0.7). In a slab the returned light
    // mostly leaves through a smooth bottom after one more crossing with its direction kept: the
    // round trips stay in the first order's lobe (measured on the quick study's slabs: the uniform
    // series there misplaced more light, docs/models.md).
    if (bins_) return;  // the slab's later orders in bins (lamina1/slab.h)
    const bool everywhere = !ch_.series_lambertian_only || (ms_ && layers_.base == Base::Conductor);
    series_on_ = ch_.inter_reflection && !(smooth_base && alpha0_ == 0) &&
                 (layers_.base == Base::Lambertian || everywhere || alpha1_ >= alpha0_);
    series_btdf_ = series_on_ && !ch_.series_lambertian_only;
    // Where the uniform series is off (a base smoother than the rough coat), the light the coat's
    // bottom returns meets a base that keeps its direction: it stays in the first order's lobe,
    // which each round trip multiplies by a² R_in E_b, summed as the smooth stack's delta series
    // is (lamina's docs/physics.md §6.5), over the part (1 − u) the base does not spread.
    mirror_series_ = ch_.inter_reflection && inside_exit_ && !series_on_;
    if (mirror_series_) {
        mirror_series_curve_.fill([&](double mu) {
            const double mu_in = std::max(mu, mu_crit + 1e-9);
            const double mu_out = safe_sqrt(1 - (1 - mu_in * mu_in) * sqr(eta0_));
            const double spread2 = sqr(0.5 * alpha0_ * spread_factor(mu_out, mu_in, eta0_));
            const double u = spread2 > 0 ? sqr(alpha1_) / (sqr(alpha1_) + spread2) : 1.0;
            const Rgb a = attenuation(mu_in);
            const Rgb round_trip =
                a * a * base_albedo(mu_in) * (inside_reflectance(mu_in) * (1 - u));
            Rgb S(1.0);
            for (int c = 0; c < 3; ++c)
                S[c] = 1 / std::sqrt(std::max(1e-6, 1 - round_trip[c]));  // √ of 1/(1 − ·)
            return S;
        });
    }
    if (!series_on_) return;
    balance_ = ch_.first_order_balance && alpha0_ > 0 && ch_.directional_transmittance &&
               layers_.base != Base::Lambertian;
    // The round trips as a lobe of their own (Options::round_trip_lobe): where the series is
    // summed over a conductor (the orders ≥ 2 restored; a rough coat, the directional
    // transmittance), the returned light leaves near the mirror direction, not as
    // uniform radiance (docs/models.md, lamina-1, item 3): the lobe takes the light the returned
    // light lets out, followed by its direction through the round trips (returned_escape).
    // The share of that light the lobe takes (round_trip_weight): all of it over a conductor no
    // rougher than the coat, none over one much rougher, which spreads the returned light again.
    const double weight = round_trip_weight(alpha0_, alpha1_);
    // Under single scattering only where the conductor is smoother than the coat, as before.
    round_trip_on_ = ch_.round_trip_lobe && layers_.base == Base::Conductor && alpha0_ > 0 &&
                     ch_.directional_transmittance && (alpha1_ < alpha0_ || (ms_ && weight > 0));
    CosineCurve<Rgb, kNx> leaving;
    precompute_returned(g_curve, round_trip_on_ ? &leaving : nullptr);
    if (round_trip_on_) {
        Rgb gain(0.0);
        for (int c = 0; c < 3; ++c) {
            const double one_minus = 1 - E_bar_[c] * r_bar_[c];
            gain[c] = one_minus > 0 ? E_bar_[c] * t_bar_[c] / one_minus : 0.0;
        }
        precompute_round_trips(gain, leaving, weight);
    }
    // X̄ = (2/η0²)∫ X(μ) μ dμ: the diffuse exit's normalization.
    X_bar_ = integrate_split01<kGauss, Rgb>([&](double mu) { return X_at(mu) * (2 * mu); }, 0.0) *
             sqr(inv_eta0_);
    for (int c = 0; c < 3; ++c) {
        const double one_minus = 1 - E_bar_[c] * r_bar_[c];
        inv_one_minus_Er_[c] = one_minus > 0 ? 1 / one_minus : 0;
        // The separable term X(μi)X(μo)K/(πη0²) must leave with the series' energy
        // X(μi) Ē_b t̄/(1 − Ē_b r̄): ∫ X(μo)/(πη0²) μo dωo = X̄ fixes K.
        K_[c] = X_bar_[c] > 0 ? E_bar_[c] * t_bar_[c] * inv_one_minus_Er_[c] / X_bar_[c] : 0;
    }
}

/// The round trips' scale (Options::round_trip_lobe). The lobe carries what the returned light
/// lets out, L(μ) per unit of light arriving at outside cosine μ (precompute_returned, with its
/// escape followed by direction: returned_escape). Its form s(μi) s(μo) L(wi, wo) (L the lobe of
/// Bsdf::round_trip with a unit scale) is reciprocal whatever s is. On the nodes μ_i of X's
/// curve, where s has its own, the lobe's energy is E_i = s_i Σ_j M_ij s_j, M_ij = ∫ L(wi_i, wo)
/// w_j(μo) μo dωo, w_j the curve's interpolation weights (each node of first_order_energy's rule
/// summed onto the two nodes about its μo). E_i = L_i at every node is a symmetric
/// matrix-scaling problem, solved by the damped fixed point s ← √(s L / (M s)) (Sinkhorn's
/// iteration, Sinkhorn & Knopp 1967, "Concerning nonnegative matrices and doubly stochastic
/// matrices", Pacific J. Math. 21(2), in a symmetric form: the square root takes the geometric
/// mean of the old scale and the one that would match row i alone; 20–40 steps to 10⁻⁹ here). What
/// the lobe does not carry (where no light reaches its row: grazing incidence) stays in the series,
/// as X = (L − E)/G with G = Ē_b t̄/(1 − Ē_b r̄) the energy the series lets out per unit of X.
inline void Bsdf::precompute_round_trips(const Rgb& gain, const CosineCurve<Rgb, kNx>& leaving,
                                         double weight) {
    constexpr int kN = kNx;
    using Curve = CosineCurve<Rgb, kN>;
    round_trip_curve_.fill([](double) { return Rgb(1.0); });
    // One node of the rule, its value shared between the two curve nodes about its μo.
    struct Share {
        Curve::Place at;
        Rgb v;
        Share operator*(double w) const { return {at, v * w}; }
    };
    struct Row {
        std::array<Rgb, kN> m{};
        Row& operator+=(const Share& s) {
            m[s.at.i] += s.v * (1 - s.at.t);
            m[s.at.i + 1] += s.v * s.at.t;
            return *this;
        }
    };
    auto share = [](const Rgb& v, const Vec3& wo) { return Share{Curve::locate(wo.z), v}; };
    std::array<Row, kN> M;
    for (int i = 0; i < kN; ++i)
        M[i] = visible_rule_energy<Row>(sqr(double(i) / (kN - 1)), true, share);
    std::array<Rgb, kN> E;
    for (int c = 0; c < 3; ++c) {
        std::array<double, kN> s{}, next{}, target{};
        auto Ms = [&](int i) {
            double sum = 0;
            for (int j = 0; j < kN; ++j)
                sum += M[i].m[j][c] * s[j];
            return sum;
        };
        for (int i = 0; i < kN; ++i) {
            target[i] = weight * std::max(leaving.v[i][c], 0.0);
            double row = 0;
            for (int j = 0; j < kN; ++j)
                row += M[i].m[j][c];
            s[i] = row > 0 ? std::sqrt(target[i] / row) : 0.0;
        }
        for (int iteration = 0; iteration < 400; ++iteration) {
            double worst = 0;
            for (int i = 0; i < kN; ++i) {
                const double Ms_i = Ms(i);
                if (target[i] > 0 && Ms_i > 0)
                    worst = std::max(worst, std::abs(s[i] * Ms_i / target[i] - 1));
                next[i] = Ms_i > 0 ? std::sqrt(s[i] * target[i] / Ms_i) : 0.0;
            }
            s = next;
            if (worst < 1e-9) break;
        }
        for (int i = 0; i < kN; ++i) {
            round_trip_curve_.v[i][c] = s[i];
            E[i][c] = s[i] * Ms(i);
        }
    }
    // X_ holds the series' own X on entry: its share 1 − weight stays there.
    for (int i = 0; i < kN; ++i)
        for (int c = 0; c < 3; ++c) {
            const double L = weight * leaving.v[i][c], left = L - E[i][c];
            // What the solve matched (to 10⁻⁹) leaves a remainder of rounding, not light.
            X_.v[i][c] =
                (1 - weight) * X_.v[i][c] + (left > 1e-6 * L && gain[c] > 0 ? left / gain[c] : 0.0);
        }
}

template <typename V, typename Out>
V Bsdf::visible_rule_energy(double mu, bool of_round_trip, Out&& out) const {
    Incident in;
    in.wi = Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
    in.wi_in = refract_in(in.wi, inv_eta0_);
    if (!(in.wi_in.z > 0)) return V{};
    incident_coat(in);
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    const GGX fixed{of_round_trip ? round_trip_alpha(in.k_top, in.k_top)
                                  : effective_alpha(in.k_top, in.k_top)};
    if (!(fixed.alpha > 0)) return V{};
    constexpr LobeForm kSpecular{true, false, false};
    const Vec3 w = in.wi_in;
    auto outside = [&](const Vec3& v) {  // v inside, within the exit cone
        return Vec3(v.x * eta0_, v.y * eta0_, safe_sqrt(1 - (1 - v.z * v.z) * sqr(eta0_)));
    };
    const double g1 = fixed.G1(w);
    auto node = [&](const Vec3& wm) {
        const Vec3 wo_in = reflect(w, wm);
        if (wo_in.z <= mu_crit) return out(Rgb(0.0), wo_in);
        const double density = g1 * fixed.D(wm);
        if (!(density > 0)) return out(Rgb(0.0), wo_in);
        const Vec3 wo = outside(wo_in);
        const Rgb a_o = coat_attenuation(wo.z, wo_in.z);
        return out((of_round_trip ? round_trip(in, wo, wo_in, a_o)
                                  : first_order(in, wo, wo_in, a_o, kSpecular)) *
                       (sqr(eta0_) * wo_in.z * 4 * w.z / density),
                   wo);
    };
    auto height = [&](const Vec3& wm) { return reflect(w, wm).z; };
    // The round trips' lobe is wider than its rule's GGX where wo is oblique (α_r follows k_o),
    // and it carries more of the light: twice the nodes in each direction.
    return of_round_trip
               ? integrate_visible_split<V, 2 * kSplitNr, 2 * kSplitNphi, kSplitBisections>(
                     fixed, w, mu_crit, height, node)
               : integrate_visible_split<V, kSplitNr, kSplitNphi, kSplitBisections>(
                     fixed, w, mu_crit, height, node);
}

/// E_lobe(μ) = ∫ f_1(wi, wo) μo dωo, the energy the first order's lobe carries out for light
/// arriving at outside cosine μ, over the inside directions (μo dωo = η0² μo' dωo', Snell's law
/// of solid angles): by the visible normals of the GGX of fixed width α_e(k_i, k_i) at wi', each
/// node weighted by the lobe (whatever its shape) over that GGX's density of wo', dωo'/dP =
/// 4 μi'/(G1(wi') D(wm)); the base's separable multiple-scattering part, broad, by a 1-D rule.
/// Like X, a curve in μ alone: under anisotropic interfaces, the lobe of their root mean square
/// roughnesses (isotropic, so the rule's half disk of visible normals is exact and the balance
/// turns with the tangents). `of_round_trip`: the same for the round trips' lobe (GGX of α_r(k_i,
/// k_i) as the rule's), which has no separable part.
inline Rgb Bsdf::first_order_energy(double mu, bool of_round_trip) const {
    Rgb sum =
        visible_rule_energy<Rgb>(mu, of_round_trip, [](const Rgb& v, const Vec3&) { return v; });
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    if (base_ms_ && !of_round_trip) {
        Incident in;
        in.wi = Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        in.wi_in = refract_in(in.wi, inv_eta0_);
        if (!(in.wi_in.z > 0)) return Rgb(0.0);
        incident_coat(in);
        auto outside = [&](const Vec3& v) {
            return Vec3(v.x * eta0_, v.y * eta0_, safe_sqrt(1 - (1 - v.z * v.z) * sqr(eta0_)));
        };
        constexpr LobeForm kMultiple{false, true, false};
        // f_1 of the separable lobe is F_ms ΔE(μi') ΔE(μo')/(π ΔĒ) times the coat's factors.
        const Rgb ms = integrate_split01<kGauss, Rgb>(
            [&](double mu_in) {
                if (mu_in <= mu_crit) return Rgb(0.0);
                const Vec3 wo_in(safe_sqrt(1 - mu_in * mu_in), 0, mu_in);
                const Vec3 wo = outside(wo_in);
                return first_order(in, wo, wo_in, coat_attenuation(wo.z, mu_in), kMultiple) *
                       (sqr(eta0_) * 2 * kPi * mu_in);
            },
            mu_crit);
        sum += ms;
    }
    return sum;
}

/// Y(μ') = ∫ f_b(w', w'') μ'' g(μ'') dω'': what the base's first reflection of light arriving at
/// inside cosine μ' sends back down after one reflection at the coat's bottom. The base's
/// separable multiple-scattering lobe sends F_ms ΔE(μ') Y_ms, Y_ms = ∫ ΔE g 2μ'' dμ'' / ΔĒ.
inline Rgb Bsdf::returned_light(double mu, const RgbEdgeCurve<33>& g, const Rgb& Y_ms) const {
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    if (layers_.base == Base::Lambertian) return layers_.albedo * r_bar_;
    if (alpha1_ == 0) return base_fresnel(mu) * g(mu);
    const GGX ggx{alpha1_};
    const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
    const double lambda_w = ggx.lambda(w);
    // Visible-normal weight: f_b μ'' dω'' = D_w F G2/G1 dwm (Heitz 2018, §2).
    auto f_y = [&](const Vec3& wm) {
        const Vec3 w2 = reflect(w, wm);
        if (w2.z <= 0) return Rgb(0.0);
        const double escape = reflection_escape(lambda_w, ggx.lambda(w2));
        return base_fresnel(dot(w, wm)) * g(w2.z) * escape;
    };
    static const QuadratureRule q = gauss_legendre(kSplitNr);
    constexpr double kTol = 1.0 / (1 << kSplitBisections);
    const Crossing coat_edge{[&](const Vec3& wm) { return reflect(w, wm).z; }, mu_crit};
    // A slab's bottom reflects totally from facets seen beyond its critical cosine: its Fresnel
    // factor steps there too (unsplit, 3e-3 of a slab's albedo at α1 = 0.3).
    Rgb sum = mu_crit_b > 0 && layers_.base == Base::Dielectric
                  ? integrate_visible_split<Rgb>(
                        ggx, w, f_y, q, kSplitNphi, kTol, coat_edge,
                        Crossing{[&](const Vec3& wm) { return dot(w, wm); }, mu_crit_b})
                  : integrate_visible_split<Rgb>(ggx, w, f_y, q, kSplitNphi, kTol, coat_edge);
    if (base_ms_) sum += F_ms_ * Y_ms * dE_base_(mu);
    return sum;
}

/// X(μ), the light the coat's bottom returns to the base after the first order (item 3).
inline void Bsdf::precompute_returned(const RgbEdgeCurve<33>& g_curve,
                                      CosineCurve<Rgb, kNx>* leaving) {
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    // The base's separable multiple-scattering lobe sends what it receives, averaged over its
    // directions: Y_ms = ∫ ΔE g 2μ'' dμ'' / ΔĒ for a curve g of what the way up keeps.
    auto ms_average = [&](const RgbEdgeCurve<33>& g) {
        return base_ms_ ? integrate_split01<kGauss, Rgb>(
                              [&](double mu) { return g(mu) * (dE_base_(mu) * 2 * mu); }, mu_crit) *
                              (1 / dE_base_bar_)
                        : Rgb(0.0);
    };
    const Rgb Y_ms = ms_average(g_curve);
    auto Y = [&](double mu) { return returned_light(mu, g_curve, Y_ms); };
    x_exact_ = layers_.base == Base::Lambertian && (alpha0_ == 0 || !ch_.directional_transmittance);
    // X (and K, X̄) serve the separable series alone.
    if (x_exact_) return;
    if (alpha0_ == 0 || !ch_.directional_transmittance) {
        // The light enters along the refracted direction (smooth coat) or is taken to.
        X_.fill([&](double mu) {
            const double mu_in = inside_cos(mu);
            return Y(mu_in) * attenuation(mu_in) * T_top_(mu);
        });
        return;
    }
    // A rough coat spreads the entering light over the inside directions, beyond the critical
    // cone too (light there cannot leave through the first order and is returned): X(μ) =
    // ∫ t(μ → w') a(μ_w') Y(μ_w') dω' over the coat's transmitted light, by the visible-normal
    // rule of the coat (weight (1 − F) G_t/G1, as in its transmittance table).
    // The coat's orders ≥ 2 transmit ΔT(μ) more, spread over the inside directions: taken as
    // cosine-distributed, they return the hemispherical average of a Y.
    const bool ms = ms_;
    auto spread = [&](const RgbEdgeCurve<17>& Y_curve) {
        return ms ? integrate_split01<kGauss, Rgb>(
                        [&](double m) { return Y_curve(m) * attenuation(m) * (2 * m); }, mu_crit)
                  : Rgb(0.0);
    };
    auto through_coat = [&](const RgbEdgeCurve<17>& Y_curve, const Rgb& Y_spread, double mu) {
        // Y_curve steps at μc, where the refracted direction's inside cosine crosses it.
        Rgb sum = over_coat_transmission<Rgb, kSplitNr, kSplitNphi, kSplitBisections>(
            mu, mu_crit, [&](const Vec3& wt, double F, double escape) {
                return Y_curve(-wt.z) * attenuation(-wt.z) * ((1 - F) * escape);
            });
        if (ms) sum += Y_spread * ms_dielectric(fgd_top_, mu, alpha0_, eta0_).transmitted;
        return sum;
    };
    RgbEdgeCurve<17> Y_curve;
    Y_curve.fill(mu_crit, Y);
    const Rgb Y_spread = spread(Y_curve);
    // What X lets out in the end (where the round trips' lobe carries it): Y with the escape
    // that returned_escape follows in place of what the way up keeps, through the coat as X.
    RgbEdgeCurve<17> YL_curve;
    Rgb YL_spread(0.0);
    if (leaving) {
        const RgbEdgeCurve<33> escape = returned_escape();
        const Rgb YL_ms = ms_average(escape);
        YL_curve.fill(mu_crit, [&](double mu) { return returned_light(mu, escape, YL_ms); });
        YL_spread = spread(YL_curve);
    }
    if (!balance_) {
        X_.fill([&](double mu) { return through_coat(Y_curve, Y_spread, mu); });
        if (leaving)
            leaving->fill([&](double mu) { return through_coat(YL_curve, YL_spread, mu); });
        return;
    }
    // The first order's balance: the accounting above returns what the first order does not let
    // out, assuming it lets out the light inside the exit cone times T_exit (g_curve's R_eff).
    // Its lobe carries a different energy E_lobe (the widened lobe's own masking and spread, the
    // outside-and-inside exit factors): the difference E_acc − E_lobe is returned too, so that
    // the light that entered leaves in the first order or in the series, as it does.
    RgbEdgeCurve<33> exit_curve;
    exit_curve.fill(mu_crit, [&](double mu) {
        if (mu <= mu_crit) return Rgb(0.0);
        return attenuation(mu) * first_order_exit(mu);
    });
    const Rgb Z_ms = ms_average(exit_curve);
    RgbEdgeCurve<17> Z_curve;
    Z_curve.fill(mu_crit, [&](double mu) { return returned_light(mu, exit_curve, Z_ms); });
    const Rgb Z_spread = spread(Z_curve);
    // The difference is smooth in μ: taken on every other node of X's and interpolated (half the
    // construction's cost of the balance; the white furnace moves by < 10⁻³).
    CosineCurve<Rgb, (kNx + 1) / 2> excess;
    excess.fill(
        [&](double mu) { return through_coat(Z_curve, Z_spread, mu) - first_order_energy(mu); });
    int node = 0;
    X_.fill([&](double mu) {
        const Rgb X = through_coat(Y_curve, Y_spread, mu);
        Rgb out = X + excess(mu) * attenuation(inside_cos(mu));
        for (int c = 0; c < 3; ++c)
            out[c] = std::max(out[c], 0.0);
        // What X lets out, with the balance: light the first order's lobe does not carry (the
        // accounting's exit exceeds it) is returned as X is and lets out the same share of
        // itself; light the lobe carries beyond the accounting (at grazing incidence, where the
        // coat sends most of what it transmits beyond the exit cone while the lobe stays on the
        // macro refraction) is taken from what leaves, whole — taken from X it would leave a
        // share 1 − G of itself too much (docs/models.md, lamina-1, item 3).
        if (leaving) {
            const Rgb XL = through_coat(YL_curve, YL_spread, mu), ex = excess(mu);
            const Rgb a_in = attenuation(inside_cos(mu));
            for (int c = 0; c < 3; ++c) {
                const double share = X[c] > 0 ? XL[c] / X[c] : 0.0;
                leaving->v[node][c] =
                    std::max(XL[c] + (ex[c] < 0 ? ex[c] : ex[c] * a_in[c] * share), 0.0);
            }
        }
        ++node;
        return out;
    });
}

/// The light that returned light lets out in the end, followed by its direction (where the
/// round trips' lobe carries it; docs/models.md, lamina-1, item 3). The series lets out G =
/// Ē_b t̄/(1 − Ē_b r̄) of it, hemispherical averages as if the light inside were uniform. Over a
/// metal smoother than the coat it is not: it stays near the direction it came with, spread a
/// little by each reflection at the coat's bottom, and near the critical angle (grazing light
/// outside) most of it is reflected back again and again, each time losing 1 − E_b to the metal,
/// where the averages let it out at the diffuse rate. Here the light is followed on inside
/// cosines: e(μ), what light arriving at the base going down at μ lets out, solves
///   e(μ) = E_b(μ) a(μ) [T_in(μ) + R_in(μ) ∫ P(μ → μ'') a(μ'') e(μ'') dμ'']
/// (the base keeps the direction, being smoother than the coat; T_in and R_in the coat's bottom
/// seen from inside, with its orders ≥ 2; P the cosine its single-scattering reflection sends
/// the light to, normalized: Walter et al. 2007, Eq. 20 with the height-correlated G2 of Heitz
/// 2014, Eq. 99, by its visible normals), a linear system on the curve's nodes. Returned: the
/// counterpart of g(μ) = a² R_eff (what a return trip keeps, precompute_albedos) — what light
/// going up at μ from the base lets out in the end: a(μ) times the part of R_eff that the coat's
/// tilted facets let out at once (T_in beyond the first order's exit), plus the rest reflected
/// and followed by e.
inline RgbEdgeCurve<33> Bsdf::returned_escape() const {
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    constexpr int kH = 17, kN = 2 * kH;  // nodes below and above the critical cosine
    SplitCurve<kH, double, true> nodes;  // its nodes' cosines and locate() alone
    nodes.split = mu_crit;
    auto index = [](bool lower, int i) { return lower ? i : kH + i; };
    // P(μ_n → ·), shared between the two nodes about each reflected cosine, rows normalized.
    std::array<std::array<double, kN>, kN> P{};
    std::array<double, kN> mu_n{};
    for (int n = 0; n < kN; ++n) {
        const bool lower = n < kH;
        const double mu = std::max(nodes.node(lower ? n : n - kH, lower), 1e-4);
        mu_n[n] = mu;
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, mu);
        const double lambda_w = coat_ggx_.lambda(w);
        double sum = 0;
        for_visible_normals<kBinNr, kBinNphi>(coat_ggx_, w, [&](const Vec3& wm, double weight) {
            const Vec3 r = reflect(w, wm);
            if (r.z <= 0) return;
            const double v = fresnel_dielectric(dot(w, wm), inv_eta0_) * weight *
                             reflection_escape(lambda_w, coat_ggx_.lambda(r));
            const auto p = nodes.locate(r.z);
            P[n][index(p.lower, p.i)] += v * (1 - p.t);
            P[n][index(p.lower, p.i + 1)] += v * p.t;
            sum += v;
        });
        if (sum > 0)
            for (double& x : P[n])
                x /= sum;
        else
            P[n][n] = 1;
    }
    // e = (I − D R_in P A)⁻¹ D T_in on the nodes, per channel (D = diag(E_b a), A = diag(a));
    // where the system is singular (no way out anywhere: a lossless mirror under a coat that
    // lets nothing out; inverse() then gives the zero matrix, whose diagonal a true inverse of
    // I − M, M ≥ 0, cannot have), the light is let out at the series' rate.
    std::array<Rgb, kN> e{};
    for (int c = 0; c < 3; ++c) {
        FluxMatrix A(kN);
        std::array<double, kN> b{};
        for (int n = 0; n < kN; ++n) {
            const double mu = mu_n[n];
            const double d = base_albedo(mu)[c] * attenuation(mu)[c];
            for (int m = 0; m < kN; ++m)
                A(n, m) = (n == m ? 1.0 : 0.0) -
                          d * inside_reflectance(mu) * P[n][m] * attenuation(mu_n[m])[c];
            b[n] = d * T_top_in_(mu);
        }
        const FluxMatrix inv = inverse(A);
        if (inv(0, 0) == 0) {
            const double one_minus = 1 - E_bar_[c] * r_bar_[c];
            const double gain = one_minus > 0 ? E_bar_[c] * t_bar_[c] / one_minus : 0.0;
            for (int n = 0; n < kN; ++n)
                e[n][c] = gain;
            continue;
        }
        for (int n = 0; n < kN; ++n)
            for (int m = 0; m < kN; ++m)
                e[n][c] += inv(n, m) * b[m];
    }
    // ρ(μ) = ∫ P(μ → μ'') a(μ'') e(μ''): what light the coat's bottom reflects from μ lets out.
    SplitCurve<kH, Rgb, true> rho;
    rho.split = nodes.split;
    for (int n = 0; n < kN; ++n) {
        Rgb sum(0.0);
        for (int m = 0; m < kN; ++m)
            sum += attenuation(mu_n[m]) * e[m] * P[n][m];
        (n < kH ? rho.below[n] : rho.above[n - kH]) = sum;
    }
    RgbEdgeCurve<33> escape;
    escape.fill(mu_crit, [&](double mu_raw) {
        const double mu = std::max(mu_raw, 1e-6);  // as g's nodes
        const Rgb a = attenuation(mu);
        // The tilted facets' share of R_eff (T_in beyond the first order's exit) leaves at once,
        // the rest is reflected.
        const double R_in = inside_reflectance(mu), R_eff = returned_share(mu);
        const double at_once = std::min(std::max(R_eff - R_in, 0.0), R_eff);
        Rgb out;
        for (int c = 0; c < 3; ++c)
            out[c] = a[c] * (at_once + (R_eff - at_once) * rho(mu)[c]);
        return out;
    });
    return escape;
}

}  // namespace lamina1

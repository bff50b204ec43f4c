#pragma once
// lamina-1's evaluation: the per-incidence state, the reflection (the coat's own, the first order
// through it, the inter-reflections, a scattering medium's light), a slab's transmission, and the
// delta lobes of smooth stacks.

#include "lamina1/bsdf.h"

namespace lamina1 {

inline Bsdf::Incident Bsdf::incident(const Vec3& wi) const {
    Incident in;
    in.wi = wi;
    if (!support_.brdf || wi.z <= 0) return in;
    in.wi_in = refract_in(wi, inv_eta0_);
    // Light exactly at grazing into an index-matched coat stays on the horizon (cos θi' = 0
    // by rounding): nothing enters, and the spread factor k = |1 − μ/(η μ')| would be 0/0.
    if (!(in.wi_in.z > 0)) return in;
    incident_coat(in);
    if (series_on_) in.X = X_at(wi.z);
    if (alpha0_ > 0) in.lambda0 = coat_ggx_.lambda(wi);
    if (top_ms_) in.dR = dR_top_(wi.z);
    if (scatters_) {
        if (base_paths_) in.E_b = mirror_albedo(in.wi_in.z);
        if (orders_on_) {
            in.orders = orders_(wi.z) * orders_norm_;
            if (support_.btdf) in.orders_t = orders_t_(wi.z) * orders_t_norm_;
            if (twice_on_) in.twice = twice_(wi.z);
        }
    }
    if (support_.btdf) {
        in.wi_mean = in.wi_in;
        in.a_mean = in.a_macro;
        if (mean_shift_) {
            // The transmitted light's mean direction, in wi's plane of incidence.
            const double mu = clamp(in.wi_in.z + mu_mean_(wi.z), 1e-4, 1.0);
            const double sxy = std::hypot(in.wi_in.x, in.wi_in.y);
            const double s_new = std::sqrt(1 - mu * mu);
            in.wi_mean =
                sxy > 0 ? Vec3(in.wi_in.x * s_new / sxy, in.wi_in.y * s_new / sxy, mu) : in.wi_in;
            in.a_mean = attenuation(mu);
        }
        // The bottom's deflection at the straight-through pair v' = mirror(wi'), leaving at
        // sin θv = η_s sin θi' (1 when it cannot leave). Taken there rather than at each wo:
        // leaving a denser medium (η_s < 1) the factor grows without bound towards grazing,
        // and a lobe whose width followed wo would no longer be normalized.
        const double s2 = sqr(eta_s_) * (1 - sqr(in.wi_mean.z));
        in.k_bottom = s2 < 1 ? spread_factor(std::sqrt(1 - s2), in.wi_mean.z, eta_s_) : 1.0;
        if (bottom_lobe_) {
            // The first order leaves through the bottom's own BTDF at the mean inside
            // direction, of roughness α_b, scaled to carry the light's first-order energy
            // E_1(μi).
            in.alpha_b = bottom_roughness(in.k_top, in.k_bottom);
            const Multi<Rgb, 2> first = first_order_(wi.z);
            const Multi<Rgb, 2> smooth = first_order_smooth(wi.z, in.wi_in.z);
            // Stored as residuals from the smooth slab, the interpolated curves can undershoot
            // zero by their interpolation error where the energy itself vanishes (grazing
            // incidence, total internal reflection at the bottom): an energy is ≥ 0.
            in.first_E = nonnegative(first.v[0] + smooth.v[1]);
            in.first_M = nonnegative(first.v[1] + smooth.v[0]);
            // The bottom lobe carries E_1 over its energy T_lobe at this incidence, by the
            // transmittance table (Walter et al. 2007, Eq. 21 over the visible normals), whose c
            // axis puts the smoothed step of total internal reflection on a node line.
            if (in.alpha_b > 0) {
                const double T_lobe = TransmittanceFormat::lookup(
                    tables_->transmittance(ch_.masking), in.wi_mean.z, in.alpha_b, eta_b_);
                if (T_lobe > 0) in.first_T = in.first_E * (1 / T_lobe);
            }
            // btdf-lobe=shared: the bottom's share of the spread's variance.
            if (ch_.btdf_lobe_shared && in.alpha_b > 0)
                in.u_bottom = sqr(alpha1_) / sqr(in.alpha_b);
        }
        if (bins_ready_) incident_bins(in);
        if (pol_on_) {
            in.pol_R = pol_R_(wi.z);
            in.pol_T = pol_T_(wi.z);
        }
    }
    return in;
}

/// What the coat does to wi for the first order (wi_in set, pointing up): T(μi), the first
/// order's coat factor T_pair, the attenuation, the spread rate and the lobe's normalization.
inline void Bsdf::incident_coat(Incident& in) const {
    const Vec3& wi = in.wi;
    in.ok = true;
    in.T = T_top_(wi.z);
    in.T_pair = in.T;
    in.a_macro = attenuation(in.wi_in.z);
    in.a = a_coat_on_ ? a_coat_(wi.z) : in.a_macro;
    if (lobe_norm_on_) in.lobe_norm = lobe_norm_(in.wi_in.z);
    in.k_top = spread_factor(wi.z, in.wi_in.z, eta0_);
    if (inside_exit_) in.T_pair = std::sqrt(in.T * exit_transmittance(wi.z, in.wi_in.z, in.k_top));
}

inline Rgb Bsdf::eval_with(const Incident& in, const Vec3& wo) const {
    if (!in.ok || wo.z == 0) return Rgb(0.0);
    if (wo.z < 0) return support_.btdf ? eval_btdf(in, wo) : Rgb(0.0);
    const Vec3& wi = in.wi;
    Rgb f(0.0);
    if (alpha0_ > 0) {
        // The coat's own reflection, exact: Walter et al. 2007, Eq. 20, with the height-
        // correlated G2 (Heitz 2014, Eq. 99).
        const GGX& ggx0 = coat_ggx_;
        const Vec3 h = normalize(wi + wo);
        const double G = 1 / (1 + in.lambda0 + ggx0.lambda(wo));
        f = Rgb(fresnel_dielectric(dot(wi, h), eta0_) * ggx0.D(h) * G / (4 * wi.z * wo.z));
        // Its orders ≥ 2 as a separable lobe of albedo ΔR(μi), reciprocal by construction
        // (the energy-compensation form of Kulla & Conty 2017, "Revisiting physically based
        // shading at Imageworks", SIGGRAPH course, with the walk's ΔR in place of 1 − E).
        if (top_ms_) f += Rgb(in.dR * dR_top_(wo.z) * kInvPi / dR_top_bar_);
    }
    const Vec3 wo_in = refract_in(wo, inv_eta0_);
    const Rgb a_o = coat_attenuation(wo.z, wo_in.z);
    // A slab's light beyond the coat's own reflection under polarization (1 where it is off).
    const Rgb pol = pol_on_ ? in.pol_R * pol_R_(wo.z) : Rgb(1.0);
    f += first_order(in, wo, wo_in, a_o, LobeForm{}) * pol;
    if (series_on_) {
        f += in.X * X_at(wo.z) * K_ * (kInvPi * inv_eta0_ * inv_eta0_) * pol;
    }
    if (round_trip_on_) f += round_trip(in, wo, wo_in, a_o);
    if (bins_) f += bins_reflection(in, wo) * pol;
    // The medium's terms take the light along the macro refractions (their depth integrals).
    if (scatters_) f += scattered(in, wo, wo_in, a_coat_on_ ? attenuation(wo_in.z) : a_o);
    return f;
}

/// First order: the base's lobe at the refracted directions, entering and leaving through the
/// coat's directional transmittance; 1/η0² compresses the solid angle. `base_ms`: with the base's
/// separable multiple-scattering lobe.
inline Rgb Bsdf::first_order(const Incident& in, const Vec3& wo, const Vec3& wo_in, const Rgb& a_o,
                             LobeForm form) const {
    // A direction refracted onto the horizon (an index-matched coat at grazing light, where
    // √(1 − sin²θ) rounds to 0) carries no first order: T is 0 there and the lobe 0/0.
    const Rgb fb = in.wi_in.z > 0 && wo_in.z > 0 ? base_lobe(in, wo.z, wo_in, form) : Rgb(0.0);
    if (!(fb.max() > 0)) return Rgb(0.0);
    // The coat enters with T(μi) and leaves with T_exit(μo); made reciprocal as the product
    // √(T T_exit)(μi) √(T T_exit)(μo), exact at the mirror pair (μo = μi) where the narrow
    // first order is.
    double T_o = T_top_(wo.z);
    if (inside_exit_)
        T_o =
            std::sqrt(T_o * exit_transmittance(wo.z, wo_in.z, spread_factor(wo.z, wo_in.z, eta0_)));
    Rgb rounds(1.0);
    if (mirror_series_) rounds = mirror_series_curve_(in.wi_in.z) * mirror_series_curve_(wo_in.z);
    return fb * (in.a * a_o) * rounds *
           (in.T_pair * T_o * (ch_.eta2_factor ? inv_eta0_ * inv_eta0_ : 1.0));
}

/// The round trips' lobe (Options::round_trip_lobe; docs/models.md, lamina-1, item 3): the light
/// the first order's exit leaves inside goes back to the coat's bottom, which reflects it to the
/// base, which sends it out, and so on. A Walter lobe of the base at the refracted pair
/// (wi', wo') with the GGX of α_r (Walter et al. 2007, Eq. 20, with the height-correlated G2 of
/// Heitz 2014, Eq. 99; round_trip_alpha: the base's two reflections and the coat bottom's one
/// widen the first order's α_e), entering and leaving as the first order does
/// (T_pair, T_exit, a, 1/η0²), times its scale s(μ) at each end (μi and μo outside; solved at
/// construction so that the lobe carries what the returned light lets out,
/// precompute_round_trips): symmetric in (wi, wo).
inline Rgb Bsdf::round_trip(const Incident& in, const Vec3& wo, const Vec3& wo_in,
                            const Rgb& a_o) const {
    if (!(in.wi_in.z > 0 && wo_in.z > 0)) return Rgb(0.0);
    const double k_o = spread_factor(wo.z, wo_in.z, eta0_);
    const GGX ggx{round_trip_alpha(in.k_top, k_o)};
    const Vec3 h = normalize(in.wi_in + wo_in);
    const Rgb fb = base_fresnel(dot(in.wi_in, h)) *
                   (ggx.D(h) * ggx.G2(in.wi_in, wo_in) / (4 * in.wi_in.z * wo_in.z));
    double T_o = T_top_(wo.z);
    if (inside_exit_) T_o = std::sqrt(T_o * exit_transmittance(wo.z, wo_in.z, k_o));
    return fb * (in.a * a_o) * round_trip_curve_(in.wi.z) * round_trip_curve_(wo.z) *
           (in.T_pair * T_o * (ch_.eta2_factor ? inv_eta0_ * inv_eta0_ : 1.0));
}

/// The scattering medium's reflected terms (out of line: absorbing stacks pay one branch).
LAMINA1_NOINLINE inline Rgb Bsdf::scattered(const Incident& in, const Vec3& wo, const Vec3& wo_in,
                                            const Rgb& a_o) const {
    Rgb f(0.0);
    if (single_on_ && wo_in.z > 0) f += single_scattering(in, wo_in, a_o, T_top_(wo.z));
    if (orders_on_) f += in.orders * orders_(wo.z);
    return f;
}

/// The medium's once-scattered light between the two refractions, exact for the slab
/// (docs/models.md, lamina-1, "Scattering media"): back-scattered at depth t on the way
/// down (the first term), and — over a conductor or dielectric base taken as a mirror of its
/// albedo E_b — scattered on the way down then mirrored, or mirrored then scattered on the
/// way up (the second), each the depth integral of the Beer–Lambert factors in closed form.
/// Entering with T(μi), leaving with T(μo) (broad light: the uniform-radiance exit), 1/η0².
inline Rgb Bsdf::single_scattering(const Incident& in, const Vec3& wo_in, const Rgb& a_o,
                                   double T_o) const {
    const Vec3& wi_in = in.wi_in;
    const double mu_i = wi_in.z, mu_o = wo_in.z;
    const double dxy = wi_in.x * wo_in.x + wi_in.y * wo_in.y, zz = mu_i * mu_o;
    // Propagation directions: −wi' in, wo' out (back-scattered), or the mirror of wo'.
    const double cos_back = -dxy - zz, cos_mirror = -dxy + zz;
    Rgb f(0.0);
    double p_back = 0, p_mirror = 0;
    const Rgb E_o = base_paths_ ? mirror_albedo(mu_o) : Rgb(0.0);
    for (int c = 0; c < 3; ++c) {
        if (c == 0 || !g_uniform_) {
            if (back_on_) p_back = hg_phase(cos_back, layers_.g[c]);
            if (base_paths_) p_mirror = hg_phase(cos_mirror, layers_.g[c]);
        }
        double v = p_back * (1 - in.a_macro[c] * a_o[c]) / (mu_i + mu_o);
        if (base_paths_) {
            v += p_mirror * attenuation_slope(mu_o, mu_i, a_o[c], in.a_macro[c], tau_t_[c]) *
                 (E_o[c] * a_o[c] + in.E_b[c] * in.a_macro[c]);
        }
        f[c] = omega_[c] * v;
    }
    return f * (in.T * T_o * (ch_.eta2_factor ? inv_eta0_ * inv_eta0_ : 1.0));
}

inline std::vector<DeltaLobe> Bsdf::delta_lobes(const Vec3& wi) const {
    std::vector<DeltaLobe> out;
    if (!support_.brdf || wi.z <= 0) return out;
    if (alpha0_ > 0) return out;
    const Vec3 wr = mirror_direction(wi);
    const double F = fresnel_dielectric(wi.z, eta0_);
    out.push_back({wr, Rgb(F)});
    // An index-matched bottom is not there for the light, whatever its roughness.
    const bool matched = bottom_matched();
    if (layers_.base == Base::Lambertian || (alpha1_ > 0 && !matched)) return out;
    // Both interfaces smooth: every order is specular (docs/physics.md §6.4–6.5 of the study):
    // the series Σ (R_in R_b a²)^k with R_in = F(μi) (Fresnel is the same from both sides).
    const Vec3 w_in = refract_in(wi, inv_eta0_);
    const Rgb a = attenuation(w_in.z);
    const Rgb Rb = base_fresnel(w_in.z);
    const double T = 1 - F;
    // Polarized (lamina1/polarization.h): the series per polarization, what it changes here.
    const PolarizationChange pol = pol_ ? pol_->change(wi.z) : PolarizationChange{};
    Rgb series(1.0);
    if (ch_.inter_reflection)
        for (int c = 0; c < 3; ++c) {
            // F R_b a² = 1 only where nothing enters (F = 1: wi exactly grazing), and the
            // lobes' T factor is 0 there: no series (not 0·∞).
            const double round_trip = F * Rb[c] * a[c] * a[c];
            series[c] = round_trip < 1 ? 1 / (1 - round_trip) : 0.0;
        }
    if (!matched) out.push_back({wr, nonnegative(Rb * a * a * series * (T * T) + pol.reflected)});
    if (support_.btdf) {
        const double sin_t = std::hypot(wi.x, wi.y) * inv_eta0_ * eta_s_;
        if (sin_t < 1) {
            const double Tb = 1 - fresnel_dielectric(w_in.z, eta_b_);
            out.push_back({transmitted_direction(wi, std::sqrt(1 - sin_t * sin_t)),
                           nonnegative(a * series * (T * Tb) + pol.transmitted)});
        }
    }
    return out;
}

inline std::vector<Vec3> Bsdf::peak_directions(const Vec3& wi) const {
    std::vector<Vec3> peaks{mirror_direction(wi)};
    if (support_.btdf && wi.z > 0) {
        const double sin_t = std::hypot(wi.x, wi.y) * inv_eta0_ * eta_s_;
        if (sin_t < 1) peaks.push_back(transmitted_direction(wi, std::sqrt(1 - sin_t * sin_t)));
        if (mean_shift_) {  // the transmission lobe's own peak
            const double sin_m = std::sqrt(1 - sqr(incident(wi).wi_mean.z)) * eta_s_;
            if (sin_m < 1) peaks.push_back(transmitted_direction(wi, std::sqrt(1 - sin_m * sin_m)));
        }
    }
    return peaks;
}

/// The slab medium's once-scattered light leaving through the bottom, exact for the slab:
/// scattered at depth t from the entering direction −wi' into the leaving one (v' turned
/// down), ϖ p(Θ) (a(μv') − a(μi'))/(μv' − μi') per unit flux inside (the depth integral of
/// the two Beer–Lambert factors), entering with T(μi), leaving as broad light with the
/// bottom's T_b(μv)/η_s².
/// (With g → g² and the scale K(μi) T(μi) in place of T(μi): the transmitted remainder shaped
/// like twice-scattered light.)
LAMINA1_NOINLINE inline Rgb Bsdf::single_transmission(const Incident& in, const Vec3& v_in,
                                                      const Rgb& a_v, double T_b, const Rgb& g,
                                                      const Rgb& scale) const {
    const Vec3& wi_in = in.wi_in;
    const double cos_forward = -(wi_in.x * v_in.x + wi_in.y * v_in.y) + wi_in.z * v_in.z;
    Rgb f(0.0);
    double p = 0;
    for (int c = 0; c < 3; ++c) {
        if (c == 0 || !g_uniform_) p = hg_phase(cos_forward, g[c]);
        f[c] = omega_[c] * p *
               attenuation_slope(v_in.z, wi_in.z, a_v[c], in.a_macro[c], tau_t_[c]) * scale[c];
    }
    return f * (T_b / (eta_s_ * eta_s_));
}

/// The BTDF of a slab: the mirrored transmission lobe through both interfaces, and the
/// diffuse light of the inter-reflections leaving through the bottom.
inline Rgb Bsdf::eval_btdf(const Incident& in, const Vec3& wo) const {
    // v: wo mirrored into the upper hemisphere; v' its refraction into the coat through the
    // bottom (η_s = η_coat/η_below): the straight-through pair has v' = mirror(wi').
    const Vec3 v(wo.x, wo.y, -wo.z);
    Rgb f(0.0);
    const bool matched = bottom_matched();
    if (matched) {
        // The coat's interface alone (for the unscattered light): its BTDF (Walter et al. 2007,
        // Eq. 21), the light crossing the layer once along wo, and under multiple scattering its
        // orders ≥ 2, ΔT(μi), cosine-distributed (as the slab's entry takes them). A smooth
        // coat's is a delta lobe.
        RoughDielectric top{eta0_, alpha0_};
        top.masking = ch_.masking;
        double t = top.eval(in.wi, wo);
        if (ms_ && alpha0_ > 0)
            t += ms_dielectric(fgd_top_, in.wi.z, alpha0_, eta0_).transmitted * kInvPi;
        f += attenuation(-wo.z) * t;
    }
    // The bottom's own lobe and the bins' light reach every wo: into a denser medium a rough
    // bottom scatters beyond the cone that refraction maps the inside hemisphere onto.
    if (bottom_lobe_ && in.alpha_b > 0 && in.u_bottom > 0) {
        // The bottom's Walter BTDF (Eq. 21) from the mean inside direction: with a smooth coat
        // the first order is exactly T(μi) a(μi') f_t,bottom(wi', wo).
        f += in.first_T * (in.u_bottom * bottom_btdf(in.alpha_b).eval(in.wi_mean, wo));
    }
    if (bins_) f += bins_transmission(in, wo);
    const auto v_in = refract_in_checked(v, 1 / eta_s_);
    // The unscattered light under polarization (1 where it is off): everything above, and the
    // narrow lobe and the series below.
    if (!v_in) return f * in.pol_T;
    const double T_b = T_bot_(v.z), T_b_in = T_bot_in_(v_in->z);
    const Rgb a_v = has_absorption_ ? attenuation(v_in->z) : Rgb(1.0);
    const double beta = transmission_roughness(in.k_top, in.k_bottom);
    if (!matched && (!bottom_lobe_ || in.u_bottom < 1) && beta > 0) {
        const GGX ggx{beta};
        const Vec3 h = normalize(in.wi_mean + *v_in);
        const double q = ggx.D(h) * ggx.G2(in.wi_mean, *v_in) / (4 * in.wi_mean.z * v_in->z);
        // The narrow lobe leaves with the bottom's transmittance from inside, T_in(μv'):
        // consistent with the bottom's reflection R_b(μ') (R_b + T_in + loss = 1).
        // The light crosses the coat's medium once: the geometric mean of the attenuations
        // along the entering and the leaving direction (both e^{−τ/μi'} at the straight-
        // through pair).
        Rgb a_once = in.a_mean * a_v;
        for (int c = 0; c < 3; ++c)
            a_once[c] = std::sqrt(a_once[c]);
        if (mirror_series_)
            a_once *= mirror_series_curve_(in.wi_mean.z) * mirror_series_curve_(v_in->z);
        if (bottom_lobe_) {
            // btdf-lobe=shared: the mirrored lobe's share 1 − u of the first order, carrying
            // E_1 over its energy Q_m (the medium's attenuation is in E_1).
            Rgb rounds(1.0);
            if (mirror_series_)
                rounds = mirror_series_curve_(in.wi_mean.z) * mirror_series_curve_(v_in->z);
            f += in.first_M * rounds * ((1 - in.u_bottom) * T_b_in * q / (eta_s_ * eta_s_));
        } else {
            f += a_once * (in.T * T_b_in * q / (eta_s_ * eta_s_));
        }
    }
    if (!bins_ && !matched && series_btdf_)
        f += in.X * inv_one_minus_Er_ * (T_b * kInvPi / (eta_s_ * eta_s_));
    f *= in.pol_T;
    // The scattered light that leaves through the bottom, as uniform radiance below it.
    if (orders_on_ && !twice_on_) f += in.orders_t * T_b;
    if (scatters_ && back_on_) f += single_transmission(in, *v_in, a_v, T_b, layers_.g, Rgb(in.T));
    if (twice_on_) f += single_transmission(in, *v_in, a_v, T_b, g_twice_, in.twice * in.T);
    return f;
}

/// The base's lobe at the refracted pair (wi', wo'), widened by the coat's refraction spread.
inline Rgb Bsdf::base_lobe(const Incident& in, double mu_o, const Vec3& wo_in,
                           LobeForm form) const {
    if (layers_.base == Base::Lambertian) return layers_.albedo * kInvPi;
    const double k_o = spread_factor(mu_o, wo_in.z, eta0_);
    const GGX ggx =
        form.anisotropic ? widened_ggx(in.k_top, k_o) : GGX{effective_alpha(in.k_top, k_o)};
    if (ggx.alpha <= 0) return Rgb(0.0);  // a delta lobe (delta_lobes)
    Rgb f(0.0);
    if (form.specular) {
        const Vec3 h = normalize(in.wi_in + wo_in);
        const double G = ggx.G2(in.wi_in, wo_in);
        const double D =
            shaped_lobe_ ? first_order_ndf(h, in.k_top, k_o, aniso_ && form.anisotropic) : ggx.D(h);
        f = base_fresnel(dot(in.wi_in, h)) * (D * G / (4 * in.wi_in.z * wo_in.z));
        if (lobe_norm_on_) f *= in.lobe_norm * lobe_norm_(wo_in.z);
    }
    // The base's orders ≥ 2 (of its own roughness α1), separable as the coat's.
    if (base_ms_ && form.base_ms)
        f += F_ms_ * (dE_base_(in.wi_in.z) * dE_base_(wo_in.z) * kInvPi / dE_base_bar_);
    return f;
}

/// The widened base lobe's normal distribution at the inside half vector h (first-order-lobe
/// compressed or sum; docs/models.md, lamina-1, item 4). Its half-vector slope is the sum of
/// three independent GGX slopes, the base's (α1) and the coat's two refractions' (α0 k_i/2,
/// α0 k_o/2): SlopeSumTable's density, with the same tail as the GGX of α_e and 2/3 to 1 of
/// its core. With `compressed`, the part of the density whose tail a coat spread makes
/// (its variance share u, as in the btdf-lobe=shared rule) is carried through one facet's
/// exact deflection instead of the linear k δ: half entering, half leaving (FacetDeflection;
/// the same for wi and wo, so the lobe stays symmetric), the summed slope S ↔ the facet tilt
/// δ by S = (k/2) tan δ and the mirror direction's turn 2θh = (k/k_n) g(δ), with the map's
/// Jacobian and the facet's transmission. D(h) = P(tan θh)/cos⁴θh. Approximation "the rate
/// of the less oblique end": both coat spreads turn the light at k = min(k_i, k_o), not at
/// their own ends — the light that reaches an oblique wo from a less oblique wi travelled
/// near the lobe's centre, the mirror of the less oblique refraction, where both facets
/// met it; the deflection rate at wo itself (k_o, which grows towards grazing exits) would
/// widen the lobe's flank tenfold at θo = 60° under α0 = 0.5 (tests/models/lamina1_lobe_test).
/// The GGX of α_e keeps k_i and k_o (its masking G2 and the sampling too).
/// `anisotropic` (an anisotropic interface; false: the isotropic material of the roughnesses'
/// root mean squares, which the lobe normalization reads): the three slopes have the covariances
/// Σ1 and (k/2)² Σ0 twice, summed to Σ; the density is the isotropic one stretched by Σ^{1/2}
/// (exactly the sum's when the three covariances are proportional), the GGX factor of Σ at the
/// slope and the table's ratio at its Mahalanobis radius, the base's share x = tr Σ1 / tr Σ; the
/// facet maps act on the slope's length along its own azimuth.
inline double Bsdf::first_order_ndf(const Vec3& h, double k_i, double k_o, bool anisotropic) const {
    // Both refractions turn the light at the rate of the pair's less oblique end (see the
    // comment above): symmetric, and k_i itself at the mirror pair. The two coat spreads
    // then have one scale, α0 k/2, and one map each.
    const double k = std::min(k_i, k_o);
    const double a_b = alpha1_, a_c = 0.5 * alpha0_ * k;
    const double c2 = h.z * h.z;
    // tan θh from the half vector's horizontal length (not from 1 − cos²θh, which rounds to a
    // tangent of 1e-8 at the lobe's peak, where the table's ratio has a slope).
    const double len = std::sqrt(h.x * h.x + h.y * h.y);  // h is a unit vector
    double s2, x;
    // Anisotropic: 1/(π √det Σ) and ûᵀ Σ⁻¹ û, û the unit azimuth of h's slope.
    double inv_norm = 0, inv_q = 0;
    if (anisotropic) {
        const SlopeCovariance total = sigma1_ + sigma0_ * (0.5 * k * k);
        const double trace = total.xx + total.yy, det = total.determinant();
        s2 = 0.5 * trace;
        x = (sigma1_.xx + sigma1_.yy) / trace;
        const double ux = len > 0 ? h.x / len : 1.0, uy = len > 0 ? h.y / len : 0.0;
        inv_q = (total.yy * ux * ux - 2 * total.xy * ux * uy + total.xx * uy * uy) / det;
        inv_norm = kInvPi / std::sqrt(det);
        if (!(det > 0)) s2 = 0;
    } else {
        s2 = sqr(a_b) + 2 * sqr(a_c);
        x = sqr(a_b) / s2;  // the base's share; the coat's two halves have y = 1/2
    }
    if (!(s2 > 0) || !(c2 > 0)) return 0;
    const double sigma = std::sqrt(s2), sqrt_inv_q = std::sqrt(inv_q);
    const float* table = tables_->slope_sum();
    const SlopeSumFormat::Shares at = SlopeSumFormat::locate(x, 0.5);
    // The density of the summed slope at length r along h's azimuth.
    auto density = [&](double r) {
        if (anisotropic)
            return inv_norm / sqr(1 + r * r * inv_q) *
                   SlopeSumFormat::ratio(table, r * sqrt_inv_q, at);
        return s2 * kInvPi / sqr(s2 + r * r) * SlopeSumFormat::ratio(table, r / sigma, at);
    };
    const double t = len / std::abs(h.z), t2 = t * t;
    if (ch_.first_order_lobe != Options::FirstOrderLobe::Compressed || !(a_c > 0))
        return density(t) / sqr(c2);
    // The coat's share 1 − x, half through the entering facet's map, half the leaving one's.
    double p = x * density(t);
    // The maps are read at a tangent of at least 1e-9: their tabulated S/t tends to a limit
    // 1e-4 from the exact 1 as t → 0, and reading it there keeps the lobe continuous at its peak.
    const double t_map = std::max(t, 1e-9);
    const double g = 2 * (1 - inv_eta0_) * std::atan(t_map) / k;
    for (const FacetDeflection* map : {&entering_, &leaving_}) {
        double sin_d, cos_d, w;
        if (!map->lookup(g, sin_d, cos_d, w)) continue;
        const double S = 0.5 * k * sin_d / cos_d;
        // P(t) t dt = P_S(S) S dS: dS/dt = sec²δ k_n / ((1 + t²) g'(δ)), S/t → 1 at 0.
        const double s_over_t = S / t_map;
        p += 0.5 * (1 - x) * density(S) * s_over_t * w / (cos_d * cos_d * (1 + t2));
    }
    return p / sqr(c2);
}

}  // namespace lamina1

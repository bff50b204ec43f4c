#pragma once
// lamina-1's BSDF: the class, the state it precomputes per material and the small helpers every
// part uses. Its parts are defined beside it: the construction and the coat's curves
// (lamina1/coat.h), a scattering medium's (lamina1/media.h), a slab's (lamina1/slab.h), the
// evaluation (lamina1/eval.h) and the sampling (lamina1/sampling.h); lamina1/lamina1.h includes
// them all. lamina's docs/models.md, "lamina-1", derives every term:
//
//   f_R = f_top                                       exact Walter reflection of the coat
//       + T(μi) T(μo) a(μi') a(μo') f_b(wi', wo'; α_e) / η0²     first order through the coat
//       + K X(μi) X(μo) / (π η0²)                    inter-reflections (separable, reciprocal)
//       + T a a f_b(wi', wo'; α_r) s(μi) s(μo) / η0²   the round trips over a conductor smoother
//                                                    than the coat, in place of K X X: s solved
//                                                    so that they carry what the returned light
//                                                    lets out, followed by its direction
//   f_T = E_1(μi) f_t,b(w̄i', wo; α_b) / T_b,in(μ̄i'; α_b)   first order through the slab's bottom
//       + B(μo)ᵀ W_s s(μi) D C(μi)                    later orders, the inside light in bins
//   (a slab's reflection: C(μo)ᵀ W (g P₁ g + P₂) C(μi) in place of K X X; lamina1/slab.h)
//
// T: the coat's directional transmittance, a: Beer–Lambert along the refracted mean directions,
// α_e and β: the base lobe widened by the coat's refraction spread (its shape the sum of the
// base's and the coat's GGX spreads, the coat's tails through one facet's exact refraction), X:
// the light the coat's bottom sends back to the base after the first order, K the normalization
// that gives the separable term the energy of the geometric series; E_1: the slab's exact
// first-order transmission, f_t,b the bottom's Walter BTDF from the coat's mean transmitted
// direction w̄i', α_b its roughness widened by the coat's spread. A scattering medium adds its
// exact single scattering (and, over a conductor or dielectric base, the once-scattered paths that
// meet the base) and a separable lobe carrying the rest of the scattered light, its energy from an
// azimuth-averaged adding–doubling (lamina1/adding.h).

#include "lamina1/adding.h"
#include "lamina1/curves.h"
#include "lamina1/math.h"
#include "lamina1/options.h"
#include "lamina1/physics.h"
#include "lamina1/polarization.h"
#include "lamina1/tables.h"

#include <array>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace lamina1 {

/// What a material supports: reflection (the coat over any base), transmission (a slab: a
/// dielectric base), or nothing, and why.
struct Support {
    bool brdf = false;
    bool btdf = false;
    std::string reason;
};

/// A drawn direction: wo, the weight eval(wi, wo)·|cos θo|/pdf and the density (solid angle).
struct Sample {
    Vec3 wo;
    Rgb weight;
    double pdf = 0;
};

/// A specular lobe of a smooth stack: all the light it carries leaves along `direction`, with
/// `energy` of the incident flux.
struct DeltaLobe {
    Vec3 direction;
    Rgb energy;
};

class Bsdf {
  public:
    /// A material of these layers with these choices, reading `tables` (which must outlive it).
    /// Never throws for any layers; support() says whether it models them.
    Bsdf(const Layers& layers, const Tables& tables, const Options& options = Options());

    const Support& support() const { return support_; }
    const Layers& layers() const { return layers_; }
    const Options& options() const { return ch_; }

    /// Everything that depends on wi alone.
    struct Incident {
        Vec3 wi, wi_in;  ///< wi and its refraction into the coat about n (pointing up)
        bool ok = false;
        double T = 0;      ///< T(μi)
        Rgb a{1.0};        ///< the coat's Beer–Lambert factor for wi (coat_attenuation)
        Rgb a_macro{1.0};  ///< exp(−τ/μi') along the macro refraction (the medium's terms)
        Rgb X{0.0};        ///< X(μi) = T(μi) a(μi') Y(μi')
        double lambda0 = 0, k_top = 0, k_bottom = 1;
        Vec3 wi_mean;       ///< the mean direction of the light the coat transmits (slabs)
        Rgb a_mean{1.0};    ///< exp(−τ/μ̄')
        double dR = 0;      ///< ΔR(μi) of the coat (multiple scattering)
        double T_pair = 0;  ///< √(T(μi) T_exit(μi)): the first order's reciprocal coat factor
        double lobe_norm = 1;  ///< 1/√N(μi'): the widened base lobe's normalization
        Rgb E_b{0.0};          ///< scattering media: the base's albedo E_b(μi') (mirror paths)
        Rgb orders{0.0};       ///< E_ms(μi)/(π Ē_ms): the scattered remainder's separable lobe
        Rgb orders_t{0.0};     ///< E_ms,T(μi)/(π T̄_b): its transmitted part (slabs)
        Rgb twice{0.0};        ///< that part's normalization as twice-scattered light
        double alpha_b = 0;    ///< the slab bottom's roughness widened by the coat's spread
        Rgb first_T{0.0};  ///< E_1(μi)/T_lobe(μi): the first order over the bottom lobe's energy
        Rgb first_E{0.0};  ///< E_1(μi): the first order's transmitted energy
        double u_bottom = 1;  ///< the first order's share in the bottom's lobe (btdf-lobe)
        Rgb first_M{0.0};     ///< E_1(μi)/Q_m(μi): over the mirrored lobe's energy (shared)
        /// slab-orders=bins (lamina1/slab.h, incident_bins): per bin, the reflection's vectors
        /// g(μi) W P₁ C(μi) and W P₂ C(μi), the light arriving at the bottom (energy and forward
        /// moment each), and the energies let out (reflected, transmitted: the sampler's
        /// weights).
        Multi<Rgb, 6 * kNbins + 2> bins{};
        /// polarization (lamina1/polarization.h): √k_R(μi) and k_T(μi), 1 where it is off.
        Rgb pol_R{1.0}, pol_T{1.0};
    };

    /// The per-incidence part of eval (wi.z > 0): evaluate many wo with eval_with.
    Incident incident(const Vec3& wi) const;

    /// The BSDF (radiance, 1/sr, cosine excluded; delta lobes excluded), light arriving from wi
    /// (wi.z > 0) and leaving towards wo (wo.z > 0 reflection, wo.z < 0 a slab's transmission).
    Rgb eval(const Vec3& wi, const Vec3& wo) const { return eval_with(incident(wi), wo); }
    Rgb eval_with(const Incident& in, const Vec3& wo) const;

    /// The specular lobes of a smooth coat (none when α0 > 0).
    std::vector<DeltaLobe> delta_lobes(const Vec3& wi) const;
    /// Directions where narrow lobes peak (quadratures refine towards them).
    std::vector<Vec3> peak_directions(const Vec3& wi) const;

    /// Draws wo for light from wi (wi.z > 0) from three uniforms in [0, 1), with the density
    /// pdf(wi, wo) (solid angle, either side); nothing where the draw fails. Delta lobes are
    /// not drawn (delta_lobes).
    std::optional<Sample> sample(const Vec3& wi, const Vec3& u) const;
    double pdf(const Vec3& wi, const Vec3& wo) const;

    /// The state the GLSL form of eval reads (lamina1/gpu.h documents the layout and what it
    /// covers), or why this material is not one it covers (the vector then empty).
    std::vector<float> gpu_state(std::string* why = nullptr) const;

    /// The coat's interface seen from inside the coat (no medium, no base), at inside cosine μ:
    /// its directional reflectance and transmittance, with the orders ≥ 2 of multiple
    /// scattering where they are on — the terms the construction builds the inside light from.
    struct InteriorAlbedos {
        double reflected = 0, transmitted = 0;
    };
    InteriorAlbedos coat_from_inside(double mu) const {
        return {inside_reflectance(mu), T_top_in_(mu)};
    }

  private:
    // Construction (lamina1/coat.h, media.h, slab.h).
    void precompute();
    void setup_transmittances();
    void precompute_lobe_normalization();
    void precompute_multiple_scattering();
    void precompute_coat_attenuation();
    RgbEdgeCurve<33> precompute_albedos();
    void precompute_mean_direction();
    void precompute_series(const RgbEdgeCurve<33>& g_curve);
    Rgb first_order_energy(double mu, bool of_round_trip = false) const;
    /// first_order_energy's rule over the visible normals alone, each node's value passed
    /// through out(value, wo), wo its outside direction (any direction where the value is 0), and
    /// summed as V (the round trips' solve sums it onto the two nodes of their curve about wo).
    template <typename V, typename Out>
    V visible_rule_energy(double mu, bool of_round_trip, Out&& out) const;
    void precompute_round_trips(const Rgb& gain, const CosineCurve<Rgb, kNx>& leaving,
                                double weight);
    Rgb returned_light(double mu, const RgbEdgeCurve<33>& g_curve, const Rgb& Y_ms) const;
    void precompute_returned(const RgbEdgeCurve<33>& g_curve,
                             CosineCurve<Rgb, kNx>* leaving = nullptr);
    RgbEdgeCurve<33> returned_escape() const;
    /// R_eff(μ): of the light going up at inside cosine μ, the part the first order does not let
    /// out, which is returned (precompute_albedos).
    double returned_share(double mu) const;
    void precompute_scattering();
    struct AddingEnergies;
    AddingEnergies adding_energies() const;
    std::vector<double> twice_shape_energy(int c, const CosineNodes& nodes,
                                           std::vector<double>& twice_phase) const;
    void precompute_scattering_curves(const AddingEnergies& e);
    void precompute_slab();
    void precompute_polarization();
    CosineCurve<Rgb, kNfirst> slab_entry();
    void slab_first_order(const CosineCurve<Rgb, kNfirst>& entry);
    /// slab-orders=bins (lamina1/slab.h).
    using BinMoments = Multi<double, 2 * kNbins>;
    struct Hat {
        int k0, k1;
        double w0, w1;
    };
    Hat hat_of(double mu) const;
    void hat_rule(int k, std::array<double, 2 * kBinSub>& mu,
                  std::array<double, 2 * kBinSub>& weight, double& area) const;
    BinMoments refracted_into_bins(double alpha, double eta, const FgdView& fgd, double mu) const;
    void slab_bins();
    BinMoments coat_entry(double mu) const;
    BinMoments bottom_exit(double mu) const;
    void incident_bins(Incident& in) const;
    Rgb bins_reflection(const Incident& in, const Vec3& wo) const;
    Rgb bins_transmission(const Incident& in, const Vec3& wo) const;

    // Evaluation (lamina1/eval.h).
    Rgb scattered(const Incident& in, const Vec3& wo, const Vec3& wo_in, const Rgb& a_o) const;
    Rgb single_scattering(const Incident& in, const Vec3& wo_in, const Rgb& a_o, double T_o) const;
    Rgb single_transmission(const Incident& in, const Vec3& v_in, const Rgb& a_v, double T_b,
                            const Rgb& g, const Rgb& scale) const;
    Rgb eval_btdf(const Incident& in, const Vec3& wo) const;
    void incident_coat(Incident& in) const;
    /// Which parts of the base lobe: its single-scattering lobe, the base's separable
    /// multiple-scattering lobe; with the interfaces' own slope covariances or, rotation-
    /// invariant, their root mean square roughnesses (the same where every interface is
    /// isotropic).
    struct LobeForm {
        bool specular = true;
        bool base_ms = true;
        bool anisotropic = true;
    };
    Rgb first_order(const Incident& in, const Vec3& wo, const Vec3& wo_in, const Rgb& a_o,
                    LobeForm form) const;
    Rgb base_lobe(const Incident& in, double mu_o, const Vec3& wo_in, LobeForm form) const;
    Rgb round_trip(const Incident& in, const Vec3& wo, const Vec3& wo_in, const Rgb& a_o) const;
    double first_order_ndf(const Vec3& h, double k_i, double k_o, bool anisotropic) const;

    // Sampling (lamina1/sampling.h): the mixture for one incidence, lobe probabilities (top
    // reflection, base lobe, diffuse series; transmission lobe, diffuse transmission) and the
    // lobes' roughnesses.
    struct Mixture {
        std::array<double, 5> p{};
        Vec3 wi_in, wi_mean;
        GGX base{0.0};  ///< the base lobe's proposal: the widened GGX of k_i on both sides
        double beta = 0;
        bool bottom_sampled = false;  ///< the transmission lobe drawn as the bottom's (btdf-lobe)
    };
    Mixture mixture(const Incident& in) const;
    /// A slab's energies at wi per channel, beyond the coat's own reflection: the first order
    /// reflected (T(μi) a² R_b(μi') T_exit(μi'), first_order_exit) and transmitted
    /// (E_1, or T a (1 − R_b)), and the later orders' (bins, else the series) reflected and
    /// transmitted.
    struct SlabEnergies {
        Rgb first_reflected{0.0}, later_reflected{0.0}, first_transmitted{0.0},
            later_transmitted{0.0};
    };
    SlabEnergies slab_energies(const Incident& in) const;
    double pdf_with(const Incident& in, const Mixture& m, const Vec3& wo) const;

    /// The coat's transmittance for the first order leaving a non-Lambertian base towards the
    /// outside cosine μ (inside μ_in, spread factor k): T_in(μ_in) where the base lobe is narrower
    /// than the coat's refraction spread α0 k/2 (the light meets the coat along one direction
    /// and leaves with that direction's transmittance from inside), T(μ) where it is wider (the
    /// radiance inside is locally uniform, and the light reaching μ outside is T(μ) by
    /// reciprocity), weighted by u = α1² / (α1² + (α0 k/2)²).
    double exit_transmittance(double mu, double mu_in, double k) const {
        const double spread2 = sqr(0.5 * alpha0_ * k),
                     u = spread2 > 0 ? sqr(alpha1_) / (sqr(alpha1_) + spread2) : 1.0;
        return u * T_top_(mu) + (1 - u) * T_top_in_(mu_in);
    }

    /// The part of the light inside at μ' (within the exit cone) that the first order lets
    /// out: T_exit along the macro refraction (exit-transmittance=inside), else T(μo).
    double first_order_exit(double mu_in) const {
        const double mu_out = safe_sqrt(1 - (1 - mu_in * mu_in) * sqr(eta0_));
        return inside_exit_ ? exit_transmittance(mu_out, mu_in, spread_factor(mu_out, mu_in, eta0_))
                            : T_top_(mu_out);
    }

    /// α_e² = α1² + (α0 k_i/2)² + (α0 k_o/2)²: a deflection of the light by ε turns the mirror
    /// direction by ε, i.e. its half vector by ε/2; independent spreads add in variance (the
    /// variance adding of Belcour 2018, §5, with GGX's α as the slope scale).
    double effective_alpha(double k_i, double k_o) const {
        if (ch_.spread == Options::Spread::Off) return alpha1_;
        return std::sqrt(sqr(alpha1_) + 0.25 * sqr(alpha0_) * (sqr(k_i) + sqr(k_o)));
    }

    /// The first round trip's lobe width: α_r² = α_e² + α1² + α0². The base reflects the light
    /// twice (each reflection turns it by twice its facet's tilt, the mirror direction's half
    /// vector by the tilt: GGX slopes of scale α1) and the coat's bottom once (the same with its
    /// own facets, scale α0), between the coat's two refractions of α_e; independent spreads
    /// add in variance, as in effective_alpha.
    double round_trip_alpha(double k_i, double k_o) const {
        return std::sqrt(sqr(effective_alpha(k_i, k_o)) + sqr(alpha1_) + sqr(alpha0_));
    }

    /// The widened base lobe as a GGX distribution: of α_e (effective_alpha), or, where an
    /// interface is anisotropic, of the slope covariance Σ_e = Σ1 + (k_i² + k_o²)/4 Σ0 — each
    /// axis of the coat's spread scaled as the isotropic α0 is, in the coat's own tangent frame,
    /// and the coat's and the base's covariances summed however their tangents are turned (the
    /// 2 × 2 covariances of Weier & Belcour 2020, §3; α_e² is half its trace when both are
    /// isotropic).
    GGX widened_ggx(double k_i, double k_o) const {
        if (!aniso_) return GGX{effective_alpha(k_i, k_o)};
        SlopeCovariance sigma = sigma1_;
        if (ch_.spread != Options::Spread::Off)
            sigma = sigma + sigma0_ * (0.25 * (sqr(k_i) + sqr(k_o)));
        // Each of Σ0, Σ1 is 0 (a smooth interface) or positive definite, and so is the sum.
        return sigma.xx + sigma.yy > 0 ? GGX::anisotropic_of(sigma) : GGX{0.0};
    }

    /// β² = ((α0 k_top)² + (α1 k_bottom)²)/4: the mirrored lobe of a slab's transmission.
    double transmission_roughness(double k_top, double k_bottom) const {
        if (ch_.spread == Options::Spread::Off) return std::max(alpha0_, alpha1_);
        return 0.5 * std::sqrt(sqr(alpha0_ * k_top) + sqr(alpha1_ * k_bottom));
    }

    /// α_b² = α1² + (α0 k_top/k_bottom)²: the coat turns the light inside by α0 k_top (per unit
    /// slope), which a bottom facet of slope s matches with k_bottom s (item 5 of lamina-1).
    double bottom_roughness(double k_top, double k_bottom) const {
        if (ch_.spread == Options::Spread::Off) return std::max(alpha0_, alpha1_);
        return std::sqrt(sqr(alpha1_) + sqr(alpha0_ * k_top / k_bottom));
    }

    /// The slab under a smooth coat: E_1/T_lobe = (1 − F(μ)) a(μ') and E_1 = (1 − F(μ)) a(μ')
    /// T_b,in(μ') (v[0], v[1]). first_order_ holds the residual from them: it vanishes with α0, and
    /// the steep edges at grazing incidence and at the bottom's critical cosine are not
    /// interpolated.
    Multi<Rgb, 2> first_order_smooth(double mu, double mu_in) const {
        Multi<Rgb, 2> r;
        r.v[0] = attenuation(mu_in) * (1 - fresnel_dielectric(mu, eta0_));
        r.v[1] = r.v[0] * T_bot_in_(mu_in);
        return r;
    }

    /// A slab over a medium of the coat's own index: its bottom is not there for the light, and
    /// the stack is the coat's interface alone (delta_lobes, eval_btdf).
    bool bottom_matched() const { return layers_.base == Base::Dielectric && eta_b_ == 1; }

    /// The slab bottom as a single rough interface seen from inside the coat (wi inside, up).
    RoughDielectric bottom_btdf(double alpha) const {
        RoughDielectric d{eta_b_, alpha};
        d.masking = ch_.masking;
        return d;
    }

    double spread_factor(double mu, double mu_in, double eta) const {
        if (ch_.spread == Options::Spread::Normal) return std::abs(1 - 1 / eta);
        return deflection(mu, mu_in, eta);
    }

    /// ∫ over the light the rough coat transmits from the outside cosine μ, by the coat's
    /// visible-normal rule (Heitz 2018), split where the refracted direction's inside cosine
    /// crosses `split`: each refracted direction wt (pointing down) is passed to f with the
    /// facet's Fresnel factor F and the refracted ray's escape from the microsurface (G_t/G1,
    /// refraction_escape), f(wt, F, escape) — the weight (1 − F)·escape of the coat's
    /// transmittance table. X(μ), a slab's entry and the coat's Beer–Lambert factor read it.
    template <typename V, int kNr, int kNphi, int kBisections, typename F>
    V over_coat_transmission(double mu, double split, F&& f) const {
        const GGX ggx0{alpha0_};
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        const double lambda_w = ggx0.lambda(w);
        auto inside_z = [&](const Vec3& wm) {
            const auto wt = refract(w, wm, eta0_);
            return wt ? -wt->z : 0.0;
        };
        return integrate_visible_split<V, kNr, kNphi, kBisections>(
            ggx0, w, split, inside_z, [&](const Vec3& wm) {
                const auto wt = refract(w, wm, eta0_);
                if (!wt || wt->z >= 0) return V{};
                return f(*wt, fresnel_dielectric(dot(w, wm), eta0_),
                         refraction_escape(ch_.masking, lambda_w, ggx0.lambda(*wt)));
            });
    }

    /// X(μ); exact for a Lambertian base when the light enters along the refracted direction
    /// (X = T(μ) a(μ') ρ r̄), else the per-material curve.
    Rgb X_at(double mu) const {
        if (!x_exact_) return X_(mu);
        return layers_.albedo * r_bar_ *
               attenuation(refract_in(Vec3(safe_sqrt(1 - mu * mu), 0, mu), inv_eta0_).z) *
               T_top_(mu);
    }

    /// The inside direction (pointing up) whose refraction through a flat interface of relative
    /// index 1/inv_eta is w (w.z > 0, entering a denser medium: always exists).
    static Vec3 refract_in(const Vec3& w, double inv_eta) {
        return {w.x * inv_eta, w.y * inv_eta, safe_sqrt(1 - (1 - w.z * w.z) * sqr(inv_eta))};
    }
    static std::optional<Vec3> refract_in_checked(const Vec3& w, double inv_eta) {
        const double s2 = (1 - w.z * w.z) * sqr(inv_eta);
        if (s2 >= 1) return std::nullopt;
        return Vec3(w.x * inv_eta, w.y * inv_eta, std::sqrt(1 - s2));
    }
    /// The cosine inside the coat of the outside cosine μ (the macro refraction).
    double inside_cos(double mu) const { return safe_sqrt(1 - (1 - mu * mu) * sqr(inv_eta0_)); }

    /// The straight-through direction with cosine cos_t below the surface, opposite wi's azimuth.
    static Vec3 transmitted_direction(const Vec3& wi, double cos_t) {
        const double s = std::hypot(wi.x, wi.y);
        const double sin_t = safe_sqrt(1 - cos_t * cos_t);
        if (s == 0) return {0, 0, -1};
        return {-sin_t * wi.x / s, -sin_t * wi.y / s, -cos_t};
    }

    /// Beer–Lambert along one path at inside cosine μ: exp(−τ/μ).
    Rgb attenuation(double mu) const {
        if (!has_absorption_) return Rgb(1.0);
        if (mu <= 0) return Rgb(0.0);
        return beer_lambert(tau_t_, 1 / mu);
    }

    /// Beer–Lambert for light crossing the coat between the outside cosine μ and the base, whose
    /// macro refraction has the inside cosine μ': a rough coat refracts it into a spread of
    /// inside directions, whose mean of exp(−τ/μ_t) is below exp(−τ/μ') (the paths about the
    /// macro refraction are longer on average, most at grazing light: 0.62 of it at 70° under
    /// α0 0.5, τ 0.9), the coat's curve a_coat_ (precompute_coat_attenuation); a smooth coat's
    /// is the macro refraction's.
    Rgb coat_attenuation(double mu, double mu_in) const {
        return a_coat_on_ ? a_coat_(mu) : attenuation(mu_in);
    }

    Rgb base_fresnel(double c) const {
        switch (layers_.base) {
            case Base::Conductor:
                return fresnel_complex_rgb(c, layers_.base_eta, layers_.base_k);
            case Base::Dielectric:
                return Rgb(fresnel_dielectric(c, eta_b_));
            case Base::Lambertian:
                break;
        }
        return layers_.albedo;
    }

    /// The albedo of the mirror that stands for a conductor or dielectric base in the scattered
    /// light's paths: its Fresnel reflectance when smooth (exact), else its directional albedo.
    Rgb mirror_albedo(double mu) const {
        return alpha1_ == 0 ? base_fresnel(mu) : mirror_albedo_curve_(mu);
    }

    /// The base's directional albedo seen from inside the coat, at inside cosine μ.
    Rgb base_albedo(double mu) const {
        const Rgb ms = base_ms_ ? F_ms_ * dE_base_(mu) : Rgb(0.0);
        switch (layers_.base) {
            case Base::Conductor:
                return fgd_base_.rgb(mu) + ms;
            case Base::Dielectric:
                return Rgb(fgd_base_in_(mu)) + ms;
            case Base::Lambertian:
                break;
        }
        return layers_.albedo;
    }

    /// The coat's reflectance from inside, R_in(μ) = FGD(μ, α0, 1/η0) (total internal reflection
    /// included), with its orders ≥ 2 under multiple scattering.
    double inside_reflectance(double mu) const {
        const double r = fgd_top_in_(mu);
        return ms_ ? r + ms_dielectric(fgd_top_in_, mu, alpha0_, inv_eta0_).reflected : r;
    }

    /// The single-scattering reflectance (FGD) of a rough dielectric interface seen from its
    /// denser side, relative index η < 1. There it steps from total reflection at the critical
    /// cosine μc over a width ~α, and the FGD table, whose cosine nodes ignore μc and whose η
    /// nodes move it, interpolates across the step: against particles 0.03–0.09 off within 2α of
    /// μc for α 0.02–0.05, 0.01–0.03 for α 0.1, so that R + T reached 1.14 there. The
    /// transmittance table has axes split at μc (within 0.007 there), and what single scattering
    /// loses to the microsurface, L(μ), is small and smooth for such coats; so near μc R is
    /// 1 − T(μ) − L(μ), with L integrated per material over the visible normals
    /// (precompute_dense_side; within 0.007 of the particles there). Away from μc the table is
    /// exact at its nodes and kept (within 0.003 beyond 3α or 0.08 of μc), and so it is for rough
    /// coats, whose L is large (0.2–0.5 under α 0.7, where the rule is 0.01–0.06 off): the two
    /// are blended by w(μ) = clamp(2 − |μ − μc|/d, 0, 1) with d = max(3α, 0.08), faded out
    /// between α 0.1 and 0.2 (by α 0.2 the table's step error is within 0.013). Smooth
    /// interfaces and η ≥ 1 read the table alone (its control variate, the exact Fresnel factor,
    /// makes it exact when smooth, and nothing steps when η ≥ 1).
    struct DenseSideFgd {
        FgdView table;
        const float* transmittance = nullptr;  ///< the transmittance table of the masking in use
        double alpha = 0, eta = 1, mu_crit = 0, width = 1, weight = 0;
        EdgeCurve<kNloss> loss;  ///< L(μ), nodes crowding towards μc
        double operator()(double mu) const {
            const double from_table = table(mu);
            const double w = weight * clamp(2 - std::abs(mu - mu_crit) / width, 0.0, 1.0);
            if (!(w > 0)) return from_table;
            const double t = TransmittanceFormat::lookup(transmittance, mu, alpha, eta);
            return from_table + w * (clamp(1 - t - loss(mu), 0.0, 1.0) - from_table);
        }
    };
    /// Fills `fgd` for the interface (α, η): the table's FGD, and where η < 1 and α > 0 its L(μ).
    void precompute_dense_side(DenseSideFgd& fgd, double alpha, double eta) const;

    /// The orders ≥ 2 of a rough dielectric interface (α, η), whose FGD `fgd` reads (FgdView or
    /// DenseSideFgd).
    template <typename Fgd>
    MultipleScatteringFormat::Dielectric ms_dielectric(const Fgd& fgd, double mu, double alpha,
                                                       double eta) const {
        return MultipleScatteringFormat::dielectric(
            tables_->multiple_scattering(), mu, alpha, eta, fgd(mu),
            TransmittanceFormat::lookup(tables_->transmittance(Masking::Smith), mu, alpha, eta));
    }

    const Tables* tables_;
    Options ch_;
    Layers layers_;
    Support support_;
    /// α0, α1: the interfaces' roughnesses; an anisotropic interface's root mean square
    /// √((α_x² + α_y²)/2), which every term 1-D in α reads (the tables, the per-material curves).
    double eta0_ = 1.5, inv_eta0_ = 1 / 1.5, alpha0_ = 0, alpha1_ = 0;
    /// An interface is anisotropic (Layers::alpha0_y, alpha1_y): the coat's reflection, the
    /// widened base lobe and their sampling use the slope covariances Σ0 and Σ1 (isotropic α² I
    /// for an isotropic interface of an anisotropic material).
    bool aniso_ = false;
    SlopeCovariance sigma0_, sigma1_;
    GGX coat_ggx_{0.0};  ///< the coat's distribution (exact top reflection, its sampling)
    double eta_b_ = 1, eta_s_ = 1;
    bool has_absorption_ = false;
    /// The FGD nodes this material reads: the base (conductor or dielectric), the coat from
    /// inside (R_in), and for the multiple-scattering table the coat from outside and a slab's
    /// bottom from below.
    FgdView fgd_base_, fgd_top_, fgd_bottom_;
    /// The coat from inside and a dielectric base from inside the coat (DenseSideFgd).
    DenseSideFgd fgd_top_in_, fgd_base_in_;
    bool series_on_ = false, series_btdf_ = false, x_exact_ = false, mean_shift_ = false;
    CosineCurve<double, kNx> mu_mean_;  ///< μ̄'(μ) − μ'(μ): the transmitted light's mean shift
    /// T(μ) of one interface (the coat from above or inside, the bottom from below or inside):
    /// exact 1 − F(μ) when smooth (or with coat-transmittance=fresnel), else the per-material
    /// curve resampled from the table with its edge at the critical cosine (none: 0) on a node,
    /// where a nearly smooth interface's T rises steeply.
    struct Transmittance {
        EdgeCurve<kNmu> curve;
        double eta = 1;
        bool exact = true;
        double operator()(double mu) const {
            return exact ? 1 - fresnel_dielectric(mu, eta) : curve(mu);
        }
    };
    Transmittance T_top_, T_bot_;
    /// The bottom's transmittance for light inside the coat (the first-order BTDF's exit) and the
    /// coat's for light inside it (the first order's consistency with R_in; see precompute).
    Transmittance T_bot_in_, T_top_in_;
    /// X(μ): the flux the coat's bottom returns to the base after the first order, per unit flux
    /// arriving from outside at μ (outside cosines).
    CosineCurve<Rgb, kNx> X_;
    bool a_coat_on_ = false;
    CosineCurve<Rgb, kNmu> a_coat_;  ///< coat_attenuation of a rough absorbing coat
    Rgb K_{0.0};                     ///< the separable term's normalization
    Rgb inv_one_minus_Er_{0.0};      ///< 1/(1 − Ē_b r̄)
    Rgb r_bar_{0.0}, E_bar_{0.0}, t_bar_{0.0}, X_bar_{0.0};
    /// Multiple scattering: the coat's ΔR from outside and its hemispherical 2∫ΔR μ dμ; the base's
    /// ΔE (conductor: white, times F_ms; dielectric: ΔR, F_ms = 1) and its average.
    bool top_ms_ = false, base_ms_ = false;
    /// The orders ≥ 2 restored (Options::microsurface, Auto resolved for these layers).
    bool ms_ = false;
    bool inside_exit_ = false;  ///< exit_transmittance in the first order (see Options)
    bool mirror_series_ = false;
    bool balance_ = false;  ///< the first order's balance returned with the series (Options)
    bool lobe_norm_on_ = false;
    /// first-order-lobe compressed or sum: first_order_ndf in place of the GGX of α_e (a coat
    /// with α0 > 0 over a conductor or dielectric base, the spread on); the facet maps it uses.
    bool shaped_lobe_ = false;
    FacetDeflection entering_, leaving_;
    /// 1/√N(μ'): N is the energy of the base lobe whose width follows wo (α_e(k_i, k_o)) over that
    /// of the lobe of fixed width α_e(k_i, k_i), over the exit cone, at inside cosine μ'.
    CosineCurve<double, kNnorm> lobe_norm_;
    /// √(1/(1 − a² R_in E_b (1 − u))) over inside cosines: the first order's round trips.
    CosineCurve<Rgb> mirror_series_curve_;
    /// The round trips' lobe (Options::round_trip_lobe, where the series is summed over a
    /// conductor, its share round_trip_weight; never with the mirror series), and its scale s(μ)
    /// over outside cosines, on X's nodes, solved so that the lobe carries what the returned light
    /// lets out (precompute_round_trips, returned_escape).
    bool round_trip_on_ = false;
    CosineCurve<Rgb, kNx> round_trip_curve_;
    CosineCurve<double> dR_top_, dE_base_;
    double dR_top_bar_ = 1, dE_base_bar_ = 1;
    Rgb F_ms_{1.0};
    /// Scattering media (precompute_scattering): τt, ϖ = τs/τt, g equal in the three channels.
    Rgb tau_t_{0.0}, omega_{0.0};
    bool scatters_ = false, g_uniform_ = true, single_on_ = false, base_paths_ = false;
    bool orders_on_ = false, back_on_ = false, twice_on_ = false;
    Rgb g_twice_{0.0};  ///< g² per channel
    /// K(μ): the transmitted remainder's energy over that of the twice-scattered shape.
    CosineCurve<Rgb, kNx> twice_;
    /// E_ms(μ), E_ms,T(μ): the energy of the scattered remainder leaving through the top and the
    /// bottom per unit flux arriving at μ; their lobes' normalizations 1/(π Ē_ms), 1/(π T̄_b).
    CosineCurve<Rgb, kNx> orders_, orders_t_;
    Rgb orders_norm_{0.0};
    double orders_t_norm_ = 0;
    /// A rough base's directional albedo over inside cosines (mirror_albedo; one lookup instead
    /// of the FGD table's three).
    CosineCurve<Rgb, kNmu> mirror_albedo_curve_;
    /// The explicit single scattering's energy at μ (the sampler's mixture weight).
    CosineCurve<Rgb, kNx> single_energy_, single_energy_t_;
    /// The slab's first order through the bottom's BTDF (Options::btdf_bottom_lobe).
    bool bottom_lobe_ = false;
    /// E_1(μ) and E_1(μ)/Q_m(μ) (v[0], v[1]) over outside cosines, as residuals from the slab
    /// under a smooth coat (first_order_smooth). The bottom lobe's energy T_lobe is looked up per
    /// incidence (incident): E_1/T_lobe interpolated between the nodes overshot E_1 by 17 % at 85°,
    /// where T_lobe falls steeply.
    CosineCurve<Multi<Rgb, 2>, kNfirst> first_order_;
    /// slab-orders=bins: the bins' edges over inside cosines (cut at the interfaces' critical
    /// cosines; in μ² between them, crowding towards the cuts); the light from outside at μ that
    /// the coat lets into each bin and from below that the bottom lets in, energy (v[k]) and
    /// forward moment (v[kNbins + k]); Incident::bins over outside cosines.
    bool bins_ = false;
    /// polarization (precompute_polarization): the slab's series for both polarizations, and
    /// its factors on the outside cosine, √k_R(μ) and k_T(μ) (pol_on_: a rough slab's eval reads
    /// them; a smooth one's delta lobes take the series' changes at μi themselves).
    std::optional<SlabPolarization> pol_;
    bool pol_on_ = false;
    CosineCurve<Rgb, kNfirst> pol_R_, pol_T_;
    bool bins_ready_ = false;  ///< set once slab_bins has run (incident() is used before)
    std::array<double, kNbins + 1> bin_edge_{};
    std::array<int, kNbins> bin_piece_{};    ///< the piece (between critical cosines) of each bin
    std::array<double, kNbins> bin_area_{};  ///< A_k = ∫ φ_k 2μ dμ
    SegmentCurve<BinMoments, kBinPer> coat_bins_, bottom_bins_;
    /// W P₁ and W P₂ per channel and azimuthal order (row-major): the bins' first and later
    /// reflections (slab_bins), W = 1/(π A_j η0²).
    std::array<std::array<std::array<double, kNbins * kNbins>, 2>, 3> bins_first_{}, bins_later_{};
    /// g(μ) = √f(μ) per channel; per incidence, the light arriving at the bottom over
    /// π A_k η_s² (both orders) and the energies let out (reflected, transmitted).
    CosineCurve<Rgb, kNslab> bins_g_;
    CosineCurve<Multi<Rgb, 2 * kNbins + 2>, kNslab> bins_down_;
};

}  // namespace lamina1

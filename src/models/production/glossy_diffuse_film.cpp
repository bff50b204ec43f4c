#include "models/production/glossy_diffuse_film.h"

#include "core/math.h"
#include "layers/compiled_stack.h"
#include "models/numerics/quadrature.h"
#include "models/production/cycles_albedo.h"
#include "models/production/film_fresnel.h"
#include "models/production/lobe_mixture.h"
#include "models/production/production_coat.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace lamina {

bool is_filmed_plastic(const Stack& stack) {
    return stack.layers.size() == 2 && stack.layers[0].interface.has_film &&
           stack.layers[0].interface.type == InterfaceType::Dielectric &&
           !stack.layers[1].interface.has_film &&
           stack.layers[1].interface.type == InterfaceType::Lambertian;
}

namespace {

/// The tabulated albedo E_film(μ) of a rough interface: uniform nodes in μ, 8 per period of the
/// film's interference (at least 65, at most 1025), read by cubic interpolation (Catmull–Rom, the
/// end slopes one-sided).
constexpr int kAlbedoNodesPerPeriod = 8, kAlbedoMinNodes = 65, kAlbedoMaxNodes = 1025;
/// Gauss–Legendre nodes per period of the interference in the film's hemispherical average.
constexpr int kAverageNodesPerPeriod = 16;

class GlossyDiffuseFilm final : public LobeMixtureModel<GlossyDiffuseFilm> {
    friend class LobeMixtureModel<GlossyDiffuseFilm>;

  public:
    GlossyDiffuseFilm(const Stack& stack, const GlossyDiffuseFilmRecipe& recipe) : r_(recipe) {
        if (!is_filmed_plastic(stack)) {
            support_.reason = fmt::format(
                "{} has a film on a dielectric base only over a Lambertian (ambient | film | "
                "dielectric | Lambertian)",
                r_.name);
            return;
        }
        const InterfaceSpec& top = stack.layers[0].interface;
        Stack bare = stack;
        bare.layers[0].interface.has_film = false;
        bare.layers[0].interface.film = {};
        CoatedStack shape;
        std::string why;
        if (!coated_stack(bare, shape, why)) {
            support_.reason = fmt::format("{} {}", r_.name, why);
            return;
        }
        if (shape.tau_a.max() > 0 || shape.tau_s.max() > 0) {
            support_.reason = fmt::format(
                "{}'s filmed dielectric base has nothing between its specular layer and its "
                "diffuse (this stack has a medium there)",
                r_.name);
            return;
        }
        if (top.film.k > 0) {
            support_.reason =
                fmt::format("{}'s thin film is transparent (no extinction k); this film's k is {}",
                            r_.name, top.film.k);
            return;
        }
        if (stack.is_anisotropic()) {
            support_.reason =
                fmt::format("{} has no anisotropic filmed dielectric base in lamina", r_.name);
            return;
        }
        if (!(shape.eta0 > 1)) {
            support_.reason = fmt::format(
                "{} represents a filmed dielectric base denser than the ambient only (relative "
                "index > 1); this one's relative index is {}",
                r_.name, shape.eta0);
            return;
        }
        film_ = stack_film_optics(stack, 0);
        if (r_.film == GlossyDiffuseFilmRecipe::Film::Cycles && film_.varies()) {
            support_.reason = fmt::format(
                "{} represents one film thickness on a dielectric base: its diffuse layering "
                "weight is not linear in the film, so a thickness range has no one value",
                r_.name);
            return;
        }
        support_.brdf = true;
        eta0_ = shape.eta0;
        alpha_ = shape.alpha0;
        ggx_ = GGX<double>{alpha_};
        f0_ = fresnel_dielectric_normal(eta0_);
        // Cycles' film sees an ambient of index 1: the film's index and thickness relative to the
        // ambient (the optical path and every ratio of indices unchanged).
        cycles_film_ior_ = film_.eta_film.real() / film_.eta_above;
        cycles_thickness_nm_ = film_.thickness_max_nm * film_.eta_above;
        // The periods the film's round-trip phase 4π η_f d cos θ_f/λ runs through over the
        // facet cosines, at most 2 η_f d/λ (the thickest film, the shortest channel).
        const double shortest_nm =
            std::min({film_.wavelength_nm[0], film_.wavelength_nm[1], film_.wavelength_nm[2]});
        periods_ = 2 * std::abs(film_.eta_film) * film_.thickness_max_nm / shortest_nm;
        C_ = shape.albedo;
        if (r_.darkened_base_color) {
            // The specification's K_r of the interface, with the film's change of its average
            // reflectance taken exactly (the film only moves light between reflection and
            // transmission, so the underside's average changes by the same, reciprocally: K_r =
            // 1 − (1 − E_F)/η0²).
            const Rgbd E_F = Rgbd(openpbr_average_fresnel_fit(eta0_)) + film_average_change();
            for (int c = 0; c < 3; ++c)
                C_[c] *= openpbr_coat_darkening(openpbr_internal_reflectance(eta0_, E_F[c]), C_[c]);
        }
        if (r_.cycles_compensation) {
            // bsdf_microfacet_setup_fresnel_generalized_schlick with the real Fresnel (exponent
            // −η): F_ss = mix(F0, 1, s), s = saturate((F_ss,fit − F0)/(1 − F0)), F_ss,fit
            // fresnel_dielectric_Fss (Kulla & Conty's fit); the film does not enter it.
            white_.emplace(std::sqrt(alpha_));
            const double s =
                clamp((kulla_conty_average_fresnel_fit(eta0_) - f0_) / (1 - f0_), 0.0, 1.0);
            f_ms_ = cycles_multiple_scattering_fresnel(f0_ + (1 - f0_) * s, white_->average());
        }
        // Without a film (≤ 0.1 nm) Cycles estimates the lobe's albedo from its table of the
        // rough dielectric's Fresnel factor (bsdf_microfacet_estimate_albedo, GENERALIZED_SCHLICK
        // with exponent < 0); with one, from the film's reflectance at the view's cosine.
        if (r_.layering == GlossyDiffuseFilmRecipe::Layering::CyclesEstimate &&
            !(cycles_thickness_nm_ > kCyclesFilmCutoffNm))
            factor_.emplace(std::sqrt(alpha_), eta0_);
        // A rough interface's E_film(μo) on its nodes; a smooth one's is film(μo) itself.
        if (r_.layering == GlossyDiffuseFilmRecipe::Layering::LobeAlbedo && alpha_ > 0) {
            const int n = std::clamp(int(std::ceil(kAlbedoNodesPerPeriod * periods_)) + 1,
                                     kAlbedoMinNodes, kAlbedoMaxNodes);
            albedo_.resize(std::size_t(n));
            for (int k = 0; k < n; ++k)
                albedo_[std::size_t(k)] = filmed_lobe_albedo(double(k) / (n - 1), alpha_,
                                                             [&](double c) { return film(c); });
        }
    }

    std::string name() const override { return r_.name; }
    Support support() const override { return support_; }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        Rgbd f(0.0);
        if (alpha_ > 0) {
            const Vec3d h = normalize(wi + wo);
            const double cos_h = dot(wi, h);
            const double G = 1 / (1 + ggx_.lambda(wi) + ggx_.lambda(wo));  // Heitz 2014, Eq. 99
            f = film(cos_h) * (ggx_.D(h) * G / (4 * wi.z * wo.z) * compensation(wo.z));
        }
        return f + C_ * layering(wo.z) * kInvPi<double>;
    }

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        if (!support_.brdf || wi.z <= 0 || alpha_ > 0) return {};
        // A smooth interface: the film's reflectance at μi along the mirror direction (Cycles'
        // compensation is 1 there: its table holds E = 1 at the first roughness node).
        return {{mirror_direction(wi), film(wi.z)}};
    }

    /// Cycles' film gives its colour (its spectral integration), not values at the wavelengths;
    /// below its cutoff there is no film.
    bool integrates_spectrum() const override {
        return r_.film == GlossyDiffuseFilmRecipe::Film::Cycles &&
               cycles_thickness_nm_ > kCyclesFilmCutoffNm;
    }

    /// Sampling (models/production/lobe_mixture.h): the lobe's visible normals with probability
    /// the film's reflectance at μi clamped to [0.1, 0.9] (0 for a smooth interface, whose delta
    /// lobe is reported apart), the cosine otherwise.
    bool has_sampling() const override { return support_.brdf; }

  private:
    /// The film's reflectance at the facet cosine c, per channel, in the recipe's form.
    Rgbd film(double c) const {
        if (r_.film == GlossyDiffuseFilmRecipe::Film::Cycles)
            return cycles_dielectric_film(cycles_film_ior_, cycles_thickness_nm_, eta0_, c);
        return film_reflectance_exact(film_, c);
    }

    /// c(μo): Cycles' compensation 1 + F_ms (1 − E)/E, or 1.
    double compensation(double mu_o) const {
        if (!white_ || alpha_ <= 0) return 1;
        return 1 + f_ms_ * (1 / white_->albedo(mu_o) - 1);
    }

    /// L(μo), the diffuse lobe's weight per channel.
    Rgbd layering(double mu_o) const {
        if (r_.layering == GlossyDiffuseFilmRecipe::Layering::CyclesEstimate) {
            // closure_layering_weight: 1 − max over the channels of the specular closure's albedo
            // relative to the weight above it, bsdf_albedo = its weight w (E + F_ms (1 − E) after
            // microfacet_ggx_preserve_energy) × bsdf_microfacet_estimate_albedo: with a film the
            // film's reflectance at the view's cosine, without one its table's Fresnel factor.
            double w = 1;
            if (white_ && alpha_ > 0) {
                const double E = white_->albedo(mu_o);
                w = E + f_ms_ * (1 - E);
            }
            if (factor_)
                return Rgbd(clamp(1 - w * (f0_ + (1 - f0_) * factor_->factor(mu_o)), 0.0, 1.0));
            return Rgbd(clamp(1 - (film(mu_o) * w).max(), 0.0, 1.0));
        }
        if (alpha_ <= 0) return Rgbd(1.0) - film(mu_o);  // a smooth interface: E = F_film
        return Rgbd(1.0) - interpolated_albedo(mu_o);
    }

    /// 2 ∫ (F_film,c(μ) − F(μ; η0)) μ dμ: the film's change of the interface's hemispherical
    /// average reflectance, by composite Gauss–Legendre (kAverageNodesPerPeriod per period of the
    /// interference, over at least 4 pieces).
    Rgbd film_average_change() const {
        static const QuadratureRule q = gauss_legendre(kAverageNodesPerPeriod);
        const int pieces = std::clamp(int(std::ceil(periods_)), 4, 512);
        Rgbd sum(0.0);
        for (int p = 0; p < pieces; ++p)
            for (std::size_t i = 0; i < q.x.size(); ++i) {
                const double mu = (p + q.x[i]) / pieces;
                sum +=
                    (film(mu) - Rgbd(fresnel_dielectric(mu, eta0_))) * (2 * mu * q.w[i] / pieces);
            }
        return sum;
    }

    /// E_film(μ) from its nodes: Catmull–Rom between the two nodes around μ, the slopes the
    /// central differences (one-sided at the ends).
    Rgbd interpolated_albedo(double mu) const {
        const int n = int(albedo_.size());
        const double x = clamp(mu, 0.0, 1.0) * (n - 1);
        const int i = std::min(int(x), n - 2);
        const double t = x - i;
        const auto node = [&](int k) { return albedo_[std::size_t(std::clamp(k, 0, n - 1))]; };
        const auto slope = [&](int k) {
            if (k == 0) return node(1) - node(0);
            if (k == n - 1) return node(k) - node(k - 1);
            return (node(k + 1) - node(k - 1)) * 0.5;
        };
        const double t2 = t * t, t3 = t2 * t;
        return node(i) * (2 * t3 - 3 * t2 + 1) + slope(i) * (t3 - 2 * t2 + t) +
               node(i + 1) * (-2 * t3 + 3 * t2) + slope(i + 1) * (t3 - t2);
    }

    ReflectionLobeMixture proposal(const Vec3d& wi) const {
        ReflectionLobeMixture m;
        m.coat = alpha_ > 0 ? clamp(film(wi.z).max(), 0.1, 0.9) : 0.0;
        m.coat_lobe = ggx_;
        m.diffuse = true;
        return m;
    }

    GlossyDiffuseFilmRecipe r_;
    Support support_;
    FilmOptics film_;
    double eta0_ = 1.5, alpha_ = 0;
    double f0_ = 0;       ///< the bare interface's normal reflectance ((η0 − 1)/(η0 + 1))²
    double periods_ = 0;  ///< interference periods over the facet cosines (at most)
    GGX<double> ggx_{0.0};
    Rgbd C_{0.0};  ///< the diffuse's colour: ρ, or ρ darkened (darkened_base_color)
    double cycles_film_ior_ = 1.5, cycles_thickness_nm_ = 0;
    std::optional<CyclesWhiteAlbedo> white_;
    std::optional<CyclesFresnelFactor> factor_;  ///< Cycles' estimate without a film
    double f_ms_ = 0;
    std::vector<Rgbd> albedo_;  ///< E_film on the nodes (a rough interface, LobeAlbedo)
};

}  // namespace

std::unique_ptr<Model> make_glossy_diffuse_film(const Stack& stack,
                                                const GlossyDiffuseFilmRecipe& recipe) {
    return std::make_unique<GlossyDiffuseFilm>(stack, recipe);
}

}  // namespace lamina

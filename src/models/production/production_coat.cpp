#include "models/production/production_coat.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/production/cycles_albedo.h"
#include "models/production/filament_dfg.h"
#include "models/production/film_fresnel.h"
#include "models/production/glossy_diffuse_film.h"
#include "models/production/lobe_mixture.h"
#include "models/production/threejs_dfg.h"
#include "models/production/uncorrelated_albedo.h"
#include "models/tables/fgd_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <optional>

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

/// x⁶ in three products (std::pow with a constant exponent is a library call: GCC expands it
/// only under -funsafe-math-optimizations).
double pow6(double x) {
    return sqr(sqr(x) * x);
}

constexpr double kF82Cos = 1.0 / 7.0;  // μ̄ of the F82-tint model (OpenPBR 1.1, "Metal")
/// OpenPBR 1.1's default specular_roughness: the diffuse base leaves it there (its specular_weight
/// is 0); openpbr-bsdf's darkening still reads it through E_F(1) (docs/models.md).
constexpr double kOpenPbrDefaultSpecularRoughness = 0.3;
/// openpbr-bsdf's compensation lobe for the metal's multiple scattering is off below r = 0.04
/// (openpbr_microfacet_multiple_scattering_lobes.h, "MinRoughnessWithVisibleEnergyLoss").
constexpr double kMetalMultipleScatteringMinRoughness = 0.04;

class ProductionCoat final : public LobeMixtureModel<ProductionCoat> {
    friend class LobeMixtureModel<ProductionCoat>;

  public:
    ProductionCoat(const Stack& stack, const CoatRecipe& recipe) : r_(recipe) {
        std::string why;
        // A film under the coat is the recipe's (MetalFilm); the rest of the stack is read
        // without it.
        Stack bare = stack;
        for (std::size_t i = 0; i < bare.layers.size(); ++i) {
            InterfaceSpec& in = bare.layers[i].interface;
            if (!in.has_film) continue;
            if (i + 1 != stack.layers.size() || in.type != InterfaceType::Conductor) {
                support_.reason =
                    fmt::format("{} has no thin film but on a metal base under its coat", r_.name);
                return;
            }
            if (r_.metal_film == CoatRecipe::MetalFilm::Unsupported) {
                support_.reason = fmt::format("{} has no thin film under its coat", r_.name);
                return;
            }
            if ((r_.metal_film == CoatRecipe::MetalFilm::ThreeJs ||
                 r_.metal_film == CoatRecipe::MetalFilm::OpenPbrBsdf ||
                 r_.metal_film == CoatRecipe::MetalFilm::Cycles ||
                 r_.metal_film == CoatRecipe::MetalFilm::OpenPbrSpec) &&
                in.film.k > 0) {
                support_.reason = fmt::format(
                    "{}'s thin film is transparent (no extinction k); this film's k is {}", r_.name,
                    in.film.k);
                return;
            }
            film_ = stack_film_optics(stack, i);
            in.has_film = false;
            in.film = {};
        }
        if (!coated_stack(bare, coat_, why)) {
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
        if (r_.coat_ior_at_least_one && coat_.eta0 < 1) {
            support_.reason = fmt::format(
                "{} clamps its coat IOR to at least 1; this coat's relative index is {}", r_.name,
                coat_.eta0);
            return;
        }
        if (r_.coat_ior_fixed && std::abs(coat_.eta0 - 1.5) > 1e-9) {
            support_.reason = fmt::format(
                "{}'s coat has a fixed IOR of 1.5 (F0 = 0.04); this coat's relative index is {}",
                r_.name, coat_.eta0);
            return;
        }
        const InterfaceSpec &coat_spec = stack.layers[0].interface,
                            &base_spec = stack.layers[1].interface;
        if (stack.is_anisotropic()) {
            if (!r_.anisotropic_roughness) {
                support_.reason = fmt::format(
                    "{} has no anisotropic roughness: the stack's anisotropic interface (alpha = "
                    "[alpha_x, alpha_y]) has no counterpart",
                    r_.name);
                return;
            }
            // OpenPBR's isotropic α of each interface: the energy terms and the roughening
            // below read it; the lobes take the interface's anisotropy (lobe_distribution).
            coat_.alpha0 = openpbr_isotropic_alpha(coat_spec);
            coat_.base_alpha = openpbr_isotropic_alpha(base_spec);
        }
        support_.brdf = true;
        eta0_ = coat_.eta0;
        switch (r_.coat_fresnel) {
            case CoatRecipe::Fresnel::Exact:
                break;
            case CoatRecipe::Fresnel::SchlickIor:
                coat_f0_ = fresnel_dielectric_normal(eta0_);
                break;
            case CoatRecipe::Fresnel::Schlick004:
                coat_f0_ = 0.04;
                break;
        }
        // Roughness: every engine's α is its parameter squared, α = r².
        double r_coat = std::sqrt(coat_.alpha0);
        if (r_.coat_min_roughness > 0) r_coat = std::max(r_coat, r_.coat_min_roughness);
        alpha_coat_ = sqr(lobe_roughness(r_coat));
        coat_ggx_ = lobe_distribution(coat_spec, alpha_coat_);
        eta_index_ = FgdTable::locate(eta0_, 0);
        coat_f0_ior_ = fresnel_dielectric_normal(eta0_);
        // openpbr-bsdf reads its table at the coat's α before its lobe's clamp; at α = 0 it takes
        // the exact Fresnel factor.
        if (r_.coat_albedo == CoatRecipe::CoatAlbedo::OpenPbrBsdf && r_coat > 0)
            coat_grid_ = OpenPbrBsdfEnergyGrid::dielectric(eta0_, sqr(r_coat));
        using CEC = CoatRecipe::CoatEnergyCompensation;
        if (r_.coat_energy_compensation == CEC::Cycles ||
            r_.coat_albedo == CoatRecipe::CoatAlbedo::Cycles) {
            // Cycles reads its tables at the coat's r, a smooth coat included (its first node).
            coat_white_.emplace(r_coat);
            // Cycles' fresnel_dielectric_Fss: Kulla & Conty's fit, 0 at η0 = 1.
            const double f_ss = eta0_ > 1 ? kulla_conty_average_fresnel_fit(eta0_) : 0.0;
            coat_fms_ = cycles_multiple_scattering_fresnel(f_ss, coat_white_->average());
            if (r_.coat_albedo == CoatRecipe::CoatAlbedo::Cycles && eta0_ > 1)
                coat_factor_.emplace(r_coat, eta0_);
        }

        // The base.
        is_metal_ = coat_.base_type == InterfaceType::Conductor;
        r_coat_ = r_coat;
        if (is_metal_) {
            const double r_prime = roughened(std::sqrt(coat_.base_alpha));
            const double r_lobe = std::max(lobe_roughness(r_prime), r_.metal_min_roughness);
            alpha_base_ = sqr(r_lobe);
            base_ggx_ = lobe_distribution(base_spec, alpha_base_);
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
                    case CoatRecipe::MetalFresnel::Artistic: {
                        // The edge colour g that puts n between Gulbrandsen's bounds at e, as the
                        // artist would set it, within [0, 1]; then the map back to n + ik.
                        const double r = std::min(f0_[c], 0.99), sr = std::sqrt(r);
                        const double n_min = (1 - r) / (1 + r), n_max = (1 + sr) / (1 - sr);
                        // At F0 = 0 the bounds meet (n = 1 whatever g): g = 0.
                        const double span = n_max - n_min;
                        const double g = span > 0 ? clamp((n_max - e) / span, 0.0, 1.0) : 0.0;
                        artistic_index_[c] = gulbrandsen_index(f0_[c], g);
                        f0_[c] = metal_fresnel_channel(1.0, c);
                        break;
                    }
                }
            }
            // openpbr-bsdf's film sees the metal through its F0 and F82 tint (Gulbrandsen's map).
            if (film_ && r_.metal_film == CoatRecipe::MetalFilm::OpenPbrBsdf)
                for (int c = 0; c < 3; ++c)
                    film_->eta_below[c] = gulbrandsen_index(f0_[c], tint82_[c]);
            // Filament's fresnel(): f90 = saturate(dot(f0, 50 · 0.33)), the edge dimmed for an F0
            // below 2 %.
            if (r_.metal_f90_from_f0) f90_ = std::min(1.0, 50 * 0.33 * (f0_[0] + f0_[1] + f0_[2]));
            // The average of the model's metal Fresnel, 2 ∫ F μ dμ (Gauss–Legendre, exact for
            // F82-tint's polynomial and Schlick's): openpbr-bsdf's E_b and its compensation lobe.
            const QuadratureRule q = gauss_legendre(16);
            for (std::size_t i = 0; i < q.x.size(); ++i)
                metal_average_ += metal_fresnel(q.x[i]) * (2 * q.w[i] * q.x[i]);
            using MEC = CoatRecipe::MetalEnergyCompensation;
            if (r_.metal_energy_compensation == MEC::Filament) dfg_.emplace(r_lobe);
            if (r_.metal_energy_compensation == MEC::ThreeJs) threejs_dfg_.emplace(r_lobe);
            if (r_.metal_energy_compensation == MEC::Cycles) {
                metal_white_.emplace(r_lobe);
                for (int c = 0; c < 3; ++c)
                    metal_fms_[c] = cycles_multiple_scattering_fresnel(
                        f82_tint_average_fresnel(f0_[c], tint82_[c]), metal_white_->average());
            }
            using MS = CoatRecipe::MetalMultipleScattering;
            if (r_.metal_multiple_scattering == MS::OpenPbrBsdf &&
                r_prime >= kMetalMultipleScatteringMinRoughness) {
                ms_grid_ = OpenPbrBsdfEnergyGrid::white(alpha_base_);
                ms_color_ = metal_average_ * metal_average_ * kInvPi<double>;
                ms_norm_ = 1 / std::max(ms_grid_->average_complement(), 1e-12);
            } else if (r_.metal_multiple_scattering == MS::EnterpriseApprox) {
                // dspbr-pt's material kernel (evaluateBaseSpecularGGX), its guards included.
                ms_roughness_ = r_lobe;
                const double e_avg = clamp(1 - 0.58 * r_lobe + 0.08 * r_lobe * r_lobe, 0.0, 1.0);
                for (int c = 0; c < 3; ++c) {
                    const double f_avg = metal_average_[c];
                    ms_color_[c] = sqr(f_avg) * e_avg / std::max(1 - f_avg * (1 - e_avg), 1e-5);
                }
                ms_norm_ = 1 / std::max(kPi<double> * (1 - e_avg), 1e-6);
            }
        } else {
            albedo_ = r_.affect_color ? coat_.albedo * coat_.albedo : coat_.albedo;
        }
        // MaterialX's base specular (weight 0 over a diffuse base) at OpenPBR's default
        // roughness, roughened by the coat.
        if (r_.diffuse_specular_throughput)
            specular_alpha_ = sqr(roughened(kOpenPbrDefaultSpecularRoughness));
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
        double ms_complement_i = 0;  ///< 1 − E(μi) of the metal's compensation lobe
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || wi.z <= 0) return in;
        in.E_i = uses_albedo() ? coat_albedo(wi.z) : 0;
        in.F_i = coat_fresnel(wi.z);
        in.mu_t_i = refracted_cos(wi.z);
        if (alpha_coat_ > 0) in.lambda_coat = coat_ggx_.lambda(wi);
        if (is_metal_ && alpha_base_ > 0) in.lambda_base = base_ggx_.lambda(wi);
        if (has_ms()) in.ms_complement_i = ms_complement(wi.z);
        return in;
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        return eval_with(incident(wi), wo);
    }

    /// What depends on μo = wo.z alone (the terms the recipe uses; ViewKeepingEvaluator keeps
    /// them for the nodes of a θ row, which share their cosines).
    struct View {
        double coat_compensation = 1;  ///< coat_compensation(μo), for a rough coat
        double coat_albedo = 0;        ///< E_coat(μo), for an attenuation by the albedo
        double metal_inv_albedo = 1;   ///< 1/E(μo) of Filament's or three.js's DFG texture
        SchlickSplit metal_fit{}, specular_fit{};  ///< MaterialX's albedo fits at μo
        double metal_missing = 0;                  ///< 1/E(μo) − 1 of Cycles' white metal albedo
        double ms_complement = 0;                  ///< ms_complement(μo)
    };

    // view and eval_in_view are compiled once each (not inlined): with FMA contraction an inlined
    // copy may round differently, and eval, prepare(wi)->eval and the evaluator for one thread
    // must agree to the bit.
    [[gnu::noinline]] View view(double mu_o) const {
        View v;
        if (!support_.brdf) return v;
        if (alpha_coat_ > 0) v.coat_compensation = coat_compensation(mu_o);
        if (uses_albedo()) v.coat_albedo = coat_albedo(mu_o);
        if (is_metal_) {
            if (alpha_base_ <= 0) return v;
            if (dfg_) v.metal_inv_albedo = 1 / dfg_->albedo(mu_o);
            if (threejs_dfg_) v.metal_inv_albedo = 1 / threejs_dfg_->albedo(mu_o);
            if (r_.metal_energy_compensation == CoatRecipe::MetalEnergyCompensation::MaterialX)
                v.metal_fit = materialx_ggx_albedo_fit(mu_o, materialx_alpha(alpha_base_));
            if (metal_white_) v.metal_missing = 1 / metal_white_->albedo(mu_o) - 1;
            if (has_ms()) v.ms_complement = ms_complement(mu_o);
        } else if (r_.diffuse_specular_throughput) {
            v.specular_fit = materialx_ggx_albedo_fit(mu_o, materialx_alpha(specular_alpha_));
        }
        return v;
    }

    Rgbd eval_with(const Incident& in, const Vec3d& wo) const {
        if (!support_.brdf || in.wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        return eval_in_view(in, wo, view(wo.z));
    }

    /// eval_with(in, wo), v = view(wo.z).
    [[gnu::noinline]] Rgbd eval_in_view(const Incident& in, const Vec3d& wo, const View& v) const {
        const Vec3d& wi = in.wi;
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        const Vec3d h = normalize(wi + wo);
        const double cos_h = dot(wi, h);
        double f_coat = 0;
        if (alpha_coat_ > 0) {
            const GGX<double>& ggx = coat_ggx_;
            const double F = coat_fresnel(r_.coat_fresnel_at_n ? wo.z : cos_h);
            if (r_.coat_visibility == CoatRecipe::Visibility::Kelemen) {
                f_coat = F * ndf(ggx, h) / (4 * cos_h * cos_h);
            } else {
                const double G = masking_shadowing(r_.coat_visibility, in.lambda_coat, ggx, wo);
                f_coat = F * ndf(ggx, h) * G / (4 * wi.z * wo.z);
            }
            f_coat *= v.coat_compensation;
        }
        Rgbd base(0.0);
        if (is_metal_) {
            if (alpha_base_ <= 0) return Rgbd(f_coat);  // a smooth base: a delta lobe
            const GGX<double>& ggx = base_ggx_;
            const double G = masking_shadowing(r_.metal_visibility, in.lambda_base, ggx, wo);
            base = base_fresnel(cos_h, wo.z) * (ndf(ggx, h) * G / (4 * wi.z * wo.z));
            if (dfg_ || threejs_dfg_) {
                // Filament's energyCompensation, three.js's multiScatteringCompensation:
                // 1 + F0 (1/E(μo) − 1), on the lobe.
                const double inv_e = v.metal_inv_albedo;
                for (int c = 0; c < 3; ++c)
                    base[c] *= 1 + f0_[c] * (inv_e - 1);
            }
            if (r_.metal_energy_compensation == CoatRecipe::MetalEnergyCompensation::MaterialX) {
                for (int c = 0; c < 3; ++c)
                    base[c] *= materialx_compensation(f0_[c], v.metal_fit);
            }
            if (metal_white_) {
                // Cycles' microfacet_ggx_preserve_energy: 1 + F_ms (1 − E(μo))/E(μo).
                const double missing = v.metal_missing;
                for (int c = 0; c < 3; ++c)
                    base[c] *= 1 + metal_fms_[c] * missing;
            }
            if (has_ms()) {
                double shape = in.ms_complement_i * v.ms_complement * ms_norm_;
                // openpbr-bsdf clamps its lobe to 1/μi (openpbr_microfacet_multiple_scattering_
                // lobes.h).
                if (ms_grid_) shape = std::min(shape, 1 / wi.z);
                base += ms_color_ * shape;
            }
        } else {
            base = albedo_ * kInvPi<double>;
            if (r_.diffuse_specular_throughput) {
                // MaterialX's dielectric_bsdf at index 1 (F0 = 0): throughput 1 − B · comp.
                const SchlickSplit& fit = v.specular_fit;
                base *= 1 - fit.bias * materialx_compensation(0.0, fit);
            }
        }
        return Rgbd(f_coat) + base * base_scale(in, wo.z, v.coat_albedo, cos_h);
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> lobes;
        if (!support_.brdf || wi.z <= 0) return lobes;
        const Vec3d wr = mirror_direction(wi);
        // At the mirror pair h = n: wi·h = μi = μo, and the smooth limit of either visibility
        // term leaves the lobe's energy equal to its Fresnel factor.
        if (alpha_coat_ == 0)
            lobes.push_back({wr, Rgbd(coat_fresnel(wi.z) * coat_compensation(wi.z))});
        if (is_metal_ && alpha_base_ == 0) {
            const Incident in = incident(wi);
            lobes.push_back(
                {wr, base_fresnel(wi.z, wi.z) *
                         base_scale(in, wi.z, uses_albedo() ? coat_albedo(wi.z) : 0.0, wi.z)});
        }
        return lobes;
    }

    /// three.js's and Cycles' films as shipped give the film's colour (their spectral
    /// integration), not its value at the stack's wavelengths.
    bool integrates_spectrum() const override {
        return film_ && (r_.metal_film == CoatRecipe::MetalFilm::ThreeJs ||
                         r_.metal_film == CoatRecipe::MetalFilm::Cycles);
    }

    /// Importance sampling (models/production/lobe_mixture.h): the coat lobe's visible normals with
    /// probability p_c, else the base (its GGX visible normals, or the cosine for a Lambertian).
    /// p_c is the coat's Fresnel at μi (clamped to [0.1, 0.9]), 0 when the coat is smooth (a delta
    /// lobe, not sampled here), 1 when the base is a smooth metal.
    bool has_sampling() const override { return support_.brdf && sampled_lobes() > 0; }

  private:
    /// The lobe of an interface whose isotropic α became `alpha` (the lobe's clamp, the
    /// roughening): GGX of α for an isotropic interface; for an anisotropic one its α_x, α_y
    /// scaled by alpha / openpbr_isotropic_alpha (OpenPBR 1.1's α_t, α_b of the new α at the same
    /// anisotropy), each clamped to the recipe's smallest lobe α as openpbr-bsdf clamps both
    /// (openpbr_compute_anisotropic_alpha), its tangent the interface's.
    GGX<double> lobe_distribution(const InterfaceSpec& s, double alpha) const {
        if (!s.is_anisotropic() || alpha <= 0) return GGX<double>{alpha};
        const double scale = alpha / openpbr_isotropic_alpha(s), least = sqr(r_.lobe_min_roughness);
        return GGX<double>::anisotropic(std::max(s.alpha * scale, least),
                                        std::max(s.alpha_b() * scale, least),
                                        deg_to_rad(s.tangent_deg));
    }

    int sampled_lobes() const { return int(alpha_coat_ > 0) + int(!is_metal_ || alpha_base_ > 0); }

    double coat_probability(const Vec3d& wi) const {
        if (alpha_coat_ <= 0) return 0;
        if (is_metal_ && alpha_base_ <= 0) return 1;
        return clamp(coat_fresnel(wi.z), 0.1, 0.9);
    }

    /// The sampling mixture: the coat lobe with p_c, the rest to the metal's lobe or the cosine.
    ReflectionLobeMixture proposal(const Vec3d& wi) const {
        ReflectionLobeMixture m;
        m.coat = coat_probability(wi);
        m.coat_lobe = coat_ggx_;
        m.base_lobe = base_ggx_;
        m.diffuse = !is_metal_;
        return m;
    }

    bool uses_albedo() const {
        using A = CoatRecipe::Attenuation;
        return r_.attenuation == A::AlbedoView || r_.attenuation == A::AlbedoReciprocal ||
               r_.attenuation == A::KullaConty;
    }

    /// E_coat(μ): the directional albedo of the coat lobe with exact Fresnel — with Smith G2 from
    /// lamina's FGD table, or openpbr-bsdf's uncorrelated lobe on its grid (the models that scale
    /// by an albedo all use the exact Fresnel).
    double coat_albedo(double mu) const {
        if (coat_grid_) return 1 - coat_grid_->complement(mu);
        if (r_.coat_albedo == CoatRecipe::CoatAlbedo::MaterialX) {
            // mx_dielectric_bsdf: (F0 A + B) × its compensation, at α ≥ 1e-8.
            const double alpha = materialx_alpha(alpha_coat_);
            const SchlickSplit fit = materialx_ggx_albedo_fit(mu, alpha);
            return (coat_f0_ior_ * fit.scale + fit.bias) *
                   materialx_compensation(coat_f0_ior_, fit);
        }
        if (r_.coat_albedo == CoatRecipe::CoatAlbedo::Cycles) {
            // bsdf_microfacet_estimate_albedo times the compensated lobe's weight
            // E + F_ms (1 − E) (microfacet_ggx_preserve_energy); η0 ≤ 1: the Fresnel factor.
            const double E = coat_white_->albedo(mu);
            const double weight =
                r_.coat_energy_compensation == CoatRecipe::CoatEnergyCompensation::Cycles
                    ? E + coat_fms_ * (1 - E)
                    : 1.0;
            if (!coat_factor_) return weight * fresnel_dielectric(clamp(mu, 0.0, 1.0), eta0_);
            return weight * (coat_f0_ior_ + (1 - coat_f0_ior_) * coat_factor_->factor(mu));
        }
        if (r_.coat_albedo == CoatRecipe::CoatAlbedo::OpenPbrBsdf && r_coat_ == 0)
            return fresnel_dielectric(mu, eta0_);
        return FgdTable::get()(mu, alpha_coat_, eta_index_);
    }

    /// Cycles' compensation of the coat lobe for multiple scattering at μo (1 without it).
    /// A smooth coat loses nothing: Cycles' table holds E = 1 at its first roughness node to the
    /// six digits it prints, so the delta lobe is left as it is.
    double coat_compensation(double mu_o) const {
        using CEC = CoatRecipe::CoatEnergyCompensation;
        switch (r_.coat_energy_compensation) {
            case CEC::None:
                return 1;
            case CEC::Cycles:
                if (alpha_coat_ == 0) return 1;
                return 1 + coat_fms_ * (1 / coat_white_->albedo(mu_o) - 1);
            case CEC::MaterialX:
                return materialx_compensation(
                    coat_f0_ior_, materialx_ggx_albedo_fit(mu_o, materialx_alpha(alpha_coat_)));
        }
        return 1;
    }

    /// MaterialX's α of a lobe: clamped to [1e-8, 1] (mx_dielectric_bsdf's safeAlpha).
    static double materialx_alpha(double alpha) { return clamp(alpha, 1e-8, 1.0); }

    /// MaterialX's compensation of a lobe of normal reflectance f0 for multiple scattering,
    /// 1 + F_ss (1 − E)/E with F_ss = f0 + (1 − f0)/21 and E = A + B of its albedo fit at the
    /// lobe's (μ, α), `fit` = materialx_ggx_albedo_fit(μ, α) (mx_ggx_energy_compensation;
    /// Turquin 2019, Eqs. 14 and 16).
    static double materialx_compensation(double f0, const SchlickSplit& fit) {
        const double E = fit.scale + fit.bias;
        return 1 + (f0 + (1 - f0) / 21) * (1 - E) / E;
    }

    /// The F82-tint Fresnel's average 2 ∫ F μ dμ in closed form, F0 + (1 − F0)/21 − b/126 with b
    /// its edge term (Cycles' fresnel_f82_Fss).
    static double f82_tint_average_fresnel(double f0, double tint) {
        const double b = schlick(kF82Cos, f0) * (1 - tint) / (kF82Cos * pow6(1 - kF82Cos));
        return f0 + (1 - f0) / 21 - b / 126;
    }

    /// The masking-shadowing of a lobe: height-correlated or uncorrelated Smith, Λ(wi) given.
    static double masking_shadowing(CoatRecipe::Visibility v, double lambda_i,
                                    const GGX<double>& ggx, const Vec3d& wo) {
        const double lambda_o = ggx.lambda(wo);
        if (v == CoatRecipe::Visibility::SmithUncorrelated)
            return 1 / ((1 + lambda_i) * (1 + lambda_o));  // Heitz 2014, Eq. 98
        return 1 / (1 + lambda_i + lambda_o);              // Heitz 2014, Eq. 99
    }

    /// The metal carries a compensation lobe for its multiple scattering.
    bool has_ms() const { return ms_grid_.has_value() || ms_roughness_ > 0; }

    /// 1 − E(μ) of the compensation lobe's white albedo.
    double ms_complement(double mu) const {
        if (ms_grid_) return ms_grid_->complement(mu);
        // dspbr-pt's fit E(μ) = 1 − r (1/2 + (1 − μ)⁵/2), clamped to [0, 1].
        const double e = clamp(1 - ms_roughness_ * (0.5 + 0.5 * schlick_weight(mu)), 0.0, 1.0);
        return 1 - e;
    }

    /// D(h), capped where the model caps it.
    double ndf(const GGX<double>& ggx, const Vec3d& h) const {
        const double d = ggx.D(h);
        return r_.max_ndf > 0 ? std::min(d, r_.max_ndf) : d;
    }

    /// The roughness parameter of a rough lobe after the model's clamp (a smooth one stays 0).
    double lobe_roughness(double r) const {
        return r > 0 ? std::max(r, r_.lobe_min_roughness) : 0.0;
    }

    /// The base's roughness parameter after the model's base-roughening rule.
    double roughened(double r_base) const {
        const double r_coat = r_coat_;
        switch (r_.roughening) {
            case CoatRecipe::Roughening::None:
                return r_base;
            case CoatRecipe::Roughening::OpenPBR:  // OpenPBR 1.1, "Roughening"
                return std::pow(std::min(1.0, sqr(sqr(r_base)) + 2 * sqr(sqr(r_coat))), 0.25);
            case CoatRecipe::Roughening::Adobe: {  // openpbr-bsdf, openpbr_bsdf.h
                const double factor = 1 - (eta0_ >= 1 ? 1 / eta0_ : eta0_);
                return std::pow(std::min(1.0, sqr(sqr(r_base)) + factor * sqr(sqr(r_coat))), 0.25);
            }
            case CoatRecipe::Roughening::Max:  // Filament, base no glossier than the coat
                return std::max(r_base, r_coat);
            case CoatRecipe::Roughening::StandardSurface:  // coat_affect_roughness = 1
                return r_base + (1 - r_base) * r_coat;
        }
        return r_base;
    }

    double coat_fresnel(double c) const {
        if (r_.coat_fresnel == CoatRecipe::Fresnel::Exact) return fresnel_dielectric(c, eta0_);
        return coat_f0_ + (1 - coat_f0_) * model_schlick_weight(c);
    }

    /// Schlick's weight in the model's form: (1 − c)⁵ or its spherical-Gaussian fit.
    double model_schlick_weight(double c) const {
        return r_.schlick_spherical_gaussian ? schlick_weight_spherical_gaussian(clamp(c, 0.0, 1.0))
                                             : schlick_weight(c);
    }

    /// μt = √(1 − (1 − μ²)/η0²) (OpenPBR 1.1, "View-dependent absorption").
    double refracted_cos(double mu) const { return safe_sqrt(1 - (1 - mu * mu) / (eta0_ * eta0_)); }

    Rgbd metal_fresnel(double c) const {
        Rgbd F;
        for (int i = 0; i < 3; ++i)
            F[i] = metal_fresnel_channel(c, i);
        return F;
    }
    double metal_fresnel_channel(double c, int i) const {
        switch (r_.metal_fresnel) {
            case CoatRecipe::MetalFresnel::Exact:
                return fresnel_conductor(c, coat_.base_eta[i], coat_.base_k[i]);
            case CoatRecipe::MetalFresnel::Schlick:
            case CoatRecipe::MetalFresnel::SchlickFilament:
                // Schlick 1994, Eq. 15, with the edge value f90 (Filament's F_Schlick).
                return f0_[i] + (f90_ - f0_[i]) * model_schlick_weight(c);
            case CoatRecipe::MetalFresnel::F82Tint:
                return f82_tint_fresnel(c, f0_[i], tint82_[i]);
            case CoatRecipe::MetalFresnel::Artistic:
                return fresnel_conductor(c, artistic_index_[i].real(), artistic_index_[i].imag());
        }
        return 0;
    }

    /// The Fresnel factor of the metal lobe at cos_h = wi·h for the view cosine mu_o: the metal's
    /// own (metal_fresnel), or the film's reflectance in the recipe's form (MetalFilm).
    Rgbd base_fresnel(double cos_h, double mu_o) const {
        if (!film_) return metal_fresnel(cos_h);
        switch (r_.metal_film) {
            case CoatRecipe::MetalFilm::Exact:
                return film_reflectance_exact(*film_, cos_h);
            case CoatRecipe::MetalFilm::ThreeJs:
                // three.js switches its iridescence off at thickness 0 (lights_fragment_begin).
                if (!(film_->thickness_max_nm > 0)) return metal_fresnel(cos_h);
                return threejs_iridescence_range(1.0, film_->eta_film.real(), mu_o,
                                                 film_->thickness_min_nm, film_->thickness_max_nm,
                                                 f0_);
            case CoatRecipe::MetalFilm::OpenPbrBsdf:
                return openpbr_bsdf_film_reflectance(*film_, cos_h, metal_fresnel(cos_h));
            case CoatRecipe::MetalFilm::Cycles: {
                // Cycles' film sees an ambient of index 1 above it: relative to the coat, its
                // index is η_f/η_c and its thickness d η_c (the same optical path in vacuum
                // wavelengths).
                const double eta_c = film_->eta_above;
                return cycles_f82_tint_film_range(
                    film_->eta_film.real() / eta_c, film_->thickness_min_nm * eta_c,
                    film_->thickness_max_nm * eta_c, f0_, tint82_, cos_h);
            }
            case CoatRecipe::MetalFilm::OpenPbrSpec:
                // OpenPBR 1.1, "Thin-film iridescence": the film is incorporated into the metal's
                // Fresnel factor (no slab of its own); thickness 0 is no film.
                if (!(film_->thickness_max_nm > 0)) return metal_fresnel(cos_h);
                return film_reflectance_exact(*film_, cos_h);
            case CoatRecipe::MetalFilm::Unsupported:
                break;
        }
        return metal_fresnel(cos_h);
    }

    /// A · T · Δ: the base's scale for the pair (in.wi, wo) with cos_h = wi·h and E_o = E_coat(μo)
    /// (read only by the attenuations by the albedo).
    Rgbd base_scale(const Incident& in, double mu_o, double E_o, double cos_h) const {
        using A = CoatRecipe::Attenuation;
        double a = 1;
        switch (r_.attenuation) {
            case A::AlbedoView:
                a = clamp(1 - E_o, 0.0, 1.0);
                break;
            case A::AlbedoReciprocal:
                a = (1 - in.E_i) * (1 - E_o);
                break;
            case A::KullaConty:
                a = (1 - in.E_i) * (1 - E_o) * kc_norm_;
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
                s[c] *= openpbr_coat_darkening(K, E_b_[c]);
        } else {
            s *= darkening_;
        }
        return s;
    }

    void setup_darkening() {
        using D = CoatRecipe::Darkening;
        if (r_.darkening == D::None) return;
        if (r_.darkening == D::MaterialX) {
            // open_pbr_surface.mtlx: Kcoat = 1 − (1 − F0)/η0², E_base = the base colour (a
            // metal's F0, a diffuse base's ρ).
            const double K = openpbr_internal_reflectance(eta0_, coat_f0_ior_);
            E_b_ = is_metal_ ? f0_ : albedo_;
            for (int c = 0; c < 3; ++c)
                darkening_[c] = openpbr_coat_darkening(K, E_b_[c]);
            return;
        }
        // OpenPBR 1.1, "Darkening": Δ = (1 − K)/(1 − E_b K), K_r = 1 − (1 − E_F(η_c))/η_c².
        const double E_F = r_.darkening == D::Spec ? openpbr_average_fresnel_fit(eta0_)
                                                   : kulla_conty_average_fresnel_fit(eta0_);
        K_r_ = openpbr_internal_reflectance(eta0_, E_F);
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
            // Adobe: E_b = the metal's average Fresnel 2∫F μ dμ (its own metal Fresnel),
            // r_b = the roughened r (before the lobe's clamp), K_s = E_F.
            E_b_ = metal_average_;
            const double r_b = roughened(std::sqrt(coat_.base_alpha));
            K = E_F + (K_r_ - E_F) * r_b;
        } else if (r_.darkening == D::Adobe) {
            // openpbr-bsdf weighs the base's specularity s, the average Fresnel of its specular
            // at the relative index the specular weight leaves: 0 gives index 1, where its fit
            // is E_F(1) = 2.67e-3, not 0. E_b = lerp(ρ, 1, s), r_b = lerp(1, r', s) with r'
            // the default specular roughness after roughening (openpbr_bsdf.h).
            const double s = kulla_conty_average_fresnel_fit(1.0);
            E_b_ = albedo_ * (1 - s) + Rgbd(s);
            const double r_b = 1 + s * (roughened(kOpenPbrDefaultSpecularRoughness) - 1);
            K = E_F + (K_r_ - E_F) * r_b;
        } else {
            E_b_ = albedo_;
        }
        for (int c = 0; c < 3; ++c)
            darkening_[c] = openpbr_coat_darkening(K, E_b_[c]);
    }

    CoatRecipe r_;
    CoatedStack coat_;
    Support support_;
    /// The film on the metal base, when the stack has one (MetalFilm).
    std::optional<FilmOptics> film_;
    double eta0_ = 1.5;
    double coat_f0_ = 0;
    double alpha_coat_ = 0, alpha_base_ = 0;
    /// The coat's and the metal's lobes: GGX of α_coat_, α_base_, anisotropic where the
    /// interface is (lobe_distribution).
    GGX<double> coat_ggx_{0.0}, base_ggx_{0.0};
    FgdTable::Index eta_index_;
    bool is_metal_ = false;
    Rgbd f0_{0.0}, tint82_{1.0};
    std::array<std::complex<double>, 3> artistic_index_{};  ///< MetalFresnel::Artistic's n + ik
    double f90_ = 1;                                        ///< the metal's Schlick edge value
    std::optional<FilamentDfgTexture> dfg_;                 ///< Filament's energy compensation
    std::optional<ThreeJsDfgTexture> threejs_dfg_;          ///< three.js's energy compensation
    // Cycles' tables: the coat's white albedo and Fresnel factor, the metal's white albedo, and
    // their F_ms (the metal's per channel).
    std::optional<CyclesWhiteAlbedo> coat_white_, metal_white_;
    std::optional<CyclesFresnelFactor> coat_factor_;
    double coat_fms_ = 0, coat_f0_ior_ = 0;
    double specular_alpha_ = 0;  ///< MaterialX's base specular over a diffuse base
    Rgbd metal_fms_{0.0};
    Rgbd albedo_{0.0};
    Rgbd tau_{0.0};
    bool has_tau_ = false;
    double kc_norm_ = 1;
    double r_coat_ = 0;  ///< the coat's roughness parameter before the lobe's clamp
    std::optional<OpenPbrBsdfEnergyGrid> coat_grid_;
    // The metal: its average Fresnel and its compensation lobe for multiple scattering,
    // ms_color_ (1 − E(μi)) (1 − E(μo)) ms_norm_ with E from openpbr-bsdf's grid or dspbr-pt's
    // fits.
    Rgbd metal_average_{0.0};
    std::optional<OpenPbrBsdfEnergyGrid> ms_grid_;
    Rgbd ms_color_{0.0};
    double ms_norm_ = 1;
    double ms_roughness_ = 0;  ///< the metal's r for dspbr-pt's fits (0: not that lobe)
    // Darkening: Δ for a wo-independent K, else K_r, r_b and E_b for the spec's K(μo).
    Rgbd darkening_{1.0};
    Rgbd E_b_{0.0};
    double K_r_ = 0, r_b_ = 1;
};

std::unique_ptr<IncidentEvaluator> ProductionCoat::prepare(const Vec3d& wi) const {
    return std::make_unique<ViewKeepingEvaluator<ProductionCoat>>(*this, wi);
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

double openpbr_isotropic_alpha(const InterfaceSpec& interface) {
    if (!interface.is_anisotropic()) return interface.alpha;
    // OpenPBR 1.1: α_t² + α_b² = α² (2 / (1 + (1 − a)²)) (1 + (1 − a)²) = 2 α².
    return std::sqrt(0.5 * (sqr(interface.alpha) + sqr(interface.alpha_b())));
}

SchlickSplit materialx_ggx_albedo_fit(double mu, double alpha) {
    // mx_ggx_dir_albedo_analytic: r = c0 + c1 x + c2 y + c3 x y + c4 x² + c5 y² + c6 x² y +
    // c7 x y² + c8 x² y², x = μ, y = α, four components; A = r.x/r.z, B = r.y/r.w.
    static constexpr double c[9][4] = {
        {0.1003, 0.9345, 1.0, 1.0},     {-0.6303, -2.323, -1.765, 0.2281},
        {9.748, 2.229, 8.263, 15.94},   {-2.038, -3.748, 11.53, -55.83},
        {29.34, 1.424, 28.96, 13.08},   {-8.245, -0.7684, -7.507, 41.26},
        {-26.44, 1.436, -36.11, 54.9},  {19.99, 0.2913, 15.86, 300.2},
        {-5.448, 0.6286, 33.37, -285.1}};
    const double x = clamp(mu, 1e-8, 1.0), y = alpha, x2 = x * x, y2 = y * y;
    const double terms[9] = {1, x, y, x * y, x2, y2, x2 * y, x * y2, x2 * y2};
    double r[4] = {0, 0, 0, 0};
    for (int k = 0; k < 9; ++k)
        for (int i = 0; i < 4; ++i)
            r[i] += c[k][i] * terms[k];
    return {clamp(r[0] / r[2], 0.0, 1.0), clamp(r[1] / r[3], 0.0, 1.0)};
}

double openpbr_internal_reflectance(double eta, double average_fresnel) {
    return 1 - (1 - average_fresnel) / (eta * eta);
}

double openpbr_coat_darkening(double K, double E_b) {
    if (!(K < 1)) return 0.0;
    return (1 - K) / (1 - E_b * K);
}

double filament_f0_clear_coat_to_surface(double f0) {
    // Filament documentation, "Clear coat" (f0ClearCoatToSurface): a fit of the F0 of an
    // interface against IOR 1.5 from its F0 against air.
    return clamp(f0 * (f0 * (0.941892 - 0.263008 * f0) + 0.346479) - 0.0285998, 0.0, 1.0);
}

double f82_tint_fresnel(double cos_theta, double f0, double tint) {
    const double mu = clamp(cos_theta, 0.0, 1.0);
    const double one_minus_bar = 1 - kF82Cos;
    const double bar6 = pow6(one_minus_bar);
    const double b = schlick(kF82Cos, f0) * (1 - tint) / (kF82Cos * bar6);
    return clamp(schlick(mu, f0) - b * mu * pow6(1 - mu), 0.0, 1.0);
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
    r.metal_visibility = CoatRecipe::Visibility::Smith;
    r.coat_min_roughness = 0;
    r.lobe_min_roughness = 0;
    r.metal_min_roughness = 0;
    r.max_ndf = 0;
    r.metal_energy_compensation = CoatRecipe::MetalEnergyCompensation::None;
    r.coat_energy_compensation = CoatRecipe::CoatEnergyCompensation::None;
    r.diffuse_specular_throughput = false;
    r.schlick_spherical_gaussian = false;
    r.metal_f90_from_f0 = false;
    r.coat_albedo = CoatRecipe::CoatAlbedo::Fgd;
    r.metal_multiple_scattering = CoatRecipe::MetalMultipleScattering::None;
    r.metal_fresnel = CoatRecipe::MetalFresnel::Exact;
    if (r.metal_film != CoatRecipe::MetalFilm::Unsupported)
        r.metal_film = CoatRecipe::MetalFilm::Exact;
    if (r.dielectric_film != CoatRecipe::DielectricFilm::Unsupported)
        r.dielectric_film = CoatRecipe::DielectricFilm::Exact;
}

std::unique_ptr<Model> make_production_coat(const Stack& stack, const CoatRecipe& recipe) {
    if (recipe.dielectric_film != CoatRecipe::DielectricFilm::Unsupported &&
        is_filmed_plastic(stack)) {
        GlossyDiffuseFilmRecipe glossy;
        glossy.name = recipe.name;
        glossy.film = recipe.dielectric_film == CoatRecipe::DielectricFilm::Cycles
                          ? GlossyDiffuseFilmRecipe::Film::Cycles
                          : GlossyDiffuseFilmRecipe::Film::Exact;
        glossy.cycles_compensation =
            recipe.coat_energy_compensation == CoatRecipe::CoatEnergyCompensation::Cycles;
        glossy.layering = recipe.coat_albedo == CoatRecipe::CoatAlbedo::Cycles
                              ? GlossyDiffuseFilmRecipe::Layering::CyclesEstimate
                              : GlossyDiffuseFilmRecipe::Layering::LobeAlbedo;
        glossy.darkened_base_color = recipe.darkening == CoatRecipe::Darkening::Spec;
        return make_glossy_diffuse_film(stack, glossy);
    }
    return std::make_unique<ProductionCoat>(stack, recipe);
}

}  // namespace lamina

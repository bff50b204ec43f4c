// Unity HDRP StackLit (Unity-Technologies/Graphics, com.unity.render-pipelines.high-definition
// Runtime/Material/StackLit/StackLit.hlsl), read for its equations (no code copied): the vertically
// layered statistics of ComputeAdding / ComputeStatistics, the energy compensation of
// GetPreLightData and the lobes of EvaluateBSDF, at StackLit's defaults (the shader features
// _VLAYERED_RECOMPUTE_PERLIGHT and _VLAYERED_USE_REFRACTED_ANGLES_FOR_BASE off, coat mask 1, no
// coat normal map, lobe mix 0). docs/models.md gives the mapping and the deviations found.
#include "models/production/unity_stacklit.h"

#include "core/math.h"
#include "models/belcour/belcour.h"
#include "models/production/filament_dfg.h"
#include "models/production/lobe_mixture.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/sampling.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>

namespace lamina {

// --- HDRP's pre-integrated FGD texture --------------------------------------------------------

UnityFgdTexture::UnityFgdTexture() {
    for (int j = 0; j < kSize; ++j) {
        const double r = double(j) / (kSize - 1);
        for (int i = 0; i < kSize; ++i) {
            const double s = double(i) / (kSize - 1);
            const double e =
                FilamentDfgTexture::estimate(s * s, r * r, kSamples, HammersleyAzimuth::Second);
            // A2B10G10R10_UNorm: the value clamped to [0, 1], 10 bits.
            texels_[std::size_t(j * kSize + i)] = std::nearbyint(clamp(e, 0.0, 1.0) * 1023) / 1023;
        }
    }
}

const UnityFgdTexture& UnityFgdTexture::get() {
    static const UnityFgdTexture texture;
    return texture;
}

double UnityFgdTexture::albedo(double mu, double perceptual_roughness) const {
    // Texel centres at the nodes k/63 of each coordinate; edges clamped.
    const double tx = clamp(std::sqrt(clamp(mu, 0.0, 1.0)), 0.0, 1.0) * (kSize - 1);
    const double ty = clamp(perceptual_roughness, 0.0, 1.0) * (kSize - 1);
    const int x0 = std::min(int(tx), kSize - 2), y0 = std::min(int(ty), kSize - 2);
    const double fx = tx - x0, fy = ty - y0;
    const double lower = mix(texel(x0, y0), texel(x0 + 1, y0), fx);
    const double upper = mix(texel(x0, y0 + 1), texel(x0 + 1, y0 + 1), fx);
    return mix(lower, upper, fy);
}

namespace {

/// HDRP's ClampNdotV: cosines of the view at ≥ 10⁻⁴.
constexpr double kMinCos = 1e-4;
/// HDRP's ClampRoughnessForAnalyticalLights: every lobe at α ≥ 1/1024 for punctual lights.
constexpr double kMinAlpha = 1.0 / 1024;
/// StackLit's clamp of α in its roughness ↔ variance mapping (RoughnessToLinearVariance).
constexpr double kVarianceAlphaMax = 0.9999;
/// Belcour 2018's σ(α) = α^1.1/(1 − α^1.1) (§5.1) with StackLit's clamp.
double variance_of_alpha(double alpha) {
    return belcour_variance_of_alpha(alpha, false, kVarianceAlphaMax);
}
/// StackLit's default smoothness of the base (0.5): the diffuse base's specular lobe keeps it.
constexpr double kDiffuseBasePerceptualRoughness = 0.5;

/// HDRP's IorToFresnel0 and Fresnel0ToIor (BSDF.hlsl): the normal reflectance between indices,
/// and the index a normal reflectance against 1 stands for.
double ior_to_f0(double transmitted, double incident) {
    return sqr((transmitted - incident) / (transmitted + incident));
}
double f0_to_ior(double f0) {
    const double s = std::sqrt(f0);
    return (1 + s) / (1 - s);
}
/// Schlick 1994, Eq. 15, with f90 = 1 (HDRP's F_Schlick).
double f_schlick(double f0, double c) {
    const double m = 1 - c, m2 = m * m;  // (1 − c)⁵ in products, not a library call
    return f0 + (1 - f0) * m2 * m2 * m;
}

/// What StackLit derives from the view alone (its GetPreLightData).
struct ViewStatistics {
    Rgbd coat_energy{0.0};  ///< E_0: the coat lobe's energy
    Rgbd base_energy{0.0};  ///< E_2: the base lobe's energy
    Rgbd diffuse{1.0};      ///< T_↑: the diffuse base's energy factor
    double alpha_base =
        0;  ///< α_b' (clamped to ≥ 1/1024); of an anisotropic base, along its tangent
    double alpha_base_b = 0;  ///< an anisotropic base's α along its bitangent (else alpha_base)
    double perceptual_roughness_base = 0;  ///< √ of α_b' before the clamp (the FGD row)
    double coat_compensation = 1;          ///< c_0
    Rgbd base_compensation{1.0};           ///< c_2
};

class UnityStackLit final : public LobeMixtureModel<UnityStackLit> {
    friend class LobeMixtureModel<UnityStackLit>;

  public:
    explicit UnityStackLit(const Stack& stack) {
        std::string why;
        if (!coated_stack(stack, coat_, why)) {
            support_.reason = "unity-stacklit " + why;
            return;
        }
        if (coat_.tau_s.max() > 0) {
            support_.reason =
                "unity-stacklit has no scattering coat (its coat is a clear or absorbing "
                "dielectric)";
            return;
        }
        if (coat_.base_type == InterfaceType::Dielectric) {
            support_.reason =
                "unity-stacklit has an opaque base (diffuse or metal) under its coat: a dielectric "
                "base with light passing below it (a slab, BTDF) has no counterpart";
            return;
        }
        if (coat_.eta0 < 1) {
            support_.reason = fmt::format(
                "unity-stacklit's coat IOR is at least 1 (StackLit's UI range); this coat's "
                "relative index is {}",
                coat_.eta0);
            return;
        }
        if (stack.layers[0].interface.is_anisotropic()) {
            support_.reason =
                "unity-stacklit has no anisotropic coat (StackLit's anisotropy is the base's): "
                "the coat's anisotropic roughness (alpha = [alpha_x, alpha_y]) has no counterpart";
            return;
        }
        support_.brdf = true;
        // The texture is built on the first model that needs it (once per process), not on its
        // first evaluation.
        fgd_ = &UnityFgdTexture::get();
        eta0_ = coat_.eta0;
        alpha_coat_ = coat_.alpha0;  // r_c = √α0, α = r_c²
        alpha_coat_lobe_ = std::max(alpha_coat_, kMinAlpha);
        coat_f0_ = ior_to_f0(eta0_, 1);
        is_metal_ = coat_.base_type == InterfaceType::Conductor;
        // The base's inputs (docs/models.md): a metal's base colour is its F0 against air
        // (metallic 1), a diffuse base's specular F0 that of its dielectric IOR set to η0
        // (metallic 0); StackLit re-derives the F0 under the coat from the index the F0 stands
        // for (ConvertF0ForAirInterfaceToF0ForNewTopIor, the F0 taken at ≤ 0.999).
        for (int c = 0; c < 3; ++c) {
            const double f0_air = is_metal_ ? fresnel_conductor(1.0, coat_.base_eta[c] * eta0_,
                                                                coat_.base_k[c] * eta0_)
                                            : ior_to_f0(eta0_, 1);
            base_f0_[c] = ior_to_f0(f0_to_ior(std::min(f0_air, 0.999)), eta0_);
        }
        rho_ = is_metal_ ? Rgbd(0.0) : coat_.albedo;
        double alpha_base = coat_.base_alpha;
        if (const InterfaceSpec& b = stack.layers[1].interface; b.is_anisotropic()) {
            // StackLit's anisotropic base (Kulla & Conty 2017's parametrization, its
            // ConvertAnisotropyToRoughness): α_t = α (1 + a), α_b = α (1 − a) along its tangent
            // and bitangent n × t; so α = (α_x + α_y)/2, a = (α_x − α_y)/(α_x + α_y), the tangent
            // the interface's.
            alpha_base = 0.5 * (b.alpha + b.alpha_b());
            anisotropy_ = (b.alpha - b.alpha_b()) / (b.alpha + b.alpha_b());
            tangent_rad_ = deg_to_rad(b.tangent_deg);
        }
        const double r_base = is_metal_ ? std::sqrt(alpha_base) : kDiffuseBasePerceptualRoughness;
        alpha_base_input_ = r_base * r_base;
    }

    std::string name() const override { return "unity-stacklit"; }
    Support support() const override { return support_; }

    /// StackLit's ComputeAdding for the view's cosine μ (clamped to ≥ 10⁻⁴), three layers: the
    /// coat's interface, its medium, the base (Belcour 2018, §4–5, the adding equations of the
    /// energy and of the variance, as StackLit writes them), then the FGD reads of
    /// GetPreLightData.
    [[gnu::noinline]] ViewStatistics view(double mu_view) const {
        ViewStatistics v;
        double cti = std::max(mu_view, kMinCos);
        const double mu_clamped = cti;
        // The stack above the layer being added: reflectances and transmittances down (0i) and
        // up (i0), their variances and the Jacobians of the refraction.
        Rgbd R0i(0.0), Ri0(0.0), T0i(1.0), Ti0(1.0);
        double s_r0i = 0, s_ri0 = 0, s_t0i = 0, s_ti0 = 0, j0i = 1, ji0 = 1;
        double m_rr = 0;
        for (int layer = 0; layer < 3; ++layer) {
            Rgbd R12(0.0), T12(1.0);
            double ctt = cti, s_r12 = 0, s_t12 = 0, s_t21 = 0, j12 = 1, j21 = 1;
            if (layer == 0) {
                // The coat's interface: the exact Fresnel at the tracked cosine (not its FGD).
                R12 = Rgbd(fresnel_dielectric(cti, eta0_));
                T12 = Rgbd(1.0) - R12;
                // The mean refracted direction, pulled back towards the incident one as the coat
                // roughens: scale = (1 − α)(√(1 − α) + α) (StackLit's "hack" for the paper's
                // Fig. 5); no TIR (η0 ≥ 1).
                const double alpha = alpha_coat_;
                const double sti = std::sqrt(1 - cti * cti);
                const double scale = clamp((1 - alpha) * (std::sqrt(1 - alpha) + alpha), 0.0, 1.0);
                const double stt = scale * (sti / eta0_) + (1 - scale) * sti;
                ctt = std::sqrt(1 - stt * stt);
                s_r12 = variance_of_alpha(alpha);
                // Transmission variances: the roughness scaled by ½|1 − cos θi/(η cos θt)| and
                // ½|1 − η cos θt/cos θi| (Belcour 2018, Eq. 10 as lamina reads it, bel18's
                // sigma-t=paper).
                s_t12 =
                    variance_of_alpha(alpha * 0.5 * std::abs((ctt * eta0_ - cti) / (ctt * eta0_)));
                s_t21 =
                    variance_of_alpha(alpha * 0.5 * std::abs((cti / eta0_ - ctt) / (cti / eta0_)));
                j12 = ctt / cti * eta0_;
                j21 = 1 / j12;
            } else if (layer == 1) {
                // The medium: Beer–Lambert along the tracked cosine, thickness 1.
                T12 = beer_lambert(coat_.tau_a, 1 / cti);
                R12 = Rgbd(0.0);
            } else {
                // The base: Schlick's Fresnel of its F0 under the coat at the tracked cosine; what
                // it does not reflect goes to the diffuse lobe
                // (VLAYERED_DIFFUSE_ENERGY_HACKED_TERM).
                for (int c = 0; c < 3; ++c)
                    R12[c] = f_schlick(base_f0_[c], cti);
                T12 = Rgbd(1.0) - R12;
            }
            const Rgbd& R21 = R12;
            const Rgbd& T21 = T12;
            const double s_r21 = s_r12;
            // Adding one layer (Belcour 2018, §4–5; docs/models.md, "Belcour 2018", Adding): the
            // series of interreflections 1/(1 − Ri0 R12), a channel whose denominator is 0 left
            // at 0.
            Rgbd m_R0i(0.0), m_Ri0(0.0), m_Rr(0.0), e_T0i(0.0), e_Ti0(0.0);
            for (int c = 0; c < 3; ++c) {
                const double denom = std::max(0.0, 1 - Ri0[c] * R12[c]);
                if (!(denom > 0)) continue;
                m_R0i[c] = T0i[c] * R12[c] * Ti0[c] / denom;
                m_Ri0[c] = T21[c] * Ri0[c] * T12[c] / denom;
                m_Rr[c] = Ri0[c] * R12[c] / denom;
                e_T0i[c] = T0i[c] * T12[c] / denom;
                e_Ti0[c] = T21[c] * Ti0[c] / denom;
            }
            const double m_r0i = m_R0i.mean(), m_ri0 = m_Ri0.mean();
            m_rr = m_Rr.mean();
            const Rgbd e_R0i = R0i + m_R0i, e_Ri0 = R21 + m_Ri0;
            const double s_r0m = s_ti0 + j0i * (s_t0i + s_r12 + m_rr * (s_r12 + s_ri0));
            const double e_r0i = e_R0i.mean(), e_ri0 = e_Ri0.mean();
            double new_s_r0i = R0i.mean() * s_r0i + m_r0i * s_r0m;
            const double new_s_t0i = j12 * s_t0i + s_t12 + j12 * (s_r12 + s_ri0) * m_rr;
            const double s_rim = s_t12 + j12 * (s_t21 + s_ri0 + m_rr * (s_r12 + s_ri0));
            double new_s_ri0 = R21.mean() * s_r21 + m_ri0 * s_rim;
            const double new_s_ti0 = ji0 * s_t21 + s_ti0 + ji0 * (s_r12 + s_ri0) * m_rr;
            new_s_r0i = e_r0i > 0 ? new_s_r0i / e_r0i : 0;
            new_s_ri0 = e_ri0 > 0 ? new_s_ri0 / e_ri0 : 0;
            const Rgbd energy = m_r0i > 0 ? m_R0i : Rgbd(0.0);
            if (layer == 0) v.coat_energy = energy;
            if (layer == 2) v.base_energy = energy;
            R0i = e_R0i;
            T0i = e_T0i;
            Ri0 = e_Ri0;
            Ti0 = e_Ti0;
            cti = std::max(ctt, kMinCos);
            // The variances and Jacobians stop at the medium: the base's lobe is added below.
            if (layer < 2) {
                s_r0i = new_s_r0i;
                s_t0i = new_s_t0i;
                s_ri0 = new_s_ri0;
                s_ti0 = new_s_ti0;
                j0i *= j12;
                ji0 *= j21;
            }
        }
        // The base lobe's variance: its own σ(α_b) added under the coat's, with the base's
        // interreflection term of the last step (StackLit's shortcut of the last adding).
        const double s_base = variance_of_alpha(alpha_base_input_);
        const double s_r0m = s_ti0 + j0i * (s_t0i + s_base + m_rr * (s_base + s_ri0));
        v.perceptual_roughness_base = std::sqrt(belcour_alpha_of_variance(s_r0m, false));
        v.alpha_base = v.alpha_base_b = std::max(sqr(v.perceptual_roughness_base), kMinAlpha);
        if (anisotropy_ != 0 && v.perceptual_roughness_base > 0) {
            // The anisotropy scaled by r/r' (GetModifiedAnisotropy, StackLit's
            // VLAYERED_ANISOTROPY_SCALAR_ROUGHNESS_CORRECTANISO), then split as the input was.
            const double a =
                anisotropy_ * std::sqrt(alpha_base_input_) / v.perceptual_roughness_base;
            const double alpha = sqr(v.perceptual_roughness_base);
            v.alpha_base = std::max(alpha * (1 + a), kMinAlpha);
            v.alpha_base_b = std::max(alpha * (1 - a), kMinAlpha);
        }
        v.diffuse = Ti0;
        // The energy compensation of each lobe, 1 + F0 (1/E − 1) (Turquin 2019, Eq. 16; StackLit's
        // GetEnergyCompensationFactor), E read from the FGD texture: the coat's at the view's
        // cosine and its perceptual roughness, the base's at the view's cosine refracted into the
        // coat (Snell, no roughness pull) and the base's roughness after adding.
        const UnityFgdTexture& fgd = *fgd_;
        const double e_coat = fgd.albedo(mu_clamped, std::sqrt(alpha_coat_));
        const double mu_base =
            std::max(std::sqrt(1 + (mu_clamped * mu_clamped - 1) / (eta0_ * eta0_)), kMinCos);
        const double e_base = fgd.albedo(mu_base, v.perceptual_roughness_base);
        v.coat_compensation = 1 + coat_f0_ * (1 / e_coat - 1);
        for (int c = 0; c < 3; ++c)
            v.base_compensation[c] = 1 + base_f0_[c] * (1 / e_base - 1);
        return v;
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        return eval_in_view(wi, wo, view(wo.z));
    }

    // The split evaluation (models/model.h, ViewKeepingEvaluator): the view's statistics are
    // most of an evaluation's cost and depend on wo.z alone.
    using Incident = Vec3d;
    using View = ViewStatistics;
    Incident incident(const Vec3d& wi) const { return wi; }
    Rgbd eval_with(const Incident& wi, const Vec3d& wo) const { return eval(wi, wo); }
    // Compiled once (not inlined): with FMA contraction an inlined copy may round differently, and
    // eval and the evaluator for one thread must agree to the bit (view is not inlined either).
    [[gnu::noinline]] Rgbd eval_in_view(const Vec3d& wi, const Vec3d& wo,
                                        const ViewStatistics& v) const {
        if (!support_.brdf || wi.z <= 0 || wo.z <= 0) return Rgbd(0.0);
        const Vec3d h = normalize(wi + wo);
        const double coat = ggx_lobe_shape(alpha_coat_lobe_, wi, wo, h);
        const double base = anisotropy_ == 0
                                ? ggx_lobe_shape(v.alpha_base, wi, wo, h)
                                : base_lobe(v).D(h) * base_lobe(v).G2(wi, wo) / (4 * wi.z * wo.z);
        return v.coat_energy * (v.coat_compensation * coat) +
               v.base_energy * v.base_compensation * base + rho_ * v.diffuse * kInvPi<double>;
    }

    /// Importance sampling (models/production/lobe_mixture.h): the coat lobe's visible normals with
    /// probability p_c, the coat's Fresnel at μi clamped to [0.1, 0.9]; else the base's lobe (GGX
    /// visible normals at the roughness the base has when viewed along wi) — for a diffuse base one
    /// time in five, the cosine otherwise.
    bool has_sampling() const override { return support_.brdf; }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

  private:
    /// The base lobe of an anisotropic base, α_t along its tangent, α_b along n × t.
    GGX<double> base_lobe(const ViewStatistics& v) const {
        return anisotropy_ == 0
                   ? GGX<double>{v.alpha_base}
                   : GGX<double>::anisotropic(v.alpha_base, v.alpha_base_b, tangent_rad_);
    }

    ReflectionLobeMixture proposal(const Vec3d& wi) const {
        ReflectionLobeMixture m;
        m.coat = clamp(fresnel_dielectric(wi.z, eta0_), 0.1, 0.9);
        m.base = is_metal_ ? 1 - m.coat : 0.2 * (1 - m.coat);
        m.coat_lobe = GGX<double>{alpha_coat_lobe_};
        m.base_lobe = base_lobe(view(wi.z));
        m.diffuse = !is_metal_;
        return m;
    }

    Support support_;
    const UnityFgdTexture* fgd_ = nullptr;
    CoatedStack coat_;
    double eta0_ = 1, alpha_coat_ = 0, alpha_coat_lobe_ = kMinAlpha, coat_f0_ = 0;
    double alpha_base_input_ = 0;
    double anisotropy_ = 0, tangent_rad_ = 0;  ///< StackLit's base anisotropy and its tangent
    bool is_metal_ = false;
    Rgbd base_f0_{0.0}, rho_{0.0};
};

std::unique_ptr<IncidentEvaluator> UnityStackLit::prepare(const Vec3d& wi) const {
    return std::make_unique<ViewKeepingEvaluator<UnityStackLit>>(*this, wi);
}

}  // namespace

std::unique_ptr<Model> make_unity_stacklit(const Stack& stack, const ModelOptions&) {
    return std::make_unique<UnityStackLit>(stack);
}

std::vector<OptionSpec> unity_stacklit_options() {
    return {};
}

}  // namespace lamina

#pragma once
// Belcour 2018, "Efficient rendering of layered materials using an atomic decomposition with
// statistical operators", ACM TOG 37(4) (SIGGRAPH): the BRDF is a sum of GGX lobes, one per
// interface, whose energies and roughnesses come from tracking three statistics of a lobe
// (energy per RGB, mean cosine, scalar variance) through the stack with an adding–doubling
// scheme (docs/models.md, "Belcour 2018", "Bel'"; paper §4–6). Bel18 forward, Bel18 symmetric,
// Bel' and WB20 (Weier & Belcour 2020, JCGT 9(2): the same scheme with 2×2 lobe covariances for
// anisotropic interfaces; docs/models.md, "Weier & Belcour 2020") are one engine with the choices
// below; each variant is its defaults (belcour_variant).

#include "models/model.h"
#include "models/model_options.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"

#include <array>
#include <string>
#include <vector>

namespace lamina {

/// Where the total-internal-reflection step (the τ_TIR table scales the upward transmission of the
/// stack above and moves the rest to upward reflection) is applied (docs/models.md, "TIR").
enum class BelcourTir {
    /// The author's code: while adding each interface below the top, before its sums, for the
    /// interface above it (its index ratio seen from below), at the cosine in the layer between and
    /// the roughness α(σT0i + σR) the interface being added reads its FGD at.
    EachInterface,
    /// lamina's former reading: once, right after the top interface, at its refracted cosine and
    /// its own roughness.
    TopInterface,
    Off,
};
inline constexpr std::array<EnumName<BelcourTir>, 3> enum_names(BelcourTir) {
    return {{{BelcourTir::EachInterface, "each-interface", "the author's code"},
             {BelcourTir::TopInterface, "top-interface", "once below the top interface"},
             {BelcourTir::Off, "off", "none"}}};
}
inline const char* enum_noun(BelcourTir) {
    return "a TIR step";
}

struct BelcourChoices {
    /// Cosine fed to the adding scheme: |wi·h| (symmetric, reciprocal) or μi (forward).
    bool symmetric = false;
    BelcourTir tir = BelcourTir::EachInterface;
    /// What τ_TIR holds (tir_table.h): the author's table by default.
    TirDefinition tir_table = TirDefinition::LobeFresnel;
    /// A medium between two interfaces keeps the step for the interface above it (lamina's former
    /// reading) or removes it (false: the author's code, where the interface below a medium sees
    /// the index ratio 1 of the medium's own layer entry).
    bool tir_across_media = false;
    /// Every medium widens the transmitted lobe by σ_HG(g) of its stack's g (true: the author's
    /// operator read literally), or only a medium that scatters (false: a medium that does not
    /// scatter has no phase function; the author's operator with g = 1 gives it no variance).
    bool medium_variance_every_medium = false;
    /// Transmission variances: the author's code (false) or the paper's Eq. 10 (true).
    bool sigma_t_paper = false;
    /// Roughness ↔ variance: the author's σ = α^1.1/(1 − α^1.1) (false) or σ = α²/(1 − α²).
    bool quadratic_mapping = false;
    /// Bel': lobe 0 replaced by the exact reflection of the top interface.
    bool exact_top = false;
    /// Bel': the slab's BTDF as one mirrored GGX lobe.
    bool btdf = false;
    /// Weier & Belcour 2020 (wb20): anisotropic interfaces, each lobe's variance a 2×2
    /// covariance (belcour_adding_anisotropic) and its lobe the anisotropic GGX of its
    /// eigen-decomposition.
    bool anisotropic = false;
    /// WB20: the FGD and TIR tables read the roughness of the covariance along the incident azimuth
    /// (false) or of its mean over azimuths, (Σxx + Σyy)/2 (true).
    bool energy_roughness_mean = false;
};

/// A lobe's directional variance as a 2×2 covariance in the surface's frame (Weier & Belcour
/// 2020: per-axis variances in an interface's tangent frame, rotated to the surface's); the scalar
/// variance σ of Belcour 2018 is σ I.
struct BelcourCovariance {
    double xx = 0, yy = 0, xy = 0;
    BelcourCovariance() = default;
    BelcourCovariance(double xx_, double yy_, double xy_) : xx(xx_), yy(yy_), xy(xy_) {}
    explicit BelcourCovariance(double sigma) : xx(sigma), yy(sigma) {}
    /// σ_t along the tangent (c, s) and σ_b along the bitangent (−s, c): R diag(σ_t, σ_b) Rᵀ.
    static BelcourCovariance of_axes(double sigma_t, double sigma_b, double c, double s) {
        return {sigma_t * c * c + sigma_b * s * s, sigma_t * s * s + sigma_b * c * c,
                (sigma_t - sigma_b) * c * s};
    }
    /// The variance along the unit direction (dx, dy): dᵀ Σ d.
    double along(double dx, double dy) const {
        return xx * dx * dx + 2 * xy * dx * dy + yy * dy * dy;
    }
    friend BelcourCovariance operator+(const BelcourCovariance& a, const BelcourCovariance& b) {
        return {a.xx + b.xx, a.yy + b.yy, a.xy + b.xy};
    }
    friend BelcourCovariance operator*(double k, const BelcourCovariance& a) {
        return {k * a.xx, k * a.yy, k * a.xy};
    }
    friend BelcourCovariance operator*(const BelcourCovariance& a, double k) {
        return {a.xx * k, a.yy * k, a.xy * k};
    }
    friend BelcourCovariance operator/(const BelcourCovariance& a, double k) {
        return {a.xx / k, a.yy / k, a.xy / k};
    }
    friend bool operator==(const BelcourCovariance&, const BelcourCovariance&) = default;
};

/// The statistics the adding scheme produces for one incident cosine.
struct BelcourStats {
    static constexpr int kMaxLobes = 8;
    struct Lobe {
        Rgbd energy{0.0};
        double alpha = 0;
        /// The lobe's covariance (belcour_adding_anisotropic; belcour_adding: σ I).
        BelcourCovariance covariance{};
    };
    std::array<Lobe, kMaxLobes> lobes{};
    int n_lobes = 0;
    /// Energy leaving through the bottom (after the last dielectric), its roughness and the mean
    /// cosine of its direction in the exit medium; valid when `transmits`.
    Rgbd transmitted{0.0};
    double alpha_t = 0;
    double cos_t = 1;
    BelcourCovariance covariance_t{};
    bool transmits = false;
};

/// One operator of the stack, top to bottom: an interface or a medium.
struct BelcourOperator {
    enum Kind { Dielectric, Conductor, Medium } kind = Dielectric;
    double n12 = 1;      ///< relative index (conductor: mean of η over RGB)
    Rgbd eta{1.0};       ///< conductor: relative η per channel (dielectric: n12)
    Rgbd k{0.0};         ///< conductor: relative κ per channel
    double alpha = 0;    ///< GGX roughness of an interface (anisotropic: along its tangent)
    double alpha_b = 0;  ///< α along the bitangent (belcour_adding_anisotropic only)
    double tangent_cos = 1, tangent_sin = 0;  ///< the tangent's direction in the surface's frame
    Rgbd tau_a{0.0}, tau_s{0.0};
    double g = 0;  ///< HG mean cosine (mean over RGB)

    /// Angle-independent variances, filled by precompute_variances (pow is the cost of the
    /// symmetric variant, which runs the scheme per evaluation); unused unless `precomputed`.
    bool precomputed = false;
    bool precomputed_quadratic = false;
    double sigma_r = 0, sigma_t12 = 0, sigma_t21 = 0, alpha_clamped = 0;
    BelcourCovariance cov_r, cov_t12, cov_t21;   ///< the same per axis (alpha, alpha_b)
    std::array<FgdTable::Index, 3> fgd_index{};  ///< per channel (dielectric: all equal)
};

/// Fills the angle-independent variances of every operator for the given mapping.
void precompute_variances(std::vector<BelcourOperator>& ops, bool quadratic_mapping);

/// Runs the adding scheme (docs/models.md) for mean incident cosine c0 ∈ (0, 1].
BelcourStats belcour_adding(const std::vector<BelcourOperator>& ops, double c0,
                            const BelcourChoices& choices);

/// Weier & Belcour 2020: the same scheme with each variance a 2×2 covariance in the surface's
/// frame (each interface's per-axis variances σ(α), σ(α_b) rotated by its tangent); the FGD and
/// TIR tables read the roughness of the variance along the incident azimuth (dir_x, dir_y) (unit;
/// at normal incidence any). Lobe energies and alpha are as belcour_adding's when every interface
/// is isotropic, up to rounding.
/// choices.energy_roughness_mean: at (Σxx + Σyy)/2 instead.
BelcourStats belcour_adding_anisotropic(const std::vector<BelcourOperator>& ops, double c0,
                                        const BelcourChoices& choices, double dir_x, double dir_y);

/// The flags of the engine (the variant-fixed choices, exact_top, btdf and anisotropic, are not
/// flags).
const ModelOptionTable<BelcourChoices>& belcour_option_table();
/// WB20's: the engine's and where the energies read their roughness.
const ModelOptionTable<BelcourChoices>& wb20_option_table();
/// The defaults of a variant: "bel18-forward", "bel18-symmetric", "bel-prime" or "wb20" (a
/// programming error otherwise).
BelcourChoices belcour_variant(const std::string& variant);

/// Belcour 2018's roughness ↔ variance mapping (§5.1 and the author's code): σ(α) = α^1.1/(1 −
/// α^1.1) with α clamped at kBelcourAlphaMax (σ(1) is infinite), and its inverse α(σ) = (σ/(1 +
/// σ))^(1/1.1) (0 for σ ≤ 0 or NaN, → 1 as σ → ∞). quadratic: lamina's ablation σ = α²/(1 − α²).
/// alpha_max: where α is clamped (Unity's StackLit, RoughnessToLinearVariance: 0.9999).
inline constexpr double kBelcourAlphaMax = 0.999;
double belcour_variance_of_alpha(double alpha, bool quadratic, double alpha_max = kBelcourAlphaMax);
double belcour_alpha_of_variance(double sigma, bool quadratic);

/// GGX reflection lobe shape D G2 / (4 μi μo) with the energy factored out (Belcour 2018, Eq. 1;
/// the lobe of every statistical model): wi, wo above the surface, h = normalize(wi + wo); 0 for
/// α ≤ 0 (a smooth lobe is a delta lobe).
double ggx_lobe_shape(double alpha, const Vec3d& wi, const Vec3d& wo, const Vec3d& h);

/// The anisotropic GGX a covariance stands for (Weier & Belcour 2020): α_x, α_y the roughnesses
/// α(λ) of its eigenvalues λ_x ≥ λ_y and psi (radians) the angle of λ_x's eigenvector from +x.
struct BelcourAnisotropicLobe {
    double alpha_x = 0, alpha_y = 0, psi = 0;
};
BelcourAnisotropicLobe belcour_lobe_of_covariance(const BelcourCovariance& c, bool quadratic);

/// A member of the family with `choices`; `name` appears in support reasons.
std::unique_ptr<Model> make_belcour_model(const std::string& name, const Stack& stack,
                                          const BelcourChoices& choices);

}  // namespace lamina

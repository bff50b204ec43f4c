#pragma once
// Belcour 2018, "Efficient rendering of layered materials using an atomic decomposition with
// statistical operators", ACM TOG 37(4) (SIGGRAPH): the BRDF is a sum of GGX lobes, one per
// interface, whose energies and roughnesses come from tracking three statistics of a lobe
// (energy per RGB, mean cosine, scalar variance) through the stack with an adding–doubling
// scheme (docs/models.md, "Belcour 2018", "Bel'"; paper §4–6). Bel18 forward, Bel18 symmetric and
// Bel' are one engine with the choices below; each variant is its defaults (belcour_variant).

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
};

/// The statistics the adding scheme produces for one incident cosine.
struct BelcourStats {
    static constexpr int kMaxLobes = 8;
    struct Lobe {
        Rgbd energy{0.0};
        double alpha = 0;
    };
    std::array<Lobe, kMaxLobes> lobes{};
    int n_lobes = 0;
    /// Energy leaving through the bottom (after the last dielectric), its roughness and the mean
    /// cosine of its direction in the exit medium; valid when `transmits`.
    Rgbd transmitted{0.0};
    double alpha_t = 0;
    double cos_t = 1;
    bool transmits = false;
};

/// One operator of the stack, top to bottom: an interface or a medium.
struct BelcourOperator {
    enum Kind { Dielectric, Conductor, Medium } kind = Dielectric;
    double n12 = 1;    ///< relative index (conductor: mean of η over RGB)
    Rgbd eta{1.0};     ///< conductor: relative η per channel (dielectric: n12)
    Rgbd k{0.0};       ///< conductor: relative κ per channel
    double alpha = 0;  ///< GGX roughness of an interface
    Rgbd tau_a{0.0}, tau_s{0.0};
    double g = 0;  ///< HG mean cosine (mean over RGB)

    /// Angle-independent variances, filled by precompute_variances (pow is the cost of the
    /// symmetric variant, which runs the scheme per evaluation); unused unless `precomputed`.
    bool precomputed = false;
    bool precomputed_quadratic = false;
    double sigma_r = 0, sigma_t12 = 0, sigma_t21 = 0, alpha_clamped = 0;
    std::array<FgdTable::Index, 3> fgd_index{};  ///< per channel (dielectric: all equal)
};

/// Fills the angle-independent variances of every operator for the given mapping.
void precompute_variances(std::vector<BelcourOperator>& ops, bool quadratic_mapping);

/// Runs the adding scheme (docs/models.md) for mean incident cosine c0 ∈ (0, 1].
BelcourStats belcour_adding(const std::vector<BelcourOperator>& ops, double c0,
                            const BelcourChoices& choices);

/// The flags of the engine (the variant-fixed choices, exact_top and btdf, are not flags).
const ModelOptionTable<BelcourChoices>& belcour_option_table();
/// The defaults of a variant: "bel18-forward", "bel18-symmetric" or "bel-prime" (a programming
/// error otherwise).
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

/// A member of the family with `choices`; `name` appears in support reasons.
std::unique_ptr<Model> make_belcour_model(const std::string& name, const Stack& stack,
                                          const BelcourChoices& choices);

}  // namespace lamina

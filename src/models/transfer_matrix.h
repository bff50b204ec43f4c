#pragma once
// Transfer-matrix layering: Randrianandrasana, Callet & Lucas 2021, "Transfer matrix based
// layered materials rendering", ACM TOG 40(4), and its public code (laurent-lu/TMbLM-Rendering,
// plugins tm2 and tm2_dielectric, read to understand them; this is lamina's own code). One model,
// `tm2`: over a conductor base it is the plugin tm2, over a dielectric base (a slab)
// tm2_dielectric.
//
// Like Belcour 2018, the BRDF is a sum of GGX lobes, one per interface, plus (for a slab) one
// transmitted lobe. Each lobe is described by its energy (RGB) and a Henyey–Greenstein asymmetry
// g instead of a variance. Every component (interface, medium) is a 2×2 transfer matrix built from
// its four transfer factors (downward r, t; upward r′, t′):
//
//     M = (1/t) [[1, −r′], [r, t t′ − r r′]],
//
// the stack is the product M_0 M_1 … (top first), its reflectance R = M21/M11 and transmittance
// T = 1/M11; over an opaque base of reflectance r_b, R = (M21 + M22 r_b)/(M11 + M12 r_b). The same
// algebra applied to the g-weighted factors (g·energy, energies averaged over RGB) gives the
// g-weighted reflectance; lobe i is the reflectance gained by adding component i (its energy, and
// its g as the gain of the weighted reflectance over the gain of energy). docs/models.md has the
// derivation and lamina's choices.
//
// GGX ↔ HG: the released code's fitted mapping g(α) = −0.085 + 1.085/(1 + (α/0.5)^1.3), clamped to
// [0, 1], and its inverse (clamped to α ∈ [1e−4, 1], g ≥ 0.2); refraction of an HG lobe,
// g′ = √(1 − (1 − g²) η^0.75); a rough transmission has the asymmetry of a GGX lobe of roughness
// ½ s α with s = |1 − η_i μ_i/(η_t μ_t)| (down) or |1 − η_t μ_t/(η_i μ_i)| (up).

#include "models/fgd_table.h"
#include "models/model.h"

#include <array>
#include <string>
#include <vector>

namespace lamina {

/// HG asymmetry of a GGX lobe of roughness α (released TM code, tm.h hg_from_ggx); exactly 1 for
/// a smooth interface.
double tm_hg_from_ggx(double alpha);
/// GGX roughness of an HG lobe of asymmetry g (tm.h hg_to_ggx): the inverse of tm_hg_from_ggx for
/// g ∈ [0.2, 1), clamped to α ∈ [1e−4, 1].
double tm_ggx_from_hg(double g);
/// Asymmetry of an HG lobe after refraction into relative index eta (tm.h hg_refract).
double tm_hg_refract(double g, double eta);

/// The ambiguous or quirky choices of the released code, each a flag (docs/models.md).
struct TmChoices {
    /// The `top` flag: lobe 0 as released (exact over a conductor base, as the plugin tm2 does;
    /// from the matrices for a slab, as tm2_dielectric does), always exact, or always the
    /// matrices' FGD-weighted lobe. The model resolves it into exact_top.
    enum class Top { Released, Exact, Lobe } top = Top::Released;
    /// Lobe 0 replaced by the exact reflection of the top interface (the released tm2's
    /// "[Bati2019] top reflection correction", i.e. Bel').
    bool exact_top = true;
    /// A slab (dielectric base): the transmitted lobe (the released tm2_dielectric). Set by the
    /// model from its stack.
    bool slab = false;
    /// Upward factors r′, t′: the released code's r′ = r at the same (incident) cosine (false) or
    /// a proper upward FGD, r′ = FGD(μt, α, 1/η) at the refracted cosine (true; this FGD already
    /// holds the microfacets' total internal reflection, so the TIR step below is skipped there).
    bool upward_fgd = false;
    /// The TIR table steps of the released code (energy moved from transmission to reflection).
    bool tir = true;
    /// The asymmetry matrices weighted per channel, one g (and GGX roughness) per channel and lobe
    /// (true), or with the released RGB-mean weights, one g per lobe (false).
    bool per_channel_g = false;
};

/// One component of the stack, top to bottom.
struct TmComponent {
    enum Kind { Dielectric, Conductor, Medium } kind = Dielectric;
    double eta = 1;     ///< dielectric: relative index below/above
    Rgbd eta_rgb{1.0};  ///< conductor: relative complex index
    Rgbd k{0.0};
    double alpha = 0;  ///< GGX roughness of an interface
    Rgbd tau_a{0.0};   ///< medium: absorption optical depth (normal)
    std::array<FgdTable::Index, 3> fgd_index{};
};

/// The lobes for one incident cosine.
struct TmLobes {
    static constexpr int kMaxLobes = 8;
    struct Lobe {
        Rgbd energy{0.0};
        double g = 0;
        double alpha = 0;     ///< tm_ggx_from_hg(g)
        Rgbd alpha_rgb{0.0};  ///< per channel (all equal to alpha unless per_channel_g)
        bool delta = false;   ///< g = 1: every interface on its way is smooth
        /// The component the lobe reflects from (0: the stack's top interface; an index-matched
        /// interface is no component and has no lobe).
        int component = 0;
    };
    std::array<Lobe, kMaxLobes> lobes{};
    int n_lobes = 0;
    /// The transmitted lobe (slab): energy, asymmetry, and the cosine of the mean direction in
    /// the exit medium.
    Lobe transmitted;
    double cos_t = 1;
    bool transmits = false;
};

/// Runs the 2×2 transfer-matrix scheme for incident cosine c0 ∈ (0, 1].
TmLobes tm_lobes(const std::vector<TmComponent>& components, double c0, const TmChoices& choices);

/// The flags of the transfer-matrix model, with the released defaults.
std::vector<OptionSpec> tm_option_specs();
/// Choices named by validated options.
TmChoices tm_choices(const ModelOptions& options);

std::unique_ptr<Model> make_tm_model(std::string model_name, const Stack& stack,
                                     const TmChoices& choices);

}  // namespace lamina

#pragma once
// Transfer-matrix layering: Randrianandrasana, Callet & Lucas 2021, "Transfer matrix based
// layered materials rendering", ACM TOG 40(4), and its public code (laurent-lu/TMbLM-Rendering,
// plugins tm2, tm2_dielectric and tm6, read to understand them; this is lamina's own code). Two
// models: `tm2` (over a conductor base the plugin tm2, over a dielectric base — a slab —
// tm2_dielectric) and `tm6` (the plugin tm6: Henyey–Greenstein media that scatter, over a
// conductor base).
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
// Six fluxes (tm6): light scattered in a medium is tracked apart from the unscattered (primary)
// light, in two direction families: "forward" (about the primary's directions: down along the
// refracted wi, up along its mirror) and "backward" (the azimuth turned by π: up towards wi
// itself). A medium is a two-stream slab (forward-scattered light stays in its family,
// back-scattered light changes direction and family) acting on each family's total flux; the
// primary flux is the unscattered part of the forward family. With the state (primary, forward,
// backward), each a (down, up) pair, a component's 6×6 matrix is block lower-triangular,
//
//     [[P, 0, 0], [A, S, X], [B, X, S]]   (2×2 blocks; S, X the same in both families),
//
// an interface P = its primary 2×2 matrix, S = its secondary one, A = B = X = 0; a medium with
// unscattered transmittance t and two-stream matrix N = (1/t_s)[[1, −r_s], [r_s, t_s² − r_s²]]:
// P = diag(1/t, t), S = N's diagonal, X = N's off-diagonal, A = S − P, B = X. Three reflectances
// (primary, forward, backward) come out, hence three lobes per component; the backward lobe is
// the GGX lobe of the incidence (−wi.x, −wi.y, wi.z), whose mirror is wi (retro-reflection).
//
// GGX ↔ HG: the released code's fitted mapping g(α) = −0.085 + 1.085/(1 + (α/0.5)^1.3), clamped to
// [0, 1], and its inverse (clamped to α ∈ [1e−4, 1], g ≥ 0.2); refraction of an HG lobe,
// g′ = √(1 − (1 − g²) η^0.75); a rough transmission has the asymmetry of a GGX lobe of roughness
// ½ s α with s = |1 − η_i μ_i/(η_t μ_t)| (down) or |1 − η_t μ_t/(η_i μ_i)| (up).

#include "models/model.h"
#include "models/model_options.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"

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

/// The fraction of Henyey–Greenstein scattering (asymmetry g ∈ (−1, 1)) that goes backwards (into
/// the hemisphere opposite to the propagation direction): the released tm6's fitted quadratic
/// (tm.h hg_lh_norm: 0.5039 − 0.8254|g| + 0.3226 g², clamped to [0, 0.5], mirrored for g < 0) ...
double tm_backscatter_fit(double g);
/// ... or the exact one, B(g) = (1 − g²)/(2g) (1/√(1 + g²) − 1/(1 + g)) (B(0) = ½), the HG
/// cumulative distribution of cos θ at 0 (Henyey & Greenstein 1941, Eq. 3 integrated).
double tm_backscatter_exact(double g);

/// Reflectance and transmittance of a two-stream slab: fluxes D (down), U (up) along the path s,
/// dD/ds = −a D + b U, dU/ds = a U − b D, over a unit path (a, b the per-path coefficients: a the
/// rate at which a stream loses flux, b the rate at which it feeds the other), D(0) = 1, U(1) = 0:
/// with γ = √(a² − b²), r = b sinh γ / (γ cosh γ + a sinh γ), t = γ / (γ cosh γ + a sinh γ)
/// (Kubelka & Munk 1931's closed form; γ → 0 taken as its limit, r = b/(1 + a), t = 1/(1 + a)).
/// a ≥ |b| ≥ 0 per channel.
struct TmTwoStream {
    Rgbd r{0.0}, t{1.0};
};
TmTwoStream tm_two_stream(const Rgbd& a, const Rgbd& b);

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
    /// What their fraction holds (tir_table.h): the released table is the Lobe definition's
    /// complement (the part of the light's GGX lobe a flat interface reflects totally).
    TirDefinition tir_table = TirDefinition::Lobe;
    /// The asymmetry matrices weighted per channel, one g (and GGX roughness) per channel and lobe
    /// (true), or with the released RGB-mean weights, one g per lobe (false).
    bool per_channel_g = false;
    /// The released tm6's asymmetry: matrices weighted per channel, one g per lobe as the channel
    /// mean of the per-channel ratios (a channel below 1e−7 counting as g = 0). Ignored with
    /// per_channel_g.
    bool ratio_mean_g = false;
    /// The model accepts scattering media (tm6); set by the model.
    bool scattering = false;
    /// Six fluxes (the stack has a scattering medium); set by the model from its stack.
    bool six_flux = false;
    /// Every lobe from the matrices divided by its GGX albedo E(μi, α) (fgd_table.h), so that it
    /// reflects exactly its energy (the released tm6), or not (the released tm2).
    bool albedo_normalized = false;
    /// A medium's back-scattered fraction of HG: the released fit (true) or the exact one.
    bool backscatter_fit = true;
};

/// One component of the stack, top to bottom.
struct TmComponent {
    enum Kind { Dielectric, Conductor, Medium } kind = Dielectric;
    double eta = 1;     ///< dielectric: relative index below/above
    Rgbd eta_rgb{1.0};  ///< conductor: relative complex index
    Rgbd k{0.0};
    double alpha = 0;  ///< GGX roughness of an interface
    Rgbd tau_a{0.0};   ///< medium: absorption optical depth (normal)
    Rgbd tau_s{0.0};   ///< medium: scattering optical depth (normal)
    Rgbd g{0.0};       ///< medium: HG asymmetry
    std::array<FgdTable::Index, 3> fgd_index{};
    /// Per-stack constants the model fills in once (negative: computed per call): an interface's
    /// reflection asymmetry g(α) and a dielectric's η^0.75.
    double g_reflect = -1, eta_pow = -1;
};

/// The lobes for one incident cosine.
struct TmLobes {
    static constexpr int kMaxLobes = 16;
    /// Which flux a lobe is made of (six fluxes; with two, every lobe is Primary).
    enum Family { Primary, Forward, Backward };
    struct Lobe {
        Rgbd energy{0.0};
        double g = 0;
        double alpha = 0;     ///< tm_ggx_from_hg(g)
        Rgbd alpha_rgb{0.0};  ///< per channel (all equal to alpha unless per_channel_g)
        bool delta = false;   ///< g = 1: every interface on its way is smooth
        /// The component the lobe reflects from (0: the stack's top interface; an index-matched
        /// interface is no component and has no lobe).
        int component = 0;
        /// Backward: the lobe is evaluated at the incidence (−wi.x, −wi.y, wi.z).
        Family family = Primary;
        /// What multiplies the GGX lobe shape: the energy, or with albedo_normalized the energy
        /// over the shape's albedo E(μi, α) (per channel with per_channel_g).
        Rgbd scale{0.0};
    };
    std::array<Lobe, kMaxLobes> lobes{};
    int n_lobes = 0;
    /// The transmitted lobe (slab): energy, asymmetry, and the cosine of the mean direction in
    /// the exit medium.
    Lobe transmitted;
    double cos_t = 1;
    bool transmits = false;
};

/// Runs the transfer-matrix scheme (2×2, or six fluxes with choices.six_flux) for incident cosine
/// c0 ∈ (0, 1].
TmLobes tm_lobes(const std::vector<TmComponent>& components, double c0, const TmChoices& choices);

/// The most lobes a stack gives (0 where it exceeds TmLobes::kMaxLobes: not supported).
int tm_lobe_count(const std::vector<TmComponent>& components, bool six_flux);

/// The defaults of a variant: "tm2" or "tm6" (a programming error otherwise).
TmChoices tm_variant(const std::string& variant);
/// The flags of a variant: tm2's, or tm6's (its media scatter, and its released code normalizes
/// lobes and fits the back-scattering).
const ModelOptionTable<TmChoices>& tm_option_table(const std::string& variant);
/// A member of the family with `choices`; `name` appears in support reasons.
std::unique_ptr<Model> make_tm_model(const std::string& name, const Stack& stack,
                                     const TmChoices& choices);

}  // namespace lamina

#include "models/transfer_matrix/transfer_matrix.h"

#include "core/math.h"
#include "models/belcour/belcour.h"
#include "models/tables/tir_table.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina {

double tm_hg_from_ggx(double alpha) {
    if (alpha <= 0) return 1.0;
    const double a = std::min(alpha, 1.0);
    return clamp(-0.085 + 1.085 / (1 + std::pow(a / 0.5, 1.3)), 0.0, 1.0);
}

namespace {

double ggx_from_hg_unclamped_g(double gc) {
    return clamp(0.5 * std::pow(1.085 / (gc + 0.085) - 1, 1 / 1.3), 1e-4, 1.0);
}

/// g′ = √(1 − (1 − g²) η^0.75) with η^0.75 given (one pow per interface, not per call).
double hg_refract_pow(double g, double eta_pow) {
    return std::min(safe_sqrt(1 - (1 - g * g) * eta_pow), 1.0);
}

}  // namespace

double tm_ggx_from_hg(double g) {
    // g ≤ 0.2 (most scattered lobes) is one value: computed once.
    static const double alpha_at_floor = ggx_from_hg_unclamped_g(0.2);
    if (!(g > 0.2)) return alpha_at_floor;
    return ggx_from_hg_unclamped_g(std::min(g, 1.0));
}

double tm_hg_refract(double g, double eta) {
    return hg_refract_pow(g, std::pow(eta, 0.75));
}

double tm_backscatter_fit(double g) {
    const double a = std::abs(g);
    const double n = clamp(0.5039 - 0.8254 * a + 0.3226 * a * a, 0.0, 0.5);
    return g < 0 ? 1 - n : n;
}

double tm_backscatter_exact(double g) {
    if (std::abs(g) < 1e-6) return 0.5 - 0.375 * g;  // the series B = ½ − (3/8) g + O(g³)
    return (1 - g * g) / (2 * g) * (1 / std::sqrt(1 + g * g) - 1 / (1 + g));
}

TmTwoStream tm_two_stream(const Rgbd& a, const Rgbd& b) {
    TmTwoStream out;
    for (int c = 0; c < 3; ++c) {
        const double gamma = safe_sqrt(a[c] * a[c] - b[c] * b[c]);
        // sinh γ and cosh γ from one expm1 (m = e^γ − 1: sinh = m (m + 2) / (2 (m + 1)), exact to
        // rounding for small γ); sinh(γ)/γ → 1 as γ → 0 (a lossless scatterer: γ = 0 exactly).
        const double m = std::expm1(gamma);
        const double sinh_g = m * (m + 2) / (2 * (m + 1));
        const double cosh_g = sinh_g + 1 / (m + 1);
        const double sinhc = gamma > 1e-8 ? sinh_g / gamma : 1.0;
        const double den = cosh_g + a[c] * sinhc;
        out.t[c] = 1 / den;
        out.r[c] = b[c] * sinhc / den;
    }
    return out;
}

namespace {

/// Optical paths are clamped as in the released code (TM_EXP_ARG_MAX): 1/T stays finite.
constexpr double kMaxOpticalPath = 45;
/// Below this a transmission factor is treated as zero (the matrix needs 1/t).
constexpr double kTinyT = 1e-12;

Rgbd max_of(const Rgbd& a, const Rgbd& b) {
    return {std::max(a[0], b[0]), std::max(a[1], b[1]), std::max(a[2], b[2])};
}

/// A cumulative reflectance (or transmittance) of a passive stack, per channel in [floor, 1]:
/// where the transfer matrices lose their precision (a transmission near kTinyT, when the mean
/// direction meets an interface just short of total reflection) their products can give any
/// value, 10⁷ or ∞ − ∞ (fuzz seed 1213, a coat whose refracted grazing light meets a lower
/// interface at its critical angle). A value that is not finite keeps `floor`: the light went
/// where the components above sent it.
Rgbd passive_fraction(const Rgbd& x, const Rgbd& floor) {
    Rgbd out;
    for (int c = 0; c < 3; ++c)
        out[c] =
            std::isfinite(x[c]) ? std::clamp(x[c], floor[c], std::max(floor[c], 1.0)) : floor[c];
    return out;
}

/// The g-weighted part of the same: a value that is not finite keeps `floor` (the value above).
/// Finite values pass: set_asymmetry caps the ratio g at 1, and a g at or below 0.2 takes the
/// roughness floor.
Rgbd weighted_fraction(const Rgbd& x, const Rgbd& floor) {
    Rgbd out;
    for (int c = 0; c < 3; ++c)
        out[c] = std::isfinite(x[c]) ? x[c] : floor[c];
    return out;
}

Rgbd max_rgb(const Rgbd& x, double lo) {
    return {std::max(x[0], lo), std::max(x[1], lo), std::max(x[2], lo)};
}

/// A 2×2 transfer matrix with entries of type T (Rgbd).
template <typename T>
struct Matrix2 {
    T m11, m12, m21, m22;
    static Matrix2 identity() { return {T(1.0), T(0.0), T(0.0), T(1.0)}; }
    static Matrix2 zero() { return {T(0.0), T(0.0), T(0.0), T(0.0)}; }
    /// The matrix of a component with downward (r, t) and upward (rp, tp) factors
    /// (Randrianandrasana et al. 2021; tm.h energy_matrix).
    static Matrix2 component(const T& r, const T& t, const T& rp, const T& tp) {
        const T t_inv = T(1.0) / t;
        return {t_inv, T(0.0) - rp * t_inv, r * t_inv, (t * tp - r * rp) * t_inv};
    }
    Matrix2 operator*(const Matrix2& b) const {
        return {m11 * b.m11 + m12 * b.m21, m11 * b.m12 + m12 * b.m22, m21 * b.m11 + m22 * b.m21,
                m21 * b.m12 + m22 * b.m22};
    }
    Matrix2 operator+(const Matrix2& b) const {
        return {m11 + b.m11, m12 + b.m12, m21 + b.m21, m22 + b.m22};
    }
    Matrix2 operator-(const Matrix2& b) const {
        return {m11 - b.m11, m12 - b.m12, m21 - b.m21, m22 - b.m22};
    }
    Matrix2 diagonal() const { return {m11, T(0.0), T(0.0), m22}; }
    Matrix2 off_diagonal() const { return {T(0.0), m12, m21, T(0.0)}; }
    /// The down and up fluxes above for (1, ρ) below: row sums against (1, ρ).
    T down_over(const T& rho) const { return m11 + m12 * rho; }
    T up_over(const T& rho) const { return m21 + m22 * rho; }
    T transmittance() const { return T(1.0) / m11; }
    /// Reflectance over an opaque base of reflectance rb (rb = 0: nothing below); the
    /// denominator m11 (1 − r′ r_b) is kept ≥ 1e−9 m11, as Belcour's adding keeps 1 − R R ≥ 1e−9
    /// (two perfect mirrors facing).
    T reflectance_over(const T& rb) const {
        return up_over(rb) / max_of(down_over(rb), m11 * 1e-9);
    }
};

/// The six-flux matrix [[P, 0, 0], [A, S, X], [B, X, S]] of transfer_matrix.h: state (primary,
/// forward, backward), each (down, up); the backward family's blocks equal the forward one's
/// with the families swapped, which every product keeps.
template <typename T>
struct Matrix6 {
    Matrix2<T> P, A, B, S, X;
    /// False while A = B = X = 0 (an interface, or a stack without a medium yet): the product
    /// then skips the zero blocks.
    bool coupled = false;
    static Matrix6 identity() {
        const auto z = Matrix2<T>::zero();
        return {Matrix2<T>::identity(), z, z, Matrix2<T>::identity(), z, false};
    }
    static Matrix6 interface(const Matrix2<T>& primary, const Matrix2<T>& secondary) {
        const auto z = Matrix2<T>::zero();
        return {primary, z, z, secondary, z, false};
    }
    /// A medium: unscattered block `primary`, two-stream matrix `total` acting on each family's
    /// total flux (the primary flux counting in the forward family's).
    static Matrix6 medium(const Matrix2<T>& primary, const Matrix2<T>& total) {
        const Matrix2<T> same = total.diagonal(), swapped = total.off_diagonal();
        return {primary, same - primary, swapped, same, swapped, true};
    }
    Matrix6 operator*(const Matrix6& n) const {
        if (!n.coupled)  // n.A = n.B = n.X = 0
            return {P * n.P, A * n.P, B * n.P, S * n.S, X * n.S, coupled};
        if (!coupled)  // A = B = X = 0
            return {P * n.P, S * n.A, S * n.B, S * n.S, S * n.X, true};
        return {P * n.P,           A * n.P + S * n.A + X * n.B, B * n.P + X * n.A + S * n.B,
                S * n.S + X * n.X, S * n.X + X * n.S,           true};
    }
    /// Primary, forward and backward reflectances for unit primary flux down on top, none
    /// scattered, and an opaque base reflecting every family with rb (0: nothing below): the
    /// down fluxes below (x, y, z) solve 1 = P(x), 0 = A(x) + S(y) + X(z), 0 = B(x) + X(y) + S(z).
    std::array<T, 3> reflectances_over(const T& rb) const {
        const T x = T(1.0) / max_of(P.down_over(rb), P.m11 * 1e-9);
        const T a = S.down_over(rb), b = X.down_over(rb);
        const T pa = A.down_over(rb) * x, pb = B.down_over(rb) * x;
        // Kept ≥ 1e-9 a² and, where a itself vanishes (a lossless stack over a perfect mirror:
        // S's down flux over rb = 1 cancels), ≥ (1e-9 S.m11)², the two-flux guard squared.
        const T det_inv =
            T(1.0) / max_of(max_of(a * a - b * b, a * a * 1e-9), S.m11 * S.m11 * 1e-18);
        const T y = (b * pb - a * pa) * det_inv, z = (b * pa - a * pb) * det_inv;
        return {P.up_over(rb) * x, A.up_over(rb) * x + S.up_over(rb) * y + X.up_over(rb) * z,
                B.up_over(rb) * x + X.up_over(rb) * y + S.up_over(rb) * z};
    }
};

/// One flux's transfer factors through a component, with their asymmetries.
struct FluxFactors {
    Rgbd r{0.0}, t{1.0}, rp{0.0}, tp{1.0};
    double gr = 0, gt = 1, grp = 0, gtp = 1;
};

/// The transfer factors of one component at the mean direction of the light reaching it: of the
/// primary flux and (six fluxes) of the light scattered in a medium above.
struct Factors {
    FluxFactors p, s;
    double c_above = 1, c_below = 1;
    bool opaque = false;  ///< conductor, or a dielectric that reflects the mean direction totally
};

Matrix2<Rgbd> energy_matrix(const FluxFactors& x) {
    return Matrix2<Rgbd>::component(x.r, x.t, x.rp, x.tp);
}

/// The matrix of the g-weighted factors (weight: RGB mean or per channel).
template <typename Weight>
Matrix2<Rgbd> asymmetry_matrix(const FluxFactors& x, const Weight& weight) {
    return Matrix2<Rgbd>::component(weight(x.r) * x.gr, max_rgb(weight(x.t) * x.gt, kTinyT),
                                    weight(x.rp) * x.grp, weight(x.tp) * x.gtp);
}

/// A lobe's asymmetry from its g-weighted energy: g = weighted/energy (≤ 1), RGB means for the
/// released tm2 scheme (one g per lobe), the mean of the channels' ratios (released tm6), or per
/// channel; α = α(g).
void set_asymmetry(TmLobes::Lobe& lobe, const Rgbd& weighted, const TmChoices& ch) {
    const auto ratio = [](double w, double e) { return e > 0 ? std::min(w / e, 1.0) : 0.0; };
    if (!ch.per_channel_g) {
        if (ch.ratio_mean_g) {
            double sum = 0;
            for (int c = 0; c < 3; ++c)
                sum += std::abs(lobe.energy[c]) > 1e-7 ? ratio(weighted[c], lobe.energy[c]) : 0.0;
            lobe.g = sum / 3;
        } else {
            lobe.g = ratio(weighted.mean(), lobe.energy.mean());
        }
        lobe.alpha = tm_ggx_from_hg(lobe.g);
        lobe.alpha_rgb = Rgbd(lobe.alpha);
        return;
    }
    for (int c = 0; c < 3; ++c)
        lobe.alpha_rgb[c] = tm_ggx_from_hg(ratio(weighted[c], lobe.energy[c]));
    lobe.g = ratio(weighted.mean(), lobe.energy.mean());
    lobe.alpha = tm_ggx_from_hg(lobe.g);
}

/// The mean over the channels of num/den, a channel with den ≤ 1e−7 counting 0 (tm.h safe_div
/// then average: the released medium asymmetries).
double channel_mean_ratio(const Rgbd& num, const Rgbd& den) {
    double sum = 0;
    for (int c = 0; c < 3; ++c)
        sum += std::abs(den[c]) > 1e-7 ? num[c] / den[c] : 0.0;
    return sum / 3;
}

/// A homogeneous medium along the mean direction of cosine c (tm.h medium_transfer_factors as
/// lamina reads it): the unscattered flux exp(−τt/c) (g = 1); the scattered light a two-stream
/// slab in which the HG phase function's back-scattered fraction b reverses direction (and
/// family) and the rest goes on: per path, a = τa + b τs, b_s = b τs. Its asymmetries follow the
/// same slab with the g-weighted coefficients (a forward scattering multiplies g by g, a backward
/// one by −g: a_g = τt − (1 − b) τs g, b_g = −b τs g), as channel means of ratios.
void medium_factors(const TmComponent& k, double c, const TmChoices& ch, Factors& x) {
    Rgbd path, back, a, bs, ag, bg;
    for (int i = 0; i < 3; ++i) {
        const double tau_t = k.tau_a[i] + k.tau_s[i];
        // The path clamped per channel at an optical path of 45 (the released clamp).
        path[i] = tau_t > 0 ? std::min(1 / c, kMaxOpticalPath / tau_t) : 1 / c;
        back[i] = ch.backscatter_fit ? tm_backscatter_fit(k.g[i]) : tm_backscatter_exact(k.g[i]);
        a[i] = (k.tau_a[i] + back[i] * k.tau_s[i]) * path[i];
        bs[i] = back[i] * k.tau_s[i] * path[i];
        ag[i] = (tau_t - (1 - back[i]) * k.tau_s[i] * k.g[i]) * path[i];
        bg[i] = -back[i] * k.tau_s[i] * k.g[i] * path[i];
        x.p.t[i] = x.p.tp[i] = std::exp(-tau_t * path[i]);
    }
    x.p.r = x.p.rp = Rgbd(0.0);
    x.p.gr = x.p.grp = 0;
    x.p.gt = x.p.gtp = 1;
    const TmTwoStream e = tm_two_stream(a, bs);
    const TmTwoStream w = tm_two_stream(ag, bg);
    x.s.r = x.s.rp = e.r;
    x.s.t = x.s.tp = e.t;
    x.s.gr = x.s.grp = channel_mean_ratio(w.r, e.r);
    x.s.gt = x.s.gtp = channel_mean_ratio(w.t, e.t);
    x.c_above = x.c_below = c;
}

/// The first-order asymmetries of one dielectric interface's transmissions and its TIR steps,
/// for a flux arriving with asymmetry g_down and coming back (after the next interface's
/// reflection, and the medium between, both ways) with g_back before refraction up
/// (tm2.cpp/tm6.cpp outgoing_lobes); eta_pow = η^0.75. Returns the asymmetry transmitted down.
double first_order(const TmComponent& k, double eta_pow, FluxFactors& x, double c_above,
                   double c_below, double g_down, double g_next, double g_between,
                   const TmChoices& ch) {
    const double g_T_next = hg_refract_pow(g_down, 1 / eta_pow) * x.gt;
    const double g_TR = g_T_next * g_between * g_next * g_between;
    const double g_TRT = hg_refract_pow(g_TR, eta_pow) * x.gtp;
    x.gt = g_down != 0 ? g_T_next / g_down : 0.0;
    x.gtp = g_TR != 0 ? g_TRT / g_TR : 0.0;
    if (ch.tir) {
        auto tir = [&](double c, double alpha, double eta) {
            return tir_fraction(ch.tir_table, c, alpha, eta);
        };
        if (k.eta < 1) {
            // Downward TIR (into a lower index), at the roughness of the arriving light.
            const double a = g_down >= 1 ? 0.0 : tm_ggx_from_hg(g_down);
            const Rgbd moved = x.t * (1 - tir(c_above, a, k.eta));
            x.r += moved;
            x.t = x.t - moved;
        } else if (!ch.upward_fgd) {
            // Upward TIR of the light coming back from below.
            const double a = g_TR >= 1 ? 0.0 : tm_ggx_from_hg(g_TR);
            const Rgbd moved = x.tp * (1 - tir(c_below, a, 1 / k.eta));
            x.rp += moved;
            x.tp = x.tp - moved;
        }
    }
    for (int c = 0; c < 3; ++c) {
        x.t[c] = std::max(x.t[c], kTinyT);
        x.tp[c] = std::max(x.tp[c], 0.0);
    }
    return g_T_next;
}

/// The transfer factors of the dielectric interface k for light arriving at cosine c (tm.h
/// dielectric_transfer_factors): FGD energies, the asymmetries of the reflections (g_r) and of
/// the rough transmissions; x.opaque where the mean direction is totally reflected. Returns the
/// cosine below.
double dielectric_factors(const TmComponent& k, double c, double g_r, const TmChoices& ch,
                          Factors& x) {
    const FgdTable& fgd = FgdTable::get();
    x.p.gr = x.p.grp = g_r;
    x.c_above = c;
    const double r = std::abs(k.eta - 1) < 1e-3 ? 0.0 : fgd(c, k.alpha, k.fgd_index[0]);
    x.p.r = x.p.rp = Rgbd(r);
    const double sin2_t = (1 - c * c) / sqr(k.eta);
    if (sin2_t >= 1) {  // the mean direction is totally reflected: nothing goes on
        x.opaque = true;
        x.s = x.p;
        return c;
    }
    const double ct = std::max(std::sqrt(1 - sin2_t), 1e-6);
    // Rough transmission as a GGX lobe of roughness ½ s α (tm.h: "fake rough transmissions
    // scaling factors"), s from the mean directions above and below.
    const double s_down = std::abs(c / (k.eta * ct) - 1);
    const double s_up = std::abs(1 - k.eta * ct / c);
    x.p.gt = tm_hg_from_ggx(0.5 * s_down * k.alpha);
    x.p.gtp = tm_hg_from_ggx(0.5 * s_up * k.alpha);
    if (ch.upward_fgd) x.p.rp = Rgbd(fgd(ct, k.alpha, 1 / k.eta, 0.0));
    x.p.t = Rgbd(1.0) - x.p.r;
    x.p.tp = Rgbd(1.0) - x.p.rp;
    x.s = x.p;  // the scattered flux meets the same interface (its g chain differs)
    x.c_below = ct;
    return ct;
}

/// An absorbing layer (two fluxes): r = r′ = 0, t = t′ = exp(−τa/μ) along the mean direction, its
/// asymmetry unchanged (g = 1, the primary-flux block of the released tm6 medium).
void absorbing_factors(const TmComponent& k, double c, Factors& x) {
    const Rgbd path = k.tau_a * (1 / c);
    for (int i = 0; i < 3; ++i)
        x.p.t[i] = x.p.tp[i] = std::exp(-std::min(path[i], kMaxOpticalPath));
    x.c_above = x.c_below = c;
}

bool index_matched(const TmComponent& k) {
    return k.kind == TmComponent::Dielectric && std::abs(k.eta - 1) < 1e-5;
}

// Kept in one piece (about 170 lines): it is the released code's scheme, one pass over the
// components with the cumulative matrices, the TIR steps and the lobes in the order that code
// forms them, and reads best side by side with it (docs/models.md, "Transfer matrices").
template <bool kSix>
TmLobes run_scheme(const std::vector<TmComponent>& comps, double c0, const TmChoices& ch) {
    TmLobes out;
    const int n = int(comps.size());
    // The reflections' asymmetries g(α) of every interface (the first-order chain looks one
    // interface ahead).
    std::array<double, 2 * TmLobes::kMaxLobes> g_r{};
    for (int i = 0; i < n; ++i)
        if (comps[i].kind != TmComponent::Medium)
            g_r[i] = comps[i].g_reflect >= 0 ? comps[i].g_reflect : tm_hg_from_ggx(comps[i].alpha);

    // One pass, top to bottom: each component's transfer factors along the refracted mean
    // direction (tm.h *_transfer_factors), its first-order asymmetries and TIR, the matrix
    // products and the lobes it adds (tm2.cpp / tm2_dielectric.cpp / tm6.cpp outgoing_lobes).
    using M = std::conditional_t<kSix, Matrix6<Rgbd>, Matrix2<Rgbd>>;
    constexpr int kFamilies = kSix ? 3 : 1;
    M E = M::identity();
    M G = M::identity();
    std::array<Rgbd, kFamilies> e_above, g_above;
    e_above.fill(Rgbd(0.0));
    g_above.fill(Rgbd(0.0));
    // The weights of the asymmetry matrices: the released tm2's RGB means, or each channel's own.
    const bool mean_weights = !ch.per_channel_g && !ch.ratio_mean_g;
    const auto weight = [&](const Rgbd& x) { return mean_weights ? Rgbd(x.mean()) : x; };
    double c = std::max(c0, 1e-6);
    double g_T = 1;   // asymmetry of the primary light transmitted down to the current component
    double g_sT = 1;  // the same for the scattered light (six fluxes)
    bool smooth = true;
    bool opaque_end = false;
    Factors medium_below;  // six fluxes: the medium under an interface, computed there
    bool have_medium_below = false;
    // Two fluxes: the product of the downward transmissions along the mean path. Once it is below
    // kTinyT in every channel the components deeper down return less than kTinyT² of the light,
    // and the matrices, which divide by these transmissions, would only add rounding noise of any
    // size (fuzz seed 1213: a medium of optical depth 60 seen at grazing, a lobe of energy 1.8e7):
    // the stack ends there, as at an opaque component. (Six fluxes: the scattered light is not
    // bounded by the primary transmission, so the scheme goes on.)
    Rgbd t_down(1.0);
    for (int i = 0; i < n; ++i) {
        const TmComponent& k = comps[i];
        if (index_matched(k)) continue;  // no component at all
        if (!kSix && t_down.max() < kTinyT) {
            opaque_end = true;
            break;
        }
        Factors x;
        std::array<Rgbd, kFamilies> R, Rg;
        double g_T_next = g_T, g_sT_next = g_sT;
        if (k.kind == TmComponent::Medium) {
            if constexpr (kSix) {
                if (have_medium_below)
                    x = medium_below;
                else
                    medium_factors(k, c, ch, x);
                have_medium_below = false;
                E = E * M::medium(energy_matrix(x.p), energy_matrix(x.s));
                G = G * M::medium(asymmetry_matrix(x.p, weight), asymmetry_matrix(x.s, weight));
                R = E.reflectances_over(Rgbd(0.0));
                Rg = G.reflectances_over(Rgbd(0.0));
            } else {
                absorbing_factors(k, c, x);
                t_down = t_down * x.p.t;
                E = E * energy_matrix(x.p);
                G = G * asymmetry_matrix(x.p, weight);
                continue;
            }
        } else if (k.kind == TmComponent::Dielectric) {
            c = dielectric_factors(k, c, g_r[i], ch, x);
        } else {
            x.p.r = FgdTable::get().rgb(c, k.alpha, k.fgd_index);
            x.p.gr = g_r[i];
            x.s = x.p;
            x.c_above = c;
            x.opaque = true;
        }
        if (k.kind == TmComponent::Medium) {
            // its lobes (six fluxes) below
        } else if (!x.opaque) {
            smooth = smooth && k.alpha <= 0;
            // The asymmetry of the light refracted down, reflected by the next interface (through
            // the medium between, the scattered light's only) and refracted back up, to first
            // order; the factors' g are the ratios of these.
            double g_next_r = 1.0;  // the slab's last interface: nothing below reflects
            for (int j = i + 1; j < n; ++j)
                if (!index_matched(comps[j]) && comps[j].kind != TmComponent::Medium) {
                    g_next_r = g_r[j];
                    break;
                }
            const double eta_pow = k.eta_pow >= 0 ? k.eta_pow : std::pow(k.eta, 0.75);
            g_T_next = first_order(k, eta_pow, x.p, x.c_above, x.c_below, g_T, g_next_r, 1.0, ch);
            if constexpr (kSix) {
                have_medium_below = i + 1 < n && comps[i + 1].kind == TmComponent::Medium;
                if (have_medium_below) medium_factors(comps[i + 1], c, ch, medium_below);
                const double g_between = have_medium_below ? medium_below.s.gt : 1.0;
                g_sT_next = first_order(k, eta_pow, x.s, x.c_above, x.c_below, g_sT, g_next_r,
                                        g_between, ch);
                E = E * M::interface(energy_matrix(x.p), energy_matrix(x.s));
                G = G * M::interface(asymmetry_matrix(x.p, weight), asymmetry_matrix(x.s, weight));
                R = E.reflectances_over(Rgbd(0.0));
                Rg = G.reflectances_over(Rgbd(0.0));
            } else {
                t_down = t_down * x.p.t;
                E = E * energy_matrix(x.p);
                G = G * asymmetry_matrix(x.p, weight);
                R[0] = E.reflectance_over(Rgbd(0.0));
                Rg[0] = G.reflectance_over(Rgbd(0.0));
            }
        } else {
            smooth = smooth && k.alpha <= 0;
            if constexpr (kSix) {
                R = E.reflectances_over(x.p.r);
                Rg = G.reflectances_over(weight(x.p.r) * x.p.gr);
            } else {
                R[0] = E.reflectance_over(x.p.r);
                Rg[0] = G.reflectance_over(weight(x.p.r) * x.p.gr);
            }
            opaque_end = true;
        }
        for (int fam = 0; fam < kFamilies; ++fam) {
            R[fam] = passive_fraction(R[fam], e_above[fam]);
            Rg[fam] = weighted_fraction(Rg[fam], g_above[fam]);
            // Clamped at 0 (as the released tm6 does): where a channel is absorbed the difference
            // is 0 up to rounding (≈ −1e−17 otherwise).
            const Rgbd energy = max_of(R[fam] - e_above[fam], Rgbd(0.0));
            const bool keep = fam == 0 ? k.kind != TmComponent::Medium : energy.max() > 0;
            if (keep && out.n_lobes < TmLobes::kMaxLobes) {
                TmLobes::Lobe& lobe = out.lobes[out.n_lobes++];
                lobe.energy = energy;
                set_asymmetry(lobe, Rg[fam] - g_above[fam], ch);
                lobe.delta = fam == 0 && smooth;
                lobe.component = i;
                lobe.family = TmLobes::Family(fam);
            }
            e_above[fam] = R[fam];
            g_above[fam] = Rg[fam];
        }
        g_T = g_T_next;
        g_sT = g_sT_next;
        if (x.opaque) break;
    }
    if constexpr (!kSix) {
        if (ch.slab && !opaque_end) {
            out.transmits = true;
            out.transmitted.energy = passive_fraction(E.transmittance(), Rgbd(0.0));
            set_asymmetry(out.transmitted, weighted_fraction(G.transmittance(), Rgbd(0.0)), ch);
            out.transmitted.delta = smooth;
            out.transmitted.scale = out.transmitted.energy;
            out.cos_t = c;
        }
    }
    // 3. What multiplies each lobe's shape (the released tm6: its energy over the shape's albedo
    //    at μi, tm6.cpp eval, "single-scattering albedo normalization").
    double last_alpha = -1, last_inv_albedo = 1;  // most scattered lobes share α = 1
    for (int l = 0; l < out.n_lobes; ++l) {
        TmLobes::Lobe& lobe = out.lobes[l];
        lobe.scale = lobe.energy;
        if (!ch.albedo_normalized || lobe.delta) continue;
        const GgxAlbedoTable& albedo = GgxAlbedoTable::get();
        if (!ch.per_channel_g) {
            if (lobe.alpha != last_alpha) {
                last_alpha = lobe.alpha;
                last_inv_albedo = 1 / std::max(albedo(c0, lobe.alpha), 1e-3);
            }
            lobe.scale = lobe.scale * last_inv_albedo;
            continue;
        }
        for (int i = 0; i < 3; ++i)
            lobe.scale[i] /= std::max(albedo(c0, lobe.alpha_rgb[i]), 1e-3);
    }
    return out;
}

}  // namespace

TmLobes tm_lobes(const std::vector<TmComponent>& comps, double c0, const TmChoices& ch) {
    return ch.six_flux ? run_scheme<true>(comps, c0, ch) : run_scheme<false>(comps, c0, ch);
}

int tm_lobe_count(const std::vector<TmComponent>& comps, bool six_flux) {
    // Two fluxes: one lobe per interface. Six: also a forward and a backward lobe per component
    // from the first scattering medium down.
    int lobes = 0;
    bool scattered = false;
    for (const TmComponent& k : comps) {
        if (k.kind != TmComponent::Medium) ++lobes;
        scattered = scattered || (k.kind == TmComponent::Medium && k.tau_s.max() > 0);
        if (six_flux && scattered) lobes += 2;
        if (k.kind == TmComponent::Conductor) break;
    }
    return lobes <= TmLobes::kMaxLobes ? lobes : 0;
}
namespace {

/// The straight-through direction with cosine cos_t below the surface, opposite wi's azimuth.
Vec3d transmitted_direction(const Vec3d& wi, double cos_t) {
    const double s = std::hypot(wi.x, wi.y);
    const double sin_t = safe_sqrt(1 - cos_t * cos_t);
    if (s == 0) return {0, 0, -1};
    return {-sin_t * wi.x / s, -sin_t * wi.y / s, -cos_t};
}

/// The virtual incidence above the surface whose GGX reflection lobe, mirrored through z = 0, is
/// the transmitted lobe (tm2_dielectric.cpp: lobes_wi = reflectZ(t.mean), evaluated with |z|).
Vec3d virtual_incidence(const Vec3d& wi, double cos_t) {
    return mirror_direction(flip_z(transmitted_direction(wi, cos_t)));
}

/// The incidence whose GGX reflection lobe peaks at wi itself: the backward lobes' (tm6.cpp
/// lobes_wi = reflectZ(wi), i.e. the azimuth turned by π).
Vec3d retro_incidence(const Vec3d& wi) {
    return {-wi.x, -wi.y, wi.z};
}

class TmModel final : public Model {
  public:
    TmModel(std::string name, const Stack& stack, const TmChoices& ch)
        : name_(std::move(name)), ch_(ch) {
        for (std::size_t i = 0; i < stack.layers.size(); ++i) {
            const InterfaceSpec& s = stack.layers[i].interface;
            const double above = stack.eta_above(i);
            TmComponent k;
            k.alpha = s.alpha;
            switch (s.type) {
                case InterfaceType::Lambertian:
                    support_.reason = fmt::format(
                        "{} has no Lambertian interface (its components are dielectric and "
                        "conductor interfaces and media)",
                        name_);
                    return;
                case InterfaceType::Dielectric:
                    k.kind = TmComponent::Dielectric;
                    k.eta = model_relative_eta(s.eta / above);  // model.h: finite for any stack
                    k.eta_rgb = Rgbd(k.eta);
                    k.fgd_index.fill(FgdTable::locate(k.eta, 0.0));
                    break;
                case InterfaceType::Conductor:
                    k.kind = TmComponent::Conductor;
                    k.eta_rgb = model_relative_eta(s.eta_rgb / above);
                    k.k = model_relative_k(s.k / above);
                    k.eta = k.eta_rgb.mean();
                    for (int c = 0; c < 3; ++c)
                        k.fgd_index[c] = FgdTable::locate(k.eta_rgb[c], k.k[c]);
                    break;
            }
            k.g_reflect = tm_hg_from_ggx(k.alpha);
            k.eta_pow = std::pow(k.eta, 0.75);
            comps_.push_back(k);
            if (stack.layers[i].has_medium && !stack.layers[i].medium.is_empty()) {
                const MediumSpec& m = stack.layers[i].medium;
                if (m.scatters() && !ch_.scattering) {
                    support_.reason = fmt::format(
                        "{} has no scattering media (its two-flux matrices carry no scattered "
                        "flux; tm6 has)",
                        name_);
                    return;
                }
                TmComponent med;
                med.kind = TmComponent::Medium;
                med.tau_a = m.tau_a;
                // A scattering optical depth below 1e-12 scatters less than 1e-12 of the light:
                // none (its two-stream solution underflows, 1e-160² is subnormal, to NaN).
                constexpr double kNegligibleTau = 1e-12;
                for (int c = 0; c < 3; ++c)
                    med.tau_s[c] = m.tau_s[c] < kNegligibleTau ? 0.0 : m.tau_s[c];
                med.g = m.g;
                ch_.six_flux = ch_.six_flux || med.tau_s.max() > 0;
                comps_.push_back(med);
            }
        }
        if (ch_.scattering && stack.transmits()) {
            support_.reason = fmt::format(
                "{} needs a conductor base (the released tm6 has no dielectric base: its six "
                "fluxes have no transmitted lobes; tm2 has slabs without scattering)",
                name_);
            return;
        }
        if (tm_lobe_count(comps_, ch_.six_flux) == 0) {
            support_.reason =
                ch_.six_flux
                    ? fmt::format(
                          "{} needs at most {} lobes (one per interface, two more per "
                          "component from the first scattering medium down)",
                          name_, int(TmLobes::kMaxLobes))
                    : fmt::format("{} needs 1 to {} interfaces", name_, int(TmLobes::kMaxLobes));
            return;
        }
        ch_.slab = stack.transmits();
        ch_.exact_top =
            ch_.top == TmChoices::Top::Exact || (ch_.top == TmChoices::Top::Released && !ch_.slab);
        support_.brdf = true;
        support_.btdf = ch_.slab;
        top_ = comps_.front();
        FgdTable::get();
        if (ch_.tir) tir_table_prepare(ch_.tir_table);
        if (ch_.albedo_normalized) GgxAlbedoTable::get();
    }

    std::string name() const override { return name_; }
    Support support() const override { return support_; }

    TmLobes lobes(double c0) const { return tm_lobes(comps_, c0, ch_); }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z == 0) return Rgbd(0.0);
        if (wo.z < 0 && !support_.btdf) return Rgbd(0.0);
        return eval_with(lobes(wi.z), wi, wo);
    }

    Rgbd eval_with(const TmLobes& st, const Vec3d& wi, const Vec3d& wo) const {
        if (wi.z <= 0 || wo.z == 0) return Rgbd(0.0);
        if (wo.z < 0) {
            const TmLobes::Lobe& t = st.transmitted;
            if (!support_.btdf || !st.transmits || t.delta) return Rgbd(0.0);
            const Vec3d wv = virtual_incidence(wi, st.cos_t);
            const Vec3d wo_up = flip_z(wo);
            return lobe_value(t, wv, wo_up, normalize(wv + wo_up));
        }
        const Vec3d h = normalize(wi + wo);
        const Vec3d wi_back = retro_incidence(wi);
        const Vec3d h_back = normalize(wi_back + wo);
        Rgbd f(0.0);
        // Lobes of one roughness and incidence share their shape (six fluxes: most scattered
        // lobes are at α = 1): a few shapes are kept.
        struct Shape {
            double alpha;
            bool back;
            double value;
        };
        std::array<Shape, 4> shapes;
        int n_shapes = 0;
        for (int k = 0; k < st.n_lobes; ++k) {
            const TmLobes::Lobe& l = st.lobes[k];
            if (l.component == 0 && l.family == TmLobes::Primary && ch_.exact_top) {
                f += exact_top(wi, wo, h);
                continue;
            }
            if (l.delta) continue;
            const bool back = l.family == TmLobes::Backward;
            if (ch_.per_channel_g) {
                f += back ? lobe_value(l, wi_back, wo, h_back) : lobe_value(l, wi, wo, h);
                continue;
            }
            double shape = -1;
            for (int s = 0; s < n_shapes; ++s)
                if (shapes[s].alpha == l.alpha && shapes[s].back == back) shape = shapes[s].value;
            if (shape < 0) {
                shape = back ? ggx_lobe_shape(l.alpha, wi_back, wo, h_back)
                             : ggx_lobe_shape(l.alpha, wi, wo, h);
                shapes[n_shapes % 4] = {l.alpha, back, shape};
                n_shapes = std::min(n_shapes + 1, 4);
            }
            f += l.scale * shape;
        }
        return f;
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> out;
        if (!support_.brdf || wi.z <= 0) return out;
        const TmLobes st = lobes(wi.z);
        const Vec3d wr = mirror_direction(wi);
        for (int k = 0; k < st.n_lobes; ++k) {
            if (st.lobes[k].component == 0 && st.lobes[k].family == TmLobes::Primary &&
                ch_.exact_top) {
                if (top_.alpha <= 0) out.push_back({wr, top_fresnel(wi.z)});
                continue;
            }
            const TmLobes::Lobe& l = st.lobes[k];
            if (l.delta && l.energy.max() > 0) out.push_back({wr, l.energy});
        }
        if (support_.btdf && st.transmits && st.transmitted.delta &&
            st.transmitted.energy.max() > 0)
            out.push_back({transmitted_direction(wi, st.cos_t), st.transmitted.energy});
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> peaks{mirror_direction(wi)};
        if (ch_.six_flux) peaks.push_back(wi);  // the backward lobes' retro-reflection
        if (support_.btdf) {
            const TmLobes st = lobes(wi.z);
            if (st.transmits) peaks.push_back(transmitted_direction(wi, st.cos_t));
        }
        return peaks;
    }

    // Importance sampling: the energy-weighted mixture of the lobes' visible-normal densities
    // (tm2.cpp sample/pdf: weights = RGB-mean lobe energies, lobe 0 at the top's roughness when
    // exact), delta lobes left out.
    bool has_sampling() const override { return support_.brdf; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!support_.brdf || wi.z <= 0) return std::nullopt;
        const TmLobes st = lobes(wi.z);
        const Mixture mix = mixture(st, wi);
        if (mix.total <= 0) return std::nullopt;
        double pick = u.x * mix.total;
        int k = 0;
        while (k + 1 < mix.n && pick >= mix.w[k]) {
            pick -= mix.w[k];
            ++k;
        }
        // The lobe is chosen by u.x; its direction comes from u.y, u.z.
        const GGX<double> ggx{mix.alpha[k]};
        const Vec3d wm = ggx.sample_visible_normal(mix.wi[k], u.y, u.z);
        Vec3d wo = reflect(mix.wi[k], wm);
        if (wo.z <= 0) return std::nullopt;
        if (mix.below[k]) wo = flip_z(wo);
        const double p = mixture_pdf(mix, wo);
        if (!(p > 0)) return std::nullopt;
        ModelSample s;
        s.wo = wo;
        s.pdf = p;
        s.weight = eval_with(st, wi, wo) * (std::abs(wo.z) / p);
        return s;
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!support_.brdf || wi.z <= 0 || wo.z == 0) return 0.0;
        const TmLobes st = lobes(wi.z);
        return mixture_pdf(mixture(st, wi), wo);
    }

  private:
    /// scale · D G2/(4 μi μo) at the lobe's roughness (one per channel with
    /// asymmetry=per-channel); scale is the energy, or the energy over the shape's albedo.
    Rgbd lobe_value(const TmLobes::Lobe& l, const Vec3d& wi, const Vec3d& wo,
                    const Vec3d& h) const {
        if (!ch_.per_channel_g) return l.scale * ggx_lobe_shape(l.alpha, wi, wo, h);
        Rgbd f;
        for (int c = 0; c < 3; ++c)
            f[c] = l.scale[c] * ggx_lobe_shape(l.alpha_rgb[c], wi, wo, h);
        return f;
    }

    struct Mixture {
        static constexpr int kMax = TmLobes::kMaxLobes + 1;
        std::array<double, kMax> w{}, alpha{};
        std::array<Vec3d, kMax> wi{};
        std::array<bool, kMax> below{};
        int n = 0;
        double total = 0;
    };

    Mixture mixture(const TmLobes& st, const Vec3d& wi) const {
        Mixture m;
        auto add = [&](double w, double alpha, const Vec3d& w_in, bool below) {
            if (!(w > 0) || alpha <= 0) return;
            m.w[m.n] = w;
            m.alpha[m.n] = alpha;
            m.wi[m.n] = w_in;
            m.below[m.n] = below;
            ++m.n;
            m.total += w;
        };
        for (int k = 0; k < st.n_lobes; ++k) {
            const TmLobes::Lobe& l = st.lobes[k];
            if (l.component == 0 && l.family == TmLobes::Primary && ch_.exact_top)
                add(l.energy.mean(), top_.alpha, wi, false);
            else if (!l.delta)
                add(l.energy.mean(), l.alpha,
                    l.family == TmLobes::Backward ? retro_incidence(wi) : wi, false);
        }
        if (support_.btdf && st.transmits && !st.transmitted.delta)
            add(st.transmitted.energy.mean(), st.transmitted.alpha, virtual_incidence(wi, st.cos_t),
                true);
        return m;
    }

    /// Σ_k w_k G1(wi_k) D_k(h_k) / (4 μ_k) / Σ w: the visible-normal reflection densities.
    static double mixture_pdf(const Mixture& m, const Vec3d& wo) {
        if (m.total <= 0) return 0.0;
        double p = 0;
        for (int k = 0; k < m.n; ++k) {
            if (m.below[k] != (wo.z < 0)) continue;
            const Vec3d wo_up = m.below[k] ? flip_z(wo) : wo;
            const Vec3d h = normalize(m.wi[k] + wo_up);
            const GGX<double> ggx{m.alpha[k]};
            p += m.w[k] * ggx.G1(m.wi[k]) * ggx.D(h) / (4 * m.wi[k].z);
        }
        return p / m.total;
    }

    Rgbd top_fresnel(double cos_theta) const {
        if (top_.kind == TmComponent::Conductor)
            return fresnel_complex_rgb(cos_theta, top_.eta_rgb, top_.k);
        return Rgbd(fresnel_dielectric(cos_theta, top_.eta));
    }

    /// The exact reflection of the top interface, F(wi·h) D G2 / (4 μi μo) (Walter et al. 2007,
    /// Eq. 20), the released tm2's "top reflection correction".
    Rgbd exact_top(const Vec3d& wi, const Vec3d& wo, const Vec3d& h) const {
        if (top_.alpha <= 0) return Rgbd(0.0);
        return top_fresnel(dot(wi, h)) * ggx_lobe_shape(top_.alpha, wi, wo, h);
    }

    std::string name_;
    TmChoices ch_;
    std::vector<TmComponent> comps_;
    TmComponent top_;
    Support support_;
};

class TmEvaluator final : public IncidentEvaluator {
  public:
    TmEvaluator(const TmModel& model, const Vec3d& wi)
        : model_(model), wi_(wi), lobes_(model.lobes(std::max(wi.z, 1e-6))) {}
    Rgbd eval(const Vec3d& wo) const override {
        if (wo.z < 0 && !model_.support().btdf) return Rgbd(0.0);
        return model_.eval_with(lobes_, wi_, wo);
    }

  private:
    const TmModel& model_;
    Vec3d wi_;
    TmLobes lobes_;
};

std::unique_ptr<IncidentEvaluator> TmModel::prepare(const Vec3d& wi) const {
    if (!support_.brdf || wi.z <= 0) return Model::prepare(wi);
    return std::make_unique<TmEvaluator>(*this, wi);
}

}  // namespace

namespace {

using TmOption = ModelOption<TmChoices>;

TmOption top_option(std::string help) {
    using C = TmChoices;
    return member_option<C, C::Top>(
        "top", &C::top,
        {{"released", C::Top::Released}, {"exact", C::Top::Exact}, {"lobe", C::Top::Lobe}},
        std::move(help));
}

TmOption upward_fgd_option() {
    return member_option<TmChoices, bool>(
        "upward-fgd", &TmChoices::upward_fgd, {{"same-cosine", false}, {"refracted", true}},
        "upward reflectance r': r at the incident cosine (released) or FGD(mu_t, alpha, 1/eta)");
}

TmOption tir_option() {
    return on_off_member<TmChoices>("tir", &TmChoices::tir,
                                    "the TIR-table steps of the released code");
}

TmOption tir_table_option() {
    return member_option<TmChoices, TirDefinition>(
        "tir-table", &TmChoices::tir_table,
        {{"lobe", TirDefinition::Lobe},
         {"lobe-fresnel", TirDefinition::LobeFresnel},
         {"microfacet", TirDefinition::Microfacet}},
        "the fraction the TIR steps move: the light's GGX lobe outside a flat interface's escape "
        "cone (the released table), one minus its Fresnel transmittance (Belcour's table), or "
        "what a rough interface's microfacets reflect totally of collimated light");
}

// The asymmetry weights: one g per lobe from the RGB-mean weights, one per channel, or (tm6) one
// per lobe as the channel mean of the per-channel ratios.
TmOption::Value asymmetry(std::string text, bool per_channel, bool ratio_mean) {
    return {std::move(text),
            [=](TmChoices& c) {
                c.per_channel_g = per_channel;
                c.ratio_mean_g = ratio_mean;
            },
            [=](const TmChoices& c) {
                return c.per_channel_g == per_channel && c.ratio_mean_g == ratio_mean;
            }};
}

const ModelOptionTable<TmChoices>& tm2_option_table() {
    static const ModelOptionTable<TmChoices> table({
        top_option("lobe 0: as released (exact over a conductor, from the matrices for a slab), "
                   "the exact top reflection, or the matrices' FGD-weighted lobe"),
        upward_fgd_option(),
        tir_option(),
        tir_table_option(),
        {"asymmetry",
         {asymmetry("rgb-mean", false, false), asymmetry("per-channel", true, false)},
         "lobe asymmetry g from RGB-mean weights, one per lobe (released), or per channel"},
    });
    return table;
}

const ModelOptionTable<TmChoices>& tm6_option_table() {
    using C = TmChoices;
    static const ModelOptionTable<C> table({
        top_option("lobe 0: as released (the exact top reflection), the exact top reflection, or "
                   "the matrices' lobe"),
        upward_fgd_option(),
        tir_option(),
        tir_table_option(),
        {"asymmetry",
         {asymmetry("ratio-mean", false, true), asymmetry("rgb-mean", false, false),
          asymmetry("per-channel", true, false)},
         "lobe asymmetry g: per-channel weights, one g per lobe as the channel mean of the "
         "ratios (released tm6), tm2's RGB-mean weights, or one g per channel"},
        member_option<C, bool>("normalization", &C::albedo_normalized,
                               {{"albedo", true}, {"none", false}},
                               "each matrix lobe divided by its GGX albedo E(mu_i, alpha) "
                               "(released tm6) or not (as tm2)"),
        member_option<C, bool>("backscatter", &C::backscatter_fit,
                               {{"fit", true}, {"exact", false}},
                               "back-scattered fraction of HG in a medium: the released quadratic "
                               "fit or the exact HG integral"),
    });
    return table;
}

}  // namespace

const ModelOptionTable<TmChoices>& tm_option_table(const std::string& variant) {
    return variant == "tm6" ? tm6_option_table() : tm2_option_table();
}

TmChoices tm_variant(const std::string& variant) {
    TmChoices c;
    if (variant == "tm6") {
        // The plugin tm6 as released: Henyey–Greenstein media (six fluxes: primary, forward- and
        // back-scattered), the exact top reflection, every other lobe normalized by its GGX
        // albedo, one asymmetry per lobe from the per-channel ratios; over a conductor base.
        c.scattering = true;
        c.ratio_mean_g = true;
        c.albedo_normalized = true;
    } else {
        // tm2 as released: over a conductor base the plugin tm2 (lobe 0 replaced by the exact
        // top-interface reflection), over a dielectric base (a slab) the plugin tm2_dielectric
        // (every lobe from the matrices, plus the transmitted lobe).
        LAMINA_CHECK(variant == "tm2");
    }
    return c;
}

std::unique_ptr<Model> make_tm_model(const std::string& name, const Stack& stack,
                                     const TmChoices& choices) {
    return std::make_unique<TmModel>(name, stack, choices);
}

}  // namespace lamina

#include "models/lamina1/lamina1.h"

#include "core/math.h"
#include "models/numerics/medium_adding.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "models/tables/fgd_table.h"
#include "models/tables/multiple_scattering_albedo.h"
#include "models/tables/slope_sum_table.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/phase.h"
#include "physics/sampling.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <optional>

namespace lamina {

namespace {

constexpr int kNmu = 65;   // nodes of the per-material curves over a cosine, μ = s²
constexpr int kNx = 33;    // nodes of X(μ), μ = s²
constexpr int kYnr = 6;    // the rule of the transmitted light's mean direction: Gauss–Legendre
constexpr int kYnphi = 8;  // in r × midpoint in φ over the half disk
// The rule of Y and X: their integrands step at the coat's critical angle (total internal
// reflection returns everything beyond it). A plain 6 × 8 rule in r put that step on one heavy
// node (Y = 0.27 instead of 0.17 at normal incidence on α1 = 0.4 under an η0 = 1.2 smooth coat,
// and the stack 7% more light than the goniophotometer); 24 × 16 nodes still moved by 2% from one
// rule to the next. The rule splits the radius of each φ node at the step instead (and, for a
// slab's Y, at its bottom's own total reflection) and integrates it in u = √(1 − r)
// (integrate_visible_split, models/numerics/visible_normal_quadrature.h): 5 Gauss–Legendre nodes
// per piece, 6 in φ; on the study's slabs, paints and frosted metals its albedos are within 1.0e-3
// (mean 5e-5) of a 16 × 32 rule, where 6 × 8 nodes in r were within 3.1e-3.
constexpr int kSplitNr = 5, kSplitNphi = 6, kSplitBisections = 14;
constexpr int kNormNr = 8, kNormNphi = 8;  // the base lobe's normalization N (its rule) ...
constexpr int kNnorm = 17;                 // ... on this many cosines (μ = s²)
/// Energies (fractions of the incident light) below this are taken as zero where a lobe is
/// normalized by them: far below anything a goniophotometer could measure.
constexpr double kNegligibleEnergy = 1e-12;
constexpr int kGauss = 24;  // Gauss–Legendre nodes per piece of the hemispherical integrals
// The slab's transmission curves (precompute_slab): nodes over a cosine (the first order, the
// later orders), and the split visible-normal rule of their integrals (r nodes per piece, φ
// nodes, bisections).
constexpr int kNfirst = 17, kNslab = 17;
constexpr int kSlabNr = 4, kSlabNphi = 8, kSlabBisections = 8;

/// A curve over a cosine μ ∈ [0, 1] on nodes μ = s² (dense at grazing), linear in s.
template <typename V, int kN = kNmu>
struct CosineCurve {
    std::array<V, kN> v{};
    template <typename F>
    void fill(F&& f) {
        for (int i = 0; i < kN; ++i)
            v[i] = f(sqr(double(i) / (kN - 1)));
    }
    V operator()(double mu) const {
        const double s = std::sqrt(clamp(mu, 0.0, 1.0)) * (kN - 1);
        const int i = std::min(int(s), kN - 2);
        const double t = s - i;
        return v[i] * (1 - t) + v[i + 1] * t;
    }
};

/// A curve over an inside cosine with a jump at the critical cosine μc (total internal reflection
/// at a smooth coat): linear on nodes uniform in [0, μc) and in [μc, 1], each piece on its own.
/// kSqrtEdge: a square-root edge there instead (a rough interface's transmittance from inside,
/// which rises as √(μ − μc) above it when nearly smooth, its step smoothed over a width ~α on
/// both sides): the nodes crowd towards μc from both sides, μ = μc (1 − (1 − t)²) below and
/// μ = μc + (1 − μc) t² above (t uniform), as integrate_split01 (models/numerics/quadrature.h)
/// places its upper nodes.
template <int kN, typename V = Rgbd, bool kSqrtEdge = false>
struct SplitCurve {
    double split = 0;
    std::array<V, kN> below{}, above{};
    template <typename F>
    void fill(double mu_split, F&& f) {
        split = clamp(mu_split, 0.0, 1.0);
        for (int i = 0; i < kN; ++i) {
            const double t = double(i) / (kN - 1);
            if (split > 0)  // else never read
                below[i] = f(
                    std::min(split * (kSqrtEdge ? 1 - sqr(1 - t) : t), std::nextafter(split, 0.0)));
            above[i] = f(split + (1 - split) * (kSqrtEdge ? t * t : t));
        }
    }
    V operator()(double mu) const {
        const bool lower = mu < split;
        const double a = lower ? 0 : split, b = lower ? split : 1;
        const auto& v = lower ? below : above;
        double x = b > a ? clamp((mu - a) / (b - a), 0.0, 1.0) : 0;
        if (kSqrtEdge) x = lower ? 1 - std::sqrt(1 - x) : std::sqrt(x);
        x *= kN - 1;
        const int i = std::min(int(x), kN - 2);
        const double t = x - i;
        return v[i] * (1 - t) + v[i + 1] * t;
    }
};

/// The square-root-edge curve (SplitCurve with kSqrtEdge).
template <int kN>
using EdgeCurve = SplitCurve<kN, double, true>;

/// N values of type T integrated and tabulated together (the curves above take it as V).
template <typename T, int N>
struct Multi {
    std::array<T, N> v{};
    Multi& operator+=(const Multi& o) {
        for (int i = 0; i < N; ++i)
            v[i] += o.v[i];
        return *this;
    }
    Multi operator+(const Multi& o) const { return Multi(*this) += o; }
    Multi operator*(double s) const {
        Multi r;
        for (int i = 0; i < N; ++i)
            r.v[i] = v[i] * s;
        return r;
    }
};

/// ∫_lo^hi f(μ) dμ by Gauss–Legendre (kGauss nodes).
template <typename V, typename F>
V integrate_range(F&& f, double lo, double hi) {
    static const QuadratureRule q = gauss_legendre(kGauss);
    V sum{};
    if (!(hi > lo)) return sum;
    for (int i = 0; i < kGauss; ++i)
        sum += f(lo + (hi - lo) * q.x[i]) * (q.w[i] * (hi - lo));
    return sum;
}

/// Each channel clamped at zero (interpolated energies, never negative).
Rgbd nonnegative(Rgbd v) {
    for (int c = 0; c < 3; ++c)
        v[c] = std::max(v[c], 0.0);
    return v;
}

/// |1 − μ/(η μ')|: the rate at which a refracted direction turns with the tilt of the facet it
/// crosses (differentiate Snell's law sin(θ − δ) = η sin(θ' + Δ − δ) in δ at δ = 0, for a facet
/// tilted by δ in the plane of incidence: dΔ/dδ = 1 − cos θ/(η cos θ')). Belcour 2018, Eq. 10,
/// is the same first-order deflection. At normal incidence 1 − 1/η.
double deflection(double mu, double mu_in, double eta) {
    return std::abs(1 - mu / (eta * mu_in));
}

/// One facet's exact deflection of the refracted light at normal incidence (docs/models.md,
/// lamina-1, item 4), for the coat's spreads' tails: a facet tilted by δ turns the inside
/// direction by g(δ) — entering from outside, g = δ − asin(sin δ/η); leaving from inside, the
/// outside ray turns by ψ = asin(η sin δ) − δ, which the smooth refraction wo → wo' sees inside
/// as g = asin(sin ψ/η) (nothing beyond total internal reflection, δ ≥ asin(1/η)). Both have
/// g'(0) = k_n = 1 − 1/η. Tabulated inverse, over g ∈ [0, g_max] (129 nodes): sin δ and cos δ
/// (both smooth in g: an interpolated cos δ alone would make tan δ grow like √g at 0), and the
/// weight k_n w(δ)/g'(δ) (the Jacobian of the map, 1 at δ = 0) with w the facet's transmission
/// 1 − F(cos δ) times the refracted ray's Smith escape 1/(1 + Λ), relative to normal incidence.
struct FacetDeflection {
    static constexpr int kN = 129, kFine = 257;
    double g_max = 0;
    std::array<double, kN> sin_delta{}, cos_delta{}, weight{};

    void build(bool entering, double eta, double alpha0) {
        const GGX<double> ggx{alpha0};
        const double k_n = 1 - 1 / eta;
        const double delta_max = entering ? 0.5 * kPi<double> : std::asin(1 / eta);
        const double w0 = 1 - fresnel_dielectric(1.0, eta);
        // The forward map on a fine δ grid (g is increasing), then inverted node by node.
        std::array<double, kFine> g{}, sn{}, c{}, wt{};
        for (int j = 0; j < kFine; ++j) {
            const double delta = delta_max * j / (kFine - 1);
            const double sd = std::sin(delta), cd = std::cos(delta);
            double gj, dg, escape_cos;
            if (entering) {
                const double ct = safe_sqrt(1 - sqr(sd / eta));
                gj = delta - std::asin(std::min(sd / eta, 1.0));
                dg = 1 - cd / (eta * ct);
                escape_cos = std::cos(gj);
            } else {
                const double x = std::min(eta * sd, 1.0);
                const double psi = std::asin(x) - delta;
                gj = std::asin(std::sin(psi) / eta);
                const double root = safe_sqrt(1 - x * x);
                dg = root > 0 ? std::cos(psi) * (eta * cd / root - 1) / (eta * std::cos(gj))
                              : HUGE_VAL;
                escape_cos = std::cos(psi);
            }
            const double F =
                entering ? fresnel_dielectric(cd, eta) : fresnel_dielectric(cd, 1 / eta);
            const Vec3d w_ref(safe_sqrt(1 - sqr(escape_cos)), 0, std::max(escape_cos, 1e-9));
            const double w = (1 - F) / (1 + ggx.lambda(w_ref)) / w0;
            g[j] = gj;
            sn[j] = sd;
            c[j] = cd;
            wt[j] = j == 0 ? 1.0 : (dg > 0 && std::isfinite(dg) ? k_n * w / dg : 0.0);
        }
        g_max = g[kFine - 1];
        int j = 0;
        for (int i = 0; i < kN; ++i) {
            const double gi = g_max * i / (kN - 1);
            while (j < kFine - 2 && g[j + 1] < gi)
                ++j;
            const double span = g[j + 1] - g[j];
            const double t = span > 0 ? clamp((gi - g[j]) / span, 0.0, 1.0) : 0.0;
            sin_delta[i] = sn[j] + t * (sn[j + 1] - sn[j]);
            cos_delta[i] = c[j] + t * (c[j + 1] - c[j]);
            weight[i] = wt[j] + t * (wt[j + 1] - wt[j]);
        }
    }

    /// sin δ, cos δ and the weight at deflection g ≥ 0; false beyond g_max (no facet turns so far).
    bool lookup(double g, double& sin_d, double& cos_d, double& w) const {
        if (!(g < g_max)) return false;
        const double f = g / g_max * (kN - 1);
        const int i = std::min(int(f), kN - 2);
        const double t = f - i;
        sin_d = sin_delta[i] + t * (sin_delta[i + 1] - sin_delta[i]);
        cos_d = cos_delta[i] + t * (cos_delta[i + 1] - cos_delta[i]);
        w = weight[i] + t * (weight[i + 1] - weight[i]);
        return cos_d > 0 && w > 0;
    }
};

class Lamina1 final : public Model {
  public:
    Lamina1(const Stack& stack, const Lamina1Choices& choices) : ch_(choices) {
        std::string why;
        if (!coated_stack(stack, coat_, why)) {
            support_.reason = fmt::format("lamina-1 {}", why);
            return;
        }
        if (coat_.eta0 < 1) {
            support_.reason = "lamina-1 needs a coat at least as dense as the ambient medium";
            return;
        }
        support_.brdf = true;
        support_.btdf = coat_.base_type == InterfaceType::Dielectric;
        eta0_ = coat_.eta0;
        inv_eta0_ = 1 / eta0_;
        alpha0_ = coat_.alpha0;
        alpha1_ = coat_.base_alpha;
        // The unscattered light is attenuated by extinction, τt = τa + τs (τa itself, bitwise,
        // without scattering).
        tau_t_ = coat_.tau_a + coat_.tau_s;
        has_absorption_ = tau_t_.max() > 0;
        scatters_ = coat_.tau_s.max() > 0;
        if (coat_.base_type == InterfaceType::Dielectric) {
            eta_b_ = coat_.base_eta[0];  // η_below/η_coat
            eta_s_ = 1 / eta_b_;         // the coat seen from below: η_coat/η_below
        }
        if (coat_.base_type == InterfaceType::Conductor)
            for (int c = 0; c < 3; ++c)
                base_fgd_[c] = FgdTable::locate(coat_.base_eta[c], coat_.base_k[c]);
        precompute();
        if (scatters_) precompute_scattering();
        precompute_slab();
    }

    std::string name() const override { return "lamina-1"; }
    Support support() const override { return support_; }

    /// Everything that depends on wi alone.
    struct Incident {
        Vec3d wi, wi_in;  ///< wi and its refraction into the coat about n (pointing up)
        bool ok = false;
        double T = 0;  ///< T(μi)
        Rgbd a{1.0};   ///< exp(−τ/μi')
        Rgbd X{0.0};   ///< X(μi) = T(μi) a(μi') Y(μi')
        double lambda0 = 0, k_top = 0, k_bottom = 1;
        Vec3d wi_mean;      ///< the mean direction of the light the coat transmits (slabs)
        Rgbd a_mean{1.0};   ///< exp(−τ/μ̄')
        double dR = 0;      ///< ΔR(μi) of the coat (multiple scattering)
        double T_pair = 0;  ///< √(T(μi) T_exit(μi)): the first order's reciprocal coat factor
        double lobe_norm = 1;  ///< 1/√N(μi'): the widened base lobe's normalization
        Rgbd E_b{0.0};         ///< scattering media: the base's albedo E_b(μi') (mirror paths)
        Rgbd orders{0.0};      ///< E_ms(μi)/(π Ē_ms): the scattered remainder's separable lobe
        Rgbd orders_t{0.0};    ///< E_ms,T(μi)/(π T̄_b): its transmitted part (slabs)
        Rgbd twice{0.0};       ///< that part's normalization as twice-scattered light
        double alpha_b = 0;    ///< the slab bottom's roughness widened by the coat's spread
        Rgbd first_T{0.0};  ///< E_1(μi)/T_lobe(μi): the first order over the bottom lobe's energy
        Rgbd first_E{0.0};  ///< E_1(μi): the first order's transmitted energy
        double u_bottom = 1;  ///< the first order's share in the bottom's lobe (btdf-lobe)
        Rgbd first_M{0.0};    ///< E_1(μi)/Q_m(μi): over the mirrored lobe's energy (shared)
        /// Φ_p(μi)/(π A_p η_s²) for the populations p = inside, beyond the exit cone (v[0], v[1])
        /// and the energy Σ_p Φ_p T_p they transmit (v[2]): the slab's later orders.
        Multi<Rgbd, 3> trapped{};
    };

    Incident incident(const Vec3d& wi) const {
        Incident in;
        in.wi = wi;
        if (!support_.brdf || wi.z <= 0) return in;
        in.wi_in = refract_in(wi, inv_eta0_);
        // Light exactly at grazing into an index-matched coat stays on the horizon (cos θi' = 0
        // by rounding): nothing enters, and the spread factor k = |1 − μ/(η μ')| would be 0/0.
        if (!(in.wi_in.z > 0)) return in;
        in.ok = true;
        in.T = T_top_(wi.z);
        in.T_pair = in.T;
        in.a = attenuation(in.wi_in.z);
        if (series_on_) in.X = X_at(wi.z);
        if (alpha0_ > 0) in.lambda0 = GGX<double>{alpha0_}.lambda(wi);
        if (top_ms_) in.dR = dR_top_(wi.z);
        if (lobe_norm_on_) in.lobe_norm = lobe_norm_(in.wi_in.z);
        if (scatters_) {
            if (base_paths_) in.E_b = mirror_albedo(in.wi_in.z);
            if (orders_on_) {
                in.orders = orders_(wi.z) * orders_norm_;
                if (support_.btdf) in.orders_t = orders_t_(wi.z) * orders_t_norm_;
                if (twice_on_) in.twice = twice_(wi.z);
            }
        }
        in.k_top = spread_factor(wi.z, in.wi_in.z, eta0_);
        if (inside_exit_)
            in.T_pair = std::sqrt(in.T * exit_transmittance(wi.z, in.wi_in.z, in.k_top));
        if (support_.btdf) {
            in.wi_mean = in.wi_in;
            in.a_mean = in.a;
            if (mean_shift_) {
                // The transmitted light's mean direction, in wi's plane of incidence.
                const double mu = clamp(in.wi_in.z + mu_mean_(wi.z), 1e-4, 1.0);
                const double sxy = std::hypot(in.wi_in.x, in.wi_in.y);
                const double s_new = std::sqrt(1 - mu * mu);
                in.wi_mean = sxy > 0 ? Vec3d(in.wi_in.x * s_new / sxy, in.wi_in.y * s_new / sxy, mu)
                                     : in.wi_in;
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
                const Multi<Rgbd, 3> first = first_order_(wi.z);
                const Multi<Rgbd, 2> smooth = first_order_smooth(wi.z, in.wi_in.z);
                // Stored as residuals from the smooth slab, the interpolated curves can undershoot
                // zero by their interpolation error where the energy itself vanishes (grazing
                // incidence, total internal reflection at the bottom): an energy is ≥ 0.
                in.first_T = nonnegative(first.v[0] + smooth.v[0]);
                in.first_E = nonnegative(first.v[1] + smooth.v[1]);
                in.first_M = nonnegative(first.v[2] + smooth.v[0]);
                // btdf-lobe=shared: the bottom's share of the spread's variance.
                if (ch_.btdf_lobe_shared && in.alpha_b > 0)
                    in.u_bottom = sqr(alpha1_) / sqr(in.alpha_b);
            }
            if (populations_) {
                in.trapped = trapped_(wi.z);
                for (Rgbd& v : in.trapped.v)
                    v = nonnegative(v);
            }
        }
        return in;
    }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        return eval_with(incident(wi), wo);
    }

    Rgbd eval_with(const Incident& in, const Vec3d& wo) const {
        if (!in.ok || wo.z == 0) return Rgbd(0.0);
        if (wo.z < 0) return support_.btdf ? eval_btdf(in, wo) : Rgbd(0.0);
        const Vec3d& wi = in.wi;
        Rgbd f(0.0);
        if (alpha0_ > 0) {
            // The coat's own reflection, exact: Walter et al. 2007, Eq. 20, with the height-
            // correlated G2 (Heitz 2014, Eq. 99).
            const GGX<double> ggx0{alpha0_};
            const Vec3d h = normalize(wi + wo);
            const double G = 1 / (1 + in.lambda0 + ggx0.lambda(wo));
            f = Rgbd(fresnel_dielectric(dot(wi, h), eta0_) * ggx0.D(h) * G / (4 * wi.z * wo.z));
            // Its orders ≥ 2 as a separable lobe of albedo ΔR(μi), reciprocal by construction
            // (the energy-compensation form of Kulla & Conty 2017, "Revisiting physically based
            // shading at Imageworks", SIGGRAPH course, with the walk's ΔR in place of 1 − E).
            if (top_ms_) f += Rgbd(in.dR * dR_top_(wo.z) * kInvPi<double> / dR_top_bar_);
        }
        const Vec3d wo_in = refract_in(wo, inv_eta0_);
        double T_o = T_top_(wo.z);
        const Rgbd a_o = attenuation(wo_in.z);
        // First order: the base's lobe at the refracted directions, entering and leaving through
        // the coat's directional transmittance; 1/η0² compresses the solid angle.
        // A direction refracted onto the horizon (an index-matched coat at grazing light, where
        // √(1 − sin²θ) rounds to 0) carries no first order: T is 0 there and the lobe 0/0.
        const Rgbd fb =
            in.wi_in.z > 0 && wo_in.z > 0 ? base_lobe(in, wi.z, wo.z, wo_in) : Rgbd(0.0);
        // The coat enters with T(μi) and leaves with T_exit(μo); made reciprocal as the product
        // √(T T_exit)(μi) √(T T_exit)(μo), exact at the mirror pair (μo = μi) where the narrow
        // first order is.
        if (inside_exit_ && fb.max() > 0)
            T_o = std::sqrt(T_o *
                            exit_transmittance(wo.z, wo_in.z, spread_factor(wo.z, wo_in.z, eta0_)));
        Rgbd rounds(1.0);
        if (mirror_series_ && fb.max() > 0)
            rounds = mirror_series_curve_(in.wi_in.z) * mirror_series_curve_(wo_in.z);
        f += fb * (in.a * a_o) * rounds *
             (in.T_pair * T_o * (ch_.eta2_factor ? inv_eta0_ * inv_eta0_ : 1.0));
        if (series_on_) {
            f += in.X * X_at(wo.z) * K_ * (kInvPi<double> * inv_eta0_ * inv_eta0_);
        }
        if (scatters_) f += scattered(in, wo, wo_in, a_o);
        return f;
    }

    /// The scattering medium's reflected terms (out of line: absorbing stacks pay one branch).
    [[gnu::noinline]] Rgbd scattered(const Incident& in, const Vec3d& wo, const Vec3d& wo_in,
                                     const Rgbd& a_o) const {
        Rgbd f(0.0);
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
    Rgbd single_scattering(const Incident& in, const Vec3d& wo_in, const Rgbd& a_o,
                           double T_o) const {
        const Vec3d& wi_in = in.wi_in;
        const double mu_i = wi_in.z, mu_o = wo_in.z;
        const double dxy = wi_in.x * wo_in.x + wi_in.y * wo_in.y, zz = mu_i * mu_o;
        // Propagation directions: −wi' in, wo' out (back-scattered), or the mirror of wo'.
        const double cos_back = -dxy - zz, cos_mirror = -dxy + zz;
        Rgbd f(0.0);
        double p_back = 0, p_mirror = 0;
        const Rgbd E_o = base_paths_ ? mirror_albedo(mu_o) : Rgbd(0.0);
        for (int c = 0; c < 3; ++c) {
            if (c == 0 || !g_uniform_) {
                if (back_on_) p_back = hg_phase(cos_back, coat_.g[c]);
                if (base_paths_) p_mirror = hg_phase(cos_mirror, coat_.g[c]);
            }
            double v = p_back * (1 - in.a[c] * a_o[c]) / (mu_i + mu_o);
            if (base_paths_) {
                v += p_mirror * attenuation_slope(mu_o, mu_i, a_o[c], in.a[c], tau_t_[c]) *
                     (E_o[c] * a_o[c] + in.E_b[c] * in.a[c]);
            }
            f[c] = omega_[c] * v;
        }
        return f * (in.T * T_o * (ch_.eta2_factor ? inv_eta0_ * inv_eta0_ : 1.0));
    }

    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> out;
        if (!support_.brdf || wi.z <= 0) return out;
        if (alpha0_ > 0) return out;
        const Vec3d wr = mirror_direction(wi);
        const double F = fresnel_dielectric(wi.z, eta0_);
        out.push_back({wr, Rgbd(F)});
        if (coat_.base_type == InterfaceType::Lambertian || alpha1_ > 0) return out;
        // Both interfaces smooth: every order is specular (docs/physics.md §6.4–6.5 of the study):
        // the series Σ (R_in R_b a²)^k with R_in = F(μi) (Fresnel is the same from both sides).
        const Vec3d w_in = refract_in(wi, inv_eta0_);
        const Rgbd a = attenuation(w_in.z);
        const Rgbd Rb = base_fresnel(w_in.z);
        const double T = 1 - F;
        Rgbd series(1.0);
        if (ch_.inter_reflection)
            for (int c = 0; c < 3; ++c) {
                // F R_b a² = 1 only where nothing enters (F = 1: wi exactly grazing), and the
                // lobes' T factor is 0 there: no series (not 0·∞).
                const double round_trip = F * Rb[c] * a[c] * a[c];
                series[c] = round_trip < 1 ? 1 / (1 - round_trip) : 0.0;
            }
        out.push_back({wr, Rb * a * a * series * (T * T)});
        if (support_.btdf) {
            const double sin_t = std::hypot(wi.x, wi.y) * inv_eta0_ * eta_s_;
            if (sin_t < 1) {
                const double Tb = 1 - fresnel_dielectric(w_in.z, eta_b_);
                out.push_back({transmitted_direction(wi, std::sqrt(1 - sin_t * sin_t)),
                               a * series * (T * Tb)});
            }
        }
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> peaks{mirror_direction(wi)};
        if (support_.btdf && wi.z > 0) {
            const double sin_t = std::hypot(wi.x, wi.y) * inv_eta0_ * eta_s_;
            if (sin_t < 1) peaks.push_back(transmitted_direction(wi, std::sqrt(1 - sin_t * sin_t)));
            if (mean_shift_) {  // the transmission lobe's own peak
                const double sin_m = std::sqrt(1 - sqr(incident(wi).wi_mean.z)) * eta_s_;
                if (sin_m < 1)
                    peaks.push_back(transmitted_direction(wi, std::sqrt(1 - sin_m * sin_m)));
            }
        }
        return peaks;
    }

    bool has_sampling() const override { return support_.brdf; }
    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override;
    double pdf(const Vec3d& wi, const Vec3d& wo) const override;

  private:
    /// The sampling mixture for one incidence: lobe probabilities (top reflection, base lobe,
    /// diffuse series; transmission lobe, diffuse transmission) and the lobes' roughnesses.
    struct Mixture {
        std::array<double, 5> p{};
        Vec3d wi_in, wi_mean;
        double alpha_base = 0, beta = 0;
        bool bottom_sampled = false;  ///< the transmission lobe drawn as the bottom's (btdf-lobe)
    };
    Mixture mixture(const Incident& in) const;
    double pdf_with(const Incident& in, const Mixture& m, const Vec3d& wo) const;

    /// The slab medium's once-scattered light leaving through the bottom, exact for the slab:
    /// scattered at depth t from the entering direction −wi' into the leaving one (v' turned
    /// down), ϖ p(Θ) (a(μv') − a(μi'))/(μv' − μi') per unit flux inside (the depth integral of
    /// the two Beer–Lambert factors), entering with T(μi), leaving as broad light with the
    /// bottom's T_b(μv)/η_s².
    /// (With g → g² and the scale K(μi) T(μi) in place of T(μi): the transmitted remainder shaped
    /// like twice-scattered light.)
    [[gnu::noinline]] Rgbd single_transmission(const Incident& in, const Vec3d& v_in,
                                               const Rgbd& a_v, double T_b, const Rgbd& g,
                                               const Rgbd& scale) const {
        const Vec3d& wi_in = in.wi_in;
        const double cos_forward = -(wi_in.x * v_in.x + wi_in.y * v_in.y) + wi_in.z * v_in.z;
        Rgbd f(0.0);
        double p = 0;
        for (int c = 0; c < 3; ++c) {
            if (c == 0 || !g_uniform_) p = hg_phase(cos_forward, g[c]);
            f[c] = omega_[c] * p * attenuation_slope(v_in.z, wi_in.z, a_v[c], in.a[c], tau_t_[c]) *
                   scale[c];
        }
        return f * (T_b / (eta_s_ * eta_s_));
    }

    /// The BTDF of a slab: the mirrored transmission lobe through both interfaces, and the
    /// diffuse light of the inter-reflections leaving through the bottom.
    Rgbd eval_btdf(const Incident& in, const Vec3d& wo) const {
        // v: wo mirrored into the upper hemisphere; v' its refraction into the coat through the
        // bottom (η_s = η_coat/η_below): the straight-through pair has v' = mirror(wi').
        const Vec3d v(wo.x, wo.y, -wo.z);
        const auto v_in = refract_in_checked(v, 1 / eta_s_);
        if (!v_in) return Rgbd(0.0);
        const double T_b = T_bot_(v.z), T_b_in = T_bot_in_(v_in->z);
        const Rgbd a_v = has_absorption_ ? attenuation(v_in->z) : Rgbd(1.0);
        Rgbd f(0.0);
        const double beta = transmission_roughness(in.k_top, in.k_bottom);
        if (bottom_lobe_ && in.alpha_b > 0 && in.u_bottom > 0) {
            // The bottom's Walter BTDF (Eq. 21) from the mean inside direction: with a smooth coat
            // the first order is exactly T(μi) a(μi') f_t,bottom(wi', wo).
            f += in.first_T * (in.u_bottom * bottom_btdf(in.alpha_b).eval(in.wi_mean, wo));
        }
        if ((!bottom_lobe_ || in.u_bottom < 1) && beta > 0) {
            const GGX<double> ggx{beta};
            const Vec3d h = normalize(in.wi_mean + *v_in);
            const double q = ggx.D(h) * ggx.G2(in.wi_mean, *v_in) / (4 * in.wi_mean.z * v_in->z);
            // The narrow lobe leaves with the bottom's transmittance from inside, T_in(μv'):
            // consistent with the bottom's reflection R_b(μ') (R_b + T_in + loss = 1).
            // The light crosses the coat's medium once: the geometric mean of the attenuations
            // along the entering and the leaving direction (both e^{−τ/μi'} at the straight-
            // through pair).
            Rgbd a_once = in.a_mean * a_v;
            for (int c = 0; c < 3; ++c)
                a_once[c] = std::sqrt(a_once[c]);
            if (mirror_series_ && !populations_)
                a_once *= mirror_series_curve_(in.wi_mean.z) * mirror_series_curve_(v_in->z);
            if (bottom_lobe_) {
                // btdf-lobe=shared: the mirrored lobe's share 1 − u of the first order, carrying
                // E_1 over its energy Q_m (the medium's attenuation is in E_1).
                Rgbd rounds(1.0);
                if (mirror_series_ && !populations_)
                    rounds = mirror_series_curve_(in.wi_mean.z) * mirror_series_curve_(v_in->z);
                f += in.first_M * rounds * ((1 - in.u_bottom) * T_b_in * q / (eta_s_ * eta_s_));
            } else {
                f += a_once * (in.T * T_b_in * q / (eta_s_ * eta_s_));
            }
        }
        if (populations_) {
            // The later orders: uniform radiance in each population leaves through the bottom as
            // the light from below at wo enters into it (reciprocity), T_{below→p}(μv)/η_s².
            const Multi<double, 2> enter = enter_below_(v.z);
            f += in.trapped.v[0] * enter.v[0] + in.trapped.v[1] * enter.v[1];
        } else if (series_btdf_) {
            f += in.X * inv_one_minus_Er_ * (T_b * kInvPi<double> / (eta_s_ * eta_s_));
        }
        // The scattered light that leaves through the bottom, as uniform radiance below it.
        if (orders_on_ && !twice_on_) f += in.orders_t * T_b;
        if (scatters_ && back_on_)
            f += single_transmission(in, *v_in, a_v, T_b, coat_.g, Rgbd(in.T));
        if (twice_on_) f += single_transmission(in, *v_in, a_v, T_b, g_twice_, in.twice * in.T);
        return f;
    }

    /// The base's lobe at the refracted pair (wi', wo'), widened by the coat's refraction spread.
    Rgbd base_lobe(const Incident& in, double /*mu_i*/, double mu_o, const Vec3d& wo_in) const {
        if (coat_.base_type == InterfaceType::Lambertian) return coat_.albedo * kInvPi<double>;
        const double alpha = effective_alpha(in.k_top, spread_factor(mu_o, wo_in.z, eta0_));
        if (alpha <= 0) return Rgbd(0.0);  // a delta lobe (delta_lobes)
        const GGX<double> ggx{alpha};
        const Vec3d h = normalize(in.wi_in + wo_in);
        const double G = ggx.G2(in.wi_in, wo_in);
        const double D = shaped_lobe_
                             ? first_order_ndf(h, in.k_top, spread_factor(mu_o, wo_in.z, eta0_))
                             : ggx.D(h);
        Rgbd f = base_fresnel(dot(in.wi_in, h)) * (D * G / (4 * in.wi_in.z * wo_in.z));
        if (lobe_norm_on_) f *= in.lobe_norm * lobe_norm_(wo_in.z);
        // The base's orders ≥ 2 (of its own roughness α1), separable as the coat's.
        if (base_ms_)
            f += F_ms_ * (dE_base_(in.wi_in.z) * dE_base_(wo_in.z) * kInvPi<double> / dE_base_bar_);
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
    double first_order_ndf(const Vec3d& h, double k_i, double k_o) const {
        // Both refractions turn the light at the rate of the pair's less oblique end (see the
        // comment above): symmetric, and k_i itself at the mirror pair. The two coat spreads
        // then have one scale, α0 k/2, and one map each.
        const double k = std::min(k_i, k_o);
        const double a_b = alpha1_, a_c = 0.5 * alpha0_ * k;
        const double s2 = sqr(a_b) + 2 * sqr(a_c);
        const double c2 = h.z * h.z;
        if (!(s2 > 0) || !(c2 > 0)) return 0;
        const double sigma = std::sqrt(s2);
        const double x = sqr(a_b) / s2;  // the base's share; the coat's two halves have y = 1/2
        const SlopeSumTable& table = SlopeSumTable::get();
        const SlopeSumTable::Shares at = SlopeSumTable::locate(x, 0.5);
        auto density = [&](double r) {
            return s2 * kInvPi<double> / sqr(s2 + r * r) * table.ratio(r / sigma, at);
        };
        const double t2 = std::max(0.0, 1 - c2) / c2, t = std::sqrt(t2);
        if (ch_.first_order_lobe != Lamina1Choices::FirstOrderLobe::Compressed || !(a_c > 0))
            return density(t) / sqr(c2);
        // The coat's share 1 − x, half through the entering facet's map, half the leaving one's.
        double p = x * density(t);
        const double g = 2 * (1 - inv_eta0_) * std::atan(t) / k;
        for (const FacetDeflection* map : {&entering_, &leaving_}) {
            double sin_d, cos_d, w;
            if (!map->lookup(g, sin_d, cos_d, w)) continue;
            const double S = 0.5 * k * sin_d / cos_d;
            // P(t) t dt = P_S(S) S dS: dS/dt = sec²δ k_n / ((1 + t²) g'(δ)), S/t → 1 at 0.
            const double s_over_t = t > 1e-12 ? S / t : 1.0;
            p += 0.5 * (1 - x) * density(S) * s_over_t * w / (cos_d * cos_d * (1 + t2));
        }
        return p / sqr(c2);
    }

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

    /// α_e² = α1² + (α0 k_i/2)² + (α0 k_o/2)²: a deflection of the light by ε turns the mirror
    /// direction by ε, i.e. its half vector by ε/2; independent spreads add in variance (the
    /// variance adding of Belcour 2018, §5, with GGX's α as the slope scale).
    double effective_alpha(double k_i, double k_o) const {
        if (ch_.spread == Lamina1Choices::Spread::Off) return alpha1_;
        return std::sqrt(sqr(alpha1_) + 0.25 * sqr(alpha0_) * (sqr(k_i) + sqr(k_o)));
    }

    /// β² = ((α0 k_top)² + (α1 k_bottom)²)/4: the mirrored lobe of a slab's transmission.
    double transmission_roughness(double k_top, double k_bottom) const {
        if (ch_.spread == Lamina1Choices::Spread::Off) return std::max(alpha0_, alpha1_);
        return 0.5 * std::sqrt(sqr(alpha0_ * k_top) + sqr(alpha1_ * k_bottom));
    }

    /// α_b² = α1² + (α0 k_top/k_bottom)²: the coat turns the light inside by α0 k_top (per unit
    /// slope), which a bottom facet of slope s matches with k_bottom s (item 5 of docs/models.md).
    double bottom_roughness(double k_top, double k_bottom) const {
        if (ch_.spread == Lamina1Choices::Spread::Off) return std::max(alpha0_, alpha1_);
        return std::sqrt(sqr(alpha1_) + sqr(alpha0_ * k_top / k_bottom));
    }

    /// The smooth slab's E_1/T_lobe = (1 − F(μ)) a(μ') and E_1 = (1 − F(μ)) a(μ') (1 − F_b(μ')):
    /// first_order_ holds the residual from them (it vanishes with α0 and α1, and the smooth
    /// slab's steep edge at grazing incidence is not interpolated).
    Multi<Rgbd, 2> first_order_smooth(double mu, double mu_in) const {
        Multi<Rgbd, 2> r;
        r.v[0] = attenuation(mu_in) * (1 - fresnel_dielectric(mu, eta0_));
        r.v[1] = r.v[0] * (1 - fresnel_dielectric(mu_in, eta_b_));
        return r;
    }

    /// The slab bottom as a single rough interface seen from inside the coat (wi inside, up).
    DielectricInterface<double> bottom_btdf(double alpha) const {
        DielectricInterface<double> d{eta_b_, alpha};
        d.transmission_masking = ch_.masking;
        return d;
    }

    double spread_factor(double mu, double mu_in, double eta) const {
        if (ch_.spread == Lamina1Choices::Spread::Normal) return std::abs(1 - 1 / eta);
        return deflection(mu, mu_in, eta);
    }

    /// X(μ); exact for a Lambertian base when the light enters along the refracted direction
    /// (X = T(μ) a(μ') ρ r̄), else the per-material curve.
    Rgbd X_at(double mu) const {
        if (!x_exact_) return X_(mu);
        return coat_.albedo * r_bar_ *
               attenuation(refract_in(Vec3d(safe_sqrt(1 - mu * mu), 0, mu), inv_eta0_).z) *
               T_top_(mu);
    }

    /// The inside direction (pointing up) whose refraction through a flat interface of relative
    /// index 1/inv_eta is w (w.z > 0, entering a denser medium: always exists).
    static Vec3d refract_in(const Vec3d& w, double inv_eta) {
        return {w.x * inv_eta, w.y * inv_eta, safe_sqrt(1 - (1 - w.z * w.z) * sqr(inv_eta))};
    }
    static std::optional<Vec3d> refract_in_checked(const Vec3d& w, double inv_eta) {
        const double s2 = (1 - w.z * w.z) * sqr(inv_eta);
        if (s2 >= 1) return std::nullopt;
        return Vec3d(w.x * inv_eta, w.y * inv_eta, std::sqrt(1 - s2));
    }

    /// The straight-through direction with cosine cos_t below the surface, opposite wi's azimuth.
    static Vec3d transmitted_direction(const Vec3d& wi, double cos_t) {
        const double s = std::hypot(wi.x, wi.y);
        const double sin_t = safe_sqrt(1 - cos_t * cos_t);
        if (s == 0) return {0, 0, -1};
        return {-sin_t * wi.x / s, -sin_t * wi.y / s, -cos_t};
    }

    /// Beer–Lambert along one path at inside cosine μ: exp(−τ/μ).
    Rgbd attenuation(double mu) const {
        if (!has_absorption_) return Rgbd(1.0);
        if (mu <= 0) return Rgbd(0.0);
        return beer_lambert(tau_t_, 1 / mu);
    }

    Rgbd base_fresnel(double c) const {
        switch (coat_.base_type) {
            case InterfaceType::Conductor:
                return fresnel_complex_rgb(c, coat_.base_eta, coat_.base_k);
            case InterfaceType::Dielectric:
                return Rgbd(fresnel_dielectric(c, eta_b_));
            case InterfaceType::Lambertian:
                break;
        }
        return coat_.albedo;
    }

    /// The albedo of the mirror that stands for a conductor or dielectric base in the scattered
    /// light's paths: its Fresnel reflectance when smooth (exact), else its directional albedo.
    Rgbd mirror_albedo(double mu) const {
        return alpha1_ == 0 ? base_fresnel(mu) : mirror_albedo_curve_(mu);
    }

    /// The base's directional albedo seen from inside the coat, at inside cosine μ.
    Rgbd base_albedo(double mu) const {
        const Rgbd ms = base_ms_ ? F_ms_ * dE_base_(mu) : Rgbd(0.0);
        switch (coat_.base_type) {
            case InterfaceType::Conductor:
                return FgdTable::get().rgb(mu, alpha1_, base_fgd_) + ms;
            case InterfaceType::Dielectric:
                return Rgbd(FgdTable::get()(mu, alpha1_, eta_b_, 0.0)) + ms;
            case InterfaceType::Lambertian:
                break;
        }
        return coat_.albedo;
    }

    void precompute();
    void precompute_scattering();
    void precompute_slab();

    Lamina1Choices ch_;
    CoatedStack coat_;
    Support support_;
    double eta0_ = 1.5, inv_eta0_ = 1 / 1.5, alpha0_ = 0, alpha1_ = 0;
    double eta_b_ = 1, eta_s_ = 1;
    bool has_absorption_ = false;
    std::array<FgdTable::Index, 3> base_fgd_{};
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
    CosineCurve<Rgbd, kNx> X_;
    Rgbd K_{0.0};                 ///< the separable term's normalization
    Rgbd inv_one_minus_Er_{0.0};  ///< 1/(1 − Ē_b r̄)
    Rgbd r_bar_{0.0}, E_bar_{0.0}, t_bar_{0.0}, X_bar_{0.0};
    /// Multiple scattering: the coat's ΔR from outside and its hemispherical 2∫ΔR μ dμ; the base's
    /// ΔE (conductor: white, times F_ms; dielectric: ΔR, F_ms = 1) and its average.
    bool top_ms_ = false, base_ms_ = false;
    bool inside_exit_ = false;  ///< exit_transmittance in the first order (see Lamina1Choices)
    bool mirror_series_ = false;
    bool lobe_norm_on_ = false;
    /// first-order-lobe compressed or sum: first_order_ndf in place of the GGX of α_e (a coat
    /// with α0 > 0 over a conductor or dielectric base, the spread on); the facet maps it uses.
    bool shaped_lobe_ = false;
    FacetDeflection entering_, leaving_;
    /// 1/√N(μ'): N is the energy of the base lobe whose width follows wo (α_e(k_i, k_o)) over that
    /// of the lobe of fixed width α_e(k_i, k_i), over the exit cone, at inside cosine μ'.
    CosineCurve<double, kNnorm> lobe_norm_;
    /// √(1/(1 − a² R_in E_b (1 − u))) over inside cosines: the first order's round trips.
    CosineCurve<Rgbd> mirror_series_curve_;
    CosineCurve<double> dR_top_, dE_base_;
    double dR_top_bar_ = 1, dE_base_bar_ = 1;
    Rgbd F_ms_{1.0};
    /// Scattering media (precompute_scattering): τt, ϖ = τs/τt, g equal in the three channels.
    Rgbd tau_t_{0.0}, omega_{0.0};
    bool scatters_ = false, g_uniform_ = true, single_on_ = false, base_paths_ = false;
    bool orders_on_ = false, back_on_ = false, twice_on_ = false;
    Rgbd g_twice_{0.0};  ///< g² per channel
    /// K(μ): the transmitted remainder's energy over that of the twice-scattered shape.
    CosineCurve<Rgbd, kNx> twice_;
    /// E_ms(μ), E_ms,T(μ): the energy of the scattered remainder leaving through the top and the
    /// bottom per unit flux arriving at μ; their lobes' normalizations 1/(π Ē_ms), 1/(π T̄_b).
    CosineCurve<Rgbd, kNx> orders_, orders_t_;
    Rgbd orders_norm_{0.0};
    double orders_t_norm_ = 0;
    /// A rough base's directional albedo over inside cosines (mirror_albedo; one lookup instead
    /// of the FGD table's three).
    CosineCurve<Rgbd, kNmu> mirror_albedo_curve_;
    /// The explicit single scattering's energy at μ (the sampler's mixture weight).
    CosineCurve<Rgbd, kNx> single_energy_, single_energy_t_;
    /// The slab's first order through the bottom's BTDF (Lamina1Choices::btdf_bottom_lobe):
    /// E_1(μ), the energy it transmits per unit flux arriving at outside cosine μ.
    bool bottom_lobe_ = false;
    /// E_1(μ)/T_lobe(μ) and E_1(μ) (v[0], v[1]) over outside cosines.
    CosineCurve<Multi<Rgbd, 3>, kNfirst> first_order_;
    /// The slab's later orders as two populations of inside light (Lamina1Choices::
    /// btdf_populations): Incident::trapped over outside cosines, and T_{below→p}(μ), the light
    /// arriving from below at μ that the bottom lets into population p.
    bool populations_ = false;
    CosineCurve<Multi<Rgbd, 3>, kNslab> trapped_;
    CosineCurve<Multi<double, 2>, kNslab> enter_below_;

    friend class SplitIncidentEvaluator<Lamina1>;
};

void Lamina1::precompute() {
    inside_exit_ = ch_.inside_exit && alpha0_ > 0 && ch_.directional_transmittance &&
                   coat_.base_type != InterfaceType::Lambertian;
    const auto& table = CoatTransmittanceTable::get(ch_.masking);
    const auto& fgd = FgdTable::get();
    // The base lobe's width follows wo through k_o, so the lobe is not normalized: its energy over
    // the exit cone exceeds that of the lobe of fixed width α_e(k_i, k_i) by N(μi') (up to 2×
    // in the tails under rough, low-index coats). Divided out reciprocally, by √N(μi') √N(μo').
    // N by the fixed lobe's visible normals (Heitz 2018), the varying lobe weighted by its ratio.
    shaped_lobe_ = ch_.first_order_lobe != Lamina1Choices::FirstOrderLobe::Ggx && alpha0_ > 0 &&
                   eta0_ > 1 && coat_.base_type != InterfaceType::Lambertian &&
                   ch_.spread != Lamina1Choices::Spread::Off;
    if (shaped_lobe_ && ch_.first_order_lobe == Lamina1Choices::FirstOrderLobe::Compressed) {
        entering_.build(true, eta0_, alpha0_);
        leaving_.build(false, eta0_, alpha0_);
    }
    lobe_norm_on_ = ch_.lobe_normalization && alpha0_ > 0 &&
                    coat_.base_type != InterfaceType::Lambertian &&
                    ch_.spread == Lamina1Choices::Spread::Angular;
    if (lobe_norm_on_) {
        static const QuadratureRule qn = gauss_legendre(kNormNr);
        const double mu_crit_in = std::sqrt(1 - sqr(inv_eta0_));
        lobe_norm_.fill([&](double mu) {
            const double mu_in = std::max(mu, mu_crit_in + 1e-6);
            const Vec3d w(safe_sqrt(1 - mu_in * mu_in), 0, mu_in);
            const double mu_out_i = safe_sqrt(1 - (1 - mu_in * mu_in) * sqr(eta0_));
            const double k_i = spread_factor(mu_out_i, mu_in, eta0_);
            const double alpha_f = effective_alpha(k_i, k_i);
            if (alpha_f <= 0) return 1.0;
            const GGX<double> fixed{alpha_f};
            double sum_fixed = 0, sum_var = 0;
            for (int a = 0; a < kNormNr; ++a)
                for (int b = 0; b < kNormNphi; ++b) {
                    const double r = qn.x[a], w_r = qn.w[a] * 2 * r / kNormNphi;
                    const Vec3d wm =
                        fixed.sample_visible_normal(w, r * r, 0.5 * (b + 0.5) / kNormNphi - 0.25);
                    const Vec3d wo = reflect(w, wm);
                    if (wo.z <= mu_crit_in) continue;  // beyond the exit cone (or below)
                    const double mu_out = safe_sqrt(1 - (1 - wo.z * wo.z) * sqr(eta0_));
                    const double k_o = spread_factor(mu_out, wo.z, eta0_);
                    const GGX<double> var{effective_alpha(k_i, k_o)};
                    const double g_fixed = fixed.G2(w, wo) / fixed.G1(w);
                    sum_fixed += w_r * g_fixed;
                    // f_var / f_fixed = D_var G2_var / (D_fixed G2_fixed) at the same half vector
                    // (D_var the shaped lobe's where first-order-lobe shapes it).
                    const double D_var = shaped_lobe_ ? first_order_ndf(wm, k_i, k_o) : var.D(wm);
                    sum_var +=
                        w_r * g_fixed * D_var * var.G2(w, wo) / (fixed.D(wm) * fixed.G2(w, wo));
                }
            return sum_fixed > 0 && sum_var > 0 ? std::sqrt(sum_fixed / sum_var) : 1.0;
        });
    }
    const MultipleScatteringAlbedo* ms =
        ch_.multiple_scattering ? &MultipleScatteringAlbedo::get() : nullptr;
    auto transmittance = [&](double mu, double alpha, double eta) {
        const double t =
            ch_.directional_transmittance ? table(mu, alpha, eta) : 1 - fresnel_dielectric(mu, eta);
        return ms ? t + ms->dielectric(mu, alpha, eta).transmitted : t;
    };
    auto setup = [&](Transmittance& t, double alpha, double eta) {
        t.eta = eta;
        t.exact = alpha == 0 || (!ch_.directional_transmittance && !ms);
        if (!t.exact)
            t.curve.fill(eta < 1 ? std::sqrt(1 - eta * eta) : 0.0,
                         [&](double mu) { return transmittance(mu, alpha, eta); });
    };
    setup(T_top_, alpha0_, eta0_);
    setup(T_top_in_, alpha0_, inv_eta0_);
    if (support_.btdf) {
        setup(T_bot_, alpha1_, eta_s_);
        setup(T_bot_in_, alpha1_, eta_b_);
    }

    // The coat's bottom seen from inside: R_in(μ) = FGD(μ, α0, 1/η0) (total internal reflection
    // included), and g(μ) = a(μ)² R_in(μ) for a return trip base → coat → base.
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    auto R_in = [&](double mu) {
        const double r = fgd(mu, alpha0_, inv_eta0_, 0.0);
        return ms ? r + ms->dielectric(mu, alpha0_, inv_eta0_).reflected : r;
    };
    // Multiple scattering's separable lobes: the coat's from outside, the base's from inside.
    top_ms_ = ms && alpha0_ > 0;
    if (top_ms_) {
        dR_top_.fill([&](double mu) { return ms->dielectric(mu, alpha0_, eta0_).reflected; });
        dR_top_bar_ =
            integrate_split01<kGauss, double>([&](double mu) { return dR_top_(mu) * 2 * mu; }, 0.0);
        top_ms_ = dR_top_bar_ > 0;
    }
    base_ms_ = ms && alpha1_ > 0 && coat_.base_type != InterfaceType::Lambertian;
    if (base_ms_) {
        if (coat_.base_type == InterfaceType::Conductor) {
            dE_base_.fill([&](double mu) { return ms->conductor(mu, alpha1_); });
        } else {
            dE_base_.fill([&](double mu) { return ms->dielectric(mu, alpha1_, eta_b_).reflected; });
        }
        dE_base_bar_ = integrate_split01<kGauss, double>(
            [&](double mu) { return dE_base_(mu) * 2 * mu; }, 0.0);
        base_ms_ = dE_base_bar_ > 0;
        if (base_ms_ && coat_.base_type == InterfaceType::Conductor) {
            // Each further facet multiplies by the conductor's Fresnel factor: with its
            // hemispherical average F̄ and the white surface's E_avg = 1 − ΔĒ, the orders ≥ 2
            // carry ΔE(μ) F̄² E_avg / (1 − F̄ (1 − E_avg)) (Kulla & Conty 2017, the F_ms factor:
            // one more bounce F̄, then escape E_avg or another bounce, summed).
            const Rgbd F_avg = integrate_split01<kGauss, Rgbd>(
                [&](double mu) {
                    return fresnel_complex_rgb(mu, coat_.base_eta, coat_.base_k) * (2 * mu);
                },
                0.0);
            const double E_avg = 1 - dE_base_bar_;
            for (int c = 0; c < 3; ++c)
                F_ms_[c] = sqr(F_avg[c]) * E_avg / (1 - F_avg[c] * (1 - E_avg));
        }
    }
    r_bar_ = integrate_split01<kGauss, Rgbd>(
        [&](double mu) { return attenuation(mu) * attenuation(mu) * (2 * mu * R_in(mu)); },
        mu_crit);
    // What the first order does not send out is returned: light inside at μ'' within the exit
    // cone leaves in the first order with the outside transmittance T(μ) (exact for a locally
    // uniform inside radiance, by reciprocity), so the part returned to the base is
    // R_eff = 1 − loss − T(μ) = R_in + T_in − T(μ), where R_in + T_in + loss = 1 from inside. For
    // a smooth coat T_in = T and R_eff = R_in; for a rough one the facets' total internal
    // reflection makes T_in < T near the critical angle, and R_in alone would count that light
    // twice. Beyond the cone nothing leaves in the first order and R_eff = R_in.
    auto g_direct = [&](double mu) {
        const Rgbd a = attenuation(mu);
        double R = R_in(mu);
        if (alpha0_ > 0 && mu > mu_crit) {
            const double mu_out = safe_sqrt(1 - (1 - mu * mu) * sqr(eta0_));
            const double T_exit =
                inside_exit_ ? exit_transmittance(mu_out, mu, spread_factor(mu_out, mu, eta0_))
                             : T_top_(mu_out);
            R = std::max(0.0, R + T_top_in_(mu) - T_exit);
        }
        return a * a * R;
    };
    // Tabulated once (Y's quadrature looks it up at every node); the node μ = 0 is taken at 1e-6,
    // where an index-matched coat's Fresnel factor is its limit 0 (not the 0/0 of grazing).
    SplitCurve<33> g_curve;
    g_curve.fill(mu_crit, [&](double mu) { return g_direct(std::max(mu, 1e-6)); });
    auto g = [&](double mu) { return g_curve(mu); };
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    E_bar_ = integrate_split01<kGauss, Rgbd>([&](double mu) { return base_albedo(mu) * (2 * mu); },
                                             mu_crit_b);
    auto inside_cos = [&](double mu) { return safe_sqrt(1 - (1 - mu * mu) * sqr(inv_eta0_)); };
    t_bar_ =
        integrate_split01<kGauss, Rgbd>(
            [&](double mu) { return attenuation(inside_cos(mu)) * (2 * mu * T_top_(mu)); }, 0.0) *
        sqr(inv_eta0_);

    // The mean direction of the light a rough coat transmits (slab BTDF): the visible facets at
    // grazing incidence lean towards the light and turn the refracted light away from the normal
    // (by k δ per facet tilt δ, item 4 of docs/models.md), so its mean lies beyond the macro
    // refraction — near grazing, beyond a slab's exit cone. By the coat's visible-normal rule.
    mean_shift_ = support_.btdf && alpha0_ > 0 && ch_.directional_transmittance && ch_.mean_shift;
    // (With btdf-lobe=bottom, precompute_slab computes it by its own rule, with the first order.)
    if (mean_shift_ && !ch_.btdf_bottom_lobe) {
        static const QuadratureRule q = gauss_legendre(kYnr);
        const GGX<double> ggx0{alpha0_};
        mu_mean_.fill([&](double mu) {
            const Vec3d w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
            double x = 0, z = 0;
            for (int a = 0; a < kYnr; ++a)
                for (int b = 0; b < kYnphi; ++b) {
                    const double r = q.x[a], w_r = q.w[a] * 2 * r;
                    const Vec3d wm =
                        ggx0.sample_visible_normal(w, r * r, 0.5 * (b + 0.5) / kYnphi - 0.25);
                    const auto wt = refract(w, wm, eta0_);
                    if (!wt || wt->z >= 0) continue;
                    const double wgt = (1 - fresnel_dielectric(dot(w, wm), eta0_)) * w_r;
                    x += wgt * wt->x;  // −wt: the inside direction pointing up, in −x
                    z += wgt * -wt->z;
                }
            const double len = std::hypot(x, z);
            // Stored as the shift from the macro refraction (which the lookup adds back exactly):
            // it vanishes with α0, and so does its interpolation error under narrow lobes.
            return (len > 0 ? z / len : inside_cos(mu)) - inside_cos(mu);
        });
    }

    const bool smooth_base = coat_.base_type != InterfaceType::Lambertian && alpha1_ == 0;
    series_on_ = ch_.inter_reflection && !(smooth_base && alpha0_ == 0) &&
                 (coat_.base_type == InterfaceType::Lambertian || !ch_.series_lambertian_only ||
                  alpha1_ >= alpha0_);
    series_btdf_ = series_on_ && !ch_.series_lambertian_only;
    // Where the uniform series is off (a base smoother than the rough coat), the light the coat's
    // bottom returns meets a base that keeps its direction: it stays in the first order's lobe,
    // which each round trip multiplies by a² R_in E_b, summed as the smooth stack's delta series
    // is (docs/physics.md §6.5 of the study), over the part (1 − u) the base does not spread.
    mirror_series_ = ch_.inter_reflection && inside_exit_ && !series_on_;
    if (mirror_series_) {
        mirror_series_curve_.fill([&](double mu) {
            const double mu_in = std::max(mu, mu_crit + 1e-9);
            const double mu_out = safe_sqrt(1 - (1 - mu_in * mu_in) * sqr(eta0_));
            const double spread2 = sqr(0.5 * alpha0_ * spread_factor(mu_out, mu_in, eta0_));
            const double u = spread2 > 0 ? sqr(alpha1_) / (sqr(alpha1_) + spread2) : 1.0;
            const Rgbd a = attenuation(mu_in);
            const Rgbd round_trip = a * a * base_albedo(mu_in) * (R_in(mu_in) * (1 - u));
            Rgbd S(1.0);
            for (int c = 0; c < 3; ++c)
                S[c] = 1 / std::sqrt(std::max(1e-6, 1 - round_trip[c]));  // √ of 1/(1 − ·)
            return S;
        });
    }
    if (!series_on_) return;
    // Y(μ') = ∫ f_b(w', w'') μ'' g(μ'') dω'': what the base's first reflection of light arriving
    // at inside cosine μ' sends back down after one reflection at the coat's bottom.
    // The base's separable multiple-scattering lobe sends F_ms ΔE(μ') ∫ ΔE g 2μ'' dμ'' / ΔĒ.
    const Rgbd Y_ms =
        base_ms_ ? integrate_split01<kGauss, Rgbd>(
                       [&](double mu) { return g(mu) * (dE_base_(mu) * 2 * mu); }, mu_crit) *
                       (1 / dE_base_bar_)
                 : Rgbd(0.0);
    auto Y = [&](double mu) -> Rgbd {
        if (coat_.base_type == InterfaceType::Lambertian) return coat_.albedo * r_bar_;
        if (smooth_base) return base_fresnel(mu) * g(mu);
        const GGX<double> ggx{alpha1_};
        const Vec3d w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        const double lambda_w = ggx.lambda(w);
        // Visible-normal weight: f_b μ'' dω'' = D_w F G2/G1 dwm (Heitz 2018, §2).
        auto f_y = [&](const Vec3d& wm) {
            const Vec3d w2 = reflect(w, wm);
            if (w2.z <= 0) return Rgbd(0.0);
            const double escape = (1 + lambda_w) / (1 + lambda_w + ggx.lambda(w2));
            return base_fresnel(dot(w, wm)) * g(w2.z) * escape;
        };
        static const QuadratureRule q = gauss_legendre(kSplitNr);
        constexpr double kTol = 1.0 / (1 << kSplitBisections);
        const Crossing coat_edge{[&](const Vec3d& wm) { return reflect(w, wm).z; }, mu_crit};
        // A slab's bottom reflects totally from facets seen beyond its critical cosine: its
        // Fresnel factor steps there too (unsplit, 3e-3 of a slab's albedo at α1 = 0.3).
        Rgbd sum = mu_crit_b > 0 && coat_.base_type == InterfaceType::Dielectric
                       ? integrate_visible_split<Rgbd>(
                             ggx, w, f_y, q, kSplitNphi, kTol, coat_edge,
                             Crossing{[&](const Vec3d& wm) { return dot(w, wm); }, mu_crit_b})
                       : integrate_visible_split<Rgbd>(ggx, w, f_y, q, kSplitNphi, kTol, coat_edge);
        if (base_ms_) sum += F_ms_ * Y_ms * dE_base_(mu);
        return sum;
    };
    x_exact_ = coat_.base_type == InterfaceType::Lambertian &&
               (alpha0_ == 0 || !ch_.directional_transmittance);
    // X (and K, X̄) serve the separable series alone: where it is off (a base smoother than the
    // coat, inter-reflection=off) they are not computed (X stays 0, never read).
    if (x_exact_ || !series_on_) {
    } else if (alpha0_ == 0 || !ch_.directional_transmittance) {
        // The light enters along the refracted direction (smooth coat) or is taken to.
        X_.fill([&](double mu) {
            const double mu_in = inside_cos(mu);
            return Y(mu_in) * attenuation(mu_in) * T_top_(mu);
        });
    } else {
        // A rough coat spreads the entering light over the inside directions, beyond the critical
        // cone too (light there cannot leave through the first order and is returned): X(μ) =
        // ∫ t(μ → w') a(μ_w') Y(μ_w') dω' over the coat's transmitted light, by the visible-
        // normal rule of the coat (weight (1 − F) G_t/G1, as in its transmittance table).
        SplitCurve<17> Y_curve;
        Y_curve.fill(mu_crit, Y);
        const GGX<double> ggx0{alpha0_};
        // The coat's orders ≥ 2 transmit ΔT(μ) more, spread over the inside directions: taken
        // as cosine-distributed, they return the hemispherical average of a Y.
        const Rgbd Y_spread =
            ms ? integrate_split01<kGauss, Rgbd>(
                     [&](double mu) { return Y_curve(mu) * attenuation(mu) * (2 * mu); }, mu_crit)
               : Rgbd(0.0);
        X_.fill([&](double mu) {
            const Vec3d w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
            const double lambda_w = ggx0.lambda(w);
            // The refracted direction's inside cosine −wt.z; Y_curve steps at μc.
            auto inside_z = [&](const Vec3d& wm) {
                const auto wt = refract(w, wm, eta0_);
                return wt ? -wt->z : 0.0;
            };
            Rgbd sum = integrate_visible_split<Rgbd, kSplitNr, kSplitNphi, kSplitBisections>(
                ggx0, w, mu_crit, inside_z, [&](const Vec3d& wm) {
                    const auto wt = refract(w, wm, eta0_);
                    if (!wt || wt->z >= 0) return Rgbd(0.0);
                    const double F = fresnel_dielectric(dot(w, wm), eta0_);
                    const double escape =
                        refraction_escape(ch_.masking, lambda_w, ggx0.lambda(*wt));
                    return Y_curve(-wt->z) * attenuation(-wt->z) * ((1 - F) * escape);
                });
            if (ms) sum += Y_spread * ms->dielectric(mu, alpha0_, eta0_).transmitted;
            return sum;
        });
    }
    // X̄ = (2/η0²)∫ X(μ) μ dμ: the diffuse exit's normalization.
    X_bar_ = integrate_split01<kGauss, Rgbd>([&](double mu) { return X_at(mu) * (2 * mu); }, 0.0) *
             sqr(inv_eta0_);
    for (int c = 0; c < 3; ++c) {
        const double one_minus = 1 - E_bar_[c] * r_bar_[c];
        inv_one_minus_Er_[c] = one_minus > 0 ? 1 / one_minus : 0;
        // The separable term X(μi)X(μo)K/(πη0²) must leave with the series' energy
        // X(μi) Ē_b t̄/(1 − Ē_b r̄): ∫ X(μo)/(πη0²) μo dωo = X̄ fixes K.
        K_[c] = X_bar_[c] > 0 ? E_bar_[c] * t_bar_[c] * inv_one_minus_Er_[c] / X_bar_[c] : 0;
    }
}

void Lamina1::precompute_scattering() {
    for (int c = 0; c < 3; ++c)
        omega_[c] = tau_t_[c] > 0 ? coat_.tau_s[c] / tau_t_[c] : 0.0;
    g_uniform_ = coat_.g[0] == coat_.g[1] && coat_.g[0] == coat_.g[2];
    const bool lambertian = coat_.base_type == InterfaceType::Lambertian;
    single_on_ = ch_.medium_single || (ch_.medium_base_paths && !lambertian);
    base_paths_ = ch_.medium_base_paths && !lambertian;
    back_on_ = ch_.medium_single;
    if (!lambertian && alpha1_ > 0)
        mirror_albedo_curve_.fill([&](double mu) { return base_albedo(std::max(mu, 1e-6)); });
    orders_on_ = ch_.medium_orders;
    twice_on_ = orders_on_ && support_.btdf && ch_.medium_transmitted_twice;
    g_twice_ = coat_.g * coat_.g;

    // The energies, by the azimuth-averaged adding of coat bottom, medium and base on 6 + 6
    // inside cosines (split at the critical cosine, where the coat's bottom steps): a unit flux
    // entering the medium at node k reaches the outside (top) or the half-space below (bottom)
    // with the fractions e·L·(I − r L)⁻¹ and t_b·G·(I − r L)⁻¹, where the medium and base send
    // back L = R + T B (I − R B)⁻¹ T and down to the bottom G = (I − R B)⁻¹ T, r is the coat
    // bottom's reflectance, e its exit (T(μ) outside: the uniform-radiance exit of the first
    // order), B the base (Lambertian: ρ 2μ_j w_j; otherwise a mirror of albedo E_b(μ_j)).
    const auto& fgd = FgdTable::get();
    const MultipleScatteringAlbedo* ms =
        ch_.multiple_scattering ? &MultipleScatteringAlbedo::get() : nullptr;
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    const CosineNodes nodes = split_cosine_nodes(6, mu_crit);
    const int n = nodes.size();
    std::vector<double> exit(n, 0.0), returned(n, 0.0), bottom(n, 0.0), bottom_single(n, 0.0);
    std::vector<Rgbd> E_nodes(n), a_nodes(n);
    for (int j = 0; j < n; ++j) {
        const double mu = nodes.mu[j];
        double R = fgd(mu, alpha0_, inv_eta0_, 0.0);
        if (ms) R += ms->dielectric(mu, alpha0_, inv_eta0_).reflected;
        if (mu > mu_crit) {
            exit[j] = T_top_(safe_sqrt(1 - (1 - mu * mu) * sqr(eta0_)));
            // What the exit does not take is returned (as R_eff in precompute).
            R = alpha0_ > 0 ? std::max(0.0, R + T_top_in_(mu) - exit[j]) : R;
        }
        returned[j] = R;
        if (support_.btdf) {
            bottom[j] = T_bot_in_(mu);
            // The once-scattered light's exit: T_b at the cosine it leaves with below.
            const double s2 = sqr(eta_s_) * (1 - mu * mu);
            bottom_single[j] = s2 < 1 ? T_bot_(std::sqrt(1 - s2)) : 0.0;
        }
        E_nodes[j] = lambertian ? coat_.albedo : mirror_albedo(mu);
        a_nodes[j] = attenuation(mu);
    }
    const FluxMatrix I = FluxMatrix::identity(n), r = FluxMatrix::diagonal(returned);
    AzimuthalPhase phase;
    std::vector<double> twice_phase;
    std::array<std::vector<double>, 3> top_left{}, bottom_left{}, single_left{}, single_bottom{},
        twice_bottom{};
    for (int c = 0; c < 3; ++c) {
        // Channels with the same medium and base share the computation.
        int same = -1;
        for (int c2 = 0; c2 < c && same < 0; ++c2) {
            bool eq =
                tau_t_[c2] == tau_t_[c] && omega_[c2] == omega_[c] && coat_.g[c2] == coat_.g[c];
            for (int j = 0; j < n && eq; ++j)
                eq = E_nodes[j][c2] == E_nodes[j][c];
            if (eq) same = c2;
        }
        if (same >= 0) {
            top_left[c] = top_left[same];
            bottom_left[c] = bottom_left[same];
            single_left[c] = single_left[same];
            single_bottom[c] = single_bottom[same];
            twice_bottom[c] = twice_bottom[same];
            continue;
        }
        // The phase matrices depend on g alone: computed once for channels of equal g.
        if (c == 0 || coat_.g[c] != coat_.g[c - 1]) phase = azimuthal_hg(nodes, coat_.g[c]);
        const SlabMatrices slab = hg_slab(nodes, phase, tau_t_[c], omega_[c]);
        FluxMatrix B(n);
        std::vector<double> E(n), a(n);
        for (int j = 0; j < n; ++j) {
            E[j] = E_nodes[j][c];
            a[j] = a_nodes[j][c];
            if (lambertian) {
                for (int k = 0; k < n; ++k)
                    B(j, k) = coat_.albedo[c] * 2 * nodes.mu[j] * nodes.w[j];
            } else {
                B(j, j) = E[j];
            }
        }
        const FluxMatrix G = inverse(I - slab.R * B) * slab.T;
        const FluxMatrix L = slab.R + slab.T * B * G;
        const FluxMatrix M = inverse(I - r * L);
        const FluxMatrix D = FluxMatrix::diagonal(a);
        const FluxMatrix L0 = D * B * D;
        const FluxMatrix M0 = inverse(I - r * L0);
        const std::vector<double> top = row_times(exit, L * M), top0 = row_times(exit, L0 * M0);
        FluxMatrix S(n);
        if (ch_.medium_single) S = hg_single_reflection(nodes, phase, tau_t_[c], omega_[c]);
        if (base_paths_) S = S + hg_single_mirror_paths(nodes, phase, tau_t_[c], omega_[c], E);
        const std::vector<double> single = row_times(exit, S);
        top_left[c].resize(n);
        single_left[c] = single;
        for (int k = 0; k < n; ++k)
            top_left[c][k] = std::max(0.0, top[k] - top0[k] - (single_on_ ? single[k] : 0.0));
        if (support_.btdf) {
            const std::vector<double> bot = row_times(bottom, G * M),
                                      bot0 = row_times(bottom, D * M0);
            // The explicit once-scattered transmission (single_transmission), first exit; and
            // the energy of the twice-scattered shape (HG(g²)) that carries the remainder.
            auto once = [&](const AzimuthalPhase& ph) {
                FluxMatrix ST(n);
                for (int j = 0; j < n; ++j)
                    for (int k = 0; k < n; ++k)
                        ST(j, k) =
                            2 * kPi<double> * nodes.w[j] * nodes.mu[j] * omega_[c] * ph.same(j, k) *
                            attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau_t_[c]);
                return row_times(bottom_single, ST);
            };
            std::vector<double> bot1(n, 0.0);
            if (ch_.medium_single) bot1 = once(phase);
            if (twice_on_) {
                // The shape's energy by its own finer rule: 2 × 24 Gauss–Legendre cosines below
                // the bottom's exit (split at its critical cosine), 32 azimuths (φ = π t²): the
                // adding's 12 cosines under-resolve the forward peak of HG(g²) (≈ 3% low at
                // g = 0.9), and this energy is what normalizes the lobe.
                static const QuadratureRule qm = gauss_legendre(12), qp = gauss_legendre(16);
                const double mu_crit_b = eta_s_ > 1 ? std::sqrt(1 - 1 / sqr(eta_s_)) : 0.0;
                const int nm = 2 * int(qm.x.size());
                auto exit_cos = [&](int m) {
                    const double width = 0.5 * (1 - mu_crit_b);
                    return mu_crit_b + width * ((m >= nm / 2) + qm.x[m % (nm / 2)]);
                };
                // The azimuthal average of HG(g²) between the rule's cosines and the incidences
                // (the nodes and μ' = 1): it depends on g alone, computed once for equal g.
                if (c == 0 || g_twice_[c] != g_twice_[c - 1]) {
                    twice_phase.assign(std::size_t(n + 1) * nm, 0.0);
                    for (int k = 0; k <= n; ++k) {
                        const double mu_k = k < n ? nodes.mu[k] : 1.0,
                                     s_k = safe_sqrt(1 - mu_k * mu_k);
                        for (int m = 0; m < nm; ++m) {
                            const double mu = exit_cos(m), s_m = safe_sqrt(1 - mu * mu);
                            double p0 = 0;
                            for (std::size_t b = 0; b < qp.x.size(); ++b) {
                                const double t = qp.x[b];
                                p0 +=
                                    qp.w[b] * 2 * t *
                                    hg_phase(mu * mu_k + s_m * s_k * std::cos(kPi<double> * t * t),
                                             g_twice_[c]);
                            }
                            twice_phase[std::size_t(k) * nm + m] = p0;
                        }
                    }
                }
                // The rule's weights with the exit and the attenuation at its cosines.
                std::vector<double> exit_weight(nm, 0.0), a_exit(nm, 0.0);
                for (int m = 0; m < nm; ++m) {
                    const double mu = exit_cos(m), s2 = sqr(eta_s_) * (1 - mu * mu);
                    a_exit[m] = std::exp(-tau_t_[c] / mu);
                    if (s2 < 1)
                        exit_weight[m] = 0.5 * (1 - mu_crit_b) * qm.w[m % (nm / 2)] * 2 *
                                         kPi<double> * mu * omega_[c] * T_bot_(std::sqrt(1 - s2));
                }
                auto shape_energy = [&](int k) {
                    const double mu_k = k < n ? nodes.mu[k] : 1.0,
                                 a_k = std::exp(-tau_t_[c] / mu_k);
                    double e = 0;
                    for (int m = 0; m < nm; ++m)
                        if (exit_weight[m] > 0)
                            e += exit_weight[m] * twice_phase[std::size_t(k) * nm + m] *
                                 attenuation_slope(exit_cos(m), mu_k, a_exit[m], a_k, tau_t_[c]);
                    return e;
                };
                // On the nodes, and at μ' = 1 (normal incidence, beyond the last node: the
                // shape's energy changes by 4% there at g = 0.9).
                twice_bottom[c].assign(n + 1, 0.0);
                for (int k = 0; k < n; ++k)
                    twice_bottom[c][k] = shape_energy(k);
                twice_bottom[c][n] = shape_energy(n);
            }
            bottom_left[c].resize(n);
            for (int k = 0; k < n; ++k) {
                bottom_left[c][k] = std::max(0.0, bot[k] - bot0[k] - bot1[k]);
                single_bottom[c].push_back(bot1[k]);
            }
        }
    }
    // Linear in μ' between the nodes, flat beyond the first and the last.
    auto at = [&](const std::array<std::vector<double>, 3>& v, double mu_in) {
        Rgbd out(0.0);
        if (v[0].empty()) return out;
        int k = 0;
        while (k + 1 < n && nodes.mu[k + 1] < mu_in)
            ++k;
        double t = 0;
        if (mu_in <= nodes.mu[0]) {
            t = 0;
        } else if (k + 1 < n) {
            t = (mu_in - nodes.mu[k]) / (nodes.mu[k + 1] - nodes.mu[k]);
        }
        const int k1 = std::min(k + 1, n - 1);
        if (k + 1 >= n) t = 0;
        for (int c = 0; c < 3; ++c)
            out[c] = v[c][k] * (1 - t) + v[c][k1] * t;
        return out;
    };
    auto inside_cos = [&](double mu) { return safe_sqrt(1 - (1 - mu * mu) * sqr(inv_eta0_)); };
    single_energy_.fill([&](double mu) { return at(single_left, inside_cos(mu)) * T_top_(mu); });
    if (support_.btdf && ch_.medium_single)
        single_energy_t_.fill(
            [&](double mu) { return at(single_bottom, inside_cos(mu)) * T_top_(mu); });
    if (!orders_on_) return;
    orders_.fill([&](double mu) { return at(top_left, inside_cos(mu)) * T_top_(mu); });
    const Rgbd orders_bar =
        integrate_split01<kGauss, Rgbd>([&](double mu) { return orders_(mu) * (2 * mu); }, 0.0);
    for (int c = 0; c < 3; ++c)
        // A remainder below kNegligibleEnergy of the incident light is none (its normalization
        // would overflow: 1/Ē of a channel whose albedo is 1e-284).
        orders_norm_[c] = orders_bar[c] > kNegligibleEnergy ? kInvPi<double> / orders_bar[c] : 0.0;
    if (support_.btdf) {
        orders_t_.fill([&](double mu) { return at(bottom_left, inside_cos(mu)) * T_top_(mu); });
        const double T_bar = integrate_split01<kGauss, double>(
            [&](double mu) { return T_bot_(mu) * (2 * mu); }, 0.0);
        orders_t_norm_ = T_bar > 0 ? kInvPi<double> / T_bar : 0.0;
        if (twice_on_)
            twice_.fill([&](double mu) {
                const double mu_in = inside_cos(mu);
                const Rgbd left = at(bottom_left, mu_in);
                Rgbd shape = at(twice_bottom, mu_in);
                if (mu_in > nodes.mu[n - 1]) {  // towards the value at μ' = 1
                    const double t = (mu_in - nodes.mu[n - 1]) / (1 - nodes.mu[n - 1]);
                    for (int c = 0; c < 3; ++c)
                        shape[c] = twice_bottom[c][n - 1] * (1 - t) + twice_bottom[c][n] * t;
                }
                Rgbd K(0.0);
                for (int c = 0; c < 3; ++c)
                    K[c] = shape[c] > kNegligibleEnergy ? left[c] / shape[c] : 0.0;
                return K;
            });
    }
}

void Lamina1::precompute_slab() {
    // An index-matched bottom lets the light straight through (a delta, whatever its roughness):
    // no BTDF lobe of its own, the first order is the mirrored lobe of the coat's spread.
    bottom_lobe_ = support_.btdf && ch_.btdf_bottom_lobe && eta_b_ != 1;
    populations_ = support_.btdf && ch_.btdf_populations && ch_.inter_reflection &&
                   !ch_.multiple_scattering && !(alpha0_ == 0 && alpha1_ == 0);
    if (!bottom_lobe_ && !populations_) return;
    const MultipleScatteringAlbedo* ms =
        ch_.multiple_scattering ? &MultipleScatteringAlbedo::get() : nullptr;
    // Inside directions fall into two populations: 0 within the coat's exit cone (μ ≥ μc), 1
    // beyond it, where a smooth coat reflects everything back.
    const double mu_c = std::sqrt(1 - sqr(inv_eta0_));
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    auto population = [&](double mu) { return mu >= mu_c ? 0 : 1; };
    // The energy of the bottom's lobe of roughness α at inside cosine μ (its transmittance from
    // inside): the coat transmittance table (Walter et al. 2007, Eq. 21 over the visible normals),
    // whose c axis puts the smoothed step of total internal reflection on a node line
    // (models/tables/coat_transmittance.h).
    const CoatTransmittanceTable& table = CoatTransmittanceTable::get(ch_.masking);
    using Rule2 = Multi<Rgbd, 2>;
    using Rule4 = Multi<Rgbd, 4>;

    // ρ_r(μ): the coat's reflection of light inside going up at μ into population r, times the
    // attenuation of the crossing down. From inside the coat is an interface of relative index
    // 1/η0 (total internal reflection beyond μc); rough: its visible normals (Heitz 2018), weight
    // F G2/G1, the reflected direction split at μc.
    SplitCurve<(kNslab + 1) / 2, Rule2> rho;
    auto rho_at = [&](double mu) {
        Rule2 r;
        if (alpha0_ == 0) {
            r.v[population(mu)] = attenuation(mu) * fresnel_dielectric(mu, inv_eta0_);
            return r;
        }
        const GGX<double> ggx0{alpha0_};
        const Vec3d w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        const double lambda_w = ggx0.lambda(w);
        return integrate_visible_split<Rule2, kSlabNr, kSlabNphi, kSlabBisections>(
            ggx0, w, mu_c, [&](const Vec3d& wm) { return reflect(w, wm).z; },
            [&](const Vec3d& wm) {
                Rule2 out;
                const Vec3d w2 = reflect(w, wm);
                if (w2.z <= 0) return out;
                const double escape = (1 + lambda_w) / (1 + lambda_w + ggx0.lambda(w2));
                out.v[population(w2.z)] =
                    attenuation(w2.z) * (fresnel_dielectric(dot(w, wm), inv_eta0_) * escape);
                return out;
            });
    };
    if (populations_) rho.fill(mu_c, [&](double mu) { return rho_at(std::max(mu, 1e-6)); });

    // The bottom seen from inside, light going down at μ: its reflection into population q times
    // the attenuation of the crossing up (v[0], v[1]), and that light after the coat's return,
    // arriving down in population r (v[2 + r]): Σ ∫ R(μ → w'') ρ_r(μ_w'').
    SplitCurve<(kNslab + 1) / 2, Rule4> bottom;
    if (populations_)
        bottom.fill(mu_crit_b, [&](double mu_in) {
            const double mu = std::max(mu_in, 1e-6);
            Rule4 r;
            if (alpha1_ == 0) {
                const Rgbd R = attenuation(mu) * fresnel_dielectric(mu, eta_b_);
                const Rule2 back = rho(mu);
                r.v[population(mu)] = R;
                r.v[2] = R * back.v[0];
                r.v[3] = R * back.v[1];
                return r;
            }
            const GGX<double> ggx1{alpha1_};
            const Vec3d w(safe_sqrt(1 - mu * mu), 0, mu);
            const double lambda_w = ggx1.lambda(w);
            return integrate_visible_split<Rule4, kSlabNr, kSlabNphi, kSlabBisections>(
                ggx1, w, mu_c, [&](const Vec3d& wm) { return reflect(w, wm).z; },
                [&](const Vec3d& wm) {
                    Rule4 out;
                    const Vec3d w2 = reflect(w, wm);
                    if (w2.z <= 0) return out;
                    const double escape = (1 + lambda_w) / (1 + lambda_w + ggx1.lambda(w2));
                    const Rgbd R =
                        attenuation(w2.z) * (fresnel_dielectric(dot(w, wm), eta_b_) * escape);
                    const Rule2 back = rho(w2.z);
                    out.v[population(w2.z)] = R;
                    out.v[2] = R * back.v[0];
                    out.v[3] = R * back.v[1];
                    return out;
                });
        });

    // The light the coat lets in at outside cosine μ, per unit flux, by its own inside direction
    // w' (the coat's transmitted light t(μ → w'), as in X): E_1(μ) = ∫ t a T_b,in dω' leaves
    // through the bottom at once (the first order, v[0]); D_r(μ) = ∫ t a (R ρ_r)(μ_w') dω'
    // comes back down in population r after one reflection at the bottom and one at the coat
    // (v[1 + r]). T_b,in and the bottom's curve step at the bottom's critical cosine: the rule
    // splits there.
    auto entering = [&](double mu_in) {
        Multi<Rgbd, 3> r;
        const Rgbd a = attenuation(mu_in);
        r.v[0] = a * T_bot_in_(mu_in);
        if (populations_) {
            const Rule4 b = bottom(mu_in);
            r.v[1] = a * b.v[2];
            r.v[2] = a * b.v[3];
        }
        return r;
    };
    CosineCurve<Multi<Rgbd, 3>, kNfirst> entry;
    if (alpha0_ == 0 || !ch_.directional_transmittance) {
        entry.fill([&](double mu) {
            const double mu_in = refract_in(Vec3d(safe_sqrt(1 - mu * mu), 0, mu), inv_eta0_).z;
            return entering(mu_in) * T_top_(mu);
        });
    } else {
        const GGX<double> ggx0{alpha0_};
        // The coat's orders ≥ 2 (multiple scattering) transmit ΔT(μ) more, taken as cosine-
        // distributed inside, as in X.
        const Rgbd once_spread =
            ms ? integrate_split01<kGauss, Rgbd>(
                     [&](double mu) { return entering(mu).v[0] * (2 * mu); }, mu_crit_b)
               : Rgbd(0.0);
        auto entry_at = [&](double mu) {
            const Vec3d w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
            const double lambda_w = ggx0.lambda(w);
            auto inside_z = [&](const Vec3d& wm) {
                const auto wt = refract(w, wm, eta0_);
                return wt ? -wt->z : 0.0;
            };
            // v[3] (x, z, ·): the (1 − F)-weighted inside direction, the transmitted light's mean
            // direction for the lobe's centre (item 5 of docs/models.md).
            Multi<Rgbd, 4> sum =
                integrate_visible_split<Multi<Rgbd, 4>, kSlabNr, kSlabNphi, kSlabBisections>(
                    ggx0, w, mu_crit_b, inside_z, [&](const Vec3d& wm) {
                        Multi<Rgbd, 4> out;
                        const auto wt = refract(w, wm, eta0_);
                        if (!wt || wt->z >= 0) return out;
                        const double F = fresnel_dielectric(dot(w, wm), eta0_);
                        const double escape =
                            refraction_escape(ch_.masking, lambda_w, ggx0.lambda(*wt));
                        const Multi<Rgbd, 3> e = entering(-wt->z) * ((1 - F) * escape);
                        for (int i = 0; i < 3; ++i)
                            out.v[i] = e.v[i];
                        out.v[3] = Rgbd(wt->x, -wt->z, 0.0) * (1 - F);
                        return out;
                    });
            if (ms) sum.v[0] += once_spread * ms->dielectric(mu, alpha0_, eta0_).transmitted;
            return sum;
        };
        // The mean direction's curve has twice the nodes (its odd ones interpolated).
        static_assert(2 * (kNfirst - 1) == kNx - 1, "the mean direction shares the nodes");
        for (int i = 0; i < kNfirst; ++i) {
            const double mu = sqr(double(i) / (kNfirst - 1));
            const Multi<Rgbd, 4> e = entry_at(mu);
            for (int k = 0; k < 3; ++k)
                entry.v[i].v[k] = e.v[k];
            if (mean_shift_) {
                // Stored as the shift from the macro refraction, as in precompute.
                const double len = std::hypot(e.v[3][0], e.v[3][1]);
                const double mu_in =
                    refract_in(Vec3d(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)), inv_eta0_).z;
                mu_mean_.v[2 * i] = (len > 0 ? e.v[3][1] / len : mu_in) - mu_in;
                if (i > 0)
                    mu_mean_.v[2 * i - 1] = 0.5 * (mu_mean_.v[2 * i - 2] + mu_mean_.v[2 * i]);
            }
        }
    }

    if (bottom_lobe_) {
        // T_lobe(μ): the energy of the bottom's lobe of roughness α_b at the mean inside direction
        // (both depend on wi only), by its visible normals, split where the facets reflect
        // totally; the lobe is divided by it and carries E_1.
        first_order_.fill([&](double mu) {
            const Incident in = incident(Vec3d(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)));
            Multi<Rgbd, 3> r;
            r.v[1] = entry(mu).v[0];
            const double mu_in = in.ok ? in.wi_in.z : 0.0;
            if (in.ok && in.alpha_b > 0) {
                const double T_lobe = table(in.wi_mean.z, in.alpha_b, eta_b_);
                if (T_lobe > 0) r.v[0] = r.v[1] * (1 / T_lobe);
            }
            // btdf-lobe=shared: Q_m = ∫_cone T_b,in(μv') q(w̄i', v'; β) μv' dωv', the mirrored
            // lobe's energy (as eval_btdf weights it), by the visible normals of β at w̄i', split
            // where the mirrored direction leaves the exit cone.
            const double beta = in.ok ? transmission_roughness(in.k_top, in.k_bottom) : 0.0;
            if (ch_.btdf_lobe_shared && beta > 0) {
                const GGX<double> ggx{beta};
                const Vec3d& w = in.wi_mean;
                const double lambda_w = ggx.lambda(w);
                const double Q_m =
                    integrate_visible_split<double, kSlabNr, kSlabNphi, kSlabBisections>(
                        ggx, w, mu_crit_b, [&](const Vec3d& wm) { return reflect(w, wm).z; },
                        [&](const Vec3d& wm) {
                            const Vec3d v_in = reflect(w, wm);
                            if (v_in.z <= mu_crit_b) return 0.0;
                            return T_bot_in_(v_in.z) * (1 + lambda_w) /
                                   (1 + lambda_w + ggx.lambda(v_in));
                        });
                if (Q_m > 0) r.v[2] = r.v[1] * (1 / Q_m);
            }
            const Multi<Rgbd, 2> smooth = first_order_smooth(mu, mu_in);
            r.v[0] = r.v[0] - smooth.v[0];
            r.v[1] = r.v[1] - smooth.v[1];
            r.v[2] = r.v[2] - smooth.v[0];
            return r;
        });
    }
    if (!populations_) return;

    // T_{below→p}(μ): light arriving from below at μ that the bottom lets into population p. From
    // below the bottom is an interface of relative index η_s (into the denser coat); rough: its
    // visible normals, weight (1 − F) G_t/G1, the refracted direction split at μc.
    enter_below_.fill([&](double mu_out) {
        const double mu = std::max(mu_out, 1e-4);
        Multi<double, 2> r;
        if (alpha1_ == 0) {
            const double mu_in = safe_sqrt(1 - (1 - mu * mu) / sqr(eta_s_));
            r.v[population(mu_in)] = 1 - fresnel_dielectric(mu, eta_s_);
            return r;
        }
        const GGX<double> ggx1{alpha1_};
        const Vec3d w(safe_sqrt(1 - mu * mu), 0, mu);
        const double lambda_w = ggx1.lambda(w);
        auto inside_z = [&](const Vec3d& wm) {
            const auto wt = refract(w, wm, eta_s_);
            return wt ? -wt->z : 0.0;
        };
        return integrate_visible_split<Multi<double, 2>, kSlabNr, kSlabNphi, kSlabBisections>(
            ggx1, w, mu_c, inside_z, [&](const Vec3d& wm) {
                Multi<double, 2> out;
                const auto wt = refract(w, wm, eta_s_);
                if (!wt || wt->z >= 0) return out;
                out.v[population(-wt->z)] =
                    (1 - fresnel_dielectric(dot(w, wm), eta_s_)) *
                    refraction_escape(ch_.masking, lambda_w, ggx1.lambda(*wt));
                return out;
            });
    });

    // After the first return the light is taken as uniform radiance within each population
    // (A_p = ∫_p 2μ dμ): the bottom reflects population p into q with R_pq, the coat returns q
    // into r with ρ_qr, and the bottom lets p out with T_p = (2/(A_p η_s²)) ∫ T_{below→p} μ dμ
    // (reciprocity of the bottom's BTDF). With M = ρ R, the light arriving down summed over every
    // round trip is Φ = (1 − M)⁻¹ D.
    const double A[2] = {1 - sqr(mu_c), sqr(mu_c)};
    const double range[2][2] = {{mu_c, 1.0}, {0.0, mu_c}};
    double T_out[2] = {0, 0};
    Rgbd R_pq[2][2], rho_qr[2][2];
    for (int p = 0; p < 2; ++p) {
        const double lo = range[p][0], hi = range[p][1];
        if (!(A[p] > 0)) continue;
        const Rule4 Rb = integrate_range<Rule4>(
            [&](double mu) { return bottom(std::min(mu, std::nextafter(hi, 0.0))) * (2 * mu); }, lo,
            hi);
        const Rule2 rh = integrate_range<Rule2>(
            [&](double mu) { return rho(std::min(mu, std::nextafter(hi, 0.0))) * (2 * mu); }, lo,
            hi);
        for (int q = 0; q < 2; ++q) {
            R_pq[p][q] = Rb.v[q] * (1 / A[p]);
            rho_qr[p][q] = rh.v[q] * (1 / A[p]);
        }
        T_out[p] = integrate_split01<kGauss, double>(
                       [&](double mu) { return enter_below_(mu).v[p] * (2 * mu); }, 0.0) /
                   (A[p] * sqr(eta_s_));
    }
    trapped_.fill([&](double mu) {
        const Multi<Rgbd, 3> e = entry(mu);
        Multi<Rgbd, 3> r;
        for (int c = 0; c < 3; ++c) {
            // M_rp = Σ_q ρ_qr R_pq; Φ = (1 − M)⁻¹ D by the 2 × 2 inverse.
            double M[2][2];
            for (int rr = 0; rr < 2; ++rr)
                for (int p = 0; p < 2; ++p)
                    M[rr][p] = rho_qr[0][rr][c] * R_pq[p][0][c] + rho_qr[1][rr][c] * R_pq[p][1][c];
            const double a = 1 - M[0][0], b = -M[0][1], cc = -M[1][0], d = 1 - M[1][1];
            const double det = a * d - b * cc;
            if (!(det > 0)) continue;
            const double D0 = e.v[1][c], D1 = e.v[2][c];
            const double phi[2] = {(d * D0 - b * D1) / det, (a * D1 - cc * D0) / det};
            for (int p = 0; p < 2; ++p) {
                if (!(A[p] > 0)) continue;
                r.v[p][c] = phi[p] * kInvPi<double> / (A[p] * sqr(eta_s_));
                r.v[2][c] += phi[p] * T_out[p];
            }
        }
        return r;
    });
}

std::unique_ptr<IncidentEvaluator> Lamina1::prepare(const Vec3d& wi) const {
    return std::make_unique<SplitIncidentEvaluator<Lamina1>>(*this, wi);
}

Lamina1::Mixture Lamina1::mixture(const Incident& in) const {
    Mixture m;
    if (!in.ok) return m;
    m.wi_in = in.wi_in;
    m.wi_mean = in.wi_mean;
    const double a = in.a.mean();
    if (alpha0_ > 0) m.p[0] = fresnel_dielectric(in.wi.z, eta0_);
    const double E_b = base_albedo(in.wi_in.z).mean();
    if (coat_.base_type == InterfaceType::Lambertian) {
        m.p[1] = in.T * a * E_b;
    } else {
        // The base lobe is drawn with its incident-side widening on both sides (k_o ≈ k_i).
        m.alpha_base = effective_alpha(in.k_top, in.k_top);
        if (m.alpha_base > 0) m.p[1] = in.T * a * E_b;
    }
    if (series_on_) m.p[2] = (in.X * K_ * X_bar_).mean();
    m.p[2] += in.dR;  // the coat's separable multiple-scattering lobe, also cosine-distributed
    // A scattering medium's light: broad (its single scattering) or separable (the rest), both
    // drawn with the cosine lobe.
    if (scatters_) {
        if (single_on_) m.p[2] += single_energy_(in.wi.z).mean();
        if (orders_on_) m.p[2] += orders_(in.wi.z).mean();
    }
    if (support_.btdf) {
        m.bottom_sampled = bottom_lobe_ && in.u_bottom >= 0.5;
        m.beta = m.bottom_sampled ? in.alpha_b : transmission_roughness(in.k_top, in.k_bottom);
        if (m.beta > 0)
            m.p[3] = bottom_lobe_ ? in.first_E.mean() : in.T * a * std::max(0.0, 1 - E_b);
        if (populations_)
            m.p[4] = in.trapped.v[2].mean();
        else if (series_btdf_)
            m.p[4] = (in.X * inv_one_minus_Er_).mean() * 0.5;
        if (orders_on_) m.p[4] += orders_t_(in.wi.z).mean();
        if (scatters_ && back_on_) m.p[4] += single_energy_t_(in.wi.z).mean();
    }
    double total = 0;
    for (double p : m.p)
        total += p;
    if (!(total > 0)) return Mixture{};
    for (double& p : m.p)
        p /= total;
    return m;
}

double Lamina1::pdf_with(const Incident& in, const Mixture& m, const Vec3d& wo) const {
    if (!in.ok || wo.z == 0) return 0;
    double pdf = 0;
    if (wo.z > 0) {
        if (m.p[0] > 0) {
            const Vec3d h = normalize(in.wi + wo);
            pdf += m.p[0] * GGX<double>{alpha0_}.D_visible(in.wi, h) / (4 * std::abs(dot(wo, h)));
        }
        if (m.p[1] > 0) {
            if (coat_.base_type == InterfaceType::Lambertian) {
                pdf += m.p[1] * wo.z * kInvPi<double>;
            } else {
                // Drawn inside the coat: dω'/dω = μo/(η0² μo') (Snell's law of solid angles).
                // (A wo refracted onto the horizon, wo' = 0 by rounding, is never drawn: density
                // 0.)
                const Vec3d wo_in = refract_in(wo, inv_eta0_);
                if (wo_in.z > 0) {
                    const Vec3d h = normalize(m.wi_in + wo_in);
                    const double pdf_in = GGX<double>{m.alpha_base}.D_visible(m.wi_in, h) /
                                          (4 * std::abs(dot(wo_in, h)));
                    pdf += m.p[1] * pdf_in * wo.z / (sqr(eta0_) * wo_in.z);
                }
            }
        }
        if (m.p[2] > 0) pdf += m.p[2] * wo.z * kInvPi<double>;
        return pdf;
    }
    if (m.p[3] > 0 && m.bottom_sampled) {
        // Refracted through the visible normals of α_b at the mean inside direction (Walter et
        // al. 2007, Eq. 17: dωm/dωo = η_o² |wo·wm| / (η_i wi·wm + η_o wo·wm)², η_o/η_i = η_b).
        const DielectricInterface<double> bottom = bottom_btdf(m.beta);
        if (const auto wm = bottom.half_vector(m.wi_mean, wo)) {
            const double denom = sqr(dot(m.wi_mean, *wm) + eta_b_ * dot(wo, *wm));
            const double jacobian = sqr(eta_b_) * std::abs(dot(wo, *wm)) / denom;
            // A nearly index-matched bottom straight through: the half vector is rounding noise.
            if (denom > 0 && std::isfinite(jacobian))
                pdf += m.p[3] * GGX<double>{m.beta}.D_visible(m.wi_mean, *wm) * jacobian;
        }
    } else if (m.p[3] > 0) {
        const Vec3d v(wo.x, wo.y, -wo.z);
        if (const auto v_in = refract_in_checked(v, 1 / eta_s_)) {
            const Vec3d h = normalize(m.wi_mean + *v_in);
            const double pdf_in =
                GGX<double>{m.beta}.D_visible(m.wi_mean, h) / (4 * std::abs(dot(*v_in, h)));
            pdf += m.p[3] * pdf_in * v.z / (sqr(eta_s_) * v_in->z);
        }
    }
    if (m.p[4] > 0) pdf += m.p[4] * -wo.z * kInvPi<double>;
    return pdf;
}

std::optional<ModelSample> Lamina1::sample(const Vec3d& wi, const Vec3d& u) const {
    if (!support_.brdf || wi.z <= 0) return std::nullopt;
    const Incident in = incident(wi);
    const Mixture m = mixture(in);
    // u.x picks the lobe, (u.y, u.z) draw its direction.
    int lobe = 0;
    double c = m.p[0];
    while (lobe < 4 && u.x >= c)
        c += m.p[++lobe];
    if (m.p[lobe] <= 0) return std::nullopt;
    Vec3d wo;
    switch (lobe) {
        case 0: {
            const Vec3d wm = GGX<double>{alpha0_}.sample_visible_normal(wi, u.y, u.z);
            wo = reflect(wi, wm);
            if (wo.z <= 0) return std::nullopt;  // shadowed by the coat's microsurface
            break;
        }
        case 1:
            if (coat_.base_type == InterfaceType::Lambertian) {
                wo = sample_cosine_hemisphere(u.y, u.z);
            } else {
                const Vec3d wm = GGX<double>{m.alpha_base}.sample_visible_normal(m.wi_in, u.y, u.z);
                const Vec3d wo_in = reflect(m.wi_in, wm);
                const double s2 = sqr(eta0_) * (1 - sqr(wo_in.z));
                if (wo_in.z <= 0 || s2 >= 1) return std::nullopt;  // shadowed, or totally reflected
                wo = Vec3d(wo_in.x * eta0_, wo_in.y * eta0_, std::sqrt(1 - s2));
            }
            break;
        case 2:
            wo = sample_cosine_hemisphere(u.y, u.z);
            break;
        case 3: {
            const Vec3d wm = GGX<double>{m.beta}.sample_visible_normal(m.wi_mean, u.y, u.z);
            if (m.bottom_sampled) {
                const auto wt = refract(m.wi_mean, wm, eta_b_);
                if (!wt || wt->z >= 0) return std::nullopt;  // totally reflected by the facet
                wo = *wt;
                break;
            }
            const Vec3d v_in = reflect(m.wi_mean, wm);
            const double s2 = sqr(eta_s_) * (1 - sqr(v_in.z));
            if (v_in.z <= 0 || s2 >= 1) return std::nullopt;
            wo = Vec3d(v_in.x * eta_s_, v_in.y * eta_s_, -std::sqrt(1 - s2));
            break;
        }
        default: {
            const Vec3d w = sample_cosine_hemisphere(u.y, u.z);
            wo = Vec3d(w.x, w.y, -w.z);
        }
    }
    if (wo.z == 0 || (wo.z < 0 && !support_.btdf)) return std::nullopt;
    const double pdf = pdf_with(in, m, wo);
    if (!(pdf > 0)) return std::nullopt;
    const Rgbd weight = eval_with(in, wo) * (std::abs(wo.z) / pdf);
    // A direction drawn where the density underflows (a denormal pdf at the horizon, u at 1):
    // its weight would overflow; it is rejected, as a direction of zero density is.
    if (!std::isfinite(weight.max())) return std::nullopt;
    return ModelSample{wo, weight, pdf};
}

double Lamina1::pdf(const Vec3d& wi, const Vec3d& wo) const {
    if (!support_.brdf || wi.z <= 0) return 0;
    const Incident in = incident(wi);
    return pdf_with(in, mixture(in), wo);
}

}  // namespace

std::unique_ptr<Model> make_lamina1(const Stack& stack, const ModelOptions& options) {
    return std::make_unique<Lamina1>(stack, lamina1_option_table().parse(options));
}

}  // namespace lamina

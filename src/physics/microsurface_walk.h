// Multiple scattering on a rough GGX interface: the microsurface random walk of Heitz, Hanika,
// d'Eon & Dachsbacher 2016, "Multiple-scattering microfacet BSDFs with the Smith model", ACM TOG
// 35(4) (SIGGRAPH 2016), for dielectric and conductor microsurfaces.
//
// The single-scattering interfaces (dielectric.h, conductor.h) keep the fraction G2/G1 of a
// particle that escapes the microsurface after one facet and drop the rest (docs/physics.md §3:
// "lost to the microsurface"). The walk instead follows the particle from facet to facet until it
// leaves: a ray meets the microsurface at a height drawn from the Smith model's uncorrelated
// heights (uniform on [−1, 1]; the paper shows the BSDF does not depend on it), scatters off a
// facet drawn from the distribution of normals visible from its direction (which may point below
// the horizon after a first bounce), and so on. Nothing is lost but what a conductor's Fresnel
// factor absorbs. The first order of the walk is the single-scattering interface with the
// height-correlated Smith masking-shadowing (the tests check it bin by bin): with c = C1(h) of the
// first hit, c has density (1 + Λi) c^Λi; a reflected ray escapes with probability c^Λo, so
// G2/G1 = (1 + Λi)/(1 + Λi + Λo), the G2 of dielectric.h and conductor.h; a refracted ray leaves
// below, where the heights above it have C1 = 1 − c, so G2/G1 = ∫ (1 + Λi) c^Λi (1 − c)^Λo dc =
// (1 + Λi) B(1 + Λi, 1 + Λo) (B: Euler's Beta function), the single-scattering dielectric's
// default refraction masking (TransmissionMasking::Smith, physics/smith_masking.h); its `pbrt`
// option, 1/(1 + Λi + Λo) as pbrt-v4 uses for both lobes, differs by a few percent at grazing
// exits and by much more when both Λ are large.
//
// Conventions as in bsdf.h: `wi` points away from the surface towards where the light comes from
// (above: wi.z > 0; from below a dielectric: wi.z < 0). Directions of travel are written `wr`.
// Heights below the surface are seen from there with heights and directions negated (the
// microsurface is point-symmetric, microfacet.h).
//
// One walk for both particle kernels: microsurface_walk is a branch-free lane template
// (core/lane.h) that walks a set of lanes under a mask until each has left. The scalar kernel
// runs it at one lane through walk_rough_dielectric / walk_rough_conductor; the SIMD kernel
// (simulator/kernel_simd.cpp) on its vectors. The lane test (tests/simulator/kernel_simd_test.cpp)
// compares the two particle by particle from the same random numbers.

#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/math.h"
#include "core/rgb.h"
#include "core/vec.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/polarization.h"

#include <cmath>
#include <limits>
#include <optional>
#include <type_traits>

// A lane header (core/lane.h): the walk is written once, as lane templates, included once as an
// ordinary header and once per SIMD target (the SIMD kernel runs the walk on its lanes); the
// scalar entry points below them only once.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_MICROSURFACE_WALK_LANES_H
#define LAMINA_PHYSICS_MICROSURFACE_WALK_LANES_H
#define LAMINA_PHYSICS_MICROSURFACE_WALK_BODY
#endif
#elif defined(LAMINA_PHYSICS_MICROSURFACE_WALK_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_MICROSURFACE_WALK_TARGET
#undef LAMINA_PHYSICS_MICROSURFACE_WALK_TARGET
#else
#define LAMINA_PHYSICS_MICROSURFACE_WALK_TARGET
#endif
#define LAMINA_PHYSICS_MICROSURFACE_WALK_BODY
#endif

#ifdef LAMINA_PHYSICS_MICROSURFACE_WALK_BODY
#undef LAMINA_PHYSICS_MICROSURFACE_WALK_BODY

LAMINA_LANE_BEGIN

/// CDF C1 of the microsurface's heights, uniform on [−1, 1] (Heitz et al. 2016), and its
/// inverse on [0, 1].
template <typename T, typename L = Lane<T>>
inline T microsurface_height_cdf(T h) {
    return L::min(L::max((h + L::constant(1)) * L::constant(0.5), L::constant(0)), L::constant(1));
}
template <typename T, typename L = Lane<T>>
inline T microsurface_height_cdf_inverse(T u) {
    return L::min(L::max(L::constant(2) * u - L::constant(1), L::constant(-1)), L::constant(1));
}

/// The next intersection of a ray with the microsurface: its height, unless the ray escapes.
template <typename T, typename M>
struct MicrosurfaceHit {
    T height;
    M escapes;
};

/// The height of the next intersection of a ray leaving height h along the direction of travel
/// wr (unit) with the microsurface of GGX roughness ggx (anisotropic or not), or an escape (upwards
/// only), from one uniform number u ∈ [0, 1). Heitz et al. 2016 (the height-dependent masking
/// G1(wr, h) = C1(h)^Λ(wr) and its inverse): a ray going up escapes with probability C1(h)^Λ(wr);
/// otherwise, and always going down, the next height follows from C1(h') = C1(h) / (1 −
/// u)^(1/Λ(wr)), with the signed Λ of a direction of travel: Λ(wr) going up, −1 − Λ(−wr) going down
/// (their GGX Λ evaluated with cot θ < 0). The powers are taken as exponentials of logarithms,
/// C1(h') = exp(ln C1(h) − ln(1 − u)/Λ), and the escape test in logarithms. Straight up (wr.z >
/// 0.9999) nothing masks the ray; straight down (wr.z < −0.9999, Λ → −1) C1(h') = u C1(h); a
/// horizontal ray (|wr.z| < 1e-4) meets the surface where it is. A branch-free lane template
/// (core/lane.h).
template <typename T, typename L = Lane<T>, bool kA>
inline MicrosurfaceHit<T, typename L::Mask> microsurface_next_height(const GgxLanes<T, kA>& ggx,
                                                                     const LaneVec3<T>& wr, T h,
                                                                     T u) {
    return microsurface_next_height<T, L>(ggx, wr, h, u, L::negate(L::less(u, u)), false);
}

/// The same for the lanes of `walking` only (the heights of other lanes are not computed when
/// every walking lane escapes); `at_top`: every lane is above all facets (h ≥ 1, C1 = 1, so
/// ln C1 = 0 exactly), as at a walk's first step.
template <typename T, typename L = Lane<T>, bool kA>
inline MicrosurfaceHit<T, typename L::Mask> microsurface_next_height(const GgxLanes<T, kA>& ggx,
                                                                     const LaneVec3<T>& wr, T h,
                                                                     T u, typename L::Mask walking,
                                                                     bool at_top) {
    const T zero = L::constant(0), one = L::constant(1);
    const T c = microsurface_height_cdf<T, L>(h);
    const auto straight_up = L::less(L::constant(0.9999), wr.z);
    const auto straight_down = L::less(wr.z, L::constant(-0.9999));
    const auto horizontal = L::less(L::abs(wr.z), L::constant(1e-4));
    const auto up = L::less(zero, wr.z);
    const T lambda = ggx_lambda<T, L>(ggx, wr.x, wr.y, wr.z);
    const T lambda_signed = L::select(up, lambda, zero - one - lambda);
    // ln C1(h), C1 kept above 1e-30: C1 = 0 (the lowest height) would give 0 · ∞ for a tiny Λ.
    // Going up, u ≥ 1 − C1^Λ ⟺ ln(1 − u) ≤ Λ ln C1: the escape test needs no power.
    const T log_c = at_top ? zero : L::log(L::max(c, L::constant(1e-30)));
    // ln(1 − u) as a logarithm of 1 − u: u is a multiple of its generator's resolution (2^-24 in
    // float, 2^-53 in double: core/rng.h), so 1 − u is exact and log1p would only add its
    // correction (a division), by exactly 1.
    const T log_1mu = L::log(one - u);
    const auto escapes_masked = L::both(up, L::negate(L::less(lambda_signed * log_c, log_1mu)));
    const auto escapes = L::either(
        straight_up, L::both(L::negate(L::either(straight_down, horizontal)), escapes_masked));
    if (L::none(L::both(walking, L::negate(escapes)))) return {h, escapes};
    const T c_next = L::exp(log_c - log_1mu / lambda_signed);
    const T h_next =
        L::select(straight_down, microsurface_height_cdf_inverse<T, L>(u * c),
                  L::select(horizontal, h, microsurface_height_cdf_inverse<T, L>(c_next)));
    return {h_next, escapes};
}

/// Where the walks of a set of lanes left the microsurface. Per lane one of: `escaped` (wo is the
/// direction of travel out of the microsurface, weight the flux factor it carries: a conductor's
/// Fresnel factors, 1 for a dielectric), `capped` (given up past its facet cap: it would meet one
/// more facet; its flux is lost to the microsurface), `degenerate` (a numerical degeneracy:
/// grazing arrival, a facet not facing the ray after rounding; lost and counted), or none of
/// them for lanes outside the walking mask. `order` counts the facets met (the scattering order).
template <typename T, typename M>
struct MicrosurfaceWalkLanes {
    LaneVec3<T> wo;
    T weight[3];
    T order;
    M escaped, capped, degenerate;
    /// Lanes whose walk the caller's `suspend` rule stopped before their next facet (below): wo
    /// is their direction of travel, h their height (the interface's frame), side ±1 the side
    /// they are on, order and weight as far as they went; MicrosurfaceWalkResume takes them up.
    M suspended;
    T h, side;
};

/// A walk to take up where microsurface_walk suspended it: on the lanes of `lanes`, at height h
/// (the interface's frame) on side `side` (+1 above, −1 below), having met `order` facets (the
/// next one counted) with flux factors `weight`; their direction of travel is the one the walk's
/// wi is the opposite of. They go on to the facet they had reached, then walk as any lane.
template <typename T, typename M>
struct MicrosurfaceWalkResume {
    M lanes;
    T h, side, order;
    T weight[3];
};

/// microsurface_walk's default `suspend` rule: walks run until every lane has left.
struct MicrosurfaceNeverSuspend {
    template <typename M>
    bool operator()(const M&) const {
        return false;
    }
};

/// The microsurface walk of Heitz et al. 2016 on the lanes of `walking`, each arriving from wi
/// (pointing away from the surface, unit) on a rough interface of GGX roughness ggx (α > 0,
/// anisotropic or not: the heights' Λ and the visible normals are those of microfacet.h), written
/// once for every lane type: while some lane walks, every lane draws its numbers (`uniform()`
/// returns a lane of uniform numbers in [0, 1); the draws of a lane that walks follow the same
/// sequence whatever the other lanes do: one for the height, then two for the visible normal and
/// those of `scatter`), lanes that walk find their next height (microsurface_next_height) and
/// either escape, stop at the cap of max_order facets, or meet a facet drawn from the normals
/// visible from their direction (the complete distribution: below the horizon too) and scatter
/// off it. `scatter(w, wm, cos_w_m, above, walking, wr_new, crosses, weight)` turns the arriving
/// w (away from the surface), the facet normal wm (unit, on the particle's side, w·wm > 0) into
/// the new direction of travel, the mask of lanes that crossed to the other side, and multiplies
/// the flux weights of the walking lanes. Heights and directions below the surface are seen from
/// there negated (the microsurface is point-symmetric, microfacet.h). `two_sided`: light may
/// arrive from below (a dielectric); otherwise a lane with wi.z ≤ 0 is degenerate. `visit(h, w,
/// above, walking, weight, order)`, if given, sees every facet before the lanes scatter off it:
/// its height (the interface's frame), the arriving w, the side, the walking lanes, their flux
/// weights so far and the facet's order (next-event estimation; it draws nothing).
///
/// Suspending and resuming (the SIMD kernel: a few lanes still walking would otherwise keep the
/// whole vector in the walk while the others wait). `suspend(walking)` is asked on every pass but
/// the first, once the walking lanes have their next facet's height and before they draw it; if
/// it says so, those lanes stop there as `suspended`, with what resume needs. The lanes of
/// `resume->lanes` (a subset of `walking`) start there: their first pass draws the height's
/// number like every lane but keeps their stored height, and they then meet their facet. A lane's
/// walk suspended and resumed is the walk it would have been with that one extra number drawn.
struct MicrosurfaceNoVisit {
    template <typename... A>
    void operator()(A&&...) const {}
};
template <typename T, typename L, typename Scatter, typename Uniform,
          typename Visit = MicrosurfaceNoVisit, bool kA = false,
          typename Suspend = MicrosurfaceNeverSuspend>
inline MicrosurfaceWalkLanes<T, typename L::Mask> microsurface_walk(
    const GgxLanes<T, kA>& ggx, const LaneVec3<T>& wi, typename L::Mask walking, bool two_sided,
    Scatter&& scatter, Uniform&& uniform, int max_order, Visit&& visit = Visit{},
    const MicrosurfaceWalkResume<T, typename L::Mask>* resume = nullptr,
    Suspend&& suspend = Suspend{}) {
    using M = typename L::Mask;
    const T zero = L::constant(0), one = L::constant(1);
    const M no_lane = L::both(walking, L::negate(walking));
    M resumed = resume ? L::both(walking, resume->lanes) : no_lane;
    MicrosurfaceWalkLanes<T, M> r;
    for (int c = 0; c < 3; ++c)
        r.weight[c] = resume ? L::select(resumed, resume->weight[c], one) : one;
    r.order = resume ? L::select(resumed, resume->order, zero) : zero;
    const auto arrives =
        L::either(resumed, two_sided ? L::less(zero, L::abs(wi.z)) : L::less(zero, wi.z));
    r.degenerate = L::both(walking, L::negate(arrives));
    walking = L::both(walking, arrives);
    r.escaped = r.capped = r.suspended = no_lane;
    // The side the particle is on (+1: the side the interface's normal points to).
    T side = L::select(L::less(zero, wi.z), one, zero - one);
    if (resume) side = L::select(resumed, resume->side, side);
    auto above = L::less(zero, side);
    LaneVec3<T> wr = {zero - wi.x, zero - wi.y, zero - wi.z};  // the direction of travel
    T h = side * L::constant(2);  // above every facet (C1 = 1) on its own side
    if (resume) h = L::select(resumed, resume->h, h);
    const T cap = L::constant(double(max_order));
    bool first = true;  // every lane but the resumed ones above all facets
    while (true) {
        // The next facet, in the frame of the side the particle is on (a resumed lane has its
        // own: the number is drawn and not used).
        const T u = uniform();
        const MicrosurfaceHit<T, M> hit = microsurface_next_height<T, L>(
            ggx, {side * wr.x, side * wr.y, side * wr.z}, side * h, u, walking, first);
        const M moves = L::both(walking, L::negate(resumed));
        const auto escapes = L::both(moves, hit.escapes);
        r.escaped = L::either(r.escaped, escapes);
        walking = L::both(walking, L::negate(escapes));
        const auto capped =
            L::both(L::both(walking, L::negate(resumed)), L::negate(L::less(r.order, cap)));
        r.capped = L::either(r.capped, capped);
        walking = L::both(walking, L::negate(capped));
        if (L::none(walking)) break;
        const M arrived = L::both(walking, L::negate(resumed));
        h = L::select(arrived, side * hit.height, h);
        r.order = L::select(arrived, r.order + one, r.order);
        if (!first && suspend(walking)) {
            r.suspended = walking;
            break;
        }
        first = false;
        resumed = no_lane;
        // A facet visible from the arriving direction (below the horizon after a first bounce).
        const LaneVec3<T> w = {zero - wr.x, zero - wr.y, zero - wr.z};
        visit(h, w, above, walking, static_cast<const T*>(r.weight), r.order);
        const T u1 = uniform(), u2 = uniform();
        const LaneVec3<T> wm_side = ggx_sample_visible_normal_complete<T, L>(
            ggx, {side * w.x, side * w.y, side * w.z}, u1, u2);
        const LaneVec3<T> wm = {side * wm_side.x, side * wm_side.y, side * wm_side.z};
        const T cos_w_m = lane_dot<T, L>(w, wm);
        const auto facing = L::less(zero, cos_w_m);  // false: rounding at grazing (or NaN)
        r.degenerate = L::either(r.degenerate, L::both(walking, L::negate(facing)));
        walking = L::both(walking, facing);
        if (L::none(walking)) break;
        LaneVec3<T> wr_new;
        auto crosses = L::negate(walking);
        scatter(w, wm, cos_w_m, above, walking, wr_new, crosses, r.weight);
        const auto finite = L::less(L::abs(wr_new.z), L::constant(HUGE_VAL));
        r.degenerate = L::either(r.degenerate, L::both(walking, L::negate(finite)));
        walking = L::both(walking, finite);
        wr = lane_select<T, L>(walking, wr_new, wr);
        const auto flips = L::both(walking, crosses);
        side = L::select(flips, zero - side, side);
        above = L::less(zero, side);
    }
    r.wo = wr;
    r.h = h;
    r.side = side;
    return r;
}

/// The dielectric facet of the walk (Heitz et al. 2016, their dielectric phase function): it
/// reflects with its exact Fresnel probability (fresnel_dielectric_full, one uniform number drawn
/// per step) and refracts otherwise; eta = η below / η above, inv_eta = 1/eta.
/// Polarized (kPolarized, `pol` the state; physics/polarization.h): as dielectric_event, the state
/// is turned into the facet's plane of incidence and the branch chosen with its reflected flux
/// fraction (polarized_dielectric_choice); where the channels' states differ, the choice's flux
/// factors multiply the walk's weights (the particle's flux for the choice's weights is
/// pol->flux times the weights so far).
template <typename T, typename L, typename Uniform, bool kPolarized = false>
struct MicrosurfaceDielectricFacet {
    T eta, inv_eta;
    Uniform& uniform;
    PolarizationLanes<T>* pol = nullptr;
    template <typename M>
    void operator()(const LaneVec3<T>& w, const LaneVec3<T>& wm, T cos_w_m, M above, M walking,
                    LaneVec3<T>& wr_new, M& crosses, T* weight) const {
        FresnelDielectric<T> fr;
        M reflects;
        const T eta_side = L::select(above, eta, inv_eta);
        const T inv_eta_side = L::select(above, inv_eta, eta);
        if constexpr (kPolarized) {
            const DielectricMueller<T> fm =
                fresnel_dielectric_mueller<T, L>(cos_w_m, eta_side, inv_eta_side);
            fr = {L::constant(0), fm.cos_theta_t, fm.eta, fm.inv_eta};
            const T zero = L::constant(0);
            stokes_rotate_frame<T, L>(pol->stokes, {zero - w.x, zero - w.y, zero - w.z},
                                      lane_cross<T, L>(w, wm), pol->channels, walking);
            const T uc = uniform();
            T flux[3];
            for (int c = 0; c < 3; ++c)
                flux[c] = pol->channels == 3 ? pol->flux[c] * weight[c] : weight[c];
            reflects = polarized_dielectric_choice<T, L>(*pol, fm, uc, walking, flux);
            if (pol->channels == 3)
                for (int c = 0; c < 3; ++c)
                    weight[c] = L::select(walking, weight[c] * pol->factor[c], weight[c]);
        } else {
            fr = fresnel_dielectric_full<T, L>(cos_w_m, eta_side, inv_eta_side);
            const T uc = uniform();
            reflects = L::less(uc, fr.reflectance);
        }
        const T two_cos = cos_w_m + cos_w_m;
        const LaneVec3<T> reflected = {two_cos * wm.x - w.x, two_cos * wm.y - w.y,
                                       two_cos * wm.z - w.z};
        crosses = L::negate(reflects);
        wr_new = reflected;
        if (L::none(L::both(walking, crosses))) return;  // no lane refracts
        // Snell about wm (fresnel.h refract, from the side wm points to): the reflectance is 1
        // under total internal reflection, so refracting lanes have cos θt > 0.
        const T along = cos_w_m * fr.inv_eta - fr.cos_theta_t;
        const T neg_inv_eta = L::constant(0) - fr.inv_eta;
        const LaneVec3<T> refracted = lane_normalize<T, L>(
            {L::mul_add(w.x, neg_inv_eta, wm.x * along), L::mul_add(w.y, neg_inv_eta, wm.y * along),
             L::mul_add(w.z, neg_inv_eta, wm.z * along)});
        wr_new = lane_select<T, L>(reflects, reflected, refracted);
    }
};

/// The conductor facet of the walk (Heitz et al. 2016, their conductor phase function): a mirror
/// that multiplies the flux by its Fresnel factors, `fresnel(cos_w_m, factors)` filling the three
/// channels' (fresnel_conductor); no number drawn.
/// Polarized (a `mueller` source given, `pol` the state): as conductor_event, the state is turned
/// into the facet's plane of incidence and multiplied by the reflection Mueller matrices
/// `mueller(cos, m)` fills per channel; the factors are the reflected fractions of the state.
template <typename T, typename L, typename Fresnel, typename Mueller = NoMueller>
struct MicrosurfaceConductorFacet {
    const Fresnel& fresnel;
    PolarizationLanes<T>* pol = nullptr;
    const Mueller* mueller = nullptr;
    template <typename M>
    void operator()(const LaneVec3<T>& w, const LaneVec3<T>& wm, T cos_w_m, M /*above*/, M walking,
                    LaneVec3<T>& wr_new, M& crosses, T* weight) const {
        T factors[3];
        if constexpr (!std::is_same_v<Mueller, NoMueller>) {
            const T zero = L::constant(0);
            stokes_rotate_frame<T, L>(pol->stokes, {zero - w.x, zero - w.y, zero - w.z},
                                      lane_cross<T, L>(w, wm), pol->channels, walking);
            InterfaceMueller<T> m[3] = {};
            reflection_on_lanes(*mueller, cos_w_m, m, walking);
            StokesLanes<T>& st = pol->stokes;
            factors[0] = stokes_apply<T, L>(m[0], st.q[0], st.u[0], st.v[0], walking);
            factors[1] = factors[2] = factors[0];
            for (int c = 1; c < pol->channels; ++c)
                factors[c] = stokes_apply<T, L>(m[c], st.q[c], st.u[c], st.v[c], walking);
        } else {
            reflection_on_lanes(fresnel, cos_w_m, factors, walking);
        }
        for (int c = 0; c < 3; ++c)
            weight[c] = L::select(walking, weight[c] * factors[c], weight[c]);
        const T two_cos = cos_w_m + cos_w_m;
        wr_new = {two_cos * wm.x - w.x, two_cos * wm.y - w.y, two_cos * wm.z - w.z};
        crosses = L::both(walking, L::negate(walking));  // no lane
    }
};

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_MICROSURFACE_WALK_BODY

#if !defined(LAMINA_LANE_TARGET) && !defined(LAMINA_PHYSICS_MICROSURFACE_WALK_H)
#define LAMINA_PHYSICS_MICROSURFACE_WALK_H

namespace lamina {

/// Where a walk left the microsurface: direction (pointing away from it), the flux weight it
/// carries (RGB: a conductor's Fresnel factors; 1 for a dielectric) and the number of facets it
/// met (the scattering order, ≥ 1). `escaped` is false for a walk given up at its facet cap (it
/// would meet one more facet): its flux is lost to the microsurface and wo is meaningless.
template <typename T>
struct MicrosurfaceExit {
    Vec3<T> wo;
    Rgb<T> weight{T(1)};
    int order = 0;
    bool escaped = true;
};

/// The scalar instantiation of microsurface_walk (one lane, bool masks) as an optional exit.
template <typename T>
std::optional<MicrosurfaceExit<T>> microsurface_exit(const MicrosurfaceWalkLanes<T, bool>& r) {
    if (r.degenerate) return std::nullopt;
    MicrosurfaceExit<T> exit;
    exit.wo = {r.wo.x, r.wo.y, r.wo.z};
    exit.weight = {r.weight[0], r.weight[1], r.weight[2]};
    exit.order = int(r.order);
    exit.escaped = !r.capped;
    return exit;
}

/// The microsurface walk of a particle arriving from wi on a rough dielectric interface of
/// relative index eta (below / above) and roughness ggx.alpha > 0, light from either side. Each
/// facet reflects with its exact Fresnel probability and refracts otherwise (Heitz et al. 2016,
/// the random walk with their dielectric phase function). `uniform()` returns uniform
/// numbers in [0, 1). A walk that, after max_order facets, would meet one more is given up
/// (escaped = false: the caller books its flux as lost to the microsurface); a numerical
/// degeneracy returns nothing (the caller counts it). The lane template microsurface_walk at one
/// lane: the SIMD kernel runs the same lines on its vectors.
template <bool kAnisotropic = false, typename T, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric(const GGX<T>& ggx, T eta,
                                                         const Vec3<T>& wi, Uniform&& uniform,
                                                         int max_order) {
    auto draw = [&] { return T(uniform()); };
    const MicrosurfaceDielectricFacet<T, Lane<T>, decltype(draw)> facet{eta, T(1) / eta, draw};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(ggx.template lanes<kAnisotropic>(),
                                                           {wi.x, wi.y, wi.z}, true, true, facet,
                                                           draw, max_order));
}

/// The microsurface walk of a particle arriving from wi (wi.z > 0) on a rough conductor; each
/// facet multiplies the flux by its Fresnel factor (Heitz et al. 2016, the conductor phase
/// function). `fresnel(cos)` returns the RGB reflectance at a facet cosine. Given up past
/// max_order facets and empty on a degeneracy, as walk_rough_dielectric.
template <bool kAnisotropic = false, typename T, typename Fresnel, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor(const GGX<T>& ggx, const Fresnel& fresnel,
                                                        const Vec3<T>& wi, Uniform&& uniform,
                                                        int max_order) {
    auto draw = [&] { return T(uniform()); };
    auto factors = [&](T cos_w_m, T* out) {
        const Rgb<T> f = fresnel(cos_w_m);
        out[0] = f[0], out[1] = f[1], out[2] = f[2];
    };
    const MicrosurfaceConductorFacet<T, Lane<T>, decltype(factors)> facet{factors};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(ggx.template lanes<kAnisotropic>(),
                                                           {wi.x, wi.y, wi.z}, true, false, facet,
                                                           draw, max_order));
}

/// walk_rough_dielectric following the particle's polarization (physics/polarization.h): `pol`
/// holds its state (in and out: the exit's, in the frame of the last facet met) and its flux per
/// channel; the exit's weight is 1, or where the channels' states differ the product of the flux
/// factors of the facets' branch choices (polarized_dielectric_choice).
template <bool kAnisotropic = false, typename T, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric_polarized(const GGX<T>& ggx, T eta,
                                                                   const Vec3<T>& wi,
                                                                   Uniform&& uniform, int max_order,
                                                                   PolarizationLanes<T>& pol) {
    auto draw = [&] { return T(uniform()); };
    const MicrosurfaceDielectricFacet<T, Lane<T>, decltype(draw), true> facet{eta, T(1) / eta, draw,
                                                                              &pol};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(ggx.template lanes<kAnisotropic>(),
                                                           {wi.x, wi.y, wi.z}, true, true, facet,
                                                           draw, max_order));
}

/// walk_rough_conductor following the particle's polarization: `mueller(cos, m)` fills the
/// reflection Mueller matrices of the three channels (fresnel_conductor_mueller); the exit's
/// weight is the product of the facets' reflected fractions of the state.
template <bool kAnisotropic = false, typename T, typename Mueller, typename Uniform>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor_polarized(const GGX<T>& ggx,
                                                                  const Mueller& mueller,
                                                                  const Vec3<T>& wi,
                                                                  Uniform&& uniform, int max_order,
                                                                  PolarizationLanes<T>& pol) {
    auto draw = [&] { return T(uniform()); };
    const NoMueller unpolarized;
    const MicrosurfaceConductorFacet<T, Lane<T>, NoMueller, Mueller> facet{unpolarized, &pol,
                                                                           &mueller};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(ggx.template lanes<kAnisotropic>(),
                                                           {wi.x, wi.y, wi.z}, true, false, facet,
                                                           draw, max_order));
}

// ---- Evaluating the walk: phase functions, height masking and next-event estimation -------------
// The walk's BSDF has no closed form; Heitz et al. 2016 (§5, "stochastic evaluation") estimate it
// without bias by a walk that, at every facet it meets, connects towards the exit direction wo:
//
//     f(wi, wo)·|cos θo| = E[ Σ_facets  W_j · p_j(wo) · G1(wo, h_j) ],
//
// p_j the facet's phase function (the density of the walk's next direction at wo), G1(wo, h_j)
// the probability that a ray leaving the facet's height h_j along wo escapes the microsurface on
// the side wo points to (C1(h)^Λ(wo) above; C1(−h)^Λ(−wo) below, the heights seen from there), and
// W_j the flux weight the exit would carry (the conductor's Fresnel factors of the facets met so
// far and of this one; 1 for a dielectric, whose Fresnel factor is the branch probability inside
// p_j). The product p_j·G1 is the density of "the walk leaves along wo right after facet j", so the
// sum is the density of the walk's exit direction (weighted by its flux): the BSDF in the flux
// convention of the interfaces' eval()·|cos θo| (dielectric.h, conductor.h; no η² radiance
// factor: the flux leaving per solid angle of wo). docs/rendering.md §1.6 derives the first order.

/// The height-dependent masking G1(wo, h) = C1(h)^Λ(wo) of a ray leaving height h along wo on the
/// upper side (Heitz et al. 2016, from Smith's uncorrelated heights): the probability that it
/// escapes the microsurface; zero for wo.z ≤ 0 (it meets the microsurface again).
template <typename T>
inline T microsurface_escape(const GGX<T>& ggx, const Vec3<T>& wo, T h) {
    if (!(wo.z > 0)) return T(0);
    const T c = microsurface_height_cdf(h);
    const T lambda = ggx.lambda(wo);
    if (lambda == 0) return T(1);
    return std::pow(c, lambda);
}

/// The dielectric phase function of one facet met by a particle on the *upper* side coming from w
/// (w = −direction of travel; w may point below the horizon after a first bounce): the density
/// (1/sr) of the walk's next direction at wo, for the facets visible from w (D_visible_complete)
/// that reflect with probability F(w·wm) and refract into the lower side otherwise (Heitz et al.
/// 2016, their dielectric phase function). `refracted` selects the branch: wo on the lower side
/// (refraction, eta = η_lower / η_upper of this side's frame) or the upper side (reflection).
/// Reflection: F D_w(wm) / (4 w·wm), wm = (w + wo)/|w + wo| (Walter et al. 2007, Eq. 14);
/// refraction: (1 − F) D_w(wm) η² |wo·wm| / (w·wm + η wo·wm)², wm ∝ −(w + η wo) (Walter Eqs.
/// 16-17).
template <typename T>
inline T microsurface_dielectric_phase(const GGX<T>& ggx, T eta, const Vec3<T>& w,
                                       const Vec3<T>& wo, bool refracted) {
    Vec3<T> wm = refracted ? -(w + wo * eta) : w + wo;
    const T len2 = dot(wm, wm);
    if (!(len2 > 0)) return T(0);
    wm = wm / std::sqrt(len2);
    if (wm.z < 0) wm = -wm;
    const T cos_w_m = dot(w, wm), cos_o_m = dot(wo, wm);
    if (!(cos_w_m > 0)) return T(0);
    const T F = fresnel_dielectric(cos_w_m, eta);
    const T visible = ggx.D_visible_complete(w, wm);
    if (!refracted) return F * visible / (T(4) * cos_w_m);
    if (!(cos_o_m < 0)) return T(0);
    const T denom = sqr(cos_w_m + eta * cos_o_m);
    if (!(denom > 0)) return T(0);
    return (T(1) - F) * visible * sqr(eta) * -cos_o_m / denom;
}

/// The conductor's facet: the density of the reflected direction, D_w(wm) / (4 w·wm), and the
/// facet cosine w·wm at which its Fresnel factor is taken (0 when wo cannot be reached from w).
template <typename T>
inline T microsurface_reflection_density(const GGX<T>& ggx, const Vec3<T>& w, const Vec3<T>& wo,
                                         T& cos_w_m) {
    cos_w_m = T(0);
    const Vec3<T> sum = w + wo;
    const T len2 = dot(sum, sum);
    if (!(len2 > 0)) return T(0);
    const Vec3<T> wm = sum / std::sqrt(len2);
    const T c = dot(w, wm);
    if (!(c > 0) || !(wm.z > 0)) return T(0);
    cos_w_m = c;
    return ggx.D_visible_complete(w, wm) / (T(4) * c);
}

/// One facet a walk meets, as the visiting walks below report it before it scatters: its height
/// h (in the interface's frame), the direction w the particle comes from (−direction of travel),
/// whether the particle is on the upper side (`outside`), the flux weight it carries (a
/// conductor's Fresnel factors of the earlier facets; 1 for a dielectric) and the order (1 for
/// the first facet).
template <typename T>
struct MicrosurfaceFacet {
    T h;
    Vec3<T> w;
    bool outside;
    Rgb<T> weight;
    int order;
};

/// Next-event estimation from a dielectric facet towards wo (the interface's frame, either side,
/// wo.z ≠ 0): the facet's phase density at wo times G1(wo, h) on wo's side. A particle on the
/// lower side is seen from there (heights, directions negated, eta → 1/eta), so the branch is a
/// reflection when wo is on the particle's side and a refraction otherwise.
template <typename T>
inline T microsurface_dielectric_connect(const GGX<T>& ggx, T eta,
                                         const MicrosurfaceFacet<T>& facet, const Vec3<T>& wo) {
    if (wo.z == 0) return T(0);
    const bool wo_up = wo.z > 0;
    const bool refracted = facet.outside != wo_up;
    const T escape =
        wo_up ? microsurface_escape(ggx, wo, facet.h) : microsurface_escape(ggx, -wo, -facet.h);
    if (!(escape > 0)) return T(0);
    const T phase = facet.outside
                        ? microsurface_dielectric_phase(ggx, eta, facet.w, wo, refracted)
                        : microsurface_dielectric_phase(ggx, T(1) / eta, -facet.w, -wo, refracted);
    return phase * escape;
}

/// Next-event estimation from a conductor facet towards wo (wo.z > 0): `density` is the walk's
/// density of leaving along wo right after this facet, D_w(wm)/(4 w·wm)·G1(wo, h) (the walk draws
/// its directions without the Fresnel factor), and `weight` the flux that exit would carry,
/// facet.weight·F(w·wm).
template <typename T>
struct MicrosurfaceConnection {
    T density = 0;
    Rgb<T> weight{T(0)};
};
template <typename T, typename Fresnel>
inline MicrosurfaceConnection<T> microsurface_conductor_connect(const GGX<T>& ggx,
                                                                const Fresnel& fresnel,
                                                                const MicrosurfaceFacet<T>& facet,
                                                                const Vec3<T>& wo) {
    MicrosurfaceConnection<T> out;
    const T escape = microsurface_escape(ggx, wo, facet.h);
    if (!(escape > 0)) return out;
    T cos_w_m;
    const T density = microsurface_reflection_density(ggx, facet.w, wo, cos_w_m);
    if (!(density > 0)) return out;
    out.density = density * escape;
    out.weight = facet.weight * fresnel(cos_w_m);
    return out;
}

// ---- Polarized next-event estimation (physics/polarization.h)
// ------------------------------------ A connection from a facet carries the state the particle has
// when it meets the facet (the polarized visiting walks below keep it in their PolarizationLanes
// while they visit): turned into the plane of incidence of the connecting facet (w, wm), the
// branch's Fresnel factor of the unpolarized phase function, F or 1 − F (dielectric) or F
// (conductor), becomes the state's own fraction a + b q, and the light leaves in the branch's
// Mueller matrix; the connection's Stokes vector is written in the tabulation frame of wo
// (stokes_bin_frame).

/// Per channel a Stokes vector (S0..S3) in the tabulation frame of a direction of travel.
template <typename T>
struct StokesRgb {
    T s[3][4] = {};
};

/// Adds to `out` the Stokes vectors of the light that `state` (one for all channels, or one per
/// channel) turns into through the branch `m` of a facet of normal wm met from w (unit vectors; wm
/// on either side), `scale[c]` times the branch's fraction a + b q over its unpolarized a, leaving
/// along wo; nothing where a = 0. One state serves all channels with the matrix of channel 0.
template <typename T>
inline void microsurface_stokes_through(const InterfaceMueller<T>* m, bool per_channel_matrix,
                                        const Vec3<T>& w, const Vec3<T>& wm, const Vec3<T>& wo,
                                        StokesLanes<T> state, int channels, const T scale[3],
                                        StokesRgb<T>& out) {
    const Vec3<T> n = cross(w, wm);
    stokes_rotate_frame<T>(state, {-w.x, -w.y, -w.z}, {n.x, n.y, n.z}, channels, true);
    T ratio[3] = {0, 0, 0};
    for (int c = 0; c < channels; ++c) {
        const InterfaceMueller<T>& mc = m[per_channel_matrix ? c : 0];
        if (!(mc.a > 0)) continue;
        ratio[c] = stokes_apply<T>(mc, state.q[c], state.u[c], state.v[c], true) / mc.a;
    }
    stokes_rotate_frame<T>(state, {wo.x, wo.y, wo.z}, stokes_bin_frame<T>({wo.x, wo.y, wo.z}),
                           channels, true);
    for (int c = 0; c < 3; ++c) {
        const int k = channels == 3 ? c : 0;
        const T f = scale[c] * ratio[channels == 3 ? c : 0];
        out.s[c][0] += f;
        out.s[c][1] += f * state.q[k];
        out.s[c][2] += f * state.u[k];
        out.s[c][3] += f * state.v[k];
    }
}

/// microsurface_dielectric_connect for a particle in polarization state `state`: the connection's
/// density (its own, with the state's branch fraction in place of F or 1 − F) times the facet's
/// weight, as Stokes vectors in wo's tabulation frame, added to `out`.
template <typename T>
inline void microsurface_dielectric_connect_polarized(const GGX<T>& ggx, T eta,
                                                      const MicrosurfaceFacet<T>& facet,
                                                      const Vec3<T>& wo,
                                                      const StokesLanes<T>& state, int channels,
                                                      StokesRgb<T>& out) {
    const T base = microsurface_dielectric_connect(ggx, eta, facet, wo);
    if (!(base > 0) || !std::isfinite(base)) return;
    // The connecting facet as microsurface_dielectric_phase finds it, seen from the particle's
    // side.
    const bool refracted = facet.outside != (wo.z > 0);
    const T eta_side = facet.outside ? eta : T(1) / eta;
    const Vec3<T> w_side = facet.outside ? facet.w : -facet.w;
    const Vec3<T> wo_side = facet.outside ? wo : -wo;
    Vec3<T> wm = refracted ? -(w_side + wo_side * eta_side) : w_side + wo_side;
    wm = normalize(wm);
    if (wm.z < 0) wm = -wm;
    const DielectricMueller<T> fm =
        fresnel_dielectric_mueller<T>(dot(w_side, wm), eta_side, T(1) / eta_side);
    const InterfaceMueller<T>& m = refracted ? fm.transmission : fm.reflection;
    const T scale[3] = {base * facet.weight[0], base * facet.weight[1], base * facet.weight[2]};
    microsurface_stokes_through(&m, false, facet.w, wm, wo, state, channels, scale, out);
}

/// microsurface_conductor_connect for a particle in polarization state `state`: the density times
/// the facet's weight and the state's reflected fraction of the connecting facet (the Mueller
/// matrices `mueller(cos, m)` fills per channel), as Stokes vectors added to `out`.
template <typename T, typename Mueller>
inline void microsurface_conductor_connect_polarized(const GGX<T>& ggx, const Mueller& mueller,
                                                     const MicrosurfaceFacet<T>& facet,
                                                     const Vec3<T>& wo, const StokesLanes<T>& state,
                                                     int channels, StokesRgb<T>& out) {
    const T escape = microsurface_escape(ggx, wo, facet.h);
    if (!(escape > 0)) return;
    T cos_w_m;
    const T density = microsurface_reflection_density(ggx, facet.w, wo, cos_w_m);
    if (!(density > 0)) return;
    InterfaceMueller<T> m[3];
    mueller(cos_w_m, m);
    // The unpolarized weight F = a, turned into the state's fraction a + b q by the ratio.
    T scale[3];
    for (int c = 0; c < 3; ++c)
        scale[c] = density * escape * facet.weight[c] * m[c].a;
    microsurface_stokes_through(m, true, facet.w, normalize(facet.w + wo), wo, state, channels,
                                scale, out);
}

/// walk_rough_dielectric with a visitor: `visit(const MicrosurfaceFacet<T>&)` is called at every
/// facet before the particle scatters off it (kAnisotropic as walk_rough_dielectric's). The same
/// walk (microsurface_walk at one lane, the same random numbers in the same order): returns the
/// same exit.
template <typename T, typename Visit>
struct MicrosurfaceFacetVisitor {
    Visit& visit;
    void operator()(T h, const LaneVec3<T>& w, bool above, bool walking, const T* weight,
                    T order) const {
        if (walking)
            visit(MicrosurfaceFacet<T>{h, Vec3<T>(w.x, w.y, w.z), above,
                                       Rgb<T>(weight[0], weight[1], weight[2]), int(order)});
    }
};
template <bool kAnisotropic = false, typename T, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric_visiting(const GGX<T>& ggx, T eta,
                                                                  const Vec3<T>& wi,
                                                                  Uniform&& uniform, int max_order,
                                                                  Visit&& visit) {
    auto draw = [&] { return T(uniform()); };
    const MicrosurfaceDielectricFacet<T, Lane<T>, decltype(draw)> facet{eta, T(1) / eta, draw};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(
        ggx.template lanes<kAnisotropic>(), {wi.x, wi.y, wi.z}, true, true, facet, draw, max_order,
        MicrosurfaceFacetVisitor<T, std::remove_reference_t<Visit>>{visit}));
}

/// walk_rough_conductor with a visitor, as walk_rough_dielectric_visiting.
template <bool kAnisotropic = false, typename T, typename Fresnel, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor_visiting(const GGX<T>& ggx,
                                                                 const Fresnel& fresnel,
                                                                 const Vec3<T>& wi,
                                                                 Uniform&& uniform, int max_order,
                                                                 Visit&& visit) {
    auto draw = [&] { return T(uniform()); };
    auto factors = [&](T cos_w_m, T* out) {
        const Rgb<T> f = fresnel(cos_w_m);
        out[0] = f[0], out[1] = f[1], out[2] = f[2];
    };
    const MicrosurfaceConductorFacet<T, Lane<T>, decltype(factors)> facet{factors};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(
        ggx.template lanes<kAnisotropic>(), {wi.x, wi.y, wi.z}, true, false, facet, draw, max_order,
        MicrosurfaceFacetVisitor<T, std::remove_reference_t<Visit>>{visit}));
}

/// walk_rough_dielectric_polarized with a visitor, as walk_rough_dielectric_visiting; at each call
/// `pol.stokes` holds the state with which the particle meets the facet.
template <bool kAnisotropic = false, typename T, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_dielectric_polarized_visiting(
    const GGX<T>& ggx, T eta, const Vec3<T>& wi, Uniform&& uniform, int max_order,
    PolarizationLanes<T>& pol, Visit&& visit) {
    auto draw = [&] { return T(uniform()); };
    const MicrosurfaceDielectricFacet<T, Lane<T>, decltype(draw), true> facet{eta, T(1) / eta, draw,
                                                                              &pol};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(
        ggx.template lanes<kAnisotropic>(), {wi.x, wi.y, wi.z}, true, true, facet, draw, max_order,
        MicrosurfaceFacetVisitor<T, std::remove_reference_t<Visit>>{visit}));
}

/// walk_rough_conductor_polarized with a visitor, as walk_rough_dielectric_polarized_visiting.
template <bool kAnisotropic = false, typename T, typename Mueller, typename Uniform, typename Visit>
std::optional<MicrosurfaceExit<T>> walk_rough_conductor_polarized_visiting(
    const GGX<T>& ggx, const Mueller& mueller, const Vec3<T>& wi, Uniform&& uniform, int max_order,
    PolarizationLanes<T>& pol, Visit&& visit) {
    auto draw = [&] { return T(uniform()); };
    const NoMueller unpolarized;
    const MicrosurfaceConductorFacet<T, Lane<T>, NoMueller, Mueller> facet{unpolarized, &pol,
                                                                           &mueller};
    return microsurface_exit(microsurface_walk<T, Lane<T>>(
        ggx.template lanes<kAnisotropic>(), {wi.x, wi.y, wi.z}, true, false, facet, draw, max_order,
        MicrosurfaceFacetVisitor<T, std::remove_reference_t<Visit>>{visit}));
}

/// One walk's unbiased estimate of the multiple-scattering rough dielectric's f(wi, wo)·|cos θo|
/// (flux convention, as DielectricInterface::eval·|cos θo|), orders 1..max_order (Heitz et al.
/// 2016, stochastic evaluation). Zero for wi.z = 0 or wo.z = 0.
template <typename T, typename Uniform>
T eval_rough_dielectric_multiple(const GGX<T>& ggx, T eta, const Vec3<T>& wi, const Vec3<T>& wo,
                                 Uniform&& uniform, int max_order) {
    if (wo.z == 0) return T(0);
    T sum(0);
    walk_rough_dielectric_visiting(ggx, eta, wi, uniform, max_order,
                                   [&](const MicrosurfaceFacet<T>& facet) {
                                       sum += microsurface_dielectric_connect(ggx, eta, facet, wo);
                                   });
    return std::isfinite(sum) ? sum : T(0);
}

/// One walk's unbiased estimate of the multiple-scattering rough conductor's f(wi, wo)·cos θo
/// (RGB), orders 1..max_order. Zero unless wi.z > 0 and wo.z > 0.
template <typename T, typename Fresnel, typename Uniform>
Rgb<T> eval_rough_conductor_multiple(const GGX<T>& ggx, const Fresnel& fresnel, const Vec3<T>& wi,
                                     const Vec3<T>& wo, Uniform&& uniform, int max_order) {
    Rgb<T> sum(T(0));
    if (!(wo.z > 0)) return sum;
    walk_rough_conductor_visiting(ggx, fresnel, wi, uniform, max_order,
                                  [&](const MicrosurfaceFacet<T>& facet) {
                                      const MicrosurfaceConnection<T> c =
                                          microsurface_conductor_connect(ggx, fresnel, facet, wo);
                                      sum += c.weight * c.density;
                                  });
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(sum[c])) return Rgb<T>(T(0));
    return sum;
}

}  // namespace lamina

#endif  // LAMINA_PHYSICS_MICROSURFACE_WALK_H

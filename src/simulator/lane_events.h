// The SIMD kernel's lane state and the adapters of the physics' event templates to it: the
// state of the lanes' particles (LaneVectors: direction, flux, the losses booked per budget
// term, polarization and, in spectral runs, each lane's stack), and per interface type and
// medium the call of the lane template that the scalar kernel instantiates at one lane
// (physics/dielectric.h, conductor.h, lambertian.h, microsurface_walk.h, medium.h), with a thin
// film's reflection in place of a conductor's Fresnel terms (simulator/lane_film.h). The kernel
// (simulator/kernel_simd.cpp) manages the lanes around them. A per-target header (core/lane_hwy.h);
// layers/compiled_stack.h and physics/thin_film.h must already be included as ordinary headers.

#include "core/lane_hwy.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/medium.h"
#include "physics/microsurface_walk.h"
#include "physics/polarization.h"
#include "simulator/lane_conductor.h"
#include "simulator/lane_film.h"
#include "simulator/lane_rng.h"

#include <algorithm>
#include <bit>
#include <cstdint>

// Highway's per-target include guard: the body once per instruction set.
#if defined(LAMINA_SIMULATOR_LANE_EVENTS_H) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_SIMULATOR_LANE_EVENTS_H
#undef LAMINA_SIMULATOR_LANE_EVENTS_H
#else
#define LAMINA_SIMULATOR_LANE_EVENTS_H
#endif

LAMINA_LANE_BEGIN

// ---- Lane state ---------------------------------------------------------------------------------

enum LossTerm { kLossMedium = 0, kLossBase = 1, kLossMicro = 2, kLossCutOff = 3, kLossTerms = 4 };

// Why a lane's particle ended this step.
enum Finish : std::int32_t { kGoesOn = 0, kReflected = 1, kTransmitted = 2, kEnded = 3 };

// The state of the lanes' particles, kept in vectors from step to step.
struct LaneVectors {
    V3 d;
    VF w[3];
    VF depth;  // inside a scattering medium: 0 at its top, 1 at its bottom
    // Flux lost per budget term, summed in float over the lane's recent steps (whatever particle
    // each step belonged to) and moved into double sums every kFlushSteps (8) steps: a few
    // particles' worth of float additions at most, rounding-level like the particle's own float
    // arithmetic.
    VF loss[kLossTerms][3];
    VF exit_sum[4][3];  // the same for R, R², T, T² of the particles that left
    VI events_done;     // events of the lane's ended particles
    VI k;               // at an interface: its index; in a medium: its layer
    VI in_medium, events, live, finish;
    // Spectral runs: the lane's stack (SpectralTracing::stacks' index t · 3 + hero), its hero
    // channel, its wavelength group and whether its secondary wavelengths still travel
    // (SpectralParticle).
    VI at, hero, group, secondaries;
    // Lanes whose microsurface walk is suspended (non-zero), waiting at their interface k to go
    // on, and where their walks stand (physics/microsurface_walk.h MicrosurfaceWalkResume; their
    // direction of travel is d).
    VI mid_walk;
    VF walk_h, walk_side, walk_order, walk_weight[3];
    bool touched[kLossTerms] = {};  // loss terms some lane may have booked in this block
    int set = 0;  // which of the kernel's lane sets these lanes are (its per-lane records)
    // Polarized runs: the lanes' polarization (physics/polarization.h); pol.flux points at w.
    PolarizationLanes<VF> pol;

    // Multiplies the flux of the lanes in m by `factor` (per channel) and books what is taken
    // under `term`.
    HWY_INLINE void Keep(MF m, int term, const VF factor[3]) {
        touched[term] = true;
        for (int c = 0; c < 3; ++c) {
            const VF kept = hn::Mul(w[c], factor[c]);
            loss[term][c] = hn::Add(loss[term][c], hn::IfThenElseZero(m, hn::Sub(w[c], kept)));
            w[c] = hn::IfThenElse(m, kept, w[c]);
        }
    }
    HWY_INLINE void Keep(MF m, int term, VF factor) {
        const VF f[3] = {factor, factor, factor};
        Keep(m, term, f);
    }
    HWY_INLINE MF Black() const {
        const DF df;
        const VF zero = hn::Zero(df);
        return hn::And(hn::And(hn::Eq(w[0], zero), hn::Eq(w[1], zero)), hn::Eq(w[2], zero));
    }
    // The lanes of m whose microsurface walks are suspended (MicrosurfaceWalkEvent): they wait
    // at their interface.
    HWY_INLINE MF MidWalk(MF m) const {
        return hn::And(m, hn::RebindMask(DF(), hn::Ne(mid_walk, hn::Zero(DI()))));
    }
    HWY_INLINE void End(MF m, Finish why) {
        const DI di;
        finish = hn::IfThenElse(hn::RebindMask(di, m), hn::Set(di, why), finish);
    }
};

// ---- Interface events (goniophotometer.cpp trace_particle, `apply`) ----------------------------

// An interface's GGX roughness (physics/microfacet.h) on the vectors' lanes: the very roughness
// the scalar kernel's events take (GGX::lanes), broadcast. kAnisotropic (the stack has an
// anisotropic interface, CompiledStack::anisotropic): the general instance, with the interface's
// α_x, α_y and tangent frame, at every rough interface of the stack, as trace_particle takes it;
// else the isotropic instance.
template <bool kAnisotropic>
HWY_INLINE GgxLanes<VF, kAnisotropic> VecGgx(const GGX<float>& ggx) {
    const DF df;
    const auto g = ggx.template lanes<kAnisotropic>();
    return {hn::Set(df, g.alpha),    hn::Set(df, g.alpha2), hn::Set(df, g.d_alpha),
            hn::Set(df, g.d_alpha2), hn::Set(df, g.bx),     hn::Set(df, g.by)};
}

// The same on a pair of vectors (VecLane2).
template <bool kAnisotropic>
HWY_INLINE GgxLanes<VF2, kAnisotropic> VecGgxPair(const GGX<float>& ggx) {
    const auto g = VecGgx<kAnisotropic>(ggx);
    return {{g.alpha, g.alpha},       {g.alpha2, g.alpha2}, {g.d_alpha, g.d_alpha},
            {g.d_alpha2, g.d_alpha2}, {g.bx, g.bx},         {g.by, g.by}};
}

// Two lane sets' polarization states as their pair's (the sets' channels alike), their fluxes
// `flux` (the pair's), and back.
HWY_INLINE PolarizationLanes<VF2> PairPolarization(const PolarizationLanes<VF>& a,
                                                   const PolarizationLanes<VF>& b,
                                                   const VF2* flux) {
    PolarizationLanes<VF2> p;
    p.stokes.x = Pair(a.stokes.x, b.stokes.x);
    for (int c = 0; c < 3; ++c) {
        p.stokes.q[c] = {a.stokes.q[c], b.stokes.q[c]};
        p.stokes.u[c] = {a.stokes.u[c], b.stokes.u[c]};
        p.stokes.v[c] = {a.stokes.v[c], b.stokes.v[c]};
        p.factor[c] = {a.factor[c], b.factor[c]};
    }
    p.channels = a.channels;
    p.flux = flux;
    return p;
}
HWY_INLINE void SplitPolarization(const PolarizationLanes<VF2>& p, PolarizationLanes<VF>& a,
                                  PolarizationLanes<VF>& b) {
    a.stokes.x = First(p.stokes.x);
    b.stokes.x = Second(p.stokes.x);
    for (int c = 0; c < 3; ++c) {
        a.stokes.q[c] = p.stokes.q[c].a;
        b.stokes.q[c] = p.stokes.q[c].b;
        a.stokes.u[c] = p.stokes.u[c].a;
        b.stokes.u[c] = p.stokes.u[c].b;
        a.stokes.v[c] = p.stokes.v[c].a;
        b.stokes.v[c] = p.stokes.v[c].b;
        a.factor[c] = p.factor[c].a;
        b.factor[c] = p.factor[c].b;
    }
}

// What a dielectric's event did to the lanes of m, booked on v (DielectricEvent).
template <bool kPolarized>
HWY_INLINE void KeepDielectricEvent(const DielectricInterface<float>& iface,
                                    const InterfaceEventLanes<VF, MF>& e, MF m, LaneVectors& v,
                                    MF& degenerate) {
    degenerate = hn::Or(degenerate, e.degenerate);
    const MF ok = hn::AndNot(e.degenerate, m);
    if constexpr (kPolarized)
        if (v.pol.channels == 3) v.Keep(ok, kLossBase, v.pol.factor);
    if (!iface.is_smooth()) v.Keep(ok, kLossMicro, e.shadowing);
    v.d = Select(ok, e.wo, v.d);
}

// A rough or smooth dielectric (dielectric.h dielectric_event, the template the scalar kernel
// instantiates at one lane): the particle arrives along d (wi = −d), the relative index eta (and
// its inverse) per lane: the interface's, or a spectral lane's. Polarized (kPolarized): the
// event's polarized form on the lanes' states; where the channels' states differ, its reweighting
// of the channels is booked with the base, as trace_particle does.
template <bool kPolarized, bool kAnisotropic>
HWY_INLINE void DielectricEvent(const DielectricInterface<float>& iface, VF eta, VF inv_eta, MF m,
                                LaneVectors& v, VF uc, VF u1, VF u2, MF& degenerate) {
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    KeepDielectricEvent<kPolarized>(
        iface,
        dielectric_event<VF, VecLane, kPolarized>(
            eta, inv_eta, VecGgx<kAnisotropic>(iface.distribution()), iface.event_shape(), wi, uc,
            u1, u2, m, kPolarized ? &v.pol : nullptr),
        m, v, degenerate);
}

// The same event (unpolarized) on two lane sets at once, the template instantiated on their pair
// (VecLane2): the two sets' lanes m and n, their numbers uc, u1, u2 (first and second vector).
template <bool kAnisotropic>
HWY_INLINE void DielectricEventPair(const DielectricInterface<float>& iface, VF eta, VF inv_eta,
                                    MF m, MF n, LaneVectors& v, LaneVectors& w, VF2 uc, VF2 u1,
                                    VF2 u2, MF& degenerate_v, MF& degenerate_w) {
    const GgxLanes<VF2, kAnisotropic> g2 = VecGgxPair<kAnisotropic>(iface.distribution());
    const LaneVec3<VF2> wi = Pair({hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)},
                                  {hn::Neg(w.d.x), hn::Neg(w.d.y), hn::Neg(w.d.z)});
    const InterfaceEventLanes<VF2, MF2> e = dielectric_event<VF2, VecLane2, false>(
        {eta, eta}, {inv_eta, inv_eta}, g2, iface.event_shape(), wi, uc, u1, u2, {m, n});
    KeepDielectricEvent<false>(iface, {First(e.wo), e.shadowing.a, e.reflected.a, e.degenerate.a},
                               m, v, degenerate_v);
    KeepDielectricEvent<false>(iface, {Second(e.wo), e.shadowing.b, e.reflected.b, e.degenerate.b},
                               n, w, degenerate_w);
}

// What a conductor's event did to the lanes of m, its Fresnel factors `fresnel`, booked on v
// (ConductorEvent).
HWY_INLINE void KeepConductorEvent(const ConductorInterface<float>& iface,
                                   const InterfaceEventLanes<VF, MF>& e, const VF fresnel[3], MF m,
                                   LaneVectors& v, MF& degenerate) {
    degenerate = hn::Or(degenerate, e.degenerate);
    const MF ok = hn::AndNot(e.degenerate, m);
    v.Keep(ok, kLossBase, fresnel);
    if (!iface.is_smooth()) v.Keep(ok, kLossMicro, e.shadowing);
    v.d = Select(ok, e.wo, v.d);
}

// A rough or smooth conductor (conductor.h conductor_event, the same template): light from above
// only. Polarized: the Fresnel factors are the reflected fractions of the lanes' states. The
// reflection at a facet comes from `fresnel_of` and `mueller_of` (lane_conductor.h: the bare
// conductor's; a filmed conductor's, FilmReflection).
template <bool kPolarized, bool kAnisotropic, typename Fresnel, typename Mueller>
HWY_INLINE void ConductorEvent(const ConductorInterface<float>& iface, const Fresnel& fresnel_of,
                               const Mueller& mueller_of, MF m, LaneVectors& v, VF u1, VF u2,
                               MF& degenerate) {
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    VF fresnel[3];
    InterfaceEventLanes<VF, MF> e;
    if constexpr (kPolarized)
        e = conductor_event<VF, VecLane>(VecGgx<kAnisotropic>(iface.distribution()),
                                         iface.is_smooth(), iface.uncorrelated_shadowing, wi, u1,
                                         u2, m, fresnel_of, fresnel, &v.pol, mueller_of);
    else
        e = conductor_event<VF, VecLane>(VecGgx<kAnisotropic>(iface.distribution()),
                                         iface.is_smooth(), iface.uncorrelated_shadowing, wi, u1,
                                         u2, m, fresnel_of, fresnel);
    KeepConductorEvent(iface, e, fresnel, m, v, degenerate);
}

// The bare conductor's event on two lane sets at once (VecLane2; DielectricEventPair), its
// reflection ConductorFresnel and ConductorMueller on the pair; polarized, the states' channels
// alike.
template <bool kPolarized, bool kAnisotropic>
HWY_INLINE void ConductorEventPair(const ConductorInterface<float>& iface, MF m, MF n,
                                   LaneVectors& v, LaneVectors& w, VF2 u1, VF2 u2, MF& degenerate_v,
                                   MF& degenerate_w) {
    const LaneVec3<VF2> wi = Pair({hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)},
                                  {hn::Neg(w.d.x), hn::Neg(w.d.y), hn::Neg(w.d.z)});
    const ConductorFresnel fresnel_of{iface};
    VF2 fresnel[3];
    InterfaceEventLanes<VF2, MF2> e;
    if constexpr (kPolarized) {
        const VF2 flux[3] = {{v.w[0], w.w[0]}, {v.w[1], w.w[1]}, {v.w[2], w.w[2]}};
        PolarizationLanes<VF2> pol = PairPolarization(v.pol, w.pol, flux);
        e = conductor_event<VF2, VecLane2>(VecGgxPair<kAnisotropic>(iface.distribution()),
                                           iface.is_smooth(), iface.uncorrelated_shadowing, wi, u1,
                                           u2, MF2{m, n}, fresnel_of, fresnel, &pol,
                                           ConductorMueller{iface});
        SplitPolarization(pol, v.pol, w.pol);
    } else {
        e = conductor_event<VF2, VecLane2>(VecGgxPair<kAnisotropic>(iface.distribution()),
                                           iface.is_smooth(), iface.uncorrelated_shadowing, wi, u1,
                                           u2, MF2{m, n}, fresnel_of, fresnel);
    }
    const VF fresnel_v[3] = {fresnel[0].a, fresnel[1].a, fresnel[2].a};
    const VF fresnel_w[3] = {fresnel[0].b, fresnel[1].b, fresnel[2].b};
    KeepConductorEvent(iface, {First(e.wo), e.shadowing.a, e.reflected.a, e.degenerate.a},
                       fresnel_v, m, v, degenerate_v);
    KeepConductorEvent(iface, {Second(e.wo), e.shadowing.b, e.reflected.b, e.degenerate.b},
                       fresnel_w, n, w, degenerate_w);
}

// A rough interface with multiple scattering on its microsurface (physics/microsurface_walk.h
// microsurface_walk, the template the scalar kernel instantiates at one lane): the lanes of m walk
// from facet to facet, every lane of the vector drawing its numbers while any walks, until each
// has escaped (its new direction; a conductor's exit carries its Fresnel factors, the rest
// absorbed by the base), met its facet cap (its flux lost to the microsurface) or a degeneracy
// (lost and counted, as a failed sample), as trace_particle books the walk. `weighted`: the exit's
// weight is booked on a dielectric too (polarized, the channels' states differing).
//
// `may_suspend`: once a quarter of the lanes or fewer are still walking (after their first facet),
// their walks are suspended before their next facet (v.mid_walk and the walk_ fields, d their
// direction of travel): they wait at the interface, and go on the next time the kernel steps it
// (the lanes of m with mid_walk set), beside the lanes that arrive there, instead of holding the
// vector for the few more facets most of them need. Nothing is booked for a suspended lane.
template <bool kAnisotropic, typename Facet>
HWY_INLINE void MicrosurfaceWalkEvent(const GGX<float>& ggx, bool two_sided, const Facet& facet,
                                      MF m, LaneVectors& v, LaneRng& rng, int max_order,
                                      MF& degenerate, bool may_suspend, bool weighted = false) {
    const DF df;
    const DI di;
    const VF zero = hn::Zero(df);
    const V3 wi = {hn::Neg(v.d.x), hn::Neg(v.d.y), hn::Neg(v.d.z)};
    auto draw = [&] { return rng.Uniform(); };
    const MF resumed = v.MidWalk(m);
    const MicrosurfaceWalkResume<VF, MF> resume{
        resumed,
        v.walk_h,
        v.walk_side,
        v.walk_order,
        {v.walk_weight[0], v.walk_weight[1], v.walk_weight[2]}};
    const std::size_t quarter = hn::Lanes(df) / 4;
    auto suspend = [&](MF walking) { return may_suspend && hn::CountTrue(df, walking) <= quarter; };
    const MicrosurfaceWalkLanes<VF, MF> walk = microsurface_walk<VF, VecLane>(
        VecGgx<kAnisotropic>(ggx), wi, m, two_sided, facet, draw, max_order, MicrosurfaceNoVisit{},
        hn::AllFalse(df, resumed) ? nullptr : &resume, suspend);
    degenerate = hn::Or(degenerate, walk.degenerate);
    if (!two_sided || weighted) v.Keep(walk.escaped, kLossBase, walk.weight);
    v.Keep(walk.capped, kLossMicro, zero);
    v.d = Select(hn::Or(walk.escaped, walk.suspended), walk.wo, v.d);
    v.mid_walk = hn::IfThenElse(
        hn::RebindMask(di, m),
        hn::IfThenElseZero(hn::RebindMask(di, walk.suspended), hn::Set(di, 1)), v.mid_walk);
    if (hn::AllFalse(df, walk.suspended)) return;
    v.walk_h = hn::IfThenElse(walk.suspended, walk.h, v.walk_h);
    v.walk_side = hn::IfThenElse(walk.suspended, walk.side, v.walk_side);
    v.walk_order = hn::IfThenElse(walk.suspended, walk.order, v.walk_order);
    for (int c = 0; c < 3; ++c)
        v.walk_weight[c] = hn::IfThenElse(walk.suspended, walk.weight[c], v.walk_weight[c]);
}

template <bool kPolarized, bool kAnisotropic>
HWY_INLINE void DielectricWalkEvent(const DielectricInterface<float>& iface, VF eta, VF inv_eta,
                                    MF m, LaneVectors& v, LaneRng& rng, int max_order,
                                    MF& degenerate, bool may_suspend) {
    auto draw = [&] { return rng.Uniform(); };
    const MicrosurfaceDielectricFacet<VF, VecLane, decltype(draw), kPolarized> facet{
        eta, inv_eta, draw, kPolarized ? &v.pol : nullptr};
    MicrosurfaceWalkEvent<kAnisotropic>(iface.distribution(), true, facet, m, v, rng, max_order,
                                        degenerate, may_suspend, kPolarized && v.pol.channels == 3);
}

template <bool kPolarized, bool kAnisotropic, typename Fresnel, typename Mueller>
HWY_INLINE void ConductorWalkEvent(const ConductorInterface<float>& iface, const Fresnel& fresnel,
                                   const Mueller& mueller, MF m, LaneVectors& v, LaneRng& rng,
                                   int max_order, MF& degenerate, bool may_suspend) {
    if constexpr (kPolarized) {
        const MicrosurfaceConductorFacet<VF, VecLane, Fresnel, Mueller> facet{fresnel, &v.pol,
                                                                              &mueller};
        MicrosurfaceWalkEvent<kAnisotropic>(iface.distribution(), false, facet, m, v, rng,
                                            max_order, degenerate, may_suspend);
    } else {
        const MicrosurfaceConductorFacet<VF, VecLane, Fresnel> facet{fresnel};
        MicrosurfaceWalkEvent<kAnisotropic>(iface.distribution(), false, facet, m, v, rng,
                                            max_order, degenerate, may_suspend);
    }
}

// A filmed conductor's event (film_event's conductor branch): the lanes' thicknesses drawn first
// where the film's thickness varies (one number per event, from each lane's own stream), then the
// conductor event or walk with the film's reflection in place of the bare Fresnel terms, booked as
// the bare conductor's (absorbed by the base, lost to the microsurface). `films`: each lane's film
// (the layer's, or a spectral lane's stack's: the same thickness distribution, other wavelengths).
// Isotropic: a stack with a film has no anisotropic interface (validate_kernel_for).
template <bool kPolarized>
HWY_NOINLINE void FilmConductorEvent(const CompiledLayer<float>& layer,
                                     const FilmOptics* const* films, MF m, LaneVectors& v,
                                     LaneRng& rng, int max_order, MF& degenerate) {
    const DF df;
    HWY_ALIGN double thickness[kMaxLanes];
    if (layer.film.varies()) {
        HWY_ALIGN float u[kMaxLanes];
        hn::Store(rng.Uniform(), df, u);
        for (std::size_t l = 0; l < hn::Lanes(df); ++l)
            thickness[l] = films[l]->thickness_nm(double(u[l]));
    } else {
        for (std::size_t l = 0; l < hn::Lanes(df); ++l)
            thickness[l] = films[l]->thickness_min_nm;
    }
    const FilmReflection reflection{films, thickness};
    if (layer.multiple) {
        // Not suspended: the thickness is the event's, drawn above.
        ConductorWalkEvent<kPolarized, false>(layer.conductor, reflection, reflection, m, v, rng,
                                              max_order, degenerate, false);
        return;
    }
    const VF u1 = rng.Uniform(), u2 = rng.Uniform();
    ConductorEvent<kPolarized, false>(layer.conductor, reflection, reflection, m, v, u1, u2,
                                      degenerate);
}

// Lambertian (lambertian.h lambertian_event, the same template): cosine-distributed on wi's side,
// weight = albedo (per channel and lane: the interface's, or a spectral lane's); it depolarizes
// (polarized runs).
template <bool kPolarized>
HWY_INLINE void KeepLambertianEvent(const VF albedo[3], MF m, LaneVectors& v, const V3& wo,
                                    MF& degenerate) {
    const DF df;
    const MF bad = hn::And(m, hn::Eq(v.d.z, hn::Zero(df)));
    degenerate = hn::Or(degenerate, bad);
    const MF ok = hn::AndNot(bad, m);
    v.Keep(ok, kLossBase, albedo);
    v.d = Select(ok, wo, v.d);
    if constexpr (kPolarized) stokes_depolarize<VF, VecLane>(v.pol.stokes, 3, ok);
}
template <bool kPolarized>
HWY_INLINE void LambertianEvent(const VF albedo[3], MF m, LaneVectors& v, VF u1, VF u2,
                                MF& degenerate) {
    KeepLambertianEvent<kPolarized>(
        albedo, m, v, lambertian_event<VF, VecLane>(hn::Neg(v.d.z), u1, u2), degenerate);
}

// The same event on two lane sets at once (VecLane2; DielectricEventPair).
template <bool kPolarized>
HWY_INLINE void LambertianEventPair(const VF albedo[3], MF m, MF n, LaneVectors& v, LaneVectors& w,
                                    VF2 u1, VF2 u2, MF& degenerate_v, MF& degenerate_w) {
    const LaneVec3<VF2> wo =
        lambertian_event<VF2, VecLane2>({hn::Neg(v.d.z), hn::Neg(w.d.z)}, u1, u2);
    KeepLambertianEvent<kPolarized>(albedo, m, v, First(wo), degenerate_v);
    KeepLambertianEvent<kPolarized>(albedo, n, w, Second(wo), degenerate_w);
}

// ---- Media (physics/medium.h, the templates the scalar kernel instantiates at one lane) -------

// A scattering medium's values on the lanes (a spectral run's: each lane's stack's), in the
// fields medium.h reads; its flags hold for every lane.
struct LaneMedium {
    VF tau_a[3], tau_s[3], tau_t[3], g[3], single_scattering_albedo[3];
    bool uniform_tau_t, uniform_g;
};

// One scattering-medium step for the lanes in m (inside layer `layer`'s medium, a CompiledMedium
// or a LaneMedium): a free flight, then either the crossing to the next interface or a scattering
// event (which depolarizes). The lanes draw their numbers as the template asks for them (every
// lane draws while any needs them).
template <bool kPolarized, typename Medium>
HWY_INLINE void ScatteringStep(const Medium& med, MF m, LaneVectors& v, LaneRng& rng) {
    const DF df;
    const DI di;
    auto uniform = [&] { return rng.Uniform(); };
    const MediumFlightLanes<VF, MF> flight =
        medium_free_flight<VF, VecLane>(med, v.d, v.w, v.depth, uniform);
    const MF leaves = hn::And(m, flight.leaves);
    const MF scatters = hn::AndNot(flight.leaves, m);
    V3 d_new = v.d;
    VF phase[3];
    if (medium_scatter<VF, VecLane>(med, v.d, flight.p, scatters, uniform, d_new, phase)) {
        VF factor[3];
        for (int c = 0; c < 3; ++c)
            factor[c] =
                hn::IfThenElse(scatters, hn::Mul(flight.factor[c], phase[c]), flight.factor[c]);
        v.Keep(m, kLossMedium, factor);
        v.depth = hn::IfThenElse(scatters, flight.depth, v.depth);
        v.d = Select(scatters, d_new, v.d);
        // A scattering event depolarizes (docs/physics.md §8).
        if constexpr (kPolarized) stokes_depolarize<VF, VecLane>(v.pol.stokes, 3, scatters);
        v.events = hn::IfThenElse(hn::RebindMask(di, scatters), hn::Add(v.events, hn::Set(di, 1)),
                                  v.events);
    } else {
        v.Keep(m, kLossMedium, flight.factor);
    }
    // Leaving lanes arrive at the interface above (k) or below (k + 1).
    const MI leave_i = hn::RebindMask(di, leaves);
    const MI down = hn::RebindMask(di, hn::Lt(v.d.z, hn::Zero(df)));
    v.k = hn::IfThenElse(hn::And(leave_i, down), hn::Add(v.k, hn::Set(di, 1)), v.k);
    v.in_medium = hn::IfThenElseZero(hn::Not(leave_i), v.in_medium);
}

LAMINA_LANE_END

#endif  // LAMINA_SIMULATOR_LANE_EVENTS_H

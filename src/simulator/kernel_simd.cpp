// The batched SIMD particle kernel (kernel_simd.h): trace_particle (goniophotometer.cpp) on SIMD
// vectors, particles as lanes. The physics is not here: every event is a lane template of
// src/physics (core/lane.h) that the scalar kernel instantiates at one lane and this kernel on its
// vectors — the interface events (dielectric.h dielectric_event, conductor.h conductor_event,
// lambertian.h lambertian_event, with the Fresnel factors, the Smith masking and the visible
// normals they use), the microsurface walk (microsurface_walk.h) and the medium step (medium.h:
// Beer–Lambert, free flights and Henyey–Greenstein scattering by spectral MIS), in their isotropic
// or general (anisotropic) GGX instance as trace_particle takes them, and a thin film on a
// conductor, whose reflection (the Airy sums of physics/thin_film_airy.h, in double, on vectors of
// doubles: simulator/lane_film.h FilmReflection) takes the place of the bare Fresnel terms in the
// conductor templates; a film on a dielectric is the scalar kernel's (SimulationSettings::kernel).
// Nor are the lane operations on Highway vectors (VecLane, core/lane_hwy.h), the vector random
// numbers (simulator/lane_rng.h) and the vector exit bins (simulator/lane_bins.h). The lane state
// and the events' adapters to it are simulator/lane_events.h, the block's queue and per-lane sums
// simulator/lane_block.h. This file holds the lane management: the refills of lanes from the
// queue, the grouping of lanes by layer, the tallies and the budget sums.
//
// Layout. A block's particles run through a fixed set of lanes; a lane whose particle ends (exit,
// absorption, cut-off) takes the block's next particle, so all lanes stay busy until the block's
// tail. Per iteration every live lane does one step: an interface event followed, for lanes that
// continue, by the crossing of the medium behind it (Beer–Lambert for absorbing media), or — for a
// lane inside a scattering medium — one free flight with its scattering event. Interfaces are
// evaluated layer by layer under the mask of the lanes that sit at that layer, with the layer's
// parameters broadcast; no lane-dependent branches. What a lane does per step is exactly what
// trace_particle does per loop (the same templates, the same budget bookkeeping, the same event
// count), so the two kernels estimate the same tables (tests/simulator: every exact-solution test
// runs on both, and a two-sample chi-square test compares them; tests/physics/lanes_test.cpp and
// tests/simulator/kernel_simd_test.cpp compare each template's instantiations).
//
// Two lane sets. The lanes are two vectors' worth, two sets (LaneSet) that step together at the
// group largest over both, and the first events take two vectors of particles at a time. At an
// interface the event runs on the pair of the two sets' vectors (VecLane2, core/lane_hwy.h):
// every operation twice, side by side, on independent data. One vector's event is a long chain of
// dependent operations during which the processor's units wait; the second chain fills them
// (docs/performance.md, "Against the yardstick"). Paired: a dielectric's single-scattering event
// (unpolarized), a bare conductor's (polarized or not), a Lambertian's (InterfaceStepPair). Each
// set alone: the microsurface walks (paired, the pair walks until the last of its 32 lanes has
// left, and the exact reference ran 2–5 % slower than with each set walking alone), spectral
// runs, filmed conductors, a polarized dielectric's single-scattering event, sets whose
// polarization states differ in their channels, scattering media, the tallies and refills.
//
// Multiple scattering on the microsurfaces (physics/microsurface_walk.h). At a rough interface
// the lanes of the event walk from facet to facet together: while any of them walks, every lane of
// the vector draws its numbers, and the event ends when each has escaped, met its facet cap or a
// degeneracy. In the main loop's steps, once a quarter of the lanes or fewer still walk (after
// their first facet), their walks are suspended (LaneVectors::mid_walk): they wait at the
// interface and go on the next time it steps, beside the lanes arriving there, rather than keeping
// the whole vector in the walk for the few facets more they need (most walks end after one
// facet; a vector's longest walk is much longer than its average). The event counts once, as in
// trace_particle, and the cut-off on events never interrupts a suspended walk.
//
// Random numbers. Each lane draws from the particle's own generator, the very stream of the scalar
// kernel (simulator/lane_rng.h). Every lane draws whenever some lane of its step needs a number,
// used or not: a particle's draws are then not those of the scalar kernel, but each is still a
// fresh uniform number independent of the particle's past.
//
// Reproducibility. A block is traced in a fixed order by one thread; exits go to the integer
// tallies and the budget to the block's double sums in a fixed lane order: the output depends on
// the block only, never on the thread count. It may differ between instruction sets (the vector
// math rounds differently; SSE4 has no fused multiply-add), never between CPUs for one set: every
// vector operation is a fixed sequence of IEEE operations (no hardware estimates, core/lane_hwy.h
// InvSqrt).

#include "simulator/kernel_simd.h"

#include "core/error.h"
#include "core/math.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

// The instruction sets: those src/simulator/CMakeLists.txt leaves (lamina_simd_unit).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "simulator/kernel_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

// The lane headers once more, their templates compiled for this instruction set (core/lane_hwy.h).
#define LAMINA_LANE_TARGET
#include "core/lane_hwy.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/medium.h"
#include "physics/microsurface_walk.h"
#include "physics/polarization.h"
#include "simulator/lane_bins.h"
#include "simulator/lane_block.h"
#include "simulator/lane_conductor.h"
#include "simulator/lane_events.h"
#include "simulator/lane_rng.h"
#undef LAMINA_LANE_TARGET

HWY_BEFORE_NAMESPACE();
namespace lamina {
namespace HWY_NAMESPACE {

// ---- The block ----

// One block traced (trace_block_simd), in two phases: every particle's first event on full
// vectors (FirstEvents), then steps of the lanes with refills from the queue until it is empty
// (Steps). Written once for both: kPolarized = false is the unpolarized kernel, with none of it;
// kAnisotropic = true the general (anisotropic) GGX instance at every rough interface (VecGgx).
// The per-step work, InterfaceStep and EndParticles, is compiled out of line (two call sites
// each); the pieces they are made of are inlined into them.
//
// kSpectral: a spectral run (job.spectral; trace_block_spectral's particles on lanes). Each lane's
// particle draws its stack (its three wavelengths and hero) first, as trace_block_spectral's does,
// from its own stream; the lanes branch on SpectralTracing::structure and gather the values that
// differ between the stacks (SpectralLayerLanes) by their stack index at every event: the
// dielectric's index, the conductor's, the albedo, the medium's depths, phase function and
// single-scattering albedo (LaneMedium), each lane's film. At a
// dispersive interface a lane's secondary wavelengths end as SpectralParticle::before_event ends
// them. Exits are tallied per lane as SpectralParticle::exit tallies them, and a particle's
// losses, kept per lane in double, are booked to its wavelength group and colour projections
// (SpectralParticle::flush) when it ends — or, for the particles that wait after their first
// event, then.
template <bool kPolarized, bool kAnisotropic, bool kSpectral>
class BlockTracer {
  public:
    BlockTracer(const BlockJob& job, Tally& tally, Scratch& scratch)
        : job_(job),
          tally_(tally),
          stack_(kSpectral ? job.spectral->structure : *job.stack),
          grid_(*job.grid),
          n_layers_(int(stack_.layers.size())),
          n_lanes_(hn::Lanes(DF())),
          zero_(hn::Zero(DF())),
          one_(hn::Set(DF(), 1.f)),
          scratch_(scratch),
          vector_bins_(grid_),
          stokes_tallies_(kPolarized && job.stokes_tallies) {
        sums_.zero();
    }

    void Trace(BlockBudget& block) {
        block_ = &block;
        if constexpr (kSpectral)
            for (auto& set : particle_loss_)
                for (auto& term : set)
                    for (auto& channel : term)
                        std::fill(std::begin(channel), std::end(channel), 0.0);
        scratch_.resize(job_.count, kPolarized);
        SeedParticles(job_.seed, job_.stream, job_.first, job_.count, scratch_.state.data(),
                      scratch_.inc.data());
        FirstEvents();
        Steps();
        sums_.reduce(block, tally_.sums.events);
        tally_.sums.degenerate += degenerate_;
    }

  private:
    // ---- Lane bookkeeping ----

    // Moves a lane set's float sums into the double ones (spectral runs: the losses into each
    // lane's particle's, particle_loss_).
    HWY_INLINE void Flush(LaneVectors& v) {
        for (int c = 0; c < 3; ++c) {
            for (int t = 0; t < kLossTerms; ++t)
                if (v.touched[t]) {
                    if constexpr (kSpectral)
                        AddToLanes(particle_loss_[v.set][t][c], v.loss[t][c]);
                    else
                        sums_.add(t, c, v.loss[t][c]);
                    v.loss[t][c] = zero_;
                }
            for (int e = 0; e < 4; ++e)
                if (left_[e / 2]) {
                    sums_.add(kLossTerms + e, c, v.exit_sum[e][c]);
                    v.exit_sum[e][c] = zero_;
                }
        }
    }

    // x added to the per-lane doubles at `into`, in double.
    static HWY_INLINE void AddToLanes(double* into, VF x) {
        const DD dd;
        const hn::Half<DF> dfh;
        const std::size_t half = hn::Lanes(dd);
        hn::Store(hn::Add(hn::Load(dd, into), hn::PromoteTo(dd, hn::LowerHalf(dfh, x))), dd, into);
        hn::Store(hn::Add(hn::Load(dd, into + half), hn::PromoteTo(dd, hn::UpperHalf(dfh, x))), dd,
                  into + half);
    }

    // ---- Spectral lanes ----

    // A table of SpectralLayerLanes at the lanes' stacks.
    HWY_INLINE VF Gather(const std::vector<float>& table, VI at) const {
        return hn::GatherIndex(DF(), table.data(), at);
    }
    // Layer `layer`'s scattering medium at the lanes' stacks, with the flags of `shared`
    // (SpectralTracing::structure's).
    HWY_INLINE LaneMedium SpectralMedium(const CompiledMedium<float>& shared, int layer,
                                         VI at) const {
        const SpectralLayerLanes& t = job_.spectral->layer_lanes[std::size_t(layer)];
        LaneMedium med;
        for (int c = 0; c < 3; ++c) {
            med.tau_a[c] = Gather(t.tau_a[c], at);
            med.tau_s[c] = Gather(t.tau_s[c], at);
            med.tau_t[c] = Gather(t.tau_t[c], at);
            med.g[c] = Gather(t.g[c], at);
            med.single_scattering_albedo[c] = Gather(t.single_scattering_albedo[c], at);
        }
        med.uniform_tau_t = shared.uniform_tau_t;
        med.uniform_g = shared.uniform_g;
        return med;
    }
    // The particle of lane l, staged by StageSpectral.
    HWY_INLINE SpectralParticle LaneParticle(std::size_t l) const {
        return spectral_particle(job_, std::size_t(at_out_[l]), group_out_[l]);
    }
    // The lanes' stacks and groups into at_out_ and group_out_, their float losses into
    // particle_loss_.
    HWY_INLINE void StageSpectral(LaneVectors& v) {
        const DI di;
        hn::Store(v.at, di, at_out_);
        hn::Store(v.group, di, group_out_);
        Flush(v);
    }
    // Lane l's particle's losses (staged; lane set `set`'s) booked to its wavelength group and
    // colour projections, and cleared for the lane's next particle.
    HWY_INLINE void BookLosses(int set, std::size_t l) {
        PathLosses losses;
        bool any = false;
        for (int t = 0; t < kLossTerms; ++t)
            for (int c = 0; c < 3; ++c) {
                double& lost = particle_loss_[set][t][c][l];
                losses.term[std::size_t(int(BudgetTerm::AbsorbedMedium) + t)][std::size_t(c)] =
                    lost;
                any = any || lost != 0.0;
                lost = 0.0;
            }
        if (any) LaneParticle(l).flush(losses, *block_);
    }
    // Before an event at layer `group`: a dispersive interface ends the secondary wavelengths of
    // the lanes in m that still carry them; the hero carries 3 times its flux
    // (SpectralParticle::before_event).
    HWY_INLINE void EndSecondaries(LaneVectors& v, int group, MF m) const {
        const DF df;
        const DI di;
        const VI dispersive = hn::GatherIndex(
            di, job_.spectral->layer_lanes[std::size_t(group)].dispersive.data(), v.at);
        const MI ends =
            hn::And(hn::RebindMask(di, m),
                    hn::And(hn::Ne(dispersive, hn::Zero(di)), hn::Ne(v.secondaries, hn::Zero(di))));
        if (hn::AllFalse(di, ends)) return;
        const MF ends_f = hn::RebindMask(df, ends);
        for (int c = 0; c < 3; ++c) {
            const MF hero = hn::RebindMask(df, hn::Eq(v.hero, hn::Set(di, c)));
            v.w[c] = hn::IfThenElse(
                ends_f, hn::IfThenElseZero(hero, hn::Mul(hn::Set(df, 3.f), v.w[c])), v.w[c]);
        }
        v.secondaries = hn::IfThenElseZero(hn::Not(ends), v.secondaries);
    }

    HWY_INLINE void Clear(LaneVectors& v) const {
        const DF df;
        const DI di;
        v.d = {zero_, zero_, zero_};
        v.depth = zero_;
        for (int c = 0; c < 3; ++c)
            v.w[c] = zero_;
        for (auto& term : v.loss)
            for (auto& channel : term)
                channel = zero_;
        for (auto& term : v.exit_sum)
            for (auto& channel : term)
                channel = zero_;
        v.k = v.in_medium = v.events = v.events_done = v.live = v.finish = hn::Zero(di);
        v.at = v.hero = v.group = v.secondaries = v.mid_walk = hn::Zero(di);
        v.walk_h = v.walk_side = v.walk_order = zero_;
        for (int c = 0; c < 3; ++c)
            v.walk_weight[c] = zero_;
        if constexpr (kPolarized) {
            v.pol.stokes = stokes_incident<VF, VecLane>(
                {hn::Set(df, -job_.wi.x), hn::Set(df, -job_.wi.y), hn::Set(df, -job_.wi.z)},
                job_.incident_stokes);
            v.pol.channels = stack_.polarization_channels;
            v.pol.flux = v.w;
        }
    }

    // ---- One interface event of the lanes in `going`, all at interface `group` ----

    // The layer's event on the lanes of `going`; marks the lanes whose sample failed. The
    // layer's values: its own, or (kSpectral) each lane's stack's (SpectralLayerLanes).
    HWY_INLINE void Event(const CompiledLayer<float>& layer, int group, LaneVectors& v,
                          LaneRng& rng, MF going, MF& degenerate_event) const {
        const DF df;
        [[maybe_unused]] const SpectralLayerLanes* lanes =
            kSpectral ? &job_.spectral->layer_lanes[std::size_t(group)] : nullptr;
        switch (layer.type) {
            case InterfaceType::Dielectric: {
                VF eta = hn::Set(df, layer.dielectric.eta);
                VF inv_eta = hn::Set(df, layer.dielectric.inv_eta());
                if constexpr (kSpectral) {
                    eta = Gather(lanes->eta, v.at);
                    inv_eta = Gather(lanes->inv_eta, v.at);
                }
                if (layer.multiple) {
                    DielectricWalkEvent<kPolarized, kAnisotropic>(
                        layer.dielectric, eta, inv_eta, going, v, rng,
                        stack_.max_microsurface_order, degenerate_event, may_suspend_);
                    break;
                }
                const VF uc = rng.Uniform(), u1 = rng.Uniform(), u2 = rng.Uniform();
                DielectricEvent<kPolarized, kAnisotropic>(layer.dielectric, eta, inv_eta, going, v,
                                                          uc, u1, u2, degenerate_event);
                break;
            }
            case InterfaceType::Conductor: {
                if constexpr (!kAnisotropic)
                    if (layer.has_film) {
                        HWY_ALIGN const FilmOptics* films[kMaxLanes];
                        if constexpr (kSpectral) {
                            HWY_ALIGN std::int32_t at[kMaxLanes];
                            hn::Store(v.at, DI(), at);
                            for (std::size_t l = 0; l < n_lanes_; ++l)
                                films[l] = &job_.spectral->stacks[std::size_t(at[l])]
                                                .layers[std::size_t(group)]
                                                .film;
                        } else {
                            std::fill(films, films + n_lanes_, &layer.film);
                        }
                        FilmConductorEvent<kPolarized>(layer, films, going, v, rng,
                                                       stack_.max_microsurface_order,
                                                       degenerate_event);
                        break;
                    }
                if constexpr (kSpectral) {
                    LaneConductorFresnel fresnel;
                    LaneConductorMueller mueller;
                    for (int c = 0; c < 3; ++c) {
                        fresnel.eta[c] = mueller.eta[c] = Gather(lanes->conductor_eta[c], v.at);
                        fresnel.k[c] = mueller.k[c] = Gather(lanes->conductor_k[c], v.at);
                    }
                    ConductorLaneEvent(layer, fresnel, mueller, going, v, rng, degenerate_event);
                } else {
                    ConductorLaneEvent(layer, ConductorFresnel{layer.conductor},
                                       ConductorMueller{layer.conductor}, going, v, rng,
                                       degenerate_event);
                }
                break;
            }
            case InterfaceType::Lambertian: {
                VF albedo[3];
                for (int c = 0; c < 3; ++c)
                    if constexpr (kSpectral)
                        albedo[c] = Gather(lanes->albedo[c], v.at);
                    else
                        albedo[c] = hn::Set(df, layer.lambertian.albedo[c]);
                const VF u1 = rng.Uniform(), u2 = rng.Uniform();
                LambertianEvent<kPolarized>(albedo, going, v, u1, u2, degenerate_event);
                break;
            }
        }
    }

    // A bare conductor's event or walk with the Fresnel factors and Mueller matrices of
    // `fresnel` and `mueller` (lane_conductor.h).
    template <typename Fresnel, typename Mueller>
    HWY_INLINE void ConductorLaneEvent(const CompiledLayer<float>& layer, const Fresnel& fresnel,
                                       const Mueller& mueller, MF going, LaneVectors& v,
                                       LaneRng& rng, MF& degenerate_event) const {
        if (layer.multiple) {
            ConductorWalkEvent<kPolarized, kAnisotropic>(layer.conductor, fresnel, mueller, going,
                                                         v, rng, stack_.max_microsurface_order,
                                                         degenerate_event, may_suspend_);
            return;
        }
        const VF u1 = rng.Uniform(), u2 = rng.Uniform();
        ConductorEvent<kPolarized, kAnisotropic>(layer.conductor, fresnel, mueller, going, v, u1,
                                                 u2, degenerate_event);
    }

    // The lanes of `continues` leave interface `group`: out of the stack at its top or bottom
    // (reflected, transmitted), else into the medium behind it, below going down and above going
    // up: a scattering medium's lanes enter it (its free flights are later steps), an absorbing
    // one's cross it (Beer–Lambert), and both arrive at the next interface.
    HWY_INLINE void LeaveInterface(LaneVectors& v, int group, MF continues) const {
        const DF df;
        const DI di;
        const MF up = hn::Gt(v.d.z, zero_);
        const MF goes_up = hn::And(continues, up), goes_down = hn::AndNot(up, continues);
        MF moves_up = goes_up, moves_down = goes_down;
        if (group == 0) {
            v.End(goes_up, kReflected);
            moves_up = hn::FirstN(df, 0);
        }
        if (group == n_layers_ - 1) {
            v.End(goes_down, kTransmitted);
            moves_down = hn::FirstN(df, 0);
        }
        for (int side = 0; side < 2; ++side) {
            const MF moving = side == 0 ? moves_up : moves_down;
            const int medium_layer = side == 0 ? group - 1 : group;
            const int k_next = side == 0 ? group - 1 : group + 1;
            if (hn::AllFalse(df, moving)) continue;
            const CompiledMedium<float>& med = stack_.layers[medium_layer].medium;
            if (med.scatters) {
                // Enters the medium: its free flights are later steps.
                const auto mi = hn::RebindMask(di, moving);
                v.in_medium = hn::IfThenElse(mi, hn::Set(di, 1), v.in_medium);
                v.k = hn::IfThenElse(mi, hn::Set(di, medium_layer), v.k);
                v.depth = hn::IfThenElse(moving, hn::Set(df, side == 0 ? 1.f : 0.f), v.depth);
                continue;
            }
            if (med.absorbs) {
                // Pure absorption: Beer–Lambert along the straight path (physics/medium.h), at
                // each spectral lane's own depths.
                VF transmittance[3];
                const VF inv_mu = hn::Div(one_, hn::Abs(v.d.z));
                if constexpr (kSpectral) {
                    const SpectralLayerLanes& lanes =
                        job_.spectral->layer_lanes[std::size_t(medium_layer)];
                    const VF tau[3] = {Gather(lanes.tau_a[0], v.at), Gather(lanes.tau_a[1], v.at),
                                       Gather(lanes.tau_a[2], v.at)};
                    beer_lambert_transmittance_lanes<VF, VecLane>(tau, inv_mu, transmittance);
                } else {
                    beer_lambert_transmittance<VF, VecLane>(med.tau_a, inv_mu, transmittance);
                }
                v.Keep(moving, kLossMedium, transmittance);
                v.End(hn::And(moving, v.Black()), kEnded);
            }
            v.k = hn::IfThenElse(hn::RebindMask(di, moving), hn::Set(di, k_next), v.k);
        }
    }

    // A lane set of the main loop: its lanes, their generators and its steps since its float
    // sums were last flushed.
    struct LaneSet {
        LaneVectors v;
        LaneRng rng;
        int steps_since_flush = 0;
    };

    void InterfaceStep(LaneVectors& v, LaneRng& rng, int group, MF going) {
        MF degenerate_event = hn::FirstN(DF(), 0);  // all false
        Arrive(v, group, going);
        Event(stack_.layers[group], group, v, rng, going, degenerate_event);
        Depart(v, group, going, degenerate_event);
    }

    // Two lane sets' interface step at one interface (StepPair, the first events): as
    // InterfaceStep on each, the event on the pair of their vectors where it has a pair form (the
    // file's comment, "Two lane sets").
    void InterfaceStepPair(LaneSet& s, LaneSet& t, int group, MF going_s, MF going_t) {
        const CompiledLayer<float>& layer = stack_.layers[group];
        MF degenerate_s = hn::FirstN(DF(), 0), degenerate_t = degenerate_s;
        Arrive(s.v, group, going_s);
        Arrive(t.v, group, going_t);
        const DF df;
        if (!kSpectral && !layer.multiple && layer.type == InterfaceType::Dielectric &&
            !kPolarized) {
            const VF uc_s = s.rng.Uniform(), u1_s = s.rng.Uniform(), u2_s = s.rng.Uniform();
            const VF uc_t = t.rng.Uniform(), u1_t = t.rng.Uniform(), u2_t = t.rng.Uniform();
            DielectricEventPair<kAnisotropic>(layer.dielectric, hn::Set(df, layer.dielectric.eta),
                                              hn::Set(df, layer.dielectric.inv_eta()), going_s,
                                              going_t, s.v, t.v, {uc_s, uc_t}, {u1_s, u1_t},
                                              {u2_s, u2_t}, degenerate_s, degenerate_t);
        } else if (!kSpectral && !layer.multiple && layer.type == InterfaceType::Conductor &&
                   !layer.has_film && s.v.pol.channels == t.v.pol.channels) {
            const VF u1_s = s.rng.Uniform(), u2_s = s.rng.Uniform();
            const VF u1_t = t.rng.Uniform(), u2_t = t.rng.Uniform();
            ConductorEventPair<kPolarized, kAnisotropic>(layer.conductor, going_s, going_t, s.v,
                                                         t.v, {u1_s, u1_t}, {u2_s, u2_t},
                                                         degenerate_s, degenerate_t);
        } else if (!kSpectral && layer.type == InterfaceType::Lambertian) {
            VF albedo[3];
            for (int c = 0; c < 3; ++c)
                albedo[c] = hn::Set(df, layer.lambertian.albedo[c]);
            const VF u1_s = s.rng.Uniform(), u2_s = s.rng.Uniform();
            const VF u1_t = t.rng.Uniform(), u2_t = t.rng.Uniform();
            LambertianEventPair<kPolarized>(albedo, going_s, going_t, s.v, t.v, {u1_s, u1_t},
                                            {u2_s, u2_t}, degenerate_s, degenerate_t);
        } else {
            Event(layer, group, s.v, s.rng, going_s, degenerate_s);
            Event(layer, group, t.v, t.rng, going_t, degenerate_t);
        }
        Depart(s.v, group, going_s, degenerate_s);
        Depart(t.v, group, going_t, degenerate_t);
    }

    // The lanes of `going` arrive at interface `group`: their event is counted (a suspended walk
    // going on is the same event: counted, and its secondary wavelengths ended, once).
    HWY_INLINE void Arrive(LaneVectors& v, int group, MF going) const {
        const DI di;
        const MF arriving = hn::AndNot(v.MidWalk(going), going);
        v.events = hn::IfThenElse(hn::RebindMask(di, arriving), hn::Add(v.events, hn::Set(di, 1)),
                                  v.events);
        if constexpr (kSpectral) EndSecondaries(v, group, arriving);
    }

    // After the event of the lanes of `going` at interface `group`: failed samples and grazing
    // directions booked, ended particles marked, the others leave the interface.
    HWY_INLINE void Depart(LaneVectors& v, int group, MF going, MF degenerate_event) {
        const DF df;
        const CompiledLayer<float>& layer = stack_.layers[group];
        const bool dielectric = layer.type == InterfaceType::Dielectric;
        const MF done = hn::AndNot(v.MidWalk(going), going);  // the lanes whose event is over
        // A failed sample loses the flux to the microsurface; an exactly grazing new direction is
        // lost to the microsurface (dielectric) or the base (opaque), as in trace_particle.
        const MF grazing = hn::AndNot(degenerate_event, hn::And(done, hn::Eq(v.d.z, zero_)));
        const MF lost = hn::Or(degenerate_event, grazing);
        v.Keep(dielectric ? lost : degenerate_event, kLossMicro, zero_);
        if (!dielectric) v.Keep(grazing, kLossBase, zero_);
        degenerate_ += hn::CountTrue(df, lost);
        const MF black = hn::And(done, v.Black());
        const MF ends = hn::Or(black, lost);
        v.End(ends, kEnded);
        LeaveInterface(v, group, hn::AndNot(ends, done));
    }

    // ---- Particles that ended in a step: sums on vectors, exits binned and tallied in lane
    // order; on_lane(l) then runs for every ended lane, in lane order ----

    // R, R², T, T² of the leaving lanes into the lanes' float sums; the ended particles' events.
    HWY_INLINE void SumEnded(LaneVectors& v, MF ended, MF reflected, MF transmitted) {
        const DF df;
        const DI di;
        // Spectral runs: each exit is tallied with its particle's colour weights (TallyExit).
        for (int side = 0; side < (kSpectral ? 0 : 2); ++side) {
            const MF leaves = side == 0 ? reflected : transmitted;
            if (hn::AllFalse(df, leaves)) continue;
            left_[side] = true;
            for (int c = 0; c < 3; ++c) {
                const VF w_out_c = hn::IfThenElseZero(leaves, v.w[c]);
                v.exit_sum[2 * side][c] = hn::Add(v.exit_sum[2 * side][c], w_out_c);
                v.exit_sum[2 * side + 1][c] =
                    hn::MulAdd(w_out_c, w_out_c, v.exit_sum[2 * side + 1][c]);
            }
        }
        v.events_done =
            hn::Add(v.events_done, hn::IfThenElseZero(hn::RebindMask(di, ended), v.events));
    }

    // The exits' bins (where the lanes are certain of them, else their directions for bin_of),
    // fluxes and, with Stokes tallies, Stokes vectors into the per-lane arrays; returns the lanes
    // whose bins are known (bit l for lane l).
    HWY_INLINE std::uint64_t StageExits(const LaneVectors& v, MF exits) {
        const DF df;
        const std::uint64_t known_bins = LaneBins(vector_bins_, v.d, theta_bin_, phi_bin_);
        if ((MaskBits(exits) & ~known_bins) != 0) {
            hn::Store(v.d.x, df, d_out_[0]);
            hn::Store(v.d.y, df, d_out_[1]);
            hn::Store(v.d.z, df, d_out_[2]);
        }
        for (int c = 0; c < 3; ++c)
            hn::Store(v.w[c], df, w_out_[c]);
        if constexpr (kPolarized)
            if (stokes_tallies_) {
                VF stokes[3][4];
                stokes_in_bin_frame<VF, VecLane>(v.pol.stokes, v.d, v.w, v.pol.channels, exits,
                                                 stokes);
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < 4; ++k)
                        hn::Store(stokes[c][k], df, stokes_out_[c][k]);
                hn::Store(v.d.y, df, d_out_[1]);
            }
        return known_bins;
    }

    // Lane l's bin (staged by StageExits).
    HWY_INLINE std::size_t ExitBin(std::size_t l, std::uint64_t known_bins) const {
        return (known_bins >> l & 1) != 0
                   ? std::size_t(theta_bin_[l]) * std::size_t(vector_bins_.n_phi) +
                         std::size_t(phi_bin_[l])
                   : grid_.bin_of(Vec3f(d_out_[0][l], d_out_[1][l], d_out_[2][l]));
    }

    // Lane l's exit (staged by StageExits) into the tallies.
    HWY_INLINE void TallyExit(std::size_t l, std::int32_t why, std::uint64_t known_bins) {
        const Rgbf w(w_out_[0][l], w_out_[1][l], w_out_[2][l]);
        const std::size_t bin = ExitBin(l, known_bins);
        if constexpr (kSpectral) {
            LaneParticle(l).exit((why == kTransmitted ? grid_.size() : 0) + bin, why == kReflected,
                                 w, tally_, *block_);
            return;
        }
        tally_.exit((why == kTransmitted ? grid_.size() : 0) + bin, w);
        if constexpr (kPolarized)
            if (stokes_tallies_) {
                float s[3][4];
                for (int c = 0; c < 3; ++c)
                    for (int k = 0; k < 4; ++k)
                        s[c][k] = stokes_out_[c][k][l];
                // Folded bins count the patch y < 0 as its mirror image (mueller.h); unfolded
                // ones are one patch each (trace_particle's exit_stokes).
                tally_.exit_stokes((why == kTransmitted ? grid_.size() : 0) + bin,
                                   d_out_[1][l] < 0 && !grid_.is_unfolded() ? 1 : 0, s);
            }
    }

    template <typename OnLane>
    void EndParticles(LaneVectors& v, MF ended, OnLane&& on_lane) {
        const DF df;
        const DI di;
        const MF reflected = LaneIs(v.finish, kReflected);
        const MF transmitted = LaneIs(v.finish, kTransmitted);
        SumEnded(v, ended, reflected, transmitted);
        const MF exits = hn::Or(reflected, transmitted);
        hn::Store(v.finish, di, finish_);
        std::uint64_t known_bins = 0;
        if (!hn::AllFalse(df, exits)) known_bins = StageExits(v, exits);
        if constexpr (kSpectral) {
            StageSpectral(v);
            // A spectral run's wavelength tally (bins × wavelength groups entries, 7.8 MB on the
            // 90 × 90 grid) is larger than the caches: the entries the exiting lanes add to are
            // fetched all at once, before the loop adds to them one after the other (an exit
            // waited on each in turn: 33 % of a spectral conductor's time, 13 % so). An RGB run's
            // tallies gain nothing from it (measured: 2 % slower).
            for (std::uint64_t bits = MaskBits(exits); bits != 0; bits &= bits - 1) {
                const std::size_t l = std::size_t(std::countr_zero(bits));
                LaneParticle(l).prefetch((finish_[l] == kTransmitted ? grid_.size() : 0) +
                                         ExitBin(l, known_bins));
            }
        }
        // Over the set bits of the mask: which lanes ended is random, a branch per lane would be
        // mispredicted half of the time.
        for (std::uint64_t ended_bits = MaskBits(ended); ended_bits != 0;
             ended_bits &= ended_bits - 1) {
            const std::size_t l = std::size_t(std::countr_zero(ended_bits));
            const std::int32_t why = finish_[l];
            if (why != kEnded) TallyExit(l, why, known_bins);
            if constexpr (kSpectral) BookLosses(v.set, l);
            on_lane(l);
        }
    }

    // ---- First events, on full vectors ----
    // Every particle starts with the same event (interface 0 met from above), so the block's
    // particles take it in order, all lanes busy; the survivors wait in a queue, in particle
    // order. The main loop then hands out particles that are past their first event: the fresh
    // particles of a two-interface stack join the others in phase (at the lower interface)
    // instead of idling for a step.
    void FirstEvents() {
        const DF df;
        const DI di;
        may_suspend_ = false;
        QueueArrays& queue = scratch_.queue;
        queue.size = 0;
        if constexpr (kSpectral) scratch_.queue_spectral.clear();
        // Two chunks of particles at a time, one per lane set (their events on the pair of
        // vectors, InterfaceStepPair), queued in order.
        LaneSet chunk[2];
        for (int i = 0; i < 2; ++i) {
            Clear(chunk[i].v);
            chunk[i].v.set = i;
        }
        [[maybe_unused]] const StokesLanes<VF> incident = chunk[0].v.pol.stokes;
        for (std::uint64_t base = 0; base < job_.count; base += 2 * n_lanes_) {
            std::size_t n[2];
            MF going[2];
            for (int i = 0; i < 2; ++i) {
                const std::uint64_t first = base + std::uint64_t(i) * n_lanes_;
                n[i] = std::size_t(
                    first < job_.count ? std::min<std::uint64_t>(n_lanes_, job_.count - first) : 0);
                LaneVectors& p = chunk[i].v;
                LaneRng& prng = chunk[i].rng;
                for (std::size_t l = 0; l < n_lanes_; ++l) {
                    prng.state[l] = l < n[i] ? scratch_.state[first + l] : 0;
                    prng.inc[l] = l < n[i] ? scratch_.inc[first + l] : 1;
                }
                prng.SyncIn();
                going[i] = hn::FirstN(df, n[i]);
                p.d = {hn::Set(df, -job_.wi.x), hn::Set(df, -job_.wi.y), hn::Set(df, -job_.wi.z)};
                for (int c = 0; c < 3; ++c)
                    p.w[c] = hn::IfThenElseZero(going[i], one_);
                p.k = p.in_medium = p.events = p.finish = hn::Zero(di);
                p.depth = zero_;
                if constexpr (kPolarized) p.pol.stokes = incident;
                if constexpr (kSpectral)
                    if (n[i] > 0) DrawStacks(p, prng, first);
            }
            InterfaceStepPair(chunk[0], chunk[1], 0, going[0], going[1]);
            for (int i = 0; i < 2 && n[i] > 0; ++i) {
                LaneVectors& p = chunk[i].v;
                LaneRng& prng = chunk[i].rng;
                const MF ended = hn::RebindMask(df, hn::Ne(p.finish, hn::Zero(di)));
                if (!hn::AllFalse(df, ended)) EndParticles(p, ended, [](std::size_t) {});
                prng.SyncOut();
                if constexpr (kSpectral) {
                    // The waiting particles' losses of their first event, booked now (the queue
                    // does not carry them).
                    StageSpectral(p);
                    for (std::uint64_t bits = MaskBits(hn::AndNot(ended, going[i])); bits != 0;
                         bits &= bits - 1)
                        BookLosses(p.set, std::size_t(std::countr_zero(bits)));
                }
                const MF waits = hn::AndNot(ended, going[i]);
                Enqueue(p, waits);
                [[maybe_unused]] HWY_ALIGN std::int32_t qsecondaries[kMaxLanes];
                if constexpr (kSpectral) hn::Store(p.secondaries, di, qsecondaries);
                std::size_t j = queue.size;
                for (std::uint64_t bits = MaskBits(waits); bits != 0; bits &= bits - 1) {
                    const std::size_t l = std::size_t(std::countr_zero(bits));
                    if constexpr (kSpectral)
                        scratch_.queue_spectral.push_back(
                            {at_out_[l], group_out_[l], qsecondaries[l]});
                    queue.state[j] = prng.state[l];
                    queue.inc[j] = prng.inc[l];
                    ++j;
                }
                queue.size = j;
                if (++chunk[i].steps_since_flush == kFlushSteps) {
                    Flush(p);
                    chunk[i].steps_since_flush = 0;
                }
            }
        }
        for (LaneSet& c : chunk) {
            Flush(c.v);
            sums_.add_events(c.v.events_done);
        }
    }

    // The stacks of the chunk's particles (job.first + base + l in lane l): each draws its
    // lattice point and hero first from its own stream, as trace_block_spectral's particles do;
    // its group is its index mod the groups.
    HWY_INLINE void DrawStacks(LaneVectors& p, LaneRng& prng, std::uint64_t base) const {
        const DF df;
        const DI di;
        const SpectralTracing& tr = *job_.spectral;
        constexpr int kPoints = 3 * kSpectralLattice;  // a group's lattice points, all channels
        const std::uint64_t groups = std::uint64_t(tr.bins / 3);
        HWY_ALIGN std::int32_t group[kMaxLanes];
        for (std::size_t l = 0; l < n_lanes_; ++l)
            group[l] = std::int32_t((job_.first + base + l) % groups);
        const VI point =
            hn::Min(hn::ConvertTo(di, hn::Mul(prng.Uniform(), hn::Set(df, float(kPoints)))),
                    hn::Set(di, kPoints - 1));
        static_assert(kSpectralLattice == 16, "the shifts below divide by kSpectralLattice");
        p.hero = hn::ShiftRight<4>(point);
        p.group = hn::Load(di, group);
        const VI t = hn::Add(hn::ShiftLeft<4>(p.group), hn::And(point, hn::Set(di, 15)));
        p.at = hn::Add(hn::Mul(t, hn::Set(di, 3)), p.hero);
        p.secondaries = hn::Set(di, 1);
    }

    // ---- The main loop ----

    // The lanes of `waits` to the end of the queue (their generators apart): their fields
    // compressed into the queue's arrays, in lane order.
    HWY_INLINE void Enqueue(const LaneVectors& p, MF waits) {
        const DF df;
        const DI di;
        QueueArrays& q = scratch_.queue;
        const std::size_t at = q.size;
        const auto waits_i = hn::RebindMask(di, waits);
        // Compressed in registers and stored whole (the arrays' spare entries take the rest; the
        // form of compress that stores to memory is slow on AMD Zen 4), or stored and copied lane
        // by lane (kVectorCompress).
        [[maybe_unused]] HWY_ALIGN float lanes_f[kVectorCompress ? 1 : kQueuedFloats][kMaxLanes];
        [[maybe_unused]] HWY_ALIGN std::int32_t lanes_i[kQueueInts][kMaxLanes];
        auto put = [&](VF x, int a) {
            if constexpr (kVectorCompress)
                hn::StoreU(hn::Compress(x, waits), df, q.f[a].data() + at);
            else
                hn::Store(x, df, lanes_f[a]);
        };
        auto put_i = [&](VI x, int a) {
            if constexpr (kVectorCompress)
                hn::StoreU(hn::Compress(x, waits_i), di, q.i[a].data() + at);
            else
                hn::Store(x, di, lanes_i[a]);
        };
        put(p.d.x, 0);
        put(p.d.y, 1);
        put(p.d.z, 2);
        for (int c = 0; c < 3; ++c)
            put(p.w[c], 3 + c);
        put(p.depth, 6);
        put_i(p.k, 0);
        put_i(p.in_medium, 1);
        put_i(p.events, 2);
        if constexpr (kPolarized) {
            const StokesLanes<VF>& s = p.pol.stokes;
            put(s.x.x, 7);
            put(s.x.y, 8);
            put(s.x.z, 9);
            for (int c = 0; c < 3; ++c) {
                put(s.q[c], 10 + c);
                put(s.u[c], 13 + c);
                put(s.v[c], 16 + c);
            }
        }
        if constexpr (!kVectorCompress) {
            std::size_t j = at;
            for (std::uint64_t bits = MaskBits(waits); bits != 0; bits &= bits - 1, ++j) {
                const std::size_t l = std::size_t(std::countr_zero(bits));
                for (int a = 0; a < kQueuedFloats; ++a)
                    q.f[a][j] = lanes_f[a][l];
                for (int a = 0; a < kQueueInts; ++a)
                    q.i[a][j] = lanes_i[a][l];
            }
        }
    }

    // Gives lane l the queue's next particle (its generator and spectral lane here, the rest in
    // Restart), or retires the lane when none is left.
    HWY_INLINE void TakeParticle(LaneRng& rng, std::size_t l) {
        const QueueArrays& queue = scratch_.queue;
        if (next_ < queue.size) {
            if constexpr (kSpectral) {
                const WaitingSpectral& q = scratch_.queue_spectral[next_];
                s_at_[l] = q.at;
                s_hero_[l] = q.at % 3;
                s_group_[l] = q.group;
                s_secondaries_[l] = q.secondaries;
            }
            rng.state[l] = queue.state[next_];
            rng.inc[l] = queue.inc[next_];
            taking_ |= std::uint64_t(1) << l;
            ++next_;
        } else {
            s_at_[l] = s_hero_[l] = s_group_[l] = s_secondaries_[l] = 0;
            rng.state[l] = 0;
            rng.inc[l] = 1;
        }
    }

    // The particles TakeParticle gave since the last restart into the lanes of `fresh`, expanded
    // from the queue in lane order; the lanes of `fresh` it retired get no flux and are not live.
    HWY_INLINE void Restart(LaneVectors& v, MF fresh) {
        const DF df;
        const DI di;
        const QueueArrays& q = scratch_.queue;
        std::uint8_t bytes[8];
        for (int b = 0; b < 8; ++b)
            bytes[b] = std::uint8_t(taking_ >> (8 * b));
        const MF taking = hn::LoadMaskBits(df, bytes);
        const auto taking_i = hn::RebindMask(di, taking);
        const auto fresh_i = hn::RebindMask(di, fresh);
        // Lane l of `taking` gets the queue's entry taken_from_ + (its rank among them): a
        // permutation of the next whole vector of entries (an expand, which AVX-512 has as one
        // instruction; its form that loads from memory is slow on AMD Zen 4: with it and the
        // compress that stores, the kernel ran 12 % slower than with one record per particle).
        HWY_ALIGN std::int32_t rank[kMaxLanes];
        std::int32_t taken = 0;
        for (std::size_t l = 0; l < n_lanes_; ++l) {
            rank[l] = std::min(taken, std::int32_t(n_lanes_) - 1);
            taken += std::int32_t(taking_ >> l & 1);
        }
        const VI rank_v = hn::Load(di, rank);
        const auto to_f = hn::IndicesFromVec(df, rank_v);
        const auto to_i = hn::IndicesFromVec(di, rank_v);
        const std::size_t at = taken_from_;
        auto take = [&](int a) {
            return hn::IfThenElseZero(
                taking, hn::TableLookupLanes(hn::LoadU(df, q.f[a].data() + at), to_f));
        };
        auto take_i = [&](int a) {
            return hn::IfThenElseZero(
                taking_i, hn::TableLookupLanes(hn::LoadU(di, q.i[a].data() + at), to_i));
        };
        v.d = Select(fresh,
                     V3{take(0), take(1), hn::IfThenElse(taking, take(2), hn::Set(df, -1.f))}, v.d);
        for (int c = 0; c < 3; ++c)
            v.w[c] = hn::IfThenElse(fresh, take(3 + c), v.w[c]);
        v.depth = hn::IfThenElse(fresh, take(6), v.depth);
        v.k = hn::IfThenElse(fresh_i, take_i(0), v.k);
        v.in_medium = hn::IfThenElse(fresh_i, take_i(1), v.in_medium);
        v.events = hn::IfThenElse(fresh_i, take_i(2), v.events);
        v.live = hn::IfThenElse(fresh_i, hn::IfThenElseZero(taking_i, hn::Set(di, 1)), v.live);
        v.mid_walk = hn::IfThenElseZero(hn::Not(fresh_i), v.mid_walk);
        if constexpr (kPolarized) {
            StokesLanes<VF>& s = v.pol.stokes;
            s.x = Select(fresh, V3{take(7), take(8), take(9)}, s.x);
            for (int c = 0; c < 3; ++c) {
                s.q[c] = hn::IfThenElse(fresh, take(10 + c), s.q[c]);
                s.u[c] = hn::IfThenElse(fresh, take(13 + c), s.u[c]);
                s.v[c] = hn::IfThenElse(fresh, take(16 + c), s.v[c]);
            }
        }
        if constexpr (kSpectral) {
            v.at = hn::IfThenElse(fresh_i, hn::Load(di, s_at_), v.at);
            v.hero = hn::IfThenElse(fresh_i, hn::Load(di, s_hero_), v.hero);
            v.group = hn::IfThenElse(fresh_i, hn::Load(di, s_group_), v.group);
            v.secondaries = hn::IfThenElse(fresh_i, hn::Load(di, s_secondaries_), v.secondaries);
        }
        taking_ = 0;
        taken_from_ = next_;
    }

    // The group of lanes that steps: those at one interface, or those inside one scattering
    // medium, whichever group is largest (ties to the first). The lanes of a two-interface stack
    // then alternate between its interfaces in phase, so each step runs one interface's code on
    // nearly full vectors.
    template <int kSets>
    struct Group {
        int layer;
        bool is_medium;
        MF lanes[kSets];
    };
    template <int kSets>
    HWY_INLINE Group<kSets> PickGroup(const LaneVectors* const (&v)[kSets],
                                      const MF (&live_mask)[kSets]) const {
        const DF df;
        const DI di;
        MF in_med[kSets], at_interface[kSets];
        bool any_in_medium = false;
        for (int i = 0; i < kSets; ++i) {
            in_med[i] =
                hn::And(live_mask[i], hn::RebindMask(df, hn::Ne(v[i]->in_medium, hn::Zero(di))));
            at_interface[i] = hn::AndNot(in_med[i], live_mask[i]);
            any_in_medium = any_in_medium || !hn::AllFalse(df, in_med[i]);
        }
        int group = 0;
        bool group_is_medium = false;
        std::size_t group_size = 0;
        for (int j = 0; j < n_layers_; ++j) {
            std::size_t at_j = 0;
            for (int i = 0; i < kSets; ++i)
                at_j += hn::CountTrue(df, hn::And(at_interface[i], LaneIs(v[i]->k, j)));
            if (at_j > group_size) {
                group = j;
                group_size = at_j;
            }
        }
        if (any_in_medium)
            for (int j = 0; j < n_layers_; ++j) {
                if (!stack_.layers[j].medium.scatters) continue;
                std::size_t in_j = 0;
                for (int i = 0; i < kSets; ++i)
                    in_j += hn::CountTrue(df, hn::And(in_med[i], LaneIs(v[i]->k, j)));
                if (in_j > group_size) {
                    group = j;
                    group_is_medium = true;
                    group_size = in_j;
                }
            }
        Group<kSets> g{group, group_is_medium, {}};
        for (int i = 0; i < kSets; ++i)
            g.lanes[i] =
                hn::And(group_is_medium ? in_med[i] : at_interface[i], LaneIs(v[i]->k, group));
        return g;
    }

    // Set s (the kernel's set `index`) given its first particles from the queue.
    HWY_INLINE void Start(LaneSet& s, int index) {
        Clear(s.v);
        s.v.set = index;
        for (std::size_t l = 0; l < n_lanes_; ++l)
            TakeParticle(s.rng, l);
        s.rng.SyncIn();
        Restart(s.v, hn::FirstN(DF(), n_lanes_));
    }

    // The start of a step of set s: its float sums flushed every kFlushSteps steps, its lanes'
    // ends cleared; returns its live lanes.
    HWY_INLINE MF BeginStep(LaneSet& s) {
        const DF df;
        const DI di;
        if (++s.steps_since_flush == kFlushSteps) {
            Flush(s.v);
            s.steps_since_flush = 0;
        }
        s.v.finish = hn::Zero(di);
        return hn::RebindMask(df, hn::Ne(s.v.live, hn::Zero(di)));
    }

    // The lanes of the group that go on to their event: the cut-off (trace_particle: checked
    // before every event; a suspended walk is the event already begun) ends the others.
    HWY_INLINE MF CutOff(LaneVectors& v, MF lanes) {
        const DF df;
        const DI di;
        const MF cut = hn::AndNot(
            v.MidWalk(lanes),
            hn::And(lanes, hn::RebindMask(df, hn::Gt(v.events, hn::Set(di, job_.max_events - 1)))));
        if (!hn::AllFalse(df, cut)) v.Keep(cut, kLossCutOff, zero_);
        v.End(cut, kEnded);
        return hn::AndNot(cut, lanes);
    }

    // A scattering-medium step of set s's lanes of `going`, inside layer `layer`'s medium.
    HWY_INLINE void MediumStep(LaneSet& s, int layer, MF going) {
        const CompiledMedium<float>& med = stack_.layers[layer].medium;
        if constexpr (kSpectral)
            ScatteringStep<kPolarized>(SpectralMedium(med, layer, s.v.at), going, s.v, s.rng);
        else
            ScatteringStep<kPolarized>(med, going, s.v, s.rng);
        s.v.End(hn::And(going, s.v.Black()), kEnded);
    }

    // The end of a step of set s: its ended lanes' tallies and refills from the queue.
    HWY_INLINE void EndStep(LaneSet& s) {
        const DF df;
        const DI di;
        const MF ended = hn::RebindMask(df, hn::Ne(s.v.finish, hn::Zero(di)));
        if (hn::AllFalse(df, ended)) return;
        s.rng.SyncOut();
        EndParticles(s.v, ended, [this, &s](std::size_t l) { TakeParticle(s.rng, l); });
        s.rng.SyncIn();
        Restart(s.v, ended);
    }

    // One step of set s's lanes: one group's event or free flight, then the ended lanes' tallies
    // and refills from the queue. False once none of its lanes lives.
    HWY_INLINE bool Step(LaneSet& s) {
        const MF live[1] = {BeginStep(s)};
        if (hn::AllFalse(DF(), live[0])) return false;
        const LaneVectors* const vs[1] = {&s.v};
        const Group<1> group = PickGroup<1>(vs, live);
        const MF going = CutOff(s.v, group.lanes[0]);
        if (group.is_medium)
            MediumStep(s, group.layer, going);
        else
            InterfaceStep(s.v, s.rng, group.layer, going);
        EndStep(s);
        return true;
    }

    // One step of two sets together, at the group largest over both (each set's lanes of it
    // step): an interface's event then runs on the pair of their vectors where it can
    // (InterfaceStepPair). False once either set has no live lane (nothing done then).
    HWY_INLINE bool StepPair(LaneSet& s, LaneSet& t) {
        const MF live[2] = {BeginStep(s), BeginStep(t)};
        if (hn::AllFalse(DF(), live[0]) || hn::AllFalse(DF(), live[1])) return false;
        const LaneVectors* const vs[2] = {&s.v, &t.v};
        const Group<2> group = PickGroup<2>(vs, live);
        const MF going_s = CutOff(s.v, group.lanes[0]);
        const MF going_t = CutOff(t.v, group.lanes[1]);
        if (group.is_medium) {
            MediumStep(s, group.layer, going_s);
            MediumStep(t, group.layer, going_t);
        } else {
            InterfaceStepPair(s, t, group.layer, going_s, going_t);
        }
        EndStep(s);
        EndStep(t);
        return true;
    }

    // The queued particles through the lanes of two sets, stepped together (StepPair) until one
    // of them has no live lane, then the other alone (Step), until the queue is empty and every
    // lane retired.
    void Steps() {
        may_suspend_ = true;
        LaneSet sets[2];
        for (int i = 0; i < 2; ++i)
            Start(sets[i], i);
        while (StepPair(sets[0], sets[1])) {
        }
        for (LaneSet& s : sets)
            while (Step(s)) {
            }
        for (LaneSet& s : sets) {
            Flush(s.v);
            sums_.add_events(s.v.events_done);
        }
    }

    const BlockJob& job_;
    Tally& tally_;
    const CompiledStack<float>& stack_;
    const HemisphereGrid& grid_;
    const int n_layers_;
    const std::size_t n_lanes_;
    const VF zero_, one_;
    Scratch& scratch_;  // the particles' generators and the queue, kept between blocks

    LaneSums sums_;
    std::uint64_t degenerate_ = 0;
    // Whether microsurface walks may be suspended (the main loop's steps; the first events run
    // every walk to its end, as their survivors wait in the queue).
    bool may_suspend_ = false;
    bool left_[2] = {false, false};  // some particle was reflected / transmitted in this block

    // The ended lanes, staged by EndParticles.
    HWY_ALIGN std::int32_t finish_[kMaxLanes];
    HWY_ALIGN float w_out_[3][kMaxLanes];
    HWY_ALIGN std::int32_t theta_bin_[kMaxLanes], phi_bin_[kMaxLanes];
    const VectorBins vector_bins_;
    HWY_ALIGN float d_out_[3][kMaxLanes];
    // Polarized runs with Stokes tallies: the exits' Stokes vectors in their bin frames.
    [[maybe_unused]] HWY_ALIGN float stokes_out_[3][4][kMaxLanes];
    const bool stokes_tallies_;

    // Compress (Enqueue) on vectors where they hold 16 lanes or more: AVX-512 has it as one
    // instruction; with fewer lanes Highway 1.0 builds it from a table of permutations, which it
    // copies onto the stack at every call (the AVX2 kernel ran 23 % slower with it), and the lanes
    // are copied one by one instead.
    static constexpr bool kVectorCompress = hn::MaxLanes(DF()) >= 16;
    static constexpr int kQueuedFloats = kQueueFloats + (kPolarized ? kQueuePolarizationFloats : 0);
    // The queue's reading position.
    std::size_t next_ = 0;        // the queue's next particle
    std::size_t taken_from_ = 0;  // the first particle given since the last restart
    std::uint64_t taking_ = 0;    // the lanes given one since (bit l for lane l)

    // Spectral runs: the staged lanes' stacks, heroes, groups and secondaries; the ended lanes'
    // stacks and groups (StageSpectral); each lane's particle's losses, per lane set (Flush); the
    // block's sums.
    [[maybe_unused]] HWY_ALIGN std::int32_t s_at_[kMaxLanes], s_hero_[kMaxLanes],
        s_group_[kMaxLanes], s_secondaries_[kMaxLanes];
    [[maybe_unused]] HWY_ALIGN std::int32_t at_out_[kMaxLanes], group_out_[kMaxLanes];
    [[maybe_unused]] HWY_ALIGN double particle_loss_[2][kLossTerms][3][kMaxLanes];
    BlockBudget* block_ = nullptr;
};

// The instance for the job: spectral or not, and for the stack (the spectral run's structure):
// polarized or not, isotropic or anisotropic.
template <bool kSpectral>
void TraceBlockFor(const CompiledStack<float>& stack, const BlockJob& job, Tally& tally,
                   BlockBudget& block) {
    thread_local Scratch scratch;
    const bool polarized = stack.polarization, anisotropic = stack.anisotropic;
    if (polarized && anisotropic)
        BlockTracer<true, true, kSpectral>(job, tally, scratch).Trace(block);
    else if (polarized)
        BlockTracer<true, false, kSpectral>(job, tally, scratch).Trace(block);
    else if (anisotropic)
        BlockTracer<false, true, kSpectral>(job, tally, scratch).Trace(block);
    else
        BlockTracer<false, false, kSpectral>(job, tally, scratch).Trace(block);
}

void TraceBlockSimd(const BlockJob& job, Tally& tally, BlockBudget& block) {
    if (job.spectral != nullptr)
        TraceBlockFor<true>(job.spectral->structure, job, tally, block);
    else
        TraceBlockFor<false>(*job.stack, job, tally, block);
}

// The instruction set this code was compiled for.
const char* TargetNameSimd() {
    return hwy::TargetName(HWY_TARGET);
}

}  // namespace HWY_NAMESPACE
}  // namespace lamina
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace lamina {

HWY_EXPORT(TraceBlockSimd);
HWY_EXPORT(TargetNameSimd);
void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block) {
    HWY_DYNAMIC_DISPATCH(TraceBlockSimd)(job, tally, block);
}

void select_simd_target() {
    static const bool done = [] {
        const char* wanted = std::getenv("LAMINA_SIMD_TARGET");
        if (wanted == nullptr || *wanted == '\0') return true;
        std::string names;
        // Targets are bits, better ones lower: keep the wanted one and those below it.
        for (std::int64_t targets = HWY_TARGETS; targets != 0; targets &= targets - 1) {
            const std::int64_t bit = targets & -targets;
            if (std::string(hwy::TargetName(bit)) == wanted) {
                if ((hwy::SupportedTargets() & bit) == 0)
                    throw InputError("environment", "LAMINA_SIMD_TARGET",
                                     fmt::format("this CPU does not support {}", wanted));
                // The cap is a mock of the CPU's supported set, and the dispatch is updated to
                // it. Highway 1.0's DisableTargets does not hold: it leaves enabled the better
                // sets not compiled here (AVX3_DL on a Zen 4 or Sapphire Rapids CPU, which
                // dispatches to AVX3), and every SupportedTargets() call resets the dispatch to
                // the CPU's full set.
                hwy::SetSupportedTargetsForTest(hwy::SupportedTargets() & ~(bit - 1));
                hwy::GetChosenTarget().Update(hwy::SupportedTargets());
                return true;
            }
            names += fmt::format("{}{}", names.empty() ? "" : ", ", hwy::TargetName(bit));
        }
        throw InputError(
            "environment", "LAMINA_SIMD_TARGET",
            fmt::format("'{}' is not an instruction set of this build ({})", wanted, names));
    }();
    (void)done;
}

const char* simd_target_name() {
    select_simd_target();
    // The set the dispatch takes, named by the code it runs.
    return HWY_DYNAMIC_DISPATCH(TargetNameSimd)();
}

}  // namespace lamina
#endif

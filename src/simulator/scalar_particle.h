#pragma once
// One particle of the goniophotometer's scalar kernel (docs/physics.md §3–§5, §8–§10): its media,
// interface events (films included) and path, written once for the RGB runs (goniophotometer.cpp)
// and the spectral ones (kernel_spectral.cpp). Internal to the simulator. Its functions have
// internal linkage in each unit that includes it, as they had when they lived in one unit: the
// compiler's view of the RGB kernel (what it inlines and contracts) is what it was, so its tables
// stay bitwise as they were, and the spectral instantiations live in a unit of their own.

#include "core/check.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "layers/compiled_stack.h"
#include "physics/medium.h"
#include "physics/microsurface_walk.h"
#include "physics/thin_film_event.h"
#include "simulator/tally.h"

#include <optional>

namespace lamina {
namespace {  // NOLINT(google-build-namespaces): see above

bool is_black(const Rgbf& w) {
    return w[0] == 0.f && w[1] == 0.f && w[2] == 0.f;
}

// ---- Media (docs/physics.md §4) -----------------------------------------------------------------
// physics/medium.h at one lane. Depth s ∈ [0, 1] across the layer (0 at its top). Returns true if
// the particle leaves through the top.
struct MediumWalk {
    const CompiledMedium<float>& m;
    ParticleRng& rng;
    PathLosses& losses;
    /// The particle's polarization (polarized runs; else null): a scattering event depolarizes
    /// (docs/physics.md §8), absorption keeps it.
    StokesLanes<float>* stokes = nullptr;

    bool traverse(Vec3f& d, Rgbf& w, int& events, int max_events) {
        if (!m.scatters) {
            // Pure absorption: Beer–Lambert along the straight path, no sampling.
            float transmittance[3];
            beer_lambert_transmittance<float>(m.tau_a, 1.f / std::abs(d.z), transmittance);
            const Rgbf before = w;
            for (int c = 0; c < 3; ++c)
                w[c] *= transmittance[c];
            losses.add(BudgetTerm::AbsorbedMedium, before - w);
            return d.z > 0;
        }
        return walk(d, w, events, max_events);
    }

    // Scattering: free flights and HG events by one-sample spectral MIS (physics/medium.h).
    bool walk(Vec3f& d, Rgbf& w, int& events, int max_events) {
        float s = d.z < 0 ? 0.f : 1.f;
        auto uniform = [&] { return rng.uniform_float(); };
        while (true) {
            const LaneVec3<float> dl = {d.x, d.y, d.z};
            const float wl[3] = {w[0], w[1], w[2]};
            const MediumFlightLanes<float, bool> flight =
                medium_free_flight<float>(m, dl, wl, s, uniform);
            const Rgbf before = w;
            if (flight.leaves) {
                for (int c = 0; c < 3; ++c)
                    w[c] *= flight.factor[c];
                losses.add(BudgetTerm::AbsorbedMedium, before - w);
                return d.z > 0;
            }
            s = flight.depth;
            LaneVec3<float> d_new;
            float phase[3];
            medium_scatter<float>(m, dl, flight.p, true, uniform, d_new, phase);
            for (int c = 0; c < 3; ++c)
                w[c] *= flight.factor[c] * phase[c];
            d = {d_new.x, d_new.y, d_new.z};
            if (stokes) stokes_depolarize<float>(*stokes, 3, true);
            losses.add(BudgetTerm::AbsorbedMedium, before - w);
            if (is_black(w)) return d.z > 0;
            if (++events >= max_events) return d.z > 0;  // the caller books the cut-off
        }
    }
};

// ---- A filmed interface (docs/physics.md §9) --------------------------------------------------
// The film's Mueller matrices (physics/thin_film_event.h) at every facet: a dielectric's single
// facet or walk through the film's branch choice, a conductor's through conductor_event and the
// conductor walk with the film's reflection in place of the bare Fresnel terms. A thickness that
// varies over the surface is drawn first, from the particle's own stream, once per event (a
// particle's lateral position never matters, docs/physics.md §2). The factors (the film's
// absorption, the reweighting of the channels) are booked as absorbed at the interface
// (`apply(sample, true)`), G2/G1 as lost to the microsurface.
template <bool kPolarized, typename Apply, typename ApplyWalk>
inline void film_event(const CompiledStack<float>& stack, const CompiledLayer<float>& layer,
                       ParticleRng& rng, const Vec3f& wi, const Rgbf& w,
                       [[maybe_unused]] PolarizationLanes<float>& pol, Apply& apply,
                       ApplyWalk& apply_walk) {
    const FilmOptics& film = layer.film;
    const double thickness =
        film.varies() ? film.thickness_nm(double(rng.uniform_float())) : film.thickness_min_nm;
    const float flux[3] = {w[0], w[1], w[2]};
    PolarizationLanes<float>* p = nullptr;
    if constexpr (kPolarized) p = &pol;
    auto uniform = [&] { return rng.uniform_float(); };
    const LaneVec3<float> wl = {wi.x, wi.y, wi.z};
    if (layer.type == InterfaceType::Dielectric) {
        const DielectricInterface<float>& di = layer.dielectric;
        if (layer.multiple) {
            const MicrosurfaceFilmFacet<decltype(uniform)> facet{film,    di.eta, thickness,
                                                                 uniform, flux,   p};
            apply_walk(microsurface_exit(microsurface_walk<float, Lane<float>>(
                           di.distribution().template lanes<false>(), wl, true, true, facet,
                           uniform, stack.max_microsurface_order)),
                       true);
            return;
        }
        const float uc = rng.uniform_float(), u1 = rng.uniform_float(), u2 = rng.uniform_float();
        const FilmEvent e =
            film_dielectric_event(film, di.eta, di.alpha, di.uncorrelated_shadowing,
                                  di.transmission_masking == TransmissionMasking::Smith, thickness,
                                  wl, uc, u1, u2, flux, p);
        std::optional<BsdfSample<float>> s;
        if (!e.degenerate) {
            s.emplace();
            s->wo = {e.scatter.wo.x, e.scatter.wo.y, e.scatter.wo.z};
            s->fresnel_weight = {e.scatter.factor[0], e.scatter.factor[1], e.scatter.factor[2]};
            s->shadowing = e.shadowing;
        }
        apply(s, true);
        return;
    }
    // A conductor: the film's reflectance (unpolarized) or reflection Mueller matrices per channel.
    const ConductorInterface<float>& cond = layer.conductor;
    const auto reflectance = [&](float cos_theta) {
        const auto md = film.reflection_from_above(double(cos_theta), thickness);
        Rgbf r;
        for (int c = 0; c < 3; ++c)
            r[c] = float(md[std::size_t(c)].a);
        return r;
    };
    [[maybe_unused]] const auto mueller = [&](float cos_theta, InterfaceMueller<float>* m) {
        const auto md = film.reflection_from_above(double(cos_theta), thickness);
        for (std::size_t c = 0; c < 3; ++c)
            m[c] = {float(md[c].a), float(md[c].b), float(md[c].c), float(md[c].d)};
    };
    if (layer.multiple) {
        if constexpr (kPolarized)
            apply_walk(walk_rough_conductor_polarized(cond.distribution(), mueller, wi, uniform,
                                                      stack.max_microsurface_order, pol),
                       true);
        else
            apply_walk(walk_rough_conductor(cond.distribution(), reflectance, wi, uniform,
                                            stack.max_microsurface_order),
                       true);
        return;
    }
    const float u1 = rng.uniform_float(), u2 = rng.uniform_float();
    float factors[3];
    const auto channel_reflectance = [&](float cos_theta, float* out) {
        const Rgbf r = reflectance(cos_theta);
        out[0] = r[0], out[1] = r[1], out[2] = r[2];
    };
    InterfaceEventLanes<float, bool> e;
    if constexpr (kPolarized)
        e = conductor_event<float>(cond.distribution().template lanes<false>(), cond.is_smooth(),
                                   cond.uncorrelated_shadowing, wl, u1, u2, true, NoMueller{},
                                   factors, &pol, mueller);
    else
        e = conductor_event<float>(cond.distribution().template lanes<false>(), cond.is_smooth(),
                                   cond.uncorrelated_shadowing, wl, u1, u2, true,
                                   channel_reflectance, factors);
    std::optional<BsdfSample<float>> s;
    if (!e.degenerate) {
        s.emplace();
        s->wo = {e.wo.x, e.wo.y, e.wo.z};
        s->fresnel_weight = {factors[0], factors[1], factors[2]};
        s->shadowing = e.shadowing;
    }
    apply(s, true);
}

// ---- One interface event ----------------------------------------------------------------------
// The event of `layer` on a particle arriving along d with flux w: its BSDF sampler (or, with
// multiple scattering, its microsurface walk) draws the new direction d, and w keeps what
// continues; the rest is booked in `losses` (absorbed by an opaque base, lost to the microsurface).
// Polarized runs: pol goes through the event too (pol.flux: the caller's copy of w). Where the
// channels' states differ, a dielectric's branch choice reweights the channels: the reweighting
// (zero in expectation per channel) is booked with the base that coloured them.
// kAnisotropic: the stack has an anisotropic interface (CompiledStack::anisotropic), and every
// rough interface takes the general instance of the GGX formulas (GGX::lanes). kFilm: the stack
// has a thin film (film_event; never with kAnisotropic: validate_kernel_for refuses the pair).
template <bool kPolarized, bool kAnisotropic, bool kFilm>
inline void interface_event(const CompiledStack<float>& stack, const CompiledLayer<float>& layer,
                            ParticleRng& rng, Tally& tally, Vec3f& d, Rgbf& w, PathLosses& losses,
                            [[maybe_unused]] PolarizationLanes<float>& pol) {
    const Vec3f wi_local = -d;
    [[maybe_unused]] const bool reweights = kPolarized && pol.channels == 3;
    // Applies a sample (taken by reference: no copy of the optional in the hot loop).
    // weight = fresnel_weight (absorbed by an opaque base) · shadowing (lost on the
    // microsurface); a missing sample is a numerical degeneracy, counted and reported.
    auto apply = [&](const std::optional<BsdfSample<float>>& s, bool opaque) {
        if (!s) {
            ++tally.sums.degenerate;
            losses.add(BudgetTerm::LostMicrosurface, w);
            w = Rgbf(0.f);
            return;
        }
        if (opaque) {  // a dielectric's fresnel_weight is 1
            const Rgbf kept = w * s->fresnel_weight;
            losses.add(BudgetTerm::AbsorbedBase, w - kept);
            w = kept;
        }
        if (s->shadowing != 1.f) {
            const Rgbf kept = w * s->shadowing;
            losses.add(BudgetTerm::LostMicrosurface, w - kept);
            w = kept;
        }
        d = s->wo;
    };
    // A rough interface with multiple scattering: the microsurface walk (Heitz et al. 2016)
    // replaces the single facet; its exit carries the conductor's Fresnel factors. A walk
    // given up at the facet cap loses its flux to the microsurface; a degenerate one too, and
    // is counted as a degeneracy.
    auto apply_walk = [&](const std::optional<MicrosurfaceExit<float>>& e, bool opaque) {
        if (!e || !e->escaped) {
            if (!e) ++tally.sums.degenerate;
            losses.add(BudgetTerm::LostMicrosurface, w);
            w = Rgbf(0.f);
            return;
        }
        if (opaque) {
            const Rgbf kept = w * e->weight;
            losses.add(BudgetTerm::AbsorbedBase, w - kept);
            w = kept;
        }
        d = e->wo;
    };
    auto uniform = [&] { return rng.uniform_float(); };
    if constexpr (kFilm) {
        if (layer.has_film) {
            film_event<kPolarized>(stack, layer, rng, wi_local, w, pol, apply, apply_walk);
            return;
        }
    }
    switch (layer.type) {
        case InterfaceType::Dielectric: {
            if (layer.multiple) {
                if constexpr (kPolarized) {
                    apply_walk(walk_rough_dielectric_polarized<kAnisotropic>(
                                   layer.dielectric.distribution(), layer.dielectric.eta, wi_local,
                                   uniform, stack.max_microsurface_order, pol),
                               reweights);
                    break;
                }
                apply_walk(walk_rough_dielectric<kAnisotropic>(
                               layer.dielectric.distribution(), layer.dielectric.eta, wi_local,
                               uniform, stack.max_microsurface_order),
                           false);
                break;
            }
            const float uc = rng.uniform_float(), u1 = rng.uniform_float(),
                        u2 = rng.uniform_float();
            if constexpr (kPolarized)
                apply(layer.dielectric.template sample_polarized<kAnisotropic>(wi_local, uc, u1, u2,
                                                                               pol),
                      reweights);
            else
                apply(layer.dielectric.template sample<false, kAnisotropic>(wi_local, uc, u1, u2),
                      false);
            break;
        }
        case InterfaceType::Conductor: {
            const ConductorInterface<float>& cond = layer.conductor;
            if (layer.multiple) {
                if constexpr (kPolarized) {
                    const auto mueller = [&](float c, InterfaceMueller<float>* m) {
                        cond.mueller(c, m);
                    };
                    apply_walk(walk_rough_conductor_polarized<kAnisotropic>(
                                   cond.distribution(), mueller, wi_local, uniform,
                                   stack.max_microsurface_order, pol),
                               true);
                    break;
                }
                apply_walk(walk_rough_conductor<kAnisotropic>(
                               cond.distribution(), [&](float c) { return cond.fresnel(c); },
                               wi_local, uniform, stack.max_microsurface_order),
                           true);
                break;
            }
            const float u1 = rng.uniform_float(), u2 = rng.uniform_float();
            if constexpr (kPolarized)
                apply(cond.template sample_polarized<kAnisotropic>(wi_local, u1, u2, pol), true);
            else
                apply(cond.template sample<false, kAnisotropic>(wi_local, u1, u2), true);
            break;
        }
        case InterfaceType::Lambertian: {
            const float u1 = rng.uniform_float(), u2 = rng.uniform_float();
            apply(layer.lambertian.sample(wi_local, u1, u2), true);
            if constexpr (kPolarized) stokes_depolarize<float>(pol.stokes, 3, true);
            break;
        }
    }
}

// ---- One particle ------------------------------------------------------------------------------
// docs/physics.md §3: at an interface the particle (arriving along −wi) draws an outgoing direction
// from the interface's BSDF sampler; its flux is multiplied by the sample weight and the parts
// that do not continue are booked (absorbed by the base, lost to the microsurface).
// Polarized runs (docs/physics.md §8): the particle also carries its Stokes vector per channel
// divided by its flux, with the frame's x axis (physics/polarization.h at one lane); every event
// passes it to the interface's polarized event, a Lambertian base and a scattering event
// depolarize it, and an exit is tallied with its Stokes vector when the job asks for it.
// Written once for both: kPolarized = false is the unpolarized kernel, with none of it; kFilm
// = true the instantiation for stacks with a thin film (film_event); kSpectral = true the spectral
// particle `sp` (its exits and losses tallied per wavelength and projected to colour).
template <bool kPolarized, bool kAnisotropic, bool kFilm, bool kSpectral = false>
void trace_particle(const CompiledStack<float>& stack, const HemisphereGrid& grid,
                    const BlockJob& job, ParticleRng& rng, Tally& tally, BlockBudget& block,
                    [[maybe_unused]] SpectralParticle* sp = nullptr) {
    const int n_layers = int(stack.layers.size());
    const int max_events = job.max_events;
    Vec3f d = -job.wi;  // propagation direction
    Rgbf w(1.f);
    PathLosses losses;
    int k = 0;  // the interface the particle is about to meet
    int events = 0;
    [[maybe_unused]] PolarizationLanes<float> pol;
    [[maybe_unused]] float flux[3];
    if constexpr (kPolarized) {
        pol.stokes = stokes_incident<float>({d.x, d.y, d.z}, job.incident_stokes);
        pol.channels = stack.polarization_channels;
        pol.flux = flux;
    }
    [[maybe_unused]] auto exit_stokes = [&](std::size_t index) {
        if (!job.stokes_tallies) return;
        float s[3][4];
        const float wl[3] = {w[0], w[1], w[2]};
        stokes_in_bin_frame<float>(pol.stokes, {d.x, d.y, d.z}, wl, pol.channels, true, s);
        // Folded bins count the patch y < 0 as its mirror image (mueller.h); unfolded ones are one
        // patch each.
        tally.exit_stokes(index, d.y < 0 && !job.grid->is_unfolded() ? 1 : 0, s);
    };
    while (true) {
        if (events >= max_events) {
            losses.add(BudgetTerm::CutOff, w);
            break;
        }
        ++events;
        const CompiledLayer<float>& layer = stack.layers[k];
        if constexpr (kSpectral) sp->before_event(k, w);
        if constexpr (kPolarized)
            for (int c = 0; c < 3; ++c)
                flux[c] = w[c];
        interface_event<kPolarized, kAnisotropic, kFilm>(stack, layer, rng, tally, d, w, losses,
                                                         pol);
        if (is_black(w)) break;
        if (d.z == 0) {
            // An exactly grazing direction (a sampler at the edge of its domain, probability
            // ~2^-24): it belongs to neither hemisphere. Its G2 is zero on a microsurface, and it
            // is counted and reported as degenerate on any interface.
            ++tally.sums.degenerate;
            losses.add(layer.type == InterfaceType::Dielectric ? BudgetTerm::LostMicrosurface
                                                               : BudgetTerm::AbsorbedBase,
                       w);
            break;
        }
        if (d.z > 0) {
            if (k == 0) {  // leaves the stack upwards: reflection
                const std::size_t bin = grid.bin_of(d);
                if constexpr (kSpectral) {
                    sp->exit(bin, true, w, tally, block);
                    if constexpr (kPolarized) exit_stokes(bin);
                } else {
                    tally.exit(bin, w);
                    if constexpr (kPolarized) exit_stokes(bin);
                    block.escape_reflected(w);
                }
                break;
            }
            // Up through the medium below interface k − 1.
            const CompiledMedium<float>& m = stack.layers[k - 1].medium;
            bool up = true;
            if (!m.is_empty()) {
                MediumWalk walk{m, rng, losses, kPolarized ? &pol.stokes : nullptr};
                up = walk.traverse(d, w, events, max_events);
                if (is_black(w)) break;
            }
            if (up) --k;
        } else {
            if (k == n_layers - 1) {  // leaves through the final dielectric: transmission
                const std::size_t bin = grid.size() + grid.bin_of(d);
                if constexpr (kSpectral) {
                    sp->exit(bin, false, w, tally, block);
                    if constexpr (kPolarized) exit_stokes(bin);
                } else {
                    tally.exit(bin, w);
                    if constexpr (kPolarized) exit_stokes(bin);
                    block.escape_transmitted(w);
                }
                break;
            }
            const CompiledMedium<float>& m = layer.medium;
            bool up = false;
            if (!m.is_empty()) {
                MediumWalk walk{m, rng, losses, kPolarized ? &pol.stokes : nullptr};
                up = walk.traverse(d, w, events, max_events);
                if (is_black(w)) break;
            }
            if (!up) ++k;
        }
    }
    if constexpr (kSpectral)
        sp->flush(losses, block);
    else
        losses.flush(block);
    tally.sums.events += std::uint64_t(events);
}

}  // namespace
}  // namespace lamina

#include "simulator/goniophotometer.h"

#include "core/check.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "layers/colorimetry.h"
#include "layers/compiled_stack.h"
#include "physics/medium.h"
#include "physics/microsurface_walk.h"
#include "physics/thin_film_event.h"
#include "simulator/kernel_simd.h"
#include "simulator/tally.h"

#include <fmt/format.h>
#include <omp.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <optional>

namespace lamina {

Rgbd EnergyBudget::sum() const {
    Rgbd s(0.0);
    for (const Rgbd& t : term)
        s += t;
    return s;
}

namespace {

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

// ---- A filmed interface (docs/physics.md §9)
// ----------------------------------------------------- The film's Mueller matrices
// (physics/thin_film_event.h) at every facet: a dielectric's single facet or walk through the
// film's branch choice, a conductor's through conductor_event and the conductor walk with the
// film's reflection in place of the bare Fresnel terms. A thickness that varies over the surface is
// drawn first, from the particle's own stream, once per event (a particle's lateral position never
// matters, docs/physics.md §2). The factors (the film's absorption, the reweighting of the
// channels) are booked as absorbed at the interface
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
        Rgbf r;
        for (int c = 0; c < 3; ++c)
            r[c] = float(film.mueller(c, double(cos_theta), true, thickness).reflection.a);
        return r;
    };
    [[maybe_unused]] const auto mueller = [&](float cos_theta, InterfaceMueller<float>* m) {
        for (int c = 0; c < 3; ++c) {
            const InterfaceMueller<double> md =
                film.mueller(c, double(cos_theta), true, thickness).reflection;
            m[c] = {float(md.a), float(md.b), float(md.c), float(md.d)};
        }
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

// ---- A spectral particle (docs/physics.md §10)
// --------------------------------------------------- Its three wavelengths (tally.h: lattice
// points t + c · L/3), the channel h whose wavelength its path follows (the hero), and where its
// exits and losses are tallied. At a dispersive interface (one whose refraction direction depends
// on the wavelength) the other two channels, whose paths would part from the hero's, are terminated
// and the hero carries 3 times its flux: the hero is uniformly distributed over the lattice, as
// each channel is, so its flux times 3 estimates what the three channels did, without bias (the
// terminated flux is not booked in the budget, which sums to 1 in expectation then).
struct SpectralParticle {
    const SpectralTracing& tracing;
    SpectralTally& tally;
    SpectralBlock& block;
    const std::vector<char>& dispersive;  ///< per layer
    int group;                            ///< t / kSpectralLattice: the wavelength bins' group
    int hero;
    bool secondaries = true;  ///< the non-hero channels still travel
    Rgbf xyz_weight[3], srgb_weight[3];

    /// Before an event at `layer`: terminates the secondaries at a dispersive interface.
    void before_event(int layer, Rgbf& w) {
        if (!secondaries || !dispersive[std::size_t(layer)]) return;
        secondaries = false;
        for (int c = 0; c < 3; ++c)
            w[c] = c == hero ? 3.f * w[c] : 0.f;
    }
    Rgbf projected(const Rgbf& w, const Rgbf (&weight)[3]) const {
        return weight[0] * w[0] + weight[1] * w[1] + weight[2] * w[2];
    }
    /// An exit into `index` (side · n_bins + bin) with flux w: the wavelength bins, XYZ and sRGB
    /// (`tally`, `block`: the main sRGB ones).
    void exit(std::size_t index, bool reflected, const Rgbf& w, Tally& main,
              BlockBudget& main_block) {
        const Rgbf xyz = projected(w, xyz_weight), srgb = projected(w, srgb_weight);
        constexpr float kScale = 1.f / float(kSpectralTallyScale);
        tally.lambda.exit(index * std::size_t(tracing.bins / 3) + std::size_t(group), w * 0.25f);
        tally.xyz.exit(index, xyz * kScale);
        main.exit(index, srgb * kScale);
        BlockBudget& g = block.groups[std::size_t(group)];
        if (reflected) {
            g.escape_reflected(w);
            block.xyz.escape_reflected(xyz);
            main_block.escape_reflected(srgb);
        } else {
            g.escape_transmitted(w);
            block.xyz.escape_transmitted(xyz);
            main_block.escape_transmitted(srgb);
        }
    }
    /// The path's losses, per wavelength group and projected.
    void flush(const PathLosses& losses, BlockBudget& main_block) {
        BlockBudget& g = block.groups[std::size_t(group)];
        for (int t = int(BudgetTerm::AbsorbedMedium); t < kBudgetTerms; ++t)
            for (int c = 0; c < 3; ++c) {
                const double lost = losses.term[std::size_t(t)][std::size_t(c)];
                g.term[std::size_t(t)][std::size_t(c)] += lost;
                for (int k = 0; k < 3; ++k) {
                    block.xyz.term[std::size_t(t)][std::size_t(k)] +=
                        lost * double(xyz_weight[c][k]);
                    main_block.term[std::size_t(t)][std::size_t(k)] +=
                        lost * double(srgb_weight[c][k]);
                }
            }
    }
};

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
                } else {
                    tally.exit(bin, w);
                    block.escape_reflected(w);
                }
                if constexpr (kPolarized) exit_stokes(bin);
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
                } else {
                    tally.exit(bin, w);
                    block.escape_transmitted(w);
                }
                if constexpr (kPolarized) exit_stokes(bin);
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

// A spectral run's block (tally.h): each particle draws its hero's lattice point first, from its
// own stream, and follows the stack compiled at its three wavelengths.
void trace_block_spectral(const BlockJob& job, Tally& tally, BlockBudget& block) {
    const SpectralTracing& tr = *job.spectral;
    const int third = tr.lattice / 3, groups = tr.bins / 3;
    for (std::uint64_t p = job.first; p < job.first + job.count; ++p) {
        ParticleRng rng(job.seed, job.stream, p);
        const int group = int(p % std::uint64_t(groups));
        constexpr int kPoints = 3 * kSpectralLattice;  // a group's lattice points, all channels
        const int point = std::min(kPoints - 1, int(rng.uniform_float() * float(kPoints)));
        const int hero = point / kSpectralLattice;
        const int t = group * kSpectralLattice + point % kSpectralLattice;
        const std::size_t at = std::size_t(t) * 3 + std::size_t(hero);
        const CompiledStack<float>& stack = tr.stacks[at];
        SpectralParticle sp{tr,
                            *job.spectral_tally,
                            *job.spectral_block,
                            tr.dispersive[at],
                            t / kSpectralLattice,
                            hero,
                            true,
                            {},
                            {}};
        const float factor = tr.group_factor[std::size_t(group)];
        for (int c = 0; c < 3; ++c) {
            sp.xyz_weight[c] = tr.xyz_weight[std::size_t(t + c * third)] * factor;
            sp.srgb_weight[c] = tr.srgb_weight[std::size_t(t + c * third)] * factor;
        }
        const bool pol = stack.polarization;
        if (stack.has_film) {
            if (pol)
                trace_particle<true, false, true, true>(stack, *job.grid, job, rng, tally, block,
                                                        &sp);
            else
                trace_particle<false, false, true, true>(stack, *job.grid, job, rng, tally, block,
                                                         &sp);
        } else if (stack.anisotropic) {
            if (pol)
                trace_particle<true, true, false, true>(stack, *job.grid, job, rng, tally, block,
                                                        &sp);
            else
                trace_particle<false, true, false, true>(stack, *job.grid, job, rng, tally, block,
                                                         &sp);
        } else if (pol) {
            trace_particle<true, false, false, true>(stack, *job.grid, job, rng, tally, block, &sp);
        } else {
            trace_particle<false, false, false, true>(stack, *job.grid, job, rng, tally, block,
                                                      &sp);
        }
    }
}

std::uint64_t incidence_stream(double theta_i_deg, int incident_polarization) {
    // The stream is the incidence itself, so a result does not depend on which other incidences
    // were simulated with it; a polarized incident state other than unpolarized adds its index
    // times an odd 64-bit constant (the golden ratio's, as in Random123's key schedule) to the
    // key, so that runs with different incident states are independent.
    return std::bit_cast<std::uint64_t>(theta_i_deg) ^
           (std::uint64_t(incident_polarization) * 0x9E3779B97F4A7C15ull);
}

// A spectral run's stacks and colour weights (tally.h; docs/physics.md §10).
SpectralTracing spectral_tracing(const Stack& stack, const SimulationSettings& settings) {
    SpectralTracing tr;
    tr.bins = settings.spectral_bins;
    tr.lattice = tr.bins * kSpectralLattice;
    const int third = tr.lattice / 3;
    const double lo = settings.spectral_min_nm, hi = settings.spectral_max_nm;
    const double cell = (hi - lo) / tr.lattice;
    auto lambda = [&](int point) { return lo + (point + 0.5) * cell; };
    for (int t = 0; t < third; ++t) {
        const Rgbd wl{lambda(t), lambda(t + third), lambda(t + 2 * third)};
        // The relative index of each dielectric at the three wavelengths.
        const Stack at[3] = {stack.at_wavelengths(wl, 0), stack.at_wavelengths(wl, 1),
                             stack.at_wavelengths(wl, 2)};
        std::vector<char> dispersive(stack.layers.size(), 0);
        for (std::size_t i = 0; i < stack.layers.size(); ++i) {
            if (stack.layers[i].interface.type != InterfaceType::Dielectric) continue;
            double relative[3];
            for (int c = 0; c < 3; ++c)
                relative[c] = at[c].layers[i].interface.eta / at[c].eta_above(i);
            dispersive[i] = relative[0] != relative[1] || relative[1] != relative[2];
        }
        for (int h = 0; h < 3; ++h) {
            tr.stacks.push_back(compile_stack<float>(at[h], settings.transport));
            tr.dispersive.push_back(dispersive);
        }
    }
    // XYZ weights: the lattice sum of f · S · (x̄, ȳ, z̄) · cell over ∫ S ȳ dλ on 360–830 nm
    // (the midpoint rule on 0.1 nm cells), times L/3 for the three uniform channels a particle
    // carries.
    double norm_y = 0;
    constexpr int kCells = 4700;
    for (int i = 0; i < kCells; ++i)
        norm_y += d65_xyz_weights(kSpectrumMinNm + (i + 0.5) * 0.1)[1] * 0.1;
    for (int point = 0; point < tr.lattice; ++point) {
        const Rgbd xyz = d65_xyz_weights(lambda(point)) * (cell * third / norm_y);
        const Rgbd srgb = xyz_to_linear_srgb(xyz);
        // The bound each tally contribution relies on (tally.h), with a group factor up to 1.5
        // (particles >= 2 groups, validate_kernel_for).
        LAMINA_CHECK(std::max(std::abs(srgb.max()), std::abs(srgb.min())) <= 5 && xyz.max() <= 5);
        tr.xyz_weight.push_back(Rgbf(xyz));
        tr.srgb_weight.push_back(Rgbf(srgb));
    }
    const int groups = tr.bins / 3;
    for (int g = 0; g < groups; ++g)
        tr.group_factor.push_back(
            float(double(settings.particles) /
                  (groups * double(spectral_group_particles(settings.particles, groups, g)))));
    return tr;
}

// The incident Stokes vectors (S1, S2, S3)/S0 of SimulationSettings::incident_polarization.
constexpr float kIncidentStokes[7][3] = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                         {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};

}  // namespace

void trace_block_scalar(const BlockJob& job, Tally& tally, BlockBudget& block) {
    if (job.spectral) {
        trace_block_spectral(job, tally, block);
        return;
    }
    for (std::uint64_t p = job.first; p < job.first + job.count; ++p) {
        ParticleRng rng(job.seed, job.stream, p);
        // Stacks with a film or an anisotropic interface have their own instantiations: those of
        // the other stacks are compiled (inlined, contracted) exactly as before either existed,
        // bit for bit.
        const bool pol = job.stack->polarization;
        if (job.stack->has_film) {
            if (pol)
                trace_particle<true, false, true>(*job.stack, *job.grid, job, rng, tally, block);
            else
                trace_particle<false, false, true>(*job.stack, *job.grid, job, rng, tally, block);
        } else if (job.stack->anisotropic) {
            if (pol)
                trace_particle<true, true, false>(*job.stack, *job.grid, job, rng, tally, block);
            else
                trace_particle<false, true, false>(*job.stack, *job.grid, job, rng, tally, block);
        } else if (pol) {
            trace_particle<true, false, false>(*job.stack, *job.grid, job, rng, tally, block);
        } else {
            trace_particle<false, false, false>(*job.stack, *job.grid, job, rng, tally, block);
        }
    }
}

std::string kernel_description(Kernel kernel) {
    if (kernel == Kernel::Auto) return "auto";
    return kernel == Kernel::Simd ? fmt::format("simd {}", simd_target_name()) : "scalar";
}

bool is_spectral_run(const Stack& stack, const SimulationSettings& settings) {
    return settings.spectral == SpectralMode::On ||
           (settings.spectral == SpectralMode::Auto && stack.is_spectral());
}

bool needs_scalar_kernel(const Stack& stack, const SimulationSettings& settings) {
    return stack.has_film() || stack.is_anisotropic() || settings.phi_i_deg != 0 ||
           is_spectral_run(stack, settings);
}

Kernel kernel_for(const SimulationSettings& settings, const Stack& stack) {
    if (settings.kernel != Kernel::Auto) return settings.kernel;
    return needs_scalar_kernel(stack, settings) ? Kernel::Scalar : Kernel::Simd;
}

void IncidenceSums::add(const IncidenceSums& o) {
    LAMINA_CHECK(bins.size() == o.bins.size());
    for (std::size_t i = 0; i < bins.size(); ++i)
        for (int k = 0; k < 6; ++k)
            bins[i][k] += o.bins[i][k];
    for (std::size_t t = 0; t < budget.size(); ++t)
        for (int c = 0; c < 3; ++c)
            budget[t][c] += o.budget[t][c];
    LAMINA_CHECK(stokes.size() == o.stokes.size());
    for (std::size_t i = 0; i < stokes.size(); ++i)
        for (int k = 0; k < kStokesSums; ++k)
            stokes[i][std::size_t(k)] += o.stokes[i][std::size_t(k)];
    events += o.events;
    degenerate += o.degenerate;
    LAMINA_CHECK(spectral_bins.size() == o.spectral_bins.size() &&
                 xyz_bins.size() == o.xyz_bins.size() &&
                 spectral_budget.size() == o.spectral_budget.size());
    for (std::size_t i = 0; i < spectral_bins.size(); ++i)
        for (int k = 0; k < 6; ++k)
            spectral_bins[i][k] += o.spectral_bins[i][k];
    for (std::size_t i = 0; i < xyz_bins.size(); ++i)
        for (int k = 0; k < 6; ++k)
            xyz_bins[i][k] += o.xyz_bins[i][k];
    auto add_budget = [](auto& into, const auto& from) {
        for (std::size_t t = 0; t < into.size(); ++t)
            for (int c = 0; c < 3; ++c)
                into[t][c] += from[t][c];
    };
    for (std::size_t g = 0; g < spectral_budget.size(); ++g)
        add_budget(spectral_budget[g], o.spectral_budget[g]);
    add_budget(xyz_budget, o.xyz_budget);
}

void validate_kernel_for(const Stack& stack, const SimulationSettings& settings) {
    if (stack.has_film() && stack.is_anisotropic())
        throw InputError(stack.name, "film",
                         "a thin film on a stack with an anisotropic interface is not traced yet "
                         "(films and anisotropy each work alone)");
    if (is_spectral_run(stack, settings)) {
        if (settings.spectral_bins % 3 != 0)
            throw InputError("settings", "spectral_bins",
                             fmt::format("got {}; allowed: a multiple of 3 in [3, 300] (each "
                                         "particle carries three wavelengths a third of the "
                                         "range apart)",
                                         settings.spectral_bins));
        if (settings.spectral_max_nm - settings.spectral_min_nm < settings.spectral_bins)
            throw InputError("settings", "spectral_max_nm",
                             fmt::format("the range [{}, {}] nm is narrower than one nm per "
                                         "wavelength bin ({} bins); widen it or use fewer bins",
                                         settings.spectral_min_nm, settings.spectral_max_nm,
                                         settings.spectral_bins));
        if (settings.particles < std::uint64_t(2 * (settings.spectral_bins / 3)))
            throw InputError("settings", "particles",
                             fmt::format("a spectral run needs at least 2 particles per "
                                         "wavelength group: {} for {} bins",
                                         2 * (settings.spectral_bins / 3), settings.spectral_bins));
        if (settings.stokes_tallies)
            throw InputError("settings", "spectral",
                             "Mueller tables are tabulated per RGB channel; give --spectral off");
        if (settings.kernel == Kernel::Simd)
            throw InputError("command line", "--kernel",
                             fmt::format("a spectral run (stack '{}'{}) is traced by the scalar "
                                         "kernel only; give --kernel scalar (or auto)",
                                         stack.name,
                                         stack.is_spectral() ? ", which has spectral values"
                                                             : ", --spectral on"));
    }
    if (settings.kernel != Kernel::Simd) return;
    if (stack.has_film())
        throw InputError("command line", "--kernel",
                         fmt::format("the stack '{}' has a thin film, which the SIMD kernel does "
                                     "not trace; give --kernel scalar (or auto)",
                                     stack.name));
    if (stack.is_anisotropic())
        throw InputError("command line", "--kernel",
                         fmt::format("the stack '{}' has an anisotropic interface, which the SIMD "
                                     "kernel does not trace; give --kernel scalar (or auto)",
                                     stack.name));
    if (settings.phi_i_deg != 0)
        throw InputError("command line", "--kernel",
                         "light from phi_i ≠ 0 is tabulated on the unfolded grid, which the SIMD "
                         "kernel does not bin; give --kernel scalar (or auto)");
}

SimulationSums simulate_sums(const Stack& stack, const SimulationSettings& settings,
                             const std::function<void(std::uint64_t)>& on_progress) {
    validate_settings(settings);
    const auto start = std::chrono::steady_clock::now();
    const CompiledStack<float> trace = compile_stack<float>(stack, settings.transport);
    validate_kernel_for(stack, settings);
    const HemisphereGrid grid = simulation_grid(stack, settings);
    const int threads = settings.threads > 0 ? settings.threads : omp_get_max_threads();
    const Kernel kernel = kernel_for(settings, stack);
    if (kernel == Kernel::Simd) select_simd_target();
    const auto trace_block = kernel == Kernel::Simd ? trace_block_simd : trace_block_scalar;
    const bool spectral = is_spectral_run(stack, settings);
    const SpectralTracing tracing =
        spectral ? spectral_tracing(stack, settings) : SpectralTracing{};
    const int groups = settings.spectral_bins / 3;

    SimulationSums result;
    result.threads_used = threads;
    const std::uint64_t n = settings.particles;
    // Particles per block: the unit of scheduling and of the double-precision budget sums. Blocks
    // are ranges of particle indices, so a run split at block boundaries (first_particle) adds up
    // to the same integers as one run.
    constexpr std::uint64_t kBlock = kParticlesPerBlock;
    const std::uint64_t blocks = (n + kBlock - 1) / kBlock;

    for (std::size_t inc = 0; inc < settings.theta_i_deg.size(); ++inc) {
        const auto inc_start = std::chrono::steady_clock::now();
        const double theta_i = deg_to_rad(settings.theta_i_deg[inc]);
        BlockJob job{&trace,
                     &grid,
                     Vec3f(direction_from_angles(theta_i, deg_to_rad(settings.phi_i_deg))),
                     settings.seed,
                     incidence_stream(settings.theta_i_deg[inc], settings.incident_polarization),
                     0,
                     0,
                     settings.transport.max_events};
        for (int k = 0; k < 3; ++k)
            job.incident_stokes[k] = kIncidentStokes[settings.incident_polarization][k];
        job.stokes_tallies = settings.stokes_tallies;
        if (spectral) job.spectral = &tracing;
        IncidenceSums total;
        total.bins.resize(2 * grid.size());
        if (settings.stokes_tallies) total.stokes.resize(2 * grid.size());
        if (spectral) {
            total.spectral_bins.resize(2 * grid.size() * std::size_t(groups));
            total.xyz_bins.resize(2 * grid.size());
            total.spectral_budget.resize(std::size_t(groups));
        }

#pragma omp parallel num_threads(threads) firstprivate(job)
        {
            Tally local(grid.size(), settings.stokes_tallies);
            std::optional<SpectralTally> local_spectral;
            if (spectral) {
                local_spectral.emplace(grid.size(), groups);
                job.spectral_tally = &*local_spectral;
            }
#pragma omp for schedule(dynamic, 1)
            for (std::uint64_t b = 0; b < blocks; ++b) {
                const std::uint64_t lo = b * kBlock, hi = std::min(n, lo + kBlock);
                BlockBudget block;
                std::optional<SpectralBlock> spectral_block;
                if (spectral) {
                    spectral_block.emplace(groups);
                    job.spectral_block = &*spectral_block;
                }
                job.first = settings.first_particle + lo;
                job.count = hi - lo;
                trace_block(job, local, block);
                local.add_block(block);
                local.count_particles(hi - lo);
                if (spectral) {
                    spectral_block->add_to(*local_spectral);
                    local_spectral->lambda.count_particles(hi - lo);
                    local_spectral->xyz.count_particles(hi - lo);
                }
                if (on_progress) on_progress(hi - lo);
            }
            IncidenceSums& mine = local.finish();
            if (spectral) {
                mine.spectral_bins = local_spectral->lambda.finish().bins;
                mine.spectral_budget = local_spectral->lambda.sums.spectral_budget;
                mine.xyz_bins = local_spectral->xyz.finish().bins;
                mine.xyz_budget = local_spectral->xyz.sums.budget;
            }
#pragma omp critical
            total.add(mine);  // integer sums: the order of merging does not matter
        }
        result.incidences.push_back(std::move(total));
        result.incidence_seconds.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - inc_start).count());
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

namespace {
/// The mean and standard error of the per-particle contributions whose sum and sum of squares a
/// tally entry holds (scales kSumScale, kSqScale), times `scale`.
std::pair<double, double> tally_estimate(Fixed128 sum, Fixed128 sum_sq, std::uint64_t n,
                                         double scale) {
    const double mean = double(sum) / kSumScale / double(n);
    const double mean_sq = double(sum_sq) / kSqScale / double(n);
    const double var = std::max(0.0, mean_sq - mean * mean);
    return {mean * scale, n > 1 ? std::sqrt(var / double(n - 1)) * scale : 0.0};
}

/// The budget terms and the standard errors of R and T of one channel of a budget's sums, times
/// `scale`.
std::array<double, kBudgetTerms + 2> budget_estimate(
    const std::array<std::array<Fixed128, 3>, kBudgetTerms + 2>& sums, int c, std::uint64_t n,
    double scale) {
    std::array<double, kBudgetTerms + 2> out{};
    const double inv_n = 1.0 / double(n), dn = n > 1 ? double(n - 1) : 1.0;
    for (int t = 0; t < kBudgetTerms; ++t)
        out[std::size_t(t)] = double(sums[std::size_t(t)][std::size_t(c)]) / kBudgetScale * inv_n;
    for (int k = 0; k < 2; ++k) {
        const double m = out[std::size_t(k == 0 ? BudgetTerm::Reflected : BudgetTerm::Transmitted)];
        const double m2 =
            double(sums[std::size_t(kBudgetTerms + k)][std::size_t(c)]) / kBudgetScale * inv_n;
        out[std::size_t(kBudgetTerms + k)] = std::sqrt(std::max(0.0, m2 - m * m) / dn);
    }
    for (double& v : out)
        v *= scale;
    return out;
}

// The spectral tables of a spectral run (SpectralTables), and its sRGB table scaled back
// (IncidenceSums' spectral fields).
void finalize_spectral(const SimulationSettings& settings, const SimulationSums& sums,
                       const HemisphereGrid& grid, bool transmits, SimulationResult& result) {
    SpectralTables& sp = result.spectral;
    const int bins = settings.spectral_bins, groups = bins / 3;
    const std::uint64_t n = settings.particles;
    for (int l = 0; l <= bins; ++l)
        sp.bin_edges_nm.push_back(settings.spectral_min_nm +
                                  (settings.spectral_max_nm - settings.spectral_min_nm) * l / bins);
    sp.n_directions = grid.size();
    sp.sides = transmits ? 2 : 1;
    const std::size_t n_inc = settings.theta_i_deg.size();
    sp.f.assign(n_inc * std::size_t(sp.sides) * grid.size() * std::size_t(bins), 0.0);
    sp.se = sp.f;
    sp.xyz = BinnedTable::zeros(grid, settings.theta_i_deg, true, transmits);
    // Wavelength bin c · groups + g: the mean over the n_g particles of group g of their channel
    // c (tallied divided by 4).
    for (std::size_t inc = 0; inc < n_inc; ++inc) {
        const IncidenceSums& total = sums.incidences[inc];
        for (int side = 0; side < sp.sides; ++side) {
            const Side s = side == 0 ? Side::Reflection : Side::Transmission;
            BinnedLobe& srgb = result.table.lobe(inc, s);
            BinnedLobe& xyz = sp.xyz.lobe(inc, s);
            for (std::size_t j = 0; j < grid.size(); ++j) {
                const double omega = grid.projected_solid_angle(j);
                const std::size_t entry = std::size_t(side) * grid.size() + j;
                for (int c = 0; c < 3; ++c) {
                    srgb.f[j][c] *= kSpectralTallyScale;
                    srgb.se[j][c] *= kSpectralTallyScale;
                    const auto& a = total.xyz_bins[entry];
                    const auto [m, e] = tally_estimate(a[c], a[3 + c], n, kSpectralTallyScale);
                    xyz.f[j][c] = m / omega;
                    xyz.se[j][c] = e / omega;
                    for (int g = 0; g < groups; ++g) {
                        const auto& b =
                            total.spectral_bins[entry * std::size_t(groups) + std::size_t(g)];
                        const auto [mb, eb] = tally_estimate(
                            b[c], b[3 + c], spectral_group_particles(n, groups, g), 4.0);
                        const std::size_t at = sp.index(inc, side, j, std::size_t(c * groups + g));
                        sp.f[at] = mb / omega;
                        sp.se[at] = eb / omega;
                    }
                }
            }
        }
        EnergyBudget xyz_budget;
        for (int c = 0; c < 3; ++c) {
            for (int g = 0; g < groups; ++g)
                sp.budget.emplace_back();  // filled below, in wavelength order
            const auto e = budget_estimate(total.xyz_budget, c, n, 1.0);
            for (int t = 0; t < kBudgetTerms; ++t)
                xyz_budget.term[std::size_t(t)][std::size_t(c)] = e[std::size_t(t)];
            xyz_budget.reflected_se[std::size_t(c)] = e[kBudgetTerms];
            xyz_budget.transmitted_se[std::size_t(c)] = e[kBudgetTerms + 1];
        }
        sp.xyz_budget.push_back(xyz_budget);
        const std::size_t first = inc * std::size_t(bins);
        for (int c = 0; c < 3; ++c)
            for (int g = 0; g < groups; ++g)
                sp.budget[first + std::size_t(c * groups + g)] =
                    budget_estimate(total.spectral_budget[std::size_t(g)], c,
                                    spectral_group_particles(n, groups, g), 1.0);
    }
}
}  // namespace

SimulationResult finalize_simulation(const Stack& stack, const SimulationSettings& settings,
                                     const SimulationSums& sums) {
    LAMINA_CHECK(sums.incidences.size() == settings.theta_i_deg.size());
    const HemisphereGrid grid = simulation_grid(stack, settings);
    const bool transmits = stack.transmits();
    SimulationResult result;
    result.settings = settings;
    result.threads_used = sums.threads_used;
    result.seconds = sums.seconds;
    result.table = BinnedTable::zeros(grid, settings.theta_i_deg, true, transmits);
    const std::uint64_t n = settings.particles;
    const double inv_n = 1.0 / double(n);
    const double dn = n > 1 ? double(n - 1) : 1.0;

    for (std::size_t inc = 0; inc < settings.theta_i_deg.size(); ++inc) {
        const IncidenceSums& total = sums.incidences[inc];
        LAMINA_CHECK(total.bins.size() == 2 * grid.size());
        IncidenceStats stats;
        for (int side = 0; side < (transmits ? 2 : 1); ++side) {
            BinnedLobe& lobe =
                result.table.lobe(inc, side == 0 ? Side::Reflection : Side::Transmission);
            for (std::size_t j = 0; j < grid.size(); ++j) {
                const double omega = grid.projected_solid_angle(j);
                const auto& acc = total.bins[side * grid.size() + j];
                for (int c = 0; c < 3; ++c) {
                    const double mean = double(acc[c]) / kSumScale * inv_n;
                    const double mean_sq = double(acc[3 + c]) / kSqScale * inv_n;
                    // Standard error of the mean of N per-particle contributions.
                    const double var = std::max(0.0, mean_sq - mean * mean);
                    lobe.f[j][c] = mean / omega;
                    lobe.se[j][c] = n > 1 ? std::sqrt(var / dn) / omega : 0.0;
                }
            }
        }
        for (int t = 0; t < kBudgetTerms; ++t)
            for (int c = 0; c < 3; ++c)
                stats.budget.term[t][c] = double(total.budget[t][c]) / kBudgetScale * inv_n;
        for (int c = 0; c < 3; ++c) {
            const double r = stats.budget.term[int(BudgetTerm::Reflected)][c];
            const double t = stats.budget.term[int(BudgetTerm::Transmitted)][c];
            const double r2 = double(total.budget[kBudgetTerms][c]) / kBudgetScale * inv_n;
            const double t2 = double(total.budget[kBudgetTerms + 1][c]) / kBudgetScale * inv_n;
            stats.budget.reflected_se[c] = std::sqrt(std::max(0.0, r2 - r * r) / dn);
            stats.budget.transmitted_se[c] = std::sqrt(std::max(0.0, t2 - t * t) / dn);
        }
        stats.events_per_particle = double(total.events) * inv_n;
        stats.degenerate_samples = total.degenerate;
        stats.seconds = inc < sums.incidence_seconds.size() ? sums.incidence_seconds[inc] : 0.0;
        result.incidences.push_back(stats);
    }
    if (settings.stokes_tallies) result.sums = sums.incidences;
    if (is_spectral_run(stack, settings))
        finalize_spectral(settings, sums, grid, transmits, result);
    return result;
}

HemisphereGrid simulation_grid(const Stack& stack, const SimulationSettings& settings) {
    return stack.is_anisotropic() || settings.phi_i_deg != 0 ? settings.grid.unfolded()
                                                             : settings.grid;
}

SimulationResult simulate(const Stack& stack, const SimulationSettings& settings,
                          const std::function<void(std::uint64_t)>& on_progress) {
    return finalize_simulation(stack, settings, simulate_sums(stack, settings, on_progress));
}

}  // namespace lamina

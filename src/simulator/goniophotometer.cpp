#include "simulator/goniophotometer.h"

#include "core/check.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
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

// ---- One particle ------------------------------------------------------------------------------
// docs/physics.md §3: at an interface the particle (arriving along −wi) draws an outgoing direction
// from the interface's BSDF sampler; its flux is multiplied by the sample weight and the parts
// that do not continue are booked (absorbed by the base, lost to the microsurface).
// Polarized runs (docs/physics.md §8): the particle also carries its Stokes vector per channel
// divided by its flux, with the frame's x axis (physics/polarization.h at one lane); every event
// passes it to the interface's polarized event, a Lambertian base and a scattering event
// depolarize it, and an exit is tallied with its Stokes vector when the job asks for it.
// Written once for both: kPolarized = false is the unpolarized kernel, with none of it; kFilm
// = true the instantiation for stacks with a thin film (film_event).
template <bool kPolarized, bool kAnisotropic, bool kFilm>
void trace_particle(const CompiledStack<float>& stack, const HemisphereGrid& grid,
                    const BlockJob& job, ParticleRng& rng, Tally& tally, BlockBudget& block) {
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
                tally.exit(bin, w);
                if constexpr (kPolarized) exit_stokes(bin);
                block.escape_reflected(w);
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
                tally.exit(bin, w);
                if constexpr (kPolarized) exit_stokes(bin);
                block.escape_transmitted(w);
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
    losses.flush(block);
    tally.sums.events += std::uint64_t(events);
}

std::uint64_t incidence_stream(double theta_i_deg, double phi_i_deg, int incident_polarization) {
    // The stream is the incidence itself, so a result does not depend on which other incidences
    // were simulated with it; a polarized incident state other than unpolarized adds its index
    // times an odd 64-bit constant (the golden ratio's, as in Random123's key schedule) to the
    // key, so that runs with different incident states are independent. The azimuth's bits enter
    // rotated by half a word (so that θi = φi does not cancel), and φi = 0 adds nothing: runs at
    // different φi are independent, and light at φi = 0 keeps the stream it always had.
    return std::bit_cast<std::uint64_t>(theta_i_deg) ^
           std::rotl(std::bit_cast<std::uint64_t>(phi_i_deg + 0.0), 32) ^
           (std::uint64_t(incident_polarization) * 0x9E3779B97F4A7C15ull);
}

// The incident Stokes vectors (S1, S2, S3)/S0 of SimulationSettings::incident_polarization.
constexpr float kIncidentStokes[7][3] = {{0, 0, 0},  {1, 0, 0},  {0, 1, 0}, {0, 0, 1},
                                         {-1, 0, 0}, {0, -1, 0}, {0, 0, -1}};

}  // namespace

void trace_block_scalar(const BlockJob& job, Tally& tally, BlockBudget& block) {
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

bool needs_scalar_kernel(const Stack& stack, const SimulationSettings& settings) {
    return stack.has_film() || stack.is_anisotropic() || settings.phi_i_deg != 0;
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
}

void validate_kernel_for(const Stack& stack, const SimulationSettings& settings) {
    if (stack.has_film() && stack.is_anisotropic())
        throw InputError(stack.name, "film",
                         "a thin film on a stack with an anisotropic interface is not traced yet "
                         "(films and anisotropy each work alone)");
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

    SimulationSums result = zero_sums(stack, settings);
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
                     incidence_stream(settings.theta_i_deg[inc], settings.phi_i_deg,
                                      settings.incident_polarization),
                     0,
                     0,
                     settings.transport.max_events};
        for (int k = 0; k < 3; ++k)
            job.incident_stokes[k] = kIncidentStokes[settings.incident_polarization][k];
        job.stokes_tallies = settings.stokes_tallies;
        IncidenceSums& total = result.incidences[inc];

#pragma omp parallel num_threads(threads) firstprivate(job)
        {
            Tally local(grid.size(), settings.stokes_tallies);
#pragma omp for schedule(dynamic, 1)
            for (std::uint64_t b = 0; b < blocks; ++b) {
                const std::uint64_t lo = b * kBlock, hi = std::min(n, lo + kBlock);
                BlockBudget block;
                job.first = settings.first_particle + lo;
                job.count = hi - lo;
                trace_block(job, local, block);
                local.add_block(block);
                local.count_particles(hi - lo);
                if (on_progress) on_progress(hi - lo);
            }
            const IncidenceSums& mine = local.finish();
#pragma omp critical
            total.add(mine);  // integer sums: the order of merging does not matter
        }
        result.incidence_seconds[inc] =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - inc_start).count();
    }
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

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
    return result;
}

HemisphereGrid simulation_grid(const Stack& stack, const SimulationSettings& settings) {
    return stack.is_anisotropic() || settings.phi_i_deg != 0 ? settings.grid.unfolded()
                                                             : settings.grid;
}

SimulationSums zero_sums(const Stack& stack, const SimulationSettings& settings) {
    const std::size_t n_bins = simulation_grid(stack, settings).size();
    SimulationSums sums;
    sums.incidences.resize(settings.theta_i_deg.size());
    for (IncidenceSums& s : sums.incidences) {
        s.bins.resize(2 * n_bins);
        if (settings.stokes_tallies) s.stokes.resize(2 * n_bins);
    }
    sums.incidence_seconds.assign(settings.theta_i_deg.size(), 0.0);
    return sums;
}

SimulationResult simulate(const Stack& stack, const SimulationSettings& settings,
                          const std::function<void(std::uint64_t)>& on_progress) {
    return finalize_simulation(stack, settings, simulate_sums(stack, settings, on_progress));
}

}  // namespace lamina

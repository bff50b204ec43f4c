#pragma once
// Order-free tallies of the goniophotometer, shared by its kernels (scalar and SIMD). Internal to
// the simulator: users see IncidenceSums (goniophotometer.h) and the finished SimulationResult.
//
// Flux is added in integers: integer addition is associative, so the sums (and the tables) are
// identical whatever the order in which threads or processes add them. A particle's flux per
// channel never exceeds 3 (the spectral MIS of media conserves the sum of the channels' fluxes, and
// every other event only removes flux), so one contribution is below 2^2.
//
// Exits first go to per-thread 64-bit sums (half the memory of 128-bit ones, so the bins stay in
// cache), at scale 2^40 for Σ flux and 2^38 for Σ flux²; every 2^18 particles of a thread they are
// widened into 128-bit sums, before 2^18 · 2^2 · 2^40 = 2^60 (resp. 2^18 · 2^4 · 2^38) could
// overflow. Resolution 2^-40 ≈ 10^-12 of the incident flux per contribution.

#include "core/check.h"
#include "core/grid.h"
#include "core/rgb.h"
#include "core/vec.h"
#include "layers/compiled_stack.h"
#include "simulator/goniophotometer.h"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace lamina {

inline constexpr double kSumScale = 0x1p40, kSqScale = 0x1p38;
inline constexpr double kBudgetScale = 0x1p56;
inline constexpr std::uint64_t kFlushParticles = std::uint64_t(1) << 18;

/// |x| < 2^39 to fixed point at scale 2^56: an integer part at scale 2^24 and the exact remainder,
/// converted separately (budget sums over blocks of particles).
inline Fixed128 to_fixed_wide(double x) {
    const double scaled = x * 0x1p24;  // exact: a power-of-two scaling
    const double hi = std::floor(scaled);
    const double lo = scaled - hi;  // exact: the fractional part, in [0, 1)
    return (Fixed128(std::int64_t(hi)) << 32) + Fixed128(std::llrint(lo * 0x1p32));
}

/// Budget terms summed in double over one block of particles (a fixed range of particle indices,
/// traced in a fixed order by one thread, so the sum does not depend on the thread count), then
/// added to the 128-bit tallies once per block.
struct BlockBudget {
    std::array<Rgbd, kBudgetTerms> term{};
    Rgbd reflected_sq{0.0}, transmitted_sq{0.0};

    void escape_reflected(const Rgbf& w) { escape(BudgetTerm::Reflected, reflected_sq, w); }
    void escape_transmitted(const Rgbf& w) { escape(BudgetTerm::Transmitted, transmitted_sq, w); }

  private:
    void escape(BudgetTerm t, Rgbd& sum_sq, const Rgbf& w) {
        for (int c = 0; c < 3; ++c) {
            term[int(t)][c] += w[c];
            sum_sq[c] += double(w[c]) * double(w[c]);
        }
    }
};

/// Adds a block's budget sums to 128-bit ones (IncidenceSums::budget's layout).
inline void add_block_budget(const BlockBudget& b,
                             std::array<std::array<Fixed128, 3>, kBudgetTerms + 2>& into) {
    for (int t = 0; t < kBudgetTerms; ++t)
        for (int c = 0; c < 3; ++c)
            into[t][c] += to_fixed_wide(b.term[t][c]);
    for (int c = 0; c < 3; ++c) {
        into[kBudgetTerms][c] += to_fixed_wide(b.reflected_sq[c]);
        into[kBudgetTerms + 1][c] += to_fixed_wide(b.transmitted_sq[c]);
    }
}

/// The flux a particle loses along its path, per budget term, in registers; added to the block's
/// double sums once, when the particle ends. Summed in double: a particle trapped in a scattering
/// slab can lose its flux in thousands of small pieces, and a float sum of them drifted by 1.2e-6
/// of the incident flux (fuzz seed 1214, case 2100: the scalar kernel's budget summed to
/// 0.9999988). Each piece is a float difference of two weights, exact or within an ulp of it.
struct PathLosses {
    std::array<Rgbd, kBudgetTerms> term{};

    void add(BudgetTerm t, const Rgbf& lost) {
        for (int c = 0; c < 3; ++c)
            term[int(t)][c] += double(lost[c]);
    }
    void flush(BlockBudget& block) const {
        for (int t = int(BudgetTerm::AbsorbedMedium); t < kBudgetTerms; ++t)
            for (int c = 0; c < 3; ++c)
                block.term[t][c] += term[t][c];
    }
};

/// One thread's tallies of one incidence.
struct Tally {
    struct Recent {
        std::array<std::int64_t, 3> sum{}, sum_sq{};
    };
    std::vector<Recent> recent;  // [side · n_bins + bin], since the last widening
    IncidenceSums sums;          // widened sums
    std::uint64_t particles_since_widening = 0;
    /// The Stokes tallies since the last widening (empty unless requested), as IncidenceSums::
    /// stokes.
    std::vector<std::array<std::int64_t, kStokesSums>> stokes_recent;

    explicit Tally(std::size_t n_bins, bool stokes = false) : recent(2 * n_bins) {
        sums.bins.resize(2 * n_bins);
        if (stokes) {
            stokes_recent.resize(2 * n_bins);
            sums.stokes.resize(2 * n_bins);
        }
    }

    /// A particle leaving into bin `index` (side · n_bins + bin) with flux `flux` (for spectral
    /// runs, their contributions already divided by their scales: goniophotometer.h).
    void exit(std::size_t index, const Rgbf& flux) {
        LAMINA_DCHECK(flux.max() <= 4.f && flux.min() >= -4.f);
        Recent& acc = recent[index];
        for (int c = 0; c < 3; ++c) {
            const double x = flux[c];
            acc.sum[c] += std::llrint(x * kSumScale);
            acc.sum_sq[c] += std::llrint(x * x * kSqScale);
        }
    }
    /// The Stokes vectors s[c] = (S0..S3) per channel (in the bin frame) of a particle leaving
    /// into bin `index` on the bin's half `half` (0: y ≥ 0, 1: y < 0). |S_k| ≤ S0 ≤ 4.
    void exit_stokes(std::size_t index, int half, const float (&s)[3][4]) {
        std::array<std::int64_t, kStokesSums>& acc = stokes_recent[index];
        for (int c = 0; c < 3; ++c)
            for (int k = 0; k < 4; ++k) {
                const double x = s[c][k];
                acc[std::size_t(c * 12 + half * 4 + k)] += std::llrint(x * kSumScale);
                acc[std::size_t(c * 12 + 8 + k)] += std::llrint(x * x * kSqScale);
            }
    }
    void widen() {
        for (std::size_t i = 0; i < stokes_recent.size(); ++i) {
            for (int k = 0; k < kStokesSums; ++k)
                sums.stokes[i][std::size_t(k)] += stokes_recent[i][std::size_t(k)];
            stokes_recent[i] = {};
        }
        for (std::size_t i = 0; i < recent.size(); ++i) {
            for (int c = 0; c < 3; ++c) {
                sums.bins[i][c] += recent[i].sum[c];
                sums.bins[i][3 + c] += recent[i].sum_sq[c];
            }
            recent[i] = Recent{};
        }
        particles_since_widening = 0;
    }
    void count_particles(std::uint64_t n) {
        particles_since_widening += n;
        if (particles_since_widening >= kFlushParticles) widen();
    }
    void add_block(const BlockBudget& b) { add_block_budget(b, sums.budget); }
    /// The widened sums (widens first).
    IncidenceSums& finish() {
        widen();
        return sums;
    }
};

// ---- Spectral runs (docs/physics.md §10) ----------------------------------------------------
// A particle carries three wavelengths: the lattice points t + c · L/3 of the run's lattice of L
// points (SimulationSettings::spectral_bins · kSpectralLattice), one per channel c, so that
// channel c's wavelength lies in wavelength bin c · groups + g, g = t / kSpectralLattice (groups =
// spectral_bins / 3). Particle p's group g is p mod groups; its point within the group and its
// hero channel are drawn from its own stream. Its exits are tallied three ways: per wavelength bin
// (the channels' fluxes, divided by 4, at entry (side · n_bins + bin) · groups + t /
// kSpectralLattice of a Tally over n_bins · groups bins), and projected to CIE XYZ and linear sRGB
// (Σ_c flux_c · weight(λ_c), divided by kSpectralTallyScale). A flux is at most 3 per channel, 9
// for a hero that carries its terminated secondaries (goniophotometer.cpp), and every weight is at
// most 5 in magnitude (checked when the run is set up) times a group factor below 1.5, so each
// contribution, divided by its scale, stays within the bounds of Tally::exit.

/// One layer's values that differ between a spectral run's stacks, per stack (SpectralTracing::
/// stacks' index t · 3 + h), for the SIMD kernel to gather into its lanes: the dielectric's
/// relative index and its inverse (the hero's), the conductor's complex index, the Lambertian
/// albedo and the medium's optical depths, phase function and single-scattering albedo per
/// channel (CompiledMedium's), and whether the layer is dispersive.
struct SpectralLayerLanes {
    std::vector<float> eta, inv_eta;
    std::array<std::vector<float>, 3> conductor_eta, conductor_k, albedo, tau_a, tau_s, tau_t, g,
        single_scattering_albedo;
    std::vector<std::int32_t> dispersive;
};

/// The stacks and weights of a spectral run.
struct SpectralTracing {
    int bins = 0;     ///< wavelength bins (a multiple of 3)
    int lattice = 0;  ///< lattice points, bins · kSpectralLattice
    /// The stack at the wavelengths of the lattice points t, t + L/3, t + 2L/3 with its
    /// dielectrics' indices at channel h's wavelength (the path the particle follows), at
    /// t · 3 + h; and per layer, whether its relative index differs between the three wavelengths
    /// (dispersive: a refraction direction that depends on the wavelength).
    std::vector<CompiledStack<float>> stacks;
    std::vector<std::vector<char>> dispersive;
    /// Per lattice point: its XYZ and linear sRGB weights (colorimetry.h), such that the
    /// expectation of Σ_c flux_c · weight(λ_c) over the particles is the projection of the
    /// spectrum.
    std::vector<Rgbf> xyz_weight, srgb_weight;
    /// What the SIMD kernel reads (kernel_simd.cpp): per layer, the values that differ between
    /// the stacks, indexed as `stacks` (SpectralLayerLanes); and the stack its lanes branch on,
    /// stacks[0] with every medium absorbing (scattering) where some stack's does, one extinction
    /// (one g) for all channels only where every stack's has, and the most polarization states
    /// any stack needs. `lanes_uniform`: every stack has the same structure (interface types,
    /// smooth or index-matched dielectrics, films), so that one stack's branches serve all lanes;
    /// else the scalar kernel traces the run.
    std::vector<SpectralLayerLanes> layer_lanes;
    CompiledStack<float> structure;
    bool lanes_uniform = false;
};

/// Particle p's wavelength group is p mod groups (the groups are stratified over the particles);
/// the particles of [0, n) in group g.
inline std::uint64_t spectral_group_particles(std::uint64_t n, int groups, int g) {
    return n / std::uint64_t(groups) + (std::uint64_t(g) < n % std::uint64_t(groups) ? 1 : 0);
}

/// One thread's spectral tallies of one incidence (the sRGB ones are its main Tally).
struct SpectralTally {
    Tally lambda, xyz;
    SpectralTally(std::size_t n_bins, int groups)
        : lambda(n_bins * std::size_t(groups)), xyz(n_bins) {
        lambda.sums.spectral_budget.resize(std::size_t(groups));
    }
};

/// The budget sums of one block of a spectral run: per wavelength group, and of XYZ (the sRGB
/// ones are the block's main BlockBudget).
struct SpectralBlock {
    std::vector<BlockBudget> groups;
    BlockBudget xyz;
    explicit SpectralBlock(int n_groups) : groups(std::size_t(n_groups)) {}
    void add_to(SpectralTally& t) const {
        for (std::size_t g = 0; g < groups.size(); ++g)
            add_block_budget(groups[g], t.lambda.sums.spectral_budget[g]);
        add_block_budget(xyz, t.xyz.sums.budget);
    }
};

/// A block of particles [first, first + count) of one incidence, traced by one kernel into
/// `tally` (exits, events, degeneracies) and `block` (the budget). Particle p draws its numbers
/// from ParticleRng(seed, stream, p).
struct BlockJob {
    const CompiledStack<float>* stack;
    const HemisphereGrid* grid;
    Vec3f wi;
    std::uint64_t seed, stream, first, count;
    int max_events;
    /// Polarized runs (CompiledStack::polarization): the incident Stokes vector (S1, S2, S3)/S0 in
    /// the bin frame of −wi, and whether exits are tallied with their Stokes vectors.
    float incident_stokes[3] = {0.f, 0.f, 0.f};
    bool stokes_tallies = false;
    /// Spectral runs (either kernel): the run's stacks and weights, and this thread's spectral
    /// tallies and block sums; null otherwise.
    const SpectralTracing* spectral = nullptr;
    SpectralTally* spectral_tally = nullptr;
    SpectralBlock* spectral_block = nullptr;
};

void trace_block_scalar(const BlockJob& job, Tally& tally, BlockBudget& block);

// ---- A spectral particle (docs/physics.md §10) -------------------------------------------------
// Its three wavelengths (tally.h: lattice points t + c · L/3), the channel h whose wavelength its
// path follows (the hero), and where its exits and losses are tallied. At a dispersive interface
// (one whose refraction direction depends on the wavelength) the other two channels, whose paths
// would part from the hero's, are terminated and the hero carries 3 times its flux (hero
// wavelength sampling's termination of the secondary wavelengths at a dispersive event: Wilkie
// et al. 2014, "Hero Wavelength Spectral Sampling", EGSR): the
// hero is uniformly distributed over the lattice, as each channel is, so its flux times 3
// estimates what the three channels did, without bias (the terminated flux is not booked in the
// budget, which sums to 1 in expectation then).
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
    /// Fetches the tally entries an exit into `index` adds to (a hint: nothing changes).
    void prefetch(std::size_t index) const {
        __builtin_prefetch(
            &tally.lambda.recent[index * std::size_t(tracing.bins / 3) + std::size_t(group)], 1);
        __builtin_prefetch(&tally.xyz.recent[index], 1);
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

/// The spectral particle of stack index `at` (SpectralTracing::stacks: t · 3 + hero) in wavelength
/// group `group`, tallied into the job's spectral tallies: its channels' colour weights.
inline SpectralParticle spectral_particle(const BlockJob& job, std::size_t at, int group) {
    const SpectralTracing& tr = *job.spectral;
    const int third = tr.lattice / 3, t = int(at / 3);
    SpectralParticle sp{tr,
                        *job.spectral_tally,
                        *job.spectral_block,
                        tr.dispersive[at],
                        group,
                        int(at % 3),
                        true,
                        {},
                        {}};
    for (int c = 0; c < 3; ++c) {
        sp.xyz_weight[c] = tr.xyz_weight[std::size_t(t + c * third)];
        sp.srgb_weight[c] = tr.srgb_weight[std::size_t(t + c * third)];
    }
    return sp;
}

}  // namespace lamina

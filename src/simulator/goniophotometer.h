#pragma once
// The virtual goniophotometer (docs/physics.md §5): Monte-Carlo particles traced through a layer
// stack, the BRDF and BTDF tabulated on a discretized hemisphere with a standard error per bin, and
// the energy budget of every incidence.
//
// Estimator: f_j = W_j / (N Ω⊥_j), W_j the flux of the particles leaving into bin j, Ω⊥_j the bin's
// projected solid angle: the cos-weighted bin average of the BSDF. The standard error comes from
// the second moment of the per-particle contributions.
//
// Reproducibility: each particle draws its random numbers from a generator keyed by (seed,
// incidence, particle index) (core/rng.h), and every tally is accumulated in 128-bit fixed point,
// whose sums do not depend on order: the output is bitwise identical for any thread count.

#include "core/grid.h"
#include "core/incidences.h"
#include "core/rgb.h"
#include "core/setting.h"
#include "core/table.h"
#include "layers/stack.h"
#include "layers/transport_settings.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lamina {

/// Particles per block (see simulate); a split run's first_particle must be a multiple of it.
inline constexpr std::uint64_t kParticlesPerBlock = 4096;

/// The particle kernel: `scalar` traces one particle at a time (the readable reference path);
/// `simd` traces a batch of particles as the lanes of SIMD vectors (kernel_simd.h), dispatched at
/// run time to what the CPU offers. Each is bitwise reproducible for any thread or process count on
/// a given machine; the two agree in distribution (a two-sample chi-square test), not bit for bit.
/// `auto` is `simd`, or `scalar` for what the SIMD kernel does not trace (a thin film on a
/// dielectric interface, docs/physics.md §9): kernel_for. Both trace anisotropic interfaces,
/// light from φi ≠ 0 (§3, §5), films on conductors and spectral runs (§10).
enum class Kernel { Scalar, Simd, Auto };
inline constexpr std::array<EnumName<Kernel>, 3> enum_names(Kernel) {
    return {{{Kernel::Scalar, "scalar", "one particle at a time, the reference path"},
             {Kernel::Simd, "simd", "particles as the lanes of SIMD vectors"},
             {Kernel::Auto, "auto", "simd, or scalar for a thin film on a dielectric"}}};
}
inline const char* enum_noun(Kernel) {
    return "a particle kernel";
}
/// The kernel as it runs on this machine: "scalar", or "simd" with the instruction set dispatched
/// to (e.g. "simd AVX3"); "auto" for auto, whose kernel depends on the stack (kernel_for). Tables
/// are bitwise reproducible for equal descriptions of the kernel that ran.
std::string kernel_description(Kernel kernel);

/// Spectral transport (docs/physics.md §10): `on` traces wavelengths, `off` the three RGB
/// channels (each at one wavelength), `auto` spectral for a stack with a spectral value
/// (Stack::is_spectral), RGB otherwise.
enum class SpectralMode { Auto, On, Off };
inline constexpr std::array<EnumName<SpectralMode>, 3> enum_names(SpectralMode) {
    return {{{SpectralMode::Auto, "auto", "spectral for a stack with a spectral value, else RGB"},
             {SpectralMode::On, "on", "trace wavelengths, tabulated in wavelength bins"},
             {SpectralMode::Off, "off", "the three RGB channels, each at one wavelength"}}};
}
inline const char* enum_noun(SpectralMode) {
    return "a spectral mode";
}

struct SimulationSettings;
/// Whether `stack` is traced spectrally under `settings` (SpectralMode).
bool is_spectral_run(const Stack& stack, const SimulationSettings& settings);
/// Whether only the scalar kernel traces `stack` under `settings` (a thin film on a dielectric
/// interface). A spectral run on the SIMD kernel whose stacks differ in structure between
/// wavelengths (a dielectric index-matched to its surroundings at some wavelengths only,
/// SpectralTracing::lanes_uniform) is handed to the scalar kernel when traced.
bool needs_scalar_kernel(const Stack& stack, const SimulationSettings& settings);
/// The kernel that traces `stack` under `settings`: auto is scalar where needs_scalar_kernel,
/// simd otherwise; scalar and simd are themselves.
Kernel kernel_for(const SimulationSettings& settings, const Stack& stack);
/// The kernel that traces the run: kernel_for's, but scalar for a spectral run on the SIMD kernel
/// whose stacks differ in structure between wavelengths (needs_scalar_kernel). What result.json's
/// `kernel_description` and the study's reference pieces name.
Kernel traced_kernel(const SimulationSettings& settings, const Stack& stack);

/// The most threads lamina runs: OpenMP creates a team's threads all at once, and 65 536 crashed
/// its runtime (a segmentation fault from OMP_NUM_THREADS=100000 alone).
inline constexpr int kMaxThreads = 1024;

/// Caps OpenMP's default team size (OMP_NUM_THREADS, or the cores) at kMaxThreads; returns the
/// size asked for when it capped it, 0 otherwise. Called once at start by the CLI and the Python
/// module, before any parallel region.
int cap_openmp_threads();

/// The goniophotometer's settings. Each is declared once, in `fields` (core/setting.h): the
/// command line, result.json, the study's files, the reference's cache key and Python read them
/// there.
struct SimulationSettings {
    std::vector<double> theta_i_deg = default_incidences_deg();  ///< each in [0, 90)
    /// The incidence azimuth φi in degrees, [0, 360]: the light comes from (sin θi cos φi,
    /// sin θi sin φi, cos θi). A non-zero φi unfolds the φ grid (simulation_grid).
    double phi_i_deg = 0.0;
    std::uint64_t particles = 1'000'000;  ///< per incidence, > 0
    std::uint64_t seed = 1;
    int threads = 0;               ///< 0: all available
    HemisphereGrid grid;           ///< its default is the study's (core/grid.h)
    Kernel kernel = Kernel::Auto;  ///< auto: SIMD, or scalar for what only it traces
    /// The physics the particles follow (shared with the random walk).
    TransportSettings transport;
    /// Spectral transport (docs/physics.md §10): the mode, the range of vacuum wavelengths traced
    /// and the number of wavelength bins the tables have over it (a multiple of 3: each particle
    /// carries three wavelengths a third of the range apart).
    SpectralMode spectral = SpectralMode::Auto;
    double spectral_min_nm = 360, spectral_max_nm = 830;
    int spectral_bins = 30;
    /// First particle index (a simulation may be split into ranges of particles, e.g. across
    /// processes; the union of ranges equals one run of all particles, bit for bit). Not a
    /// setting: distributed/split_simulation.h sets it.
    std::uint64_t first_particle = 0;
    /// The incident light's Stokes vector (polarized runs), in the frame of docs/physics.md §8
    /// (x ⊥ the plane of incidence): 0 unpolarized (1, 0, 0, 0), 1 s-polarized (1, 1, 0, 0),
    /// 2 linear at +45° (1, 0, 1, 0), 3 circular (1, 0, 0, 1), and 4–6 their opposites
    /// (p-polarized (1, −1, 0, 0), linear at −45°, circular the other way). Each state has its own
    /// random-number streams, so runs with different states are independent. Not a setting: the
    /// Mueller tables (simulator/mueller.h) set it for each of their runs.
    int incident_polarization = 0;
    /// Tally the Stokes vectors of the exits per bin (IncidenceSums::stokes; polarized runs),
    /// from which the Mueller tables follow (simulator/mueller.h). Not a setting, as above.
    bool stokes_tallies = false;

    template <typename Self, typename Visit>
    static void fields(Self& s, Visit&& visit) {
        using Key = SettingInfo::Key;
        visit({.name = "theta_i",
               .help = "Incidences in degrees, comma-separated, in [0, 90)",
               .key = Key::Fixed},
              s.theta_i_deg);
        visit({.name = "phi_i",
               .help = "Incidence azimuth in degrees, in [0, 360] (light from (sin θi cos φi, sin "
                       "θi sin φi, cos θi)); a non-zero φi unfolds the grid over φ∈[0°,360°)",
               .min = 0,
               .max = 360,
               .key_unsaid = "0"},
              s.phi_i_deg);
        // At most 10^15 (exact in a double; years of any machine's time), however written.
        visit({.name = "particles",
               .help = "Particles per incidence (1e7-style accepted)",
               .min = 1,
               .max = 1e15,
               .key = Key::Fixed},
              s.particles);
        visit({.name = "seed", .help = "Random seed", .min = 0, .key = Key::Fixed}, s.seed);
        visit({.name = "threads",
               .help = "Threads (0 = all cores), at most 1024",
               .min = 0,
               .max = kMaxThreads,
               .key = Key::No},
              s.threads);
        visit({.name = "grid",
               .help = "Bins NTHETAxNPHI over θ∈[0°,90°], φ∈[0°,180°] (folded)",
               .key = Key::Fixed},
              s.grid);
        visit({.name = "kernel",
               .help = "Particle kernel: simd (vectorized, runtime dispatch), scalar (reference "
                       "path) or auto (simd, scalar for films on dielectrics); tables are "
                       "reproducible per kernel",
               .key = Key::Fixed},
              s.kernel);
        TransportSettings::fields(s.transport, visit);
        visit({.name = "spectral",
               .help = "Spectral transport: on (wavelengths, tabulated in wavelength bins), off "
                       "(three RGB channels) or auto (on for a stack with a spectral value)",
               .key_unsaid = "auto"},
              s.spectral);
        visit({.name = "spectral_min_nm",
               .help = "Shortest vacuum wavelength traced in spectral runs, nm",
               .min = 360,
               .max = 830,
               .key_unsaid = "360"},
              s.spectral_min_nm);
        visit({.name = "spectral_max_nm",
               .help = "Longest vacuum wavelength traced in spectral runs, nm",
               .min = 360,
               .max = 830,
               .key_unsaid = "830"},
              s.spectral_max_nm);
        visit({.name = "spectral_bins",
               .help = "Wavelength bins of a spectral run's tables, a multiple of 3",
               .min = 3,
               .max = 300,
               .key_unsaid = "30"},
              s.spectral_bins);
    }
};

/// Sample wavelengths per wavelength bin of a spectral run: each particle's hero wavelength is
/// drawn uniformly from the lattice of spectral_bins · kSpectralLattice points, the middles of
/// equal cells over the range (docs/physics.md §10).
inline constexpr int kSpectralLattice = 16;

/// Sums per (side · n_bins + bin) of the Stokes tallies: per channel c, at c · 12 + h · 4 + k the
/// sum of S_k over the exits into the bin's half h (0: y ≥ 0, 1: y < 0, each in its own bin
/// frame, docs/physics.md §8), at c · 12 + 8 + k the sum of S_k² over both halves.
inline constexpr int kStokesSums = 36;

/// Where the flux of an incidence went, per channel; the terms sum to 1 to rounding.
enum class BudgetTerm {
    Reflected,
    Transmitted,
    AbsorbedMedium,
    AbsorbedBase,
    LostMicrosurface,
    CutOff
};
inline constexpr int kBudgetTerms = 6;
inline constexpr std::array<const char*, kBudgetTerms> kBudgetTermNames = {
    "reflected", "transmitted", "absorbed_medium", "absorbed_base", "lost_microsurface", "cut_off"};

struct EnergyBudget {
    std::array<Rgbd, kBudgetTerms> term{};
    Rgbd reflected_se{0.0}, transmitted_se{0.0};  ///< standard errors of R and T

    const Rgbd& operator[](BudgetTerm t) const { return term[int(t)]; }
    Rgbd sum() const;
};

struct IncidenceStats {
    EnergyBudget budget;
    double events_per_particle = 0;        ///< interface + scattering events, averaged
    std::uint64_t degenerate_samples = 0;  ///< numerical degeneracies (counted, flux dropped)
    double seconds = 0;
};

/// 128-bit fixed-point sums (simulator/tally.h for the scales).
using Fixed128 = __int128;

/// The integer sums of one incidence, from which every estimate follows (finalize_simulation).
/// Integer addition is associative: the sums of disjoint particle ranges add up to those of their
/// union bit for bit, whoever computed them (threads, processes).
struct IncidenceSums {
    /// Per (side · n_bins + bin): Σ flux per channel (0–2, scale 2^40), Σ flux² (3–5, scale 2^38).
    std::vector<std::array<Fixed128, 6>> bins;
    /// Budget terms [t][channel], then Σ R² and Σ T² per particle (rows kBudgetTerms and
    /// kBudgetTerms + 1), scale 2^56.
    std::array<std::array<Fixed128, 3>, kBudgetTerms + 2> budget{};
    std::uint64_t events = 0, degenerate = 0;
    /// The Stokes tallies (kStokesSums per entry, as bins; empty unless
    /// SimulationSettings::stokes_tallies), S_k at scale 2^40 and S_k² at 2^38.
    std::vector<std::array<Fixed128, kStokesSums>> stokes;
    /// Spectral runs (docs/physics.md §10; empty otherwise). `bins` and `budget` above then hold
    /// the linear sRGB projection (bins divided by kSpectralTallyScale), and:
    /// spectral_bins per ((side · n_bins + bin) · spectral_bins / 3 + g): Σ flux (0–2) and Σ flux²
    /// (3–5) of the wavelength bins c · spectral_bins / 3 + g, c = 0, 1, 2 (divided by 4);
    /// xyz_bins as bins, the CIE XYZ projection (divided by kSpectralTallyScale);
    /// spectral_budget[g] as budget, for the wavelength bins c · spectral_bins / 3 + g;
    /// xyz_budget as budget, for X, Y, Z.
    std::vector<std::array<Fixed128, 6>> spectral_bins, xyz_bins;
    std::vector<std::array<std::array<Fixed128, 3>, kBudgetTerms + 2>> spectral_budget;
    std::array<std::array<Fixed128, 3>, kBudgetTerms + 2> xyz_budget{};

    void add(const IncidenceSums& o);
};

struct SimulationSums {
    std::vector<IncidenceSums> incidences;  ///< one per settings.theta_i_deg
    std::vector<double> incidence_seconds;  ///< wall time of each incidence
    double seconds = 0;
    int threads_used = 1;
};

/// A spectral run's tables (docs/formats.md, "Spectral tables").
struct SpectralTables {
    std::vector<double> bin_edges_nm;  ///< spectral_bins + 1 edges over the traced range
    std::size_t n_directions = 0;      ///< the direction bins of the grid (simulation_grid)
    int sides = 1;                     ///< 1 (reflection) or 2 (and transmission)
    /// The cos-weighted bin averages of the BSDF and their standard errors, per
    /// [incidence][side][direction bin][wavelength bin] (row-major, flattened).
    std::vector<double> f, se;
    /// The energy budget per [incidence][wavelength bin]: the terms, then the standard errors of
    /// R and T (indices kBudgetTerms and kBudgetTerms + 1).
    std::vector<std::array<double, kBudgetTerms + 2>> budget;
    /// The CIE 1931 XYZ projection under D65 (channels X, Y, Z; Y = 1 for a white reflector), its
    /// energy budget per incidence as in IncidenceStats. The linear sRGB projection is the
    /// result's `table` and `incidences[].budget`.
    BinnedTable xyz;
    std::vector<EnergyBudget> xyz_budget;

    std::size_t index(std::size_t incidence, int side, std::size_t direction,
                      std::size_t lambda) const {
        const std::size_t n_lambda = bin_edges_nm.size() - 1;
        return ((incidence * std::size_t(sides) + std::size_t(side)) * n_directions + direction) *
                   n_lambda +
               lambda;
    }
};

/// Spectral tallies hold their colour projections divided by this (their bound, tally.h).
inline constexpr double kSpectralTallyScale = 16;

struct SimulationResult {
    SimulationSettings settings;
    /// A spectral run's tables (empty bin_edges_nm otherwise); `table` is then their linear sRGB
    /// projection under D65.
    SpectralTables spectral;
    /// The raw sums (kept when settings.stokes_tallies: the Mueller tables are built from them).
    std::vector<IncidenceSums> sums;
    BinnedTable table;  ///< reflection, and transmission when the stack transmits
    std::vector<IncidenceStats> incidences;
    double seconds = 0;
    int threads_used = 1;  ///< per process
    int processes = 1;     ///< processes that shared the particles (distributed/split_simulation.h)
};

/// The grid the goniophotometer tabulates a stack on: settings.grid, unfolded over φ ∈ [0°, 360°)
/// when the stack is anisotropic or the light comes from φi ≠ 0 (no mirror symmetry about the
/// plane φ = 0 then; core/grid.h). The result's table is on this grid.
HemisphereGrid simulation_grid(const Stack& stack, const SimulationSettings& settings);

/// The zero sums of a run: one IncidenceSums per incidence, its bins (and Stokes tallies when
/// settings.stokes_tallies) sized for simulation_grid(stack, settings). What a run's chunks,
/// threads and processes add their sums to (a process with no particles contributes these).
SimulationSums zero_sums(const Stack& stack, const SimulationSettings& settings);

/// Checks what the settings' codecs cannot see alone (InputError naming `where` and the setting).
void validate_settings(const SimulationSettings& settings, const std::string& where = "settings");

/// Checks that the settings' kernel traces everything the stack holds: a thin film on a dielectric
/// interface needs the scalar kernel, or auto (InputError naming --kernel for simd;
/// docs/physics.md §9); a film with an anisotropic interface is refused; a spectral run needs
/// spectral_bins a multiple of 3 and a range of at least one nm per bin. A refusal about the stack
/// names `where` (its file; the stack's name when empty) and the JSON pointer of the field.
void validate_kernel_for(const Stack& stack, const SimulationSettings& settings,
                         const std::string& where = {});

/// Traces particles [first_particle, first_particle + particles) of every incidence and returns
/// the raw sums. A run split into ranges that start at multiples of kParticlesPerBlock adds up
/// (IncidenceSums::add) to the sums of one run, bit for bit.
SimulationSums simulate_sums(const Stack& stack, const SimulationSettings& settings,
                             const std::function<void(std::uint64_t)>& on_progress = {});

/// The estimates (docs/physics.md §5) from the sums of all `settings.particles` particles.
SimulationResult finalize_simulation(const Stack& stack, const SimulationSettings& settings,
                                     const SimulationSums& sums);

/// Runs the goniophotometer: simulate_sums then finalize_simulation. `on_progress(particles_done)`
/// is called from worker threads (may be empty). Settings must be valid (validate_settings).
SimulationResult simulate(const Stack& stack, const SimulationSettings& settings,
                          const std::function<void(std::uint64_t)>& on_progress = {});

}  // namespace lamina

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
#include "simulator/kernel_spectral.h"
#include "simulator/scalar_particle.h"
#include "simulator/tally.h"

#include <fmt/format.h>
#include <omp.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

Rgbd EnergyBudget::sum() const {
    Rgbd s(0.0);
    for (const Rgbd& t : term)
        s += t;
    return s;
}

namespace {

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

bool is_spectral_run(const Stack& stack, const SimulationSettings& settings) {
    return settings.spectral == SpectralMode::On ||
           (settings.spectral == SpectralMode::Auto && stack.is_spectral());
}

namespace {
/// The first dielectric interface carrying a thin film (the SIMD kernel traces films on
/// conductors only), or the number of layers.
std::size_t first_dielectric_film(const Stack& stack) {
    std::size_t i = 0;
    while (i < stack.layers.size() &&
           !(stack.layers[i].interface.has_film &&
             stack.layers[i].interface.type == InterfaceType::Dielectric))
        ++i;
    return i;
}
}  // namespace

bool needs_scalar_kernel(const Stack& stack, const SimulationSettings&) {
    return first_dielectric_film(stack) < stack.layers.size();
}

Kernel kernel_for(const SimulationSettings& settings, const Stack& stack) {
    if (settings.kernel != Kernel::Auto) return settings.kernel;
    return needs_scalar_kernel(stack, settings) ? Kernel::Scalar : Kernel::Simd;
}

namespace {
// The hand-off of traced_kernel, given the run's spectral tracing (simulate_sums has it).
Kernel traced_kernel(Kernel kernel, bool spectral, const SpectralTracing& tracing) {
    return kernel == Kernel::Simd && spectral && !tracing.lanes_uniform ? Kernel::Scalar : kernel;
}
}  // namespace

Kernel traced_kernel(const SimulationSettings& settings, const Stack& stack) {
    const Kernel kernel = kernel_for(settings, stack);
    if (kernel != Kernel::Simd || !is_spectral_run(stack, settings)) return kernel;
    return traced_kernel(kernel, true, spectral_tracing(stack, settings));
}

void IncidenceSums::add(const IncidenceSums& o) {
    // Element-wise integer sums of equally sized tallies (bins, Stokes, budgets).
    const auto add_all = [](auto& into, const auto& from) {
        LAMINA_CHECK(into.size() == from.size());
        for (std::size_t i = 0; i < into.size(); ++i)
            for (std::size_t k = 0; k < into[i].size(); ++k)
                into[i][k] += from[i][k];
    };
    add_all(bins, o.bins);
    add_all(budget, o.budget);
    add_all(stokes, o.stokes);
    events += o.events;
    degenerate += o.degenerate;
    add_all(spectral_bins, o.spectral_bins);
    add_all(xyz_bins, o.xyz_bins);
    LAMINA_CHECK(spectral_budget.size() == o.spectral_budget.size());
    for (std::size_t g = 0; g < spectral_budget.size(); ++g)
        add_all(spectral_budget[g], o.spectral_budget[g]);
    add_all(xyz_budget, o.xyz_budget);
}

void validate_kernel_for(const Stack& stack, const SimulationSettings& settings,
                         const std::string& where) {
    check_no_film_with_anisotropy(stack, where);
    if (is_spectral_run(stack, settings)) {
        if (settings.spectral_bins % 3 != 0)
            throw InputError("settings", "spectral_bins",
                             fmt::format("got {}; allowed: a multiple of 3 in [3, 300] (each "
                                         "particle carries three wavelengths a third of the "
                                         "range apart)",
                                         settings.spectral_bins));
        if (!(settings.spectral_max_nm > settings.spectral_min_nm))
            throw InputError("settings", "spectral_max_nm",
                             fmt::format("{} nm is not above the shortest wavelength ({} nm)",
                                         settings.spectral_max_nm, settings.spectral_min_nm));
        if (settings.spectral_max_nm - settings.spectral_min_nm < settings.spectral_bins)
            throw InputError("settings", "spectral_max_nm",
                             fmt::format("the range [{}, {}] nm is narrower than one nm per "
                                         "wavelength bin ({} bins); widen it or use fewer bins",
                                         settings.spectral_min_nm, settings.spectral_max_nm,
                                         settings.spectral_bins));
        if (settings.stokes_tallies)
            throw InputError("settings", "spectral",
                             "Mueller tables are tabulated per RGB channel; give --spectral off");
    }
    if (settings.kernel != Kernel::Simd) return;
    if (const std::size_t film = first_dielectric_film(stack); film < stack.layers.size())
        throw InputError("command line", "--kernel",
                         fmt::format("the stack '{}' has a thin film on a dielectric interface "
                                     "(/layers/{}/interface/film), which the SIMD kernel does not "
                                     "trace (it traces films on conductors); give --kernel scalar "
                                     "(or auto)",
                                     stack.name, film));
}

/// The memory a run may still take, in bytes: the least of the physical memory, the kernel's
/// estimate of what it can give without swapping (MemAvailable, /proc/meminfo: free memory and the
/// reclaimable caches) and the limit of this process's control group (cgroup v2 memory.max less
/// memory.current), those that can be read; 0 when none can. Tallies are zeroed when they are
/// made, so a run past it would be killed by the system (Linux grants the allocation first).
double memory_available_bytes() {
    double have = 0;
    auto take = [&have](double bytes) {
        if (bytes > 0 && (have == 0 || bytes < have)) have = bytes;
    };
    const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGE_SIZE);
    if (pages > 0 && page_size > 0) take(double(pages) * double(page_size));
    if (std::ifstream meminfo("/proc/meminfo"); meminfo) {
        std::string key, unit;
        double kib = 0;
        while (meminfo >> key >> kib) {
            std::getline(meminfo, unit);
            if (key == "MemAvailable:") {
                take(kib * 1024.0);
                break;
            }
        }
    }
    // A number, or "max" (no limit), which the extraction fails on.
    auto read_number = [](const char* path) {
        double value = 0;
        std::ifstream in(path);
        return in >> value ? value : 0.0;
    };
    if (const double limit = read_number("/sys/fs/cgroup/memory.max"); limit > 0)
        take(limit - read_number("/sys/fs/cgroup/memory.current"));
    return have;
}

/// Refuses a run whose tallies would not fit in this machine's memory (a bad_alloc inside the
/// threads' region would abort the process): each thread's Tally (Tally::Recent and its widened
/// sums per bin and side, Stokes and spectral tallies where asked), and the result's widened sums
/// per incidence. The 3600 × 3600 grid unfolded needs about 7.5 GB per thread.
void check_tally_memory(const HemisphereGrid& grid, const SimulationSettings& settings, int threads,
                        int spectral_groups) {
    const double sides_bins = 2.0 * double(grid.size());
    const double sums = sizeof(std::array<Fixed128, 6>);
    const double stokes = settings.stokes_tallies
                              ? sizeof(std::array<Fixed128, kStokesSums>) +
                                    sizeof(std::array<std::int64_t, kStokesSums>)
                              : 0.0;
    // A spectral run's threads keep a Tally per wavelength group and one for XYZ besides.
    const double tallies_per_thread = 1.0 + (spectral_groups > 0 ? spectral_groups + 1 : 0);
    const double per_thread =
        sides_bins * (tallies_per_thread * (sizeof(Tally::Recent) + sums) + stokes);
    const double per_incidence = sides_bins * (tallies_per_thread * sums + stokes);
    const double need =
        double(threads) * per_thread + double(settings.theta_i_deg.size()) * per_incidence;
    const double have = memory_available_bytes();
    if (!(have > 0)) return;
    if (need > have)
        throw InputError(
            "settings", "grid",
            fmt::format("{}: its tallies need about {:.1f} GB ({} threads, {} incidences{}), "
                        "this machine has {:.1f} GB available; allowed: a grid whose tallies fit "
                        "(a coarser grid, fewer threads or fewer incidences per run)",
                        grid.to_string(), need / 1e9, threads, settings.theta_i_deg.size(),
                        spectral_groups > 0 ? fmt::format(", {} wavelength groups", spectral_groups)
                                            : std::string(),
                        have / 1e9));
}

int cap_openmp_threads() {
    const int asked = omp_get_max_threads();
    if (asked <= kMaxThreads) return 0;
    omp_set_num_threads(kMaxThreads);
    return asked;
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
    const bool spectral = is_spectral_run(stack, settings);
    const SpectralTracing tracing =
        spectral ? spectral_tracing(stack, settings) : SpectralTracing{};
    const bool simd = traced_kernel(kernel, spectral, tracing) == Kernel::Simd;
    const auto trace_block = simd       ? trace_block_simd
                             : spectral ? trace_block_spectral
                                        : trace_block_scalar;
    const int groups = settings.spectral_bins / 3;
    check_tally_memory(grid, settings, threads, spectral ? groups : 0);

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
        if (spectral) job.spectral = &tracing;
        IncidenceSums& total = result.incidences[inc];

        // The threads' tallies, allocated here: a bad_alloc inside the threads' region would
        // abort the process instead of reaching the caller.
        std::vector<Tally> tallies;
        std::vector<std::optional<SpectralTally>> spectral_tallies(
            static_cast<std::size_t>(threads));
        tallies.reserve(std::size_t(threads));
        for (int t = 0; t < threads; ++t) {
            tallies.emplace_back(grid.size(), settings.stokes_tallies);
            if (spectral) spectral_tallies[std::size_t(t)].emplace(grid.size(), groups);
        }

#pragma omp parallel num_threads(threads) firstprivate(job)
        {
            Tally& local = tallies[std::size_t(omp_get_thread_num())];
            std::optional<SpectralTally>& local_spectral =
                spectral_tallies[std::size_t(omp_get_thread_num())];
            if (spectral) job.spectral_tally = &*local_spectral;
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
    if (is_spectral_run(stack, settings))
        finalize_spectral(settings, sums, grid, transmits, result);
    return result;
}

HemisphereGrid simulation_grid(const Stack& stack, const SimulationSettings& settings) {
    return stack.is_anisotropic() || settings.phi_i_deg != 0 ? settings.grid.unfolded()
                                                             : settings.grid;
}

SimulationSums zero_sums(const Stack& stack, const SimulationSettings& settings) {
    const std::size_t n_bins = simulation_grid(stack, settings).size();
    const bool spectral = is_spectral_run(stack, settings);
    const std::size_t groups = std::size_t(settings.spectral_bins / 3);
    SimulationSums sums;
    sums.incidences.resize(settings.theta_i_deg.size());
    for (IncidenceSums& s : sums.incidences) {
        s.bins.resize(2 * n_bins);
        if (settings.stokes_tallies) s.stokes.resize(2 * n_bins);
        if (spectral) {
            s.spectral_bins.resize(2 * n_bins * groups);
            s.xyz_bins.resize(2 * n_bins);
            s.spectral_budget.resize(groups);
        }
    }
    sums.incidence_seconds.assign(settings.theta_i_deg.size(), 0.0);
    return sums;
}

SimulationResult simulate(const Stack& stack, const SimulationSettings& settings,
                          const std::function<void(std::uint64_t)>& on_progress) {
    return finalize_simulation(stack, settings, simulate_sums(stack, settings, on_progress));
}

}  // namespace lamina

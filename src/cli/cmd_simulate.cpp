// lamina simulate STACK.json [--theta-i 0,30,60] [--particles 1e7] [any setting of
//                 SimulationSettings: --seed, --grid, --kernel, --microsurface, …] --out DIR
// Under `mpirun -n K` the particles are split over K processes (docs/scaling.md).
#include "cli/commands.h"
#include "cli/options.h"
#include "cli/settings_options.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/incidences.h"
#include "core/progress.h"
#include "distributed/communicator.h"
#include "distributed/split_simulation.h"
#include "layers/stack.h"
#include "simulator/goniophotometer.h"
#include "simulator/mueller.h"
#include "simulator/output.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <utility>

namespace lamina::cli {

namespace {
struct SimulateArgs {
    std::string stack, out;
    SimulationSettings settings;
    bool mueller = false;
};
}  // namespace

Runner add_simulate(CLI::App& app) {
    auto a = std::make_shared<SimulateArgs>();
    auto* cmd = app.add_subcommand(
        "simulate", "Trace particles through a stack: the reference BRDF/BTDF (goniophotometer)");
    cmd->add_option("STACK", a->stack, "Stack JSON file")->required();
    add_physics_option(cmd, a->settings.transport);
    add_settings_options(cmd, a->settings);
    cmd->add_flag(
        "--mueller", a->mueller,
        "Also write the 4x4 Mueller BRDF/BTDF per bin with standard errors "
        "(mueller.npy, mueller_se.npy; needs --polarization on and an RGB run, --spectral "
        "off; four runs: unpolarized, "
        "s-polarized, +45° and circular incident light)");
    cmd->add_option("--out,-o", a->out, "Output folder")->required();
    return [a] {
        // Under mpirun every process runs this; the particles are split over them
        // (distributed/split_simulation.h) and only the root reads the stack and writes.
        Communicator& world = Communicator::world();
        SimulationSettings s = a->settings;
        if (world.distributed() && s.threads == 0) s.threads = default_threads_per_process(world);
        // The root reads the stack and sends its canonical JSON to the others (no shared file
        // system is assumed); stack_from_json(stack_to_json(s)) == s.
        Stack stack;
        std::string stack_text;
        std::unique_ptr<StagedOutput> probe;
        if (a->mueller) {  // before DIR is made, as every check of the run's inputs
            if (!s.transport.polarization)
                throw InputError("command line", "--mueller", "needs --polarization on");
            s.stokes_tallies = true;
        }
        if (world.is_root()) {
            stack = load_stack(a->stack);
            validate_kernel_for(stack, s, a->stack);  // before DIR is made
            stack_text = stack_to_json(stack).dump();
            // Fails now, not after the run, if DIR is not writable.
            probe = std::make_unique<StagedOutput>(a->out);
        }
        world.broadcast(stack_text);
        if (!world.is_root()) stack = stack_from_json(nlohmann::json::parse(stack_text), a->stack);
        // Bitwise identity with a one-process run needs one kernel variant on every process: the
        // SIMD kernel's results depend on the instruction set it dispatches to.
        const std::vector<std::string> kernels =
            world.gather(kernel_description(traced_kernel(s, stack)));
        if (world.is_root())
            for (std::size_t r = 1; r < kernels.size(); ++r)
                if (kernels[r] != kernels[0])
                    throw InputError(
                        "command line", "--kernel",
                        fmt::format("process {} runs the kernel '{}' and process 0 '{}': give "
                                    "every process the same instruction set (LAMINA_SIMD_TARGET, "
                                    "docs/scaling.md)",
                                    r, kernels[r], kernels[0]));
        // Progress of this process's share, drawn by the root only.
        std::unique_ptr<Progress> progress;
        std::function<void(std::uint64_t)> on_progress;
        if (world.is_root()) {
            const ParticleRange mine = particle_range(s.particles, world.rank(), world.size());
            progress = std::make_unique<Progress>(fmt::format("simulate {}", stack.name),
                                                  "particles", mine.count * s.theta_i_deg.size());
            on_progress = [&](std::uint64_t n) { progress->advance(n); };
        }
        // --mueller: four runs (unpolarized, s-polarized, +45°, circular incident light;
        // simulator/mueller.h), the first of which gives the tables.
        std::array<std::optional<SimulationResult>, 4> runs;
        for (int j = 0; j < (a->mueller ? 4 : 1); ++j) {
            SimulationSettings run = s;
            run.incident_polarization = j;
            if (j > 0 && progress) progress->finish();
            if (j > 0 && world.is_root())
                progress = std::make_unique<Progress>(
                    fmt::format("simulate {} (Mueller run {} of 4)", stack.name, j + 1),
                    "particles",
                    particle_range(s.particles, world.rank(), world.size()).count *
                        s.theta_i_deg.size());
            runs[std::size_t(j)] = simulate_split(world, stack, run, on_progress);
        }
        if (!runs[0]) return 0;  // not the root: its sums went to the root
        const SimulationResult& result = *runs[0];
        progress->finish();
        std::vector<std::pair<std::string, std::string>> extra;
        if (a->mueller) {
            const MuellerTable mueller =
                mueller_table({&*runs[0], &*runs[1], &*runs[2], &*runs[3]});
            extra = {{"mueller.npy", mueller_npy(mueller, false)},
                     {"mueller_se.npy", mueller_npy(mueller, true)}};
        }
        write_simulation(a->out, stack, result, extra);
        for (std::size_t i = 0; i < result.incidences.size(); ++i) {
            const EnergyBudget& b = result.incidences[i].budget;
            fmt::print("θi = {:>4}°  R = {}  T = {}  lost = {}  absorbed = {}\n", s.theta_i_deg[i],
                       format_rgb(b[BudgetTerm::Reflected]), format_rgb(b[BudgetTerm::Transmitted]),
                       format_rgb(b[BudgetTerm::LostMicrosurface]),
                       format_rgb(b[BudgetTerm::AbsorbedMedium] + b[BudgetTerm::AbsorbedBase]));
            // A thick scattering layer's cost is bounded by --max-events; what it stops is told.
            if (b[BudgetTerm::CutOff].max() > 0)
                fmt::print(
                    "          cut off after --max-events {}: {} ({:.4g} events per "
                    "particle)\n",
                    s.transport.max_events, format_rgb(b[BudgetTerm::CutOff]),
                    result.incidences[i].events_per_particle);
        }
        const std::string threads =
            fmt::format("{} thread{}", result.threads_used, result.threads_used == 1 ? "" : "s");
        const std::string workers =
            result.processes > 1 ? fmt::format("{} processes × {}", result.processes, threads)
                                 : threads;
        const bool spectral = !result.spectral.bin_edges_nm.empty();
        if (spectral)
            fmt::print(
                "spectral: {} wavelength bins over {}-{} nm; R, T above are linear sRGB "
                "(D65)\n",
                s.spectral_bins, s.spectral_min_nm, s.spectral_max_nm);
        fmt::print(
            "{:.3g} particles/s on {}; wrote {}/{{result.json,brdf.csv,energy.csv{}{}}}\n",
            double(s.particles * s.theta_i_deg.size()) / result.seconds, workers, a->out,
            a->mueller ? ",mueller.npy,mueller_se.npy" : "",
            spectral ? ",spectral.npy,spectral_se.npy,xyz.npy,xyz_se.npy,spectral_energy.csv" : "");
        return 0;
    };
}

}  // namespace lamina::cli

// lamina simulate STACK.json --theta-i 0,30,60 --particles 1e7 [--seed S] [--threads T]
//                 [--grid 90x90] --out DIR
#include "cli/commands.h"
#include "cli/options.h"
#include "core/atomic_file.h"
#include "core/progress.h"
#include "layers/stack.h"
#include "simulator/goniophotometer.h"
#include "simulator/output.h"

#include <fmt/format.h>

#include <memory>

namespace lamina::cli {

namespace {
struct SimulateArgs {
    std::string stack, theta_i = "0,15,30,45,60,70,80", particles = "1e6", grid = "90x90", out;
    std::uint64_t seed = 1;
    int threads = 0, max_events = 10000;
};
}  // namespace

Runner add_simulate(CLI::App& app) {
    auto a = std::make_shared<SimulateArgs>();
    auto* cmd = app.add_subcommand(
        "simulate", "Trace particles through a stack: the reference BRDF/BTDF (goniophotometer)");
    cmd->add_option("STACK", a->stack, "Stack JSON file")->required();
    cmd->add_option("--theta-i", a->theta_i, "Incidences in degrees, comma-separated, in [0, 90)")
        ->capture_default_str();
    cmd->add_option("--particles,-n", a->particles, "Particles per incidence (1e7-style accepted)")
        ->capture_default_str();
    cmd->add_option("--seed", a->seed, "Random seed")->capture_default_str();
    cmd->add_option("--threads", a->threads, "Threads (0 = all cores)")->capture_default_str();
    cmd->add_option("--grid", a->grid, "Bins NTHETAxNPHI over θ∈[0°,90°], φ∈[0°,180°] (folded)")
        ->capture_default_str();
    cmd->add_option("--max-events", a->max_events, "Safety cap on events per particle")
        ->capture_default_str();
    cmd->add_option("--out,-o", a->out, "Output folder")->required();
    return [a] {
        const Stack stack = load_stack(a->stack);
        SimulationSettings s;
        s.theta_i_deg = parse_incidences(a->theta_i, "--theta-i");
        s.particles = parse_count(a->particles, "--particles");
        s.seed = a->seed;
        s.threads = a->threads;
        s.grid = HemisphereGrid::parse(a->grid);
        s.max_events = a->max_events;
        validate_settings(s);
        StagedOutput probe(a->out);  // fails now, not after the run, if DIR is not writable
        Progress progress(fmt::format("simulate {}", stack.name), "particles",
                          s.particles * s.theta_i_deg.size());
        const SimulationResult result =
            simulate(stack, s, [&](std::uint64_t n) { progress.advance(n); });
        progress.finish();
        write_simulation(a->out, stack, result);
        for (std::size_t i = 0; i < result.incidences.size(); ++i) {
            const EnergyBudget& b = result.incidences[i].budget;
            fmt::print("θi = {:>4}°  R = {}  T = {}  lost = {}  absorbed = {}\n", s.theta_i_deg[i],
                       format_rgb(b[BudgetTerm::Reflected]), format_rgb(b[BudgetTerm::Transmitted]),
                       format_rgb(b[BudgetTerm::LostMicrosurface]),
                       format_rgb(b[BudgetTerm::AbsorbedMedium] + b[BudgetTerm::AbsorbedBase]));
        }
        fmt::print(
            "{:.3g} particles/s on {} threads; wrote {}/{{result.json,brdf.csv,energy.csv}}\n",
            double(s.particles * s.theta_i_deg.size()) / result.seconds, result.threads_used,
            a->out);
        return 0;
    };
}

}  // namespace lamina::cli

#include "simulator/output.h"

#include "core/atomic_file.h"
#include "lamina/version.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace lamina {

namespace {
constexpr const char* kChannels[3] = {"r", "g", "b"};

nlohmann::json rgb_json(const Rgbd& v) {
    return nlohmann::json::array({v[0], v[1], v[2]});
}
}  // namespace

std::string energy_csv(const SimulationResult& result) {
    std::string out = std::string(kEnergyCsvHeader) + "\n";
    for (std::size_t i = 0; i < result.incidences.size(); ++i) {
        const EnergyBudget& b = result.incidences[i].budget;
        for (int c = 0; c < 3; ++c) {
            fmt::format_to(std::back_inserter(out), "{},{}", result.settings.theta_i_deg[i],
                           kChannels[c]);
            for (int t = 0; t < kBudgetTerms; ++t)
                fmt::format_to(std::back_inserter(out), ",{}", b.term[t][c]);
            out += "\n";
        }
    }
    return out;
}

nlohmann::json result_json(const Stack& stack, const SimulationResult& result) {
    const SimulationSettings& s = result.settings;
    nlohmann::json j;
    j["lamina_version"] = kVersion;
    j["kind"] = "goniophotometer";
    j["stack"] = stack_to_json(stack);
    // Every setting as it was given (core/setting.h), then what ran: the kernel's instruction set,
    // the bins' ranges, the threads and processes used.
    j.update(settings_to_json(s));
    j["physics"] = physics_name(s.transport);  // exact, bpb19 or custom
    j["kernel_description"] = kernel_description(kernel_for(s, stack));
    // The grid of the tables (simulation_grid): "n_phi" stays the setting's (folded) count; an
    // unfolded table has twice as many φ bins, over [0°, 360°).
    const bool unfolded = result.table.grid.is_unfolded();
    j["grid"].update({{"theta_range_deg", {0, 90}},
                      {"phi_range_deg", {0, unfolded ? 360 : 180}},
                      {"folded", !unfolded},
                      {"n_phi_bins", result.table.grid.n_phi()}});
    j["first_particle"] = s.first_particle;
    j["mueller"] = s.stokes_tallies;
    j["threads"] = result.threads_used;
    j["processes"] = result.processes;
    j["seconds"] = result.seconds;
    j["particles_per_second"] =
        result.seconds > 0 ? double(s.particles) * double(s.theta_i_deg.size()) / result.seconds
                           : 0.0;
    nlohmann::json incidences = nlohmann::json::array();
    for (std::size_t i = 0; i < result.incidences.size(); ++i) {
        const IncidenceStats& st = result.incidences[i];
        nlohmann::json budget;
        for (int t = 0; t < kBudgetTerms; ++t)
            budget[kBudgetTermNames[t]] = rgb_json(st.budget.term[t]);
        budget["reflected_se"] = rgb_json(st.budget.reflected_se);
        budget["transmitted_se"] = rgb_json(st.budget.transmitted_se);
        budget["sum"] = rgb_json(st.budget.sum());
        incidences.push_back({{"theta_i", s.theta_i_deg[i]},
                              {"energy", budget},
                              {"events_per_particle", st.events_per_particle},
                              {"degenerate_samples", st.degenerate_samples},
                              {"seconds", st.seconds}});
    }
    j["incidences"] = incidences;
    return j;
}

void write_simulation(const std::filesystem::path& dir, const Stack& stack,
                      const SimulationResult& result,
                      const std::vector<std::pair<std::string, std::string>>& extra) {
    StagedOutput out(dir);
    out.add("brdf.csv", result.table.to_csv());
    out.add("energy.csv", energy_csv(result));
    for (const auto& [name, bytes] : extra)
        out.add(name, bytes);
    out.add("result.json", result_json(stack, result).dump(2) + "\n");
    out.commit();
}

}  // namespace lamina

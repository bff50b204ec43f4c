#include "simulator/output.h"

#include "core/atomic_file.h"
#include "core/npy.h"
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
    j["kernel_description"] = kernel_description(traced_kernel(s, stack));
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
    if (!result.spectral.bin_edges_nm.empty()) {
        // A spectral run (docs/physics.md §10): brdf.csv and energy.csv hold its linear sRGB
        // projection under D65; the wavelength bins and the XYZ budget are here.
        nlohmann::json xyz = nlohmann::json::array();
        for (const EnergyBudget& b : result.spectral.xyz_budget) {
            nlohmann::json budget;
            for (int t = 0; t < kBudgetTerms; ++t)
                budget[kBudgetTermNames[t]] = rgb_json(b.term[t]);
            budget["reflected_se"] = rgb_json(b.reflected_se);
            budget["transmitted_se"] = rgb_json(b.transmitted_se);
            xyz.push_back(budget);
        }
        j["spectral_tables"] = {{"bin_edges_nm", result.spectral.bin_edges_nm},
                                {"colour", "linear sRGB (IEC 61966-2-1), illuminant D65"},
                                {"xyz_energy", xyz}};
    }
    return j;
}

std::string spectral_energy_csv(const SimulationResult& result) {
    const SpectralTables& sp = result.spectral;
    const std::size_t bins = sp.bin_edges_nm.size() - 1;
    std::string out = std::string(kSpectralEnergyCsvHeader) + "\n";
    for (std::size_t i = 0; i < result.settings.theta_i_deg.size(); ++i)
        for (std::size_t l = 0; l < bins; ++l) {
            fmt::format_to(std::back_inserter(out), "{},{},{}", result.settings.theta_i_deg[i],
                           sp.bin_edges_nm[l], sp.bin_edges_nm[l + 1]);
            for (double v : sp.budget[i * bins + l])
                fmt::format_to(std::back_inserter(out), ",{}", v);
            out += "\n";
        }
    return out;
}

std::string spectral_npy(const SimulationResult& result, bool standard_error) {
    const SpectralTables& sp = result.spectral;
    const std::size_t bins = sp.bin_edges_nm.size() - 1, n_inc = result.settings.theta_i_deg.size();
    const std::size_t n_theta = std::size_t(result.table.grid.n_theta());
    const std::vector<double>& src = standard_error ? sp.se : sp.f;
    // Both sides always (zeros for an opaque stack), as the other tables.
    std::vector<float> data(n_inc * 2 * sp.n_directions * bins, 0.f);
    for (std::size_t i = 0; i < n_inc; ++i)
        for (int side = 0; side < sp.sides; ++side)
            for (std::size_t j = 0; j < sp.n_directions; ++j)
                for (std::size_t l = 0; l < bins; ++l)
                    data[((i * 2 + std::size_t(side)) * sp.n_directions + j) * bins + l] =
                        float(src[sp.index(i, side, j, l)]);
    return npy_float32(data, {n_inc, 2, n_theta, sp.n_directions / n_theta, bins});
}

std::string xyz_npy(const SimulationResult& result, bool standard_error) {
    const BinnedTable& t = result.spectral.xyz;
    const std::size_t n_inc = result.settings.theta_i_deg.size(), n = t.grid.size();
    const std::size_t n_theta = std::size_t(t.grid.n_theta());
    std::vector<float> data(n_inc * 2 * n * 3, 0.f);
    for (std::size_t i = 0; i < n_inc; ++i)
        for (int side = 0; side < (t.has_transmission ? 2 : 1); ++side) {
            const BinnedLobe& lobe = t.lobe(i, side == 0 ? Side::Reflection : Side::Transmission);
            for (std::size_t j = 0; j < n; ++j)
                for (int c = 0; c < 3; ++c)
                    data[((i * 2 + std::size_t(side)) * n + j) * 3 + std::size_t(c)] =
                        float(standard_error ? lobe.se[j][c] : lobe.f[j][c]);
        }
    return npy_float32(data, {n_inc, 2, n_theta, n / n_theta, 3});
}

void write_simulation(const std::filesystem::path& dir, const Stack& stack,
                      const SimulationResult& result,
                      const std::vector<std::pair<std::string, std::string>>& extra,
                      const std::string& field) {
    StagedOutput out(dir, field);
    out.add("brdf.csv", result.table.to_csv());
    out.add("energy.csv", energy_csv(result));
    for (const auto& [name, bytes] : extra)
        out.add(name, bytes);
    if (!result.spectral.bin_edges_nm.empty()) {
        out.add("spectral.npy", spectral_npy(result, false));
        out.add("spectral_se.npy", spectral_npy(result, true));
        out.add("xyz.npy", xyz_npy(result, false));
        out.add("xyz_se.npy", xyz_npy(result, true));
        out.add("spectral_energy.csv", spectral_energy_csv(result));
    }
    out.add("result.json", result_json(stack, result).dump(2) + "\n");
    // The optional tables of another kind of run into the same folder go: what the folder holds
    // is this run.
    for (const char* name : {"spectral.npy", "spectral_se.npy", "xyz.npy", "xyz_se.npy",
                             "spectral_energy.csv", "mueller.npy", "mueller_se.npy"})
        out.remove_unless_staged(name);
    out.commit();
}

}  // namespace lamina

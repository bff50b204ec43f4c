#pragma once
// Writing a goniophotometer run (docs/formats.md): DIR/result.json (stack, grid, N, seed, lamina
// version, timing, energy budget), DIR/brdf.csv (core/table.h), DIR/energy.csv, and for a spectral
// run DIR/spectral.npy, spectral_se.npy, xyz.npy, xyz_se.npy and spectral_energy.csv. All files
// are staged and moved into place together: a failed run leaves nothing half-written.

#include "layers/stack.h"
#include "simulator/goniophotometer.h"

#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace lamina {

inline constexpr const char* kEnergyCsvHeader =
    "theta_i,channel,reflected,transmitted,absorbed_medium,absorbed_base,lost_microsurface,"
    "cut_off";

/// Spectral runs: the energy budget per incidence and wavelength bin, with the standard errors of
/// R and T.
inline constexpr const char* kSpectralEnergyCsvHeader =
    "theta_i,lambda_lo_nm,lambda_hi_nm,reflected,transmitted,absorbed_medium,absorbed_base,"
    "lost_microsurface,cut_off,reflected_se,transmitted_se";

std::string energy_csv(const SimulationResult& result);
std::string spectral_energy_csv(const SimulationResult& result);
/// Spectral runs: the tables per wavelength bin (float32 [incidence, side, θ bin, φ bin,
/// wavelength bin]) and their XYZ projection ([…, 3]), or their standard errors.
std::string spectral_npy(const SimulationResult& result, bool standard_error);
std::string xyz_npy(const SimulationResult& result, bool standard_error);
nlohmann::json result_json(const Stack& stack, const SimulationResult& result);

/// Writes the three files into `dir` (created if needed), with `extra` files (name, bytes) staged
/// and moved into place with them (the Mueller tables, simulator/mueller.h). An InputError about
/// the folder names `field`, what gave it (the CLI's --out, Python's dir).
void write_simulation(const std::filesystem::path& dir, const Stack& stack,
                      const SimulationResult& result,
                      const std::vector<std::pair<std::string, std::string>>& extra = {},
                      const std::string& field = "--out");

}  // namespace lamina

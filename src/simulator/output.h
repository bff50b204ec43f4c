#pragma once
// Writing a goniophotometer run (docs/formats.md): DIR/result.json (stack, grid, N, seed, lamina
// version, timing, energy budget), DIR/brdf.csv (core/table.h), DIR/energy.csv. All three files
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

std::string energy_csv(const SimulationResult& result);
nlohmann::json result_json(const Stack& stack, const SimulationResult& result);

/// Writes the three files into `dir` (created if needed), with `extra` files (name, bytes) staged
/// and moved into place with them (the Mueller tables, simulator/mueller.h).
void write_simulation(const std::filesystem::path& dir, const Stack& stack,
                      const SimulationResult& result,
                      const std::vector<std::pair<std::string, std::string>>& extra = {});

}  // namespace lamina

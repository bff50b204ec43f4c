#pragma once
// The spectral runs of the scalar kernel, in a unit of their own (scalar_particle.h says why), and
// the stacks and weights both kernels trace them with (docs/physics.md §10; tally.h says how they
// are tallied). Internal to the simulator.

#include "simulator/goniophotometer.h"
#include "simulator/tally.h"

namespace lamina {

/// The stacks compiled at every triple of lattice wavelengths and hero, and the colour weights.
SpectralTracing spectral_tracing(const Stack& stack, const SimulationSettings& settings);

/// Traces a block of a spectral run (job.spectral and its tallies set).
void trace_block_spectral(const BlockJob& job, Tally& tally, BlockBudget& block);

/// The spectral tables of a spectral run from its sums (IncidenceSums' spectral fields), and the
/// result's sRGB table scaled back (kSpectralTallyScale).
void finalize_spectral(const SimulationSettings& settings, const SimulationSums& sums,
                       const HemisphereGrid& grid, bool transmits, SimulationResult& result);

}  // namespace lamina

#pragma once
// One goniophotometer run split over the processes of a Communicator (docs/scaling.md): each rank
// traces a contiguous range of particles, the ranks' integer sums are added at the root, and the
// root finalizes. The result is bitwise that of one process with the same settings (the sums are
// exact integers, and every range starts on a block boundary, so each block of particles is traced
// and summed exactly as in one run).

#include "distributed/communicator.h"
#include "layers/stack.h"
#include "simulator/goniophotometer.h"

#include <cstdint>
#include <functional>
#include <optional>

namespace lamina {

/// Particles [first, first + count) of one incidence, relative to the run's first particle.
struct ParticleRange {
    std::uint64_t first = 0, count = 0;
};

/// Rank `rank` of `size` gets a contiguous share of the ⌈particles / kParticlesPerBlock⌉ blocks
/// (shares differ by at most one block; the last rank's range ends at `particles`, possibly
/// mid-block). The ranges are disjoint and their union is [0, particles); a range may be empty
/// when there are fewer blocks than ranks. Requires 0 ≤ rank < size.
ParticleRange particle_range(std::uint64_t particles, int rank, int size);

/// Collective: simulates `settings` (all its particles; settings.first_particle must be a multiple
/// of kParticlesPerBlock) over the ranks of `comm`. Each rank uses settings.threads threads (0: all
/// of OpenMP's). `on_progress` receives this rank's particle counts. The root returns the result
/// (seconds: the root's wall time, reduction included; processes: comm.size()); the other ranks
/// return empty. Settings must be valid (validate_settings).
std::optional<SimulationResult> simulate_split(
    Communicator& comm, const Stack& stack, const SimulationSettings& settings,
    const std::function<void(std::uint64_t)>& on_progress = {});

}  // namespace lamina

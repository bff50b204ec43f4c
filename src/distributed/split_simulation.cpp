#include "distributed/split_simulation.h"

#include "core/check.h"

#include <chrono>

namespace lamina {

ParticleRange particle_range(std::uint64_t particles, int rank, int size) {
    LAMINA_CHECK(size >= 1 && rank >= 0 && rank < size);
    const std::uint64_t blocks = (particles + kParticlesPerBlock - 1) / kParticlesPerBlock;
    const auto block_start = [&](int r) { return blocks * std::uint64_t(r) / std::uint64_t(size); };
    const std::uint64_t lo = std::min(particles, block_start(rank) * kParticlesPerBlock);
    const std::uint64_t hi = std::min(particles, block_start(rank + 1) * kParticlesPerBlock);
    return {lo, hi - lo};
}

std::optional<SimulationResult> simulate_split(
    Communicator& comm, const Stack& stack, const SimulationSettings& settings,
    const std::function<void(std::uint64_t)>& on_progress) {
    LAMINA_CHECK(settings.first_particle % kParticlesPerBlock == 0);
    const auto start = std::chrono::steady_clock::now();
    const ParticleRange range = particle_range(settings.particles, comm.rank(), comm.size());
    SimulationSums sums;
    if (range.count > 0) {
        SimulationSettings mine = settings;
        mine.first_particle = settings.first_particle + range.first;
        mine.particles = range.count;
        sums = simulate_sums(stack, mine, on_progress);
    } else {  // fewer blocks than ranks: this rank adds zeros
        sums = zero_sums(stack, settings);
    }
    comm.sum_to_root(sums.incidences);
    if (!comm.is_root()) return std::nullopt;
    sums.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    SimulationResult result = finalize_simulation(stack, settings, sums);
    result.processes = comm.size();
    return result;
}

}  // namespace lamina

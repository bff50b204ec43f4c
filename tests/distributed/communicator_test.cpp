// The distributed layer in one process (no launcher: MPI is never initialized). The runs over
// several processes are checked end to end by tests/cli/mpi_test.sh.
#include "distributed/communicator.h"
#include "distributed/split_simulation.h"
#include "distributed/sums_buffer.h"
#include "layers/stack.h"

#include <gtest/gtest.h>

#include <cstdlib>

namespace lamina {
namespace {

Stack clear_coat_over_lambertian() {
    const Layer coat = with_medium(layer_of(dielectric_interface(1.5, 0.3)), Rgbd(0.2, 0.0, 0.5));
    return {"test plastic", 1.0, {coat, layer_of(lambertian_interface(Rgbd(0.7)))}};
}

TEST(Communicator, PlainProcessIsOneRootRank) {
    Communicator& world = Communicator::world();
    EXPECT_EQ(world.rank(), 0);
    EXPECT_EQ(world.size(), 1);
    EXPECT_TRUE(world.is_root());
    EXPECT_FALSE(world.distributed());
    std::string bytes = "abc";
    world.broadcast(bytes);
    EXPECT_EQ(bytes, "abc");
    EXPECT_EQ(world.gather("xyz"), std::vector<std::string>{"xyz"});
    world.barrier();
    EXPECT_FALSE(world.receive_at_root(false).has_value());
    EXPECT_GE(default_threads_per_process(world), 1);
}

TEST(Communicator, ParticleRangesPartitionInWholeBlocks) {
    for (int size : {1, 2, 3, 7})
        for (std::uint64_t n : {std::uint64_t(1), std::uint64_t(3000), std::uint64_t(50001),
                                std::uint64_t(4096 * 5), std::uint64_t(1'000'003)}) {
            std::uint64_t next = 0;
            for (int r = 0; r < size; ++r) {
                const ParticleRange range = particle_range(n, r, size);
                EXPECT_EQ(range.first, next) << n << " over " << size;
                // Every range starts on a block boundary (or is empty at the end).
                if (range.count > 0) {
                    EXPECT_EQ(range.first % kParticlesPerBlock, 0u);
                }
                next = range.first + range.count;
            }
            EXPECT_EQ(next, n) << n << " over " << size;
        }
}

// Flattening round-trips, and adding flat arrays is IncidenceSums::add.
TEST(Communicator, FlatSumsAddLikeIncidenceSums) {
    std::vector<IncidenceSums> a(2), b(2);
    for (int i = 0; i < 2; ++i) {
        a[i].bins.resize(5);
        b[i].bins.resize(5);
        for (std::size_t j = 0; j < 5; ++j)
            for (int k = 0; k < 6; ++k) {
                a[i].bins[j][k] = (Fixed128(1) << 100) + Fixed128(j * 7 + k + i);
                b[i].bins[j][k] = Fixed128(-3) * Fixed128(j + k + 1);
            }
        a[i].budget[2][1] = Fixed128(1) << 90;
        b[i].budget[2][1] = 5;
        a[i].events = 11 + i;
        b[i].events = 100;
        a[i].degenerate = 1;
        b[i].degenerate = 2;
    }
    std::vector<Fixed128> flat_a = flatten_sums(a);
    ASSERT_EQ(flat_a.size(), 2 * flat_sums_size(5));
    const std::vector<Fixed128> flat_b = flatten_sums(b);
    add_flat_sums(flat_b.data(), flat_a.data(), flat_a.size());
    std::vector<IncidenceSums> got = b;  // the shape
    unflatten_sums(flat_a, got);
    for (int i = 0; i < 2; ++i) {
        IncidenceSums want = a[i];
        want.add(b[i]);
        EXPECT_EQ(got[i].bins, want.bins);
        EXPECT_EQ(got[i].budget, want.budget);
        EXPECT_EQ(got[i].events, want.events);
        EXPECT_EQ(got[i].degenerate, want.degenerate);
    }
}

// A spectral run's sums (the wavelength bins, XYZ and their budgets) travel with the others.
TEST(Communicator, SpectralSumsFlattenAndAdd) {
    std::vector<IncidenceSums> a(1), b(1);
    for (IncidenceSums* s : {&a[0], &b[0]}) {
        s->bins.resize(2);
        s->spectral_bins.resize(6);
        s->xyz_bins.resize(2);
        s->spectral_budget.resize(3);
    }
    a[0].spectral_bins[5][3] = Fixed128(1) << 100;
    b[0].spectral_bins[5][3] = 7;
    a[0].xyz_bins[1][2] = -9;
    b[0].spectral_budget[2][kBudgetTerms][1] = Fixed128(1) << 80;
    a[0].xyz_budget[0][2] = 3;
    std::vector<Fixed128> flat = flatten_sums(a);
    const std::vector<Fixed128> flat_b = flatten_sums(b);
    ASSERT_EQ(flat.size(), flat_b.size());
    add_flat_sums(flat_b.data(), flat.data(), flat.size());
    std::vector<IncidenceSums> got = b;
    unflatten_sums(flat, got);
    IncidenceSums want = a[0];
    want.add(b[0]);
    EXPECT_EQ(got[0].spectral_bins, want.spectral_bins);
    EXPECT_EQ(got[0].xyz_bins, want.xyz_bins);
    EXPECT_EQ(got[0].spectral_budget, want.spectral_budget);
    EXPECT_EQ(got[0].xyz_budget, want.xyz_budget);
    EXPECT_EQ(got[0].spectral_bins[5][3], (Fixed128(1) << 100) + 7);
}

TEST(Communicator, OneProcessReductionIsTheIdentity) {
    std::vector<IncidenceSums> sums(1);
    sums[0].bins.resize(3);
    sums[0].bins[1][4] = 42;
    sums[0].events = 9;
    const std::vector<IncidenceSums> before = sums;
    Communicator::world().sum_to_root(sums);
    EXPECT_EQ(sums[0].bins, before[0].bins);
    EXPECT_EQ(sums[0].events, 9u);
}

// A split run in one process is the plain run, bit for bit; and ranges simulated apart and summed
// give the same sums as one range (what the processes do).
TEST(Communicator, SplitRangesSumToTheWholeRun) {
    const Stack stack = clear_coat_over_lambertian();
    SimulationSettings s;
    s.theta_i_deg = {0, 60};
    s.particles = 3 * kParticlesPerBlock + 123;
    s.grid = HemisphereGrid(9, 9);
    s.threads = 2;
    const SimulationResult plain = simulate(stack, s);
    const std::optional<SimulationResult> split = simulate_split(Communicator::world(), stack, s);
    ASSERT_TRUE(split.has_value());
    EXPECT_EQ(split->table.to_csv(), plain.table.to_csv());
    EXPECT_EQ(split->processes, 1);

    const SimulationSums whole = simulate_sums(stack, s);
    std::vector<IncidenceSums> total;
    for (int r = 0; r < 3; ++r) {
        const ParticleRange range = particle_range(s.particles, r, 3);
        SimulationSettings part = s;
        part.first_particle = range.first;
        part.particles = range.count;
        part.threads = 1 + r % 2;
        const SimulationSums sums = simulate_sums(stack, part);
        if (total.empty())
            total = sums.incidences;
        else
            for (std::size_t i = 0; i < total.size(); ++i)
                total[i].add(sums.incidences[i]);
    }
    for (std::size_t i = 0; i < total.size(); ++i) {
        EXPECT_EQ(total[i].bins, whole.incidences[i].bins);
        EXPECT_EQ(total[i].budget, whole.incidences[i].budget);
        EXPECT_EQ(total[i].events, whole.incidences[i].events);
    }
}

}  // namespace
}  // namespace lamina

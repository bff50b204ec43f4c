// Speed of the random-walk estimator (docs/performance.md, "The random walk"): one walk's eval
// (RandomWalkStack::eval_once, what the renderer calls per connection) with single- and with
// multiple-scattering rough interfaces (docs/rendering.md §1.6), single thread, on a rough clear
// coat (η 1.5, α 0.3, some absorption) over rough gold (α 0.3) and on a rough dielectric alone.
#include "core/rng.h"
#include "core/spherical.h"
#include "layers/stack.h"
#include "randomwalk/random_walk.h"

#include <benchmark/benchmark.h>

#include <cstdint>

namespace {

using namespace lamina;

Stack bench_stack(bool coat) {
    Stack s;
    const Layer top = layer_of(dielectric_interface(1.5, 0.3));
    if (!coat) {
        s.layers = {top};
        return s;
    }
    s.layers = {with_medium(top, Rgbd(0.05, 0.1, 0.2)),
                layer_of(conductor_interface(Rgbd(0.18, 0.42, 1.37), Rgbd(3.4, 2.35, 1.85), 0.3))};
    return s;
}

// range(0): 1 = coat over gold, 0 = rough dielectric alone; range(1): 1 = multiple scattering.
void BM_RandomWalkEvalOnce(benchmark::State& state) {
    const RandomWalkStack rw(
        bench_stack(state.range(0) == 1),
        {.microsurface = state.range(1) == 1 ? Microsurface::Multiple : Microsurface::Single});
    const Vec3d wi = incident_direction(0.6), wo = direction_from_angles(0.8, 2.6);
    std::uint64_t i = 0;
    Rgbd sum(0.0);
    for (auto _ : state) {
        ParticleRng rng(1, 2, i++);
        sum += rw.eval_once(wi, wo, rng);
    }
    benchmark::DoNotOptimize(sum);
    state.SetItemsProcessed(std::int64_t(i));
}
BENCHMARK(BM_RandomWalkEvalOnce)
    ->ArgNames({"coat", "multiple"})
    ->Args({1, 0})
    ->Args({1, 1})
    ->Args({0, 0})
    ->Args({0, 1});

}  // namespace

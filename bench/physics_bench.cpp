// Micro-benchmarks of the physics building blocks (single thread).
#include "core/rng.h"
#include "physics/dielectric.h"

#include <benchmark/benchmark.h>

namespace {

void BM_RoughDielectricSample(benchmark::State& state) {
    const lamina::DielectricInterface<float> interface { 1.5f, 0.2f };
    lamina::ParticleRng rng(1, 0, 0);
    const lamina::Vec3f wi = lamina::normalize(lamina::Vec3f(0.5f, 0.0f, 0.8f));
    for (auto _ : state) {
        auto s = interface.sample<false>(wi, rng.uniform_float(), rng.uniform_float(),
                                         rng.uniform_float());
        benchmark::DoNotOptimize(s);
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_RoughDielectricSample);

}  // namespace

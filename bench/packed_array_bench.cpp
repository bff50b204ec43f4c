// Writing and reading one quick-study table (17 sources × 7 incidences × 90 × 90 bins × RGB,
// float16): the packed array (core/packed_array.h) against the raw .npy it replaces. The table is
// a smooth synthetic lobe plus noise in the reference's place (single thread).
#include "core/npy.h"
#include "core/packed_array.h"
#include "core/rng.h"

#include <benchmark/benchmark.h>

#include <cmath>

namespace {

const std::vector<std::size_t> kShape = {17, 7, 1, 90, 90, 3};

std::vector<float> quick_table() {
    std::vector<float> t;
    lamina::ParticleRng rng(1, 0, 0);
    for (std::size_t s = 0; s < kShape[0]; ++s)
        for (std::size_t i = 0; i < kShape[1]; ++i)
            for (std::size_t th = 0; th < 90; ++th)
                for (std::size_t ph = 0; ph < 90; ++ph)
                    for (int c = 0; c < 3; ++c) {
                        const double x = (th + 0.5) / 90.0, y = (ph + 0.5) / 90.0;
                        const double f =
                            0.2 * (c + 1) +
                            3.0 * std::exp(-((x - 0.1 * i) * (x - 0.1 * i) + (1 - y) * (1 - y)) /
                                           0.02);
                        const double noise =
                            s == 0 ? 1.0 + 0.02 * (rng.uniform_float() - 0.5) : 1.0;
                        t.push_back(float(f * noise));
                    }
    return t;
}

void BM_PackTableHalf(benchmark::State& state) {
    const std::vector<float> t = quick_table();
    std::size_t bytes = 0;
    for (auto _ : state) {
        const std::string b = lamina::packed_array_file(t, kShape, true);
        bytes = b.size();
        benchmark::DoNotOptimize(b.data());
    }
    state.counters["bytes"] = double(bytes);
}
BENCHMARK(BM_PackTableHalf)->Unit(benchmark::kMillisecond);

void BM_UnpackTableHalf(benchmark::State& state) {
    const std::string b = lamina::packed_array_file(quick_table(), kShape, true);
    for (auto _ : state) {
        lamina::NpyFloat32 a = lamina::parse_packed_array(b, "bench");
        benchmark::DoNotOptimize(a.data.data());
    }
}
BENCHMARK(BM_UnpackTableHalf)->Unit(benchmark::kMillisecond);

void BM_NpyTableHalf(benchmark::State& state) {
    const std::vector<float> t = quick_table();
    std::size_t bytes = 0;
    for (auto _ : state) {
        const std::string b = lamina::npy_float16(t, kShape);
        bytes = b.size();
        benchmark::DoNotOptimize(b.data());
    }
    state.counters["bytes"] = double(bytes);
}
BENCHMARK(BM_NpyTableHalf)->Unit(benchmark::kMillisecond);

}  // namespace

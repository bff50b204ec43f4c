// Goniophotometer throughput: particles per second for the benchmark plastic and the benchmark
// metallic paint at θi = 30°, on 1 and 2 threads, with events per particle; the second argument
// picks the kernel (0 scalar, 1 SIMD). The spectral plastic's particles carry three wavelengths
// each (docs/physics.md §10): its wavelength samples per second are three times its items.
#include "layers/stack.h"
#include "simulator/goniophotometer.h"
#include "simulator/kernel_simd.h"

#include <fmt/format.h>

#include <benchmark/benchmark.h>

namespace {

using namespace lamina;

Layer coat(double alpha, Rgbd tau_a) {
    Layer l;
    l.interface.type = InterfaceType::Dielectric;
    l.interface.eta = 1.5;
    l.interface.alpha = alpha;
    l.has_medium = true;
    l.medium.tau_a = tau_a;
    return l;
}

// The benchmark plastic: α0 = 0.2, τa = (0.1, 0, 0.9), a white (ρ = 1) Lambertian.
Stack bench_plastic() {
    Layer base;
    base.interface.type = InterfaceType::Lambertian;
    base.interface.albedo = Rgbd(1.0);
    return {"bench plastic", 1.0, {coat(0.2, Rgbd(0.1, 0.0, 0.9)), base}};
}

// The benchmark metallic paint: α0 = 0.05, τa = 0.1, conductor η = 0.2, k = 3, α1 = 0.3.
Stack bench_metallic_paint() {
    Layer base;
    base.interface.type = InterfaceType::Conductor;
    base.interface.eta_rgb = Rgbd(0.2);
    base.interface.k = Rgbd(3.0);
    base.interface.alpha = 0.3;
    return {"bench metallic paint", 1.0, {coat(0.05, Rgbd(0.1)), base}};
}

void run(benchmark::State& state, const Stack& stack,
         Microsurface microsurface = Microsurface::Single, bool spectral = false) {
    SimulationSettings s;
    s.transport.microsurface = microsurface;
    s.spectral = spectral ? SpectralMode::On : SpectralMode::Off;
    s.theta_i_deg = {30.0};
    s.particles = 1'000'000;
    s.threads = int(state.range(0));
    s.kernel = state.range(1) == 1 ? Kernel::Simd : Kernel::Scalar;
    state.SetLabel((s.kernel == Kernel::Simd ? fmt::format("simd {}", simd_target_name())
                                             : std::string("scalar")) +
                   (microsurface == Microsurface::Multiple ? " multiple" : "") +
                   (spectral ? " spectral" : ""));
    double events = 0;
    for (auto _ : state) {
        const SimulationResult r = simulate(stack, s);
        events = r.incidences[0].events_per_particle;
        benchmark::DoNotOptimize(r.table.lobes.data());
    }
    state.SetItemsProcessed(std::int64_t(state.iterations()) * std::int64_t(s.particles));
    state.counters["events_per_particle"] = events;
    state.counters["threads"] = double(s.threads);
}

void BM_SimulatePlastic(benchmark::State& state) {
    run(state, bench_plastic());
}
void BM_SimulateMetallicPaint(benchmark::State& state) {
    run(state, bench_metallic_paint());
}

// A rough slab: a rough coat (α 0.3) over an absorbing medium and a rough exit (η 1 below, α 0.5),
// reflection and transmission, total internal reflection inside.
Stack bench_rough_slab() {
    Layer exit_face;
    exit_face.interface.type = InterfaceType::Dielectric;
    exit_face.interface.eta = 1.0;  // the index below: air
    exit_face.interface.alpha = 0.5;
    Layer top = coat(0.3, Rgbd(0.1, 0.0, 0.9));
    return {"bench rough slab", 1.0, {top, exit_face}};
}
void BM_SimulateRoughSlab(benchmark::State& state) {
    run(state, bench_rough_slab());
}

// Multiple scattering on the microsurfaces (Heitz et al. 2016 walk), both kernels.
void BM_SimulatePlasticMultiple(benchmark::State& state) {
    run(state, bench_plastic(), Microsurface::Multiple);
}
void BM_SimulateMetallicPaintMultiple(benchmark::State& state) {
    run(state, bench_metallic_paint(), Microsurface::Multiple);
}
void BM_SimulateRoughSlabMultiple(benchmark::State& state) {
    run(state, bench_rough_slab(), Microsurface::Multiple);
}

// The plastic traced spectrally (three wavelengths per particle) with the transport's defaults
// (polarized, multiple scattering: the exact reference), as BM_SimulatePlasticMultiple traces
// it in RGB.
void BM_SimulatePlasticSpectral(benchmark::State& state) {
    run(state, bench_plastic(), Microsurface::Multiple, true);
}

BENCHMARK(BM_SimulatePlasticSpectral)
    ->ArgsProduct({{2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulatePlastic)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulateMetallicPaint)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulatePlasticMultiple)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulateMetallicPaintMultiple)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulateRoughSlab)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulateRoughSlabMultiple)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

namespace {
// Cost anatomy: a Lambertian alone (one event per particle) and a single rough interface.
lamina::Stack bench_lambertian() {
    lamina::Layer base;
    base.interface.type = lamina::InterfaceType::Lambertian;
    base.interface.albedo = lamina::Rgbd(0.8);
    return {"lambertian", 1.0, {base}};
}
lamina::Stack bench_rough_interface() {
    lamina::Layer l;
    l.interface.type = lamina::InterfaceType::Dielectric;
    l.interface.eta = 1.5;
    l.interface.alpha = 0.2;
    return {"rough dielectric", 1.0, {l}};
}
void BM_SimulateLambertian(benchmark::State& state) {
    run(state, bench_lambertian());
}
void BM_SimulateRoughInterface(benchmark::State& state) {
    run(state, bench_rough_interface());
}
BENCHMARK(BM_SimulateLambertian)
    ->ArgsProduct({{1}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_SimulateRoughInterface)
    ->ArgsProduct({{1}, {0, 1}})
    ->ArgNames({"threads", "simd"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
}  // namespace

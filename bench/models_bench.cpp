// Speed of the analytic models (docs/performance.md, "Models"): evaluations per second (single
// thread) and the time to produce one binned table (7 incidences, 90x90, every supported side,
// all OpenMP threads).
#include "core/rng.h"
#include "core/spherical.h"
#include "models/binned.h"
#include "models/coat_transmittance.h"
#include "models/fgd_table.h"
#include "models/registry.h"
#include "models/tir_table.h"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <vector>

namespace {

using namespace lamina;

Stack typical_stack(bool slab) {
    // A rough clear coat (η 1.5, α 0.1) with some absorption over rough gold (α 0.2), or over a
    // rough dielectric (η 1.33, α 0.2) for the slab.
    Stack s;
    Layer coat;
    coat.interface.type = InterfaceType::Dielectric;
    coat.interface.eta = 1.5;
    coat.interface.alpha = 0.1;
    coat.has_medium = true;
    coat.medium.tau_a = Rgbd(0.05, 0.1, 0.2);
    Layer base;
    if (slab) {
        base.interface.type = InterfaceType::Dielectric;
        base.interface.eta = 1.33;
    } else {
        base.interface.type = InterfaceType::Conductor;
        base.interface.eta_rgb = Rgbd(0.18, 0.42, 1.37);
        base.interface.k = Rgbd(3.4, 2.35, 1.85);
    }
    base.interface.alpha = 0.2;
    s.layers = {coat, base};
    return s;
}

/// The typical coated gold with a scattering coat (τs 0.5, g 0.3): the six-flux path of tm6.
Stack milky_stack() {
    Stack s = typical_stack(false);
    s.layers[0].medium.tau_s = Rgbd(0.5);
    s.layers[0].medium.g = Rgbd(0.3);
    return s;
}

struct Pairs {
    std::vector<Vec3d> wi, wo;
    Pairs() {
        ParticleRng rng(1, 0, 0);
        for (int n = 0; n < 4096; ++n) {
            wi.push_back(direction_from_angles(1.5 * rng.uniform_double(), 0.0));
            wo.push_back(
                direction_from_angles(1.5 * rng.uniform_double(), 6.283 * rng.uniform_double()));
        }
    }
};

/// The typical coated gold, or the slab for a model that only represents slabs (none now; kept for
/// models that only represent slabs).
Stack bench_stack(const std::string& name) {
    const Stack coated_gold = typical_stack(false);
    return make_model(name, coated_gold)->support().brdf ? coated_gold : typical_stack(true);
}

void warm_tables() {
    FgdTable::get();
    TirTable::get();
    CoatTransmittanceTable::get(RefractionMasking::SmithBeta);
}

/// Model::eval(wi, wo) for random pairs (the forward Belcour variants redo their lobe statistics
/// per call here).
void BM_ModelEval(benchmark::State& state, const std::string& name, const Stack& stack) {
    warm_tables();
    const auto model = make_model(name, stack);
    static const Pairs pairs;
    std::size_t n = 0;
    for (auto _ : state) {
        const std::size_t i = n++ & 4095;
        benchmark::DoNotOptimize(model->eval(pairs.wi[i], pairs.wo[i]));
    }
    state.SetItemsProcessed(state.iterations());
}

/// The prepared per-incidence evaluator (what the binned tables and the study use).
void BM_ModelPreparedEval(benchmark::State& state, const std::string& name, const Stack& stack) {
    warm_tables();
    const auto model = make_model(name, stack);
    static const Pairs pairs;
    const auto ev = model->prepare(pairs.wi[0]);
    std::size_t n = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(ev->eval(pairs.wo[n++ & 4095]));
    state.SetItemsProcessed(state.iterations());
}

/// The same through a slab (lamina-1's BTDF): the outgoing directions mirrored below.
void BM_ModelPreparedEvalTransmission(benchmark::State& state, const std::string& name,
                                      const Stack& stack) {
    warm_tables();
    const auto model = make_model(name, stack);
    static const Pairs pairs;
    std::vector<Vec3d> below;
    for (const Vec3d& w : pairs.wo)
        below.emplace_back(w.x, w.y, -w.z);
    const auto ev = model->prepare(pairs.wi[0]);
    std::size_t n = 0;
    for (auto _ : state)
        benchmark::DoNotOptimize(ev->eval(below[n++ & 4095]));
    state.SetItemsProcessed(state.iterations());
}

/// One binned table: 7 incidences, 90x90 grid, both sides where supported, on `stack`.
void BM_StackBinnedTable(benchmark::State& state, const std::string& name, const Stack& stack) {
    warm_tables();
    const auto model = make_model(name, stack);
    const HemisphereGrid grid(90, 90);
    for (auto _ : state)
        benchmark::DoNotOptimize(bin_model(*model, grid, {0, 15, 30, 45, 60, 70, 80}));
    state.counters["threads"] = omp_get_max_threads();
}

/// lamina-1's per-material precomputation (its curves over cosines, hemispherical albedos and the
/// inter-reflection normalization; the process-wide tables already loaded): the whole constructor.
void BM_Lamina1Construct(benchmark::State& state, bool slab, bool multiple) {
    warm_tables();
    const Stack stack = typical_stack(slab);
    const std::vector<std::string> options =
        multiple ? std::vector<std::string>{"microsurface=multiple"} : std::vector<std::string>{};
    make_model("lamina-1", stack, options);  // loads the multiple-scattering table once
    for (auto _ : state)
        benchmark::DoNotOptimize(make_model("lamina-1", stack, options));
    state.SetLabel(std::string(slab ? "rough slab" : "rough coat over rough gold") +
                   (multiple ? ", microsurface=multiple" : ""));
}
BENCHMARK_CAPTURE(BM_Lamina1Construct, coated_gold, false, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, slab, true, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, coated_gold_multiple, false, true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, slab_multiple, true, true)->Unit(benchmark::kMicrosecond);

const int registered = [] {
    for (const auto& e : model_registry()) {
        if (e.stochastic) continue;  // binning 8100 noisy queries is not a model benchmark
        benchmark::RegisterBenchmark(("BM_ModelEval/" + e.name).c_str(), BM_ModelEval, e.name,
                                     bench_stack(e.name));
        benchmark::RegisterBenchmark(("BM_ModelPreparedEval/" + e.name).c_str(),
                                     BM_ModelPreparedEval, e.name, bench_stack(e.name));
        const bool gold = make_model(e.name, typical_stack(false))->support().brdf;
        benchmark::RegisterBenchmark(
            ("BM_BinnedTable/" + e.name + (gold ? "/coated-gold" : "/slab-both-sides")).c_str(),
            BM_StackBinnedTable, e.name, bench_stack(e.name))
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    // The same three measurements on the milky coat (tm6's scattering media).
    for (const char* name : {"tm6", "bel-prime"}) {
        benchmark::RegisterBenchmark(("BM_ModelEval/" + std::string(name) + "/milky-gold").c_str(),
                                     BM_ModelEval, std::string(name), milky_stack());
        benchmark::RegisterBenchmark(
            ("BM_ModelPreparedEval/" + std::string(name) + "/milky-gold").c_str(),
            BM_ModelPreparedEval, std::string(name), milky_stack());
        benchmark::RegisterBenchmark(
            ("BM_BinnedTable/" + std::string(name) + "/milky-gold").c_str(), BM_StackBinnedTable,
            std::string(name), milky_stack())
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    for (const char* name : {"lamina-1", "bel-prime", "tm2"})
        benchmark::RegisterBenchmark(
            ("BM_ModelPreparedEvalTransmission/" + std::string(name) + "/slab").c_str(),
            BM_ModelPreparedEvalTransmission, std::string(name), typical_stack(true));
    for (const char* name : {"bel-prime", "tm2"})
        benchmark::RegisterBenchmark(
            ("BM_BinnedTable/" + std::string(name) + "/slab-both-sides").c_str(),
            BM_StackBinnedTable, std::string(name), typical_stack(true))
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    return 0;
}();

}  // namespace

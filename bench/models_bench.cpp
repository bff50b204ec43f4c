// Speed of the analytic models (docs/performance.md, "Models"): evaluations per second (single
// thread) and the time to produce one binned table (7 incidences, 90x90, every supported side,
// all OpenMP threads).
#include "core/rng.h"
#include "core/spherical.h"
#include "lamina1/lamina1.h"
#include "models/lamina1/lamina1.h"
#include "models/lamina_coat/lamina_coat.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/tables/coat_transmittance.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <algorithm>
#include <vector>

namespace {

using namespace lamina;

Stack typical_stack(bool slab) {
    // A rough clear coat (η 1.5, α 0.1) with some absorption over rough gold (α 0.2), or over a
    // rough dielectric (η 1.33, α 0.2) for the slab.
    Stack s;
    const Layer coat = with_medium(layer_of(dielectric_interface(1.5, 0.1)), Rgbd(0.05, 0.1, 0.2));
    const InterfaceSpec base =
        slab ? dielectric_interface(1.33, 0.2)
             : conductor_interface(Rgbd(0.18, 0.42, 1.37), Rgbd(3.4, 2.35, 1.85), 0.2);
    s.layers = {coat, layer_of(base)};
    return s;
}

/// The typical coated gold with a scattering coat (τs 0.5, g 0.3): the six-flux path of tm6.
Stack milky_stack() {
    Stack s = typical_stack(false);
    s.layers[0].medium.tau_s = Rgbd(0.5);
    s.layers[0].medium.g = Rgbd(0.3);
    return s;
}

/// The typical coat over a Lambertian (albedo 0.8): the plastic of the WW family, lamina-1 and
/// ddb22.
Stack plastic_stack() {
    Stack s = typical_stack(false);
    s.layers[1].interface = InterfaceSpec{};
    s.layers[1].interface.type = InterfaceType::Lambertian;
    s.layers[1].interface.albedo = Rgbd(0.8);
    return s;
}

/// A rough clear coat (η 1.4, α 0.3) over the plastic's coat raised to η 1.6: ddb22's layered
/// path (Bel18's adding for the coats).
Stack layered_plastic_stack() {
    Stack s = plastic_stack();
    s.layers[0].interface.eta = 1.6;
    Layer top;
    top.interface.type = InterfaceType::Dielectric;
    top.interface.eta = 1.4;
    top.interface.alpha = 0.3;
    s.layers.insert(s.layers.begin(), top);
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

/// The typical coated gold, else the slab for a model that only represents slabs (none now), else
/// the plastic for a model with a Lambertian base only (ddb22).
Stack bench_stack(const std::string& name) {
    const Stack coated_gold = typical_stack(false);
    if (make_model(name, coated_gold)->support().brdf) return coated_gold;
    const Stack slab = typical_stack(true);
    return make_model(name, slab)->support().brdf ? slab : plastic_stack();
}

/// The name of the stack bench_stack gives a model.
std::string bench_stack_name(const std::string& name) {
    if (make_model(name, typical_stack(false))->support().brdf) return "coated-gold";
    return make_model(name, typical_stack(true))->support().brdf ? "slab-both-sides" : "plastic";
}

void warm_tables() {
    FgdTable::get();
    TirTable::get();
    CoatTransmittanceTable::get(TransmissionMasking::Smith);
}

/// Model::eval(wi, wo) for random pairs (the forward Belcour variants redo their lobe statistics
/// per call here).
void BM_ModelEvalWith(benchmark::State& state, const std::string& name, const Stack& stack,
                      const std::vector<std::string>& options) {
    warm_tables();
    const auto model = make_model(name, stack, options);
    static const Pairs pairs;
    std::size_t n = 0;
    for (auto _ : state) {
        const std::size_t i = n++ & 4095;
        benchmark::DoNotOptimize(model->eval(pairs.wi[i], pairs.wo[i]));
    }
    state.SetItemsProcessed(state.iterations());
}
void BM_ModelEval(benchmark::State& state, const std::string& name, const Stack& stack) {
    BM_ModelEvalWith(state, name, stack, {});
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
void BM_Lamina1Construct(benchmark::State& state, bool slab, bool single, bool milky = false,
                         bool series = false) {
    warm_tables();
    Stack stack = typical_stack(slab);
    if (milky) {
        // The milky coat (τs 0.5, g 0.3; τa differs per channel: three adding-doublings).
        stack.layers[0].medium.tau_s = Rgbd(0.5);
        stack.layers[0].medium.g = Rgbd(0.3);
    }
    // The default restores the microsurfaces' orders ≥ 2 (these stacks are isotropic).
    std::vector<std::string> options;
    if (single) options.push_back("microsurface=single");
    // A slab's inter-reflections as the earlier series (slab-orders=series), against the bins.
    if (series) options.push_back("slab-orders=series");
    make_model("lamina-1", stack, options);  // loads the multiple-scattering table once
    for (auto _ : state)
        benchmark::DoNotOptimize(make_model("lamina-1", stack, options));
    state.SetLabel(std::string(slab ? "rough slab" : "rough coat over rough gold") +
                   (milky ? ", HG medium" : "") + (single ? ", microsurface=single" : "") +
                   (series ? ", slab-orders=series" : ""));
}
BENCHMARK_CAPTURE(BM_Lamina1Construct, coated_gold, false, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, slab, true, false)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, slab_series, true, false, false, true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, coated_gold_single, false, true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, slab_single, true, true)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, milky_gold, false, false, true)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1Construct, milky_slab, true, false, true)
    ->Unit(benchmark::kMicrosecond);

/// The same for a frosted gold (the study's frosted metals: a clear coat, η 1.5, α 0.3, over
/// nearly smooth gold, α 0.001), where the round trips leave as a lobe whose scale is solved at
/// construction (`round-trip=lobe`, the default) or as the uniform series (`round-trip=series`).
void BM_Lamina1ConstructFrosted(benchmark::State& state, const char* round_trip) {
    warm_tables();
    Stack stack = typical_stack(false);
    stack.layers[0] = layer_of(dielectric_interface(1.5, 0.3));
    stack.layers[1] =
        layer_of(conductor_interface(Rgbd(0.18, 0.42, 1.37), Rgbd(3.4, 2.35, 1.85), 0.001));
    const std::vector<std::string> options = {std::string("round-trip=") + round_trip};
    make_model("lamina-1", stack, options);
    for (auto _ : state)
        benchmark::DoNotOptimize(make_model("lamina-1", stack, options));
    state.SetLabel(std::string("frosted gold, round-trip=") + round_trip);
}
BENCHMARK_CAPTURE(BM_Lamina1ConstructFrosted, lobe, "lobe")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1ConstructFrosted, series, "series")->Unit(benchmark::kMicrosecond);

/// A nearly smooth slab (η 1.5, α0 0.05 with the typical absorption, over a bottom of α 0.001 into
/// air), whose polarization (`polarization=on`, the default: both interfaces' Stokes blocks on
/// the inside cosines and the entry rule on 17 outside ones, lamina1/polarization.h) is built at
/// construction, against `polarization=off`; and a plastic under the same nearly smooth coat,
/// whose coat seen from inside near its critical cosine is integrated per material
/// (Bsdf::DenseSideFgd).
Stack nearly_smooth(bool slab) {
    Stack stack = slab ? typical_stack(true) : plastic_stack();
    stack.layers[0].interface.alpha = 0.05;
    if (slab) stack.layers[1] = layer_of(dielectric_interface(1.0, 0.001));
    return stack;
}
void BM_Lamina1ConstructNearlySmooth(benchmark::State& state, bool slab, const char* polarization) {
    warm_tables();
    const Stack stack = nearly_smooth(slab);
    const std::vector<std::string> options = {std::string("polarization=") + polarization};
    make_model("lamina-1", stack, options);
    for (auto _ : state)
        benchmark::DoNotOptimize(make_model("lamina-1", stack, options));
    state.SetLabel(std::string(slab ? "nearly smooth slab" : "plastic under a nearly smooth coat") +
                   ", polarization=" + polarization);
}
BENCHMARK_CAPTURE(BM_Lamina1ConstructNearlySmooth, slab_polarized, true, "on")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1ConstructNearlySmooth, slab_unpolarized, true, "off")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Lamina1ConstructNearlySmooth, plastic, false, "on")
    ->Unit(benchmark::kMicrosecond);

/// ddb22's per-material precomputation (the hemispherical integrals over the coat tables and the
/// exiting light's variance; the process-wide tables already loaded): the whole constructor.
void BM_Ddb22Construct(benchmark::State& state) {
    warm_tables();
    const Stack stack = plastic_stack();
    for (auto _ : state)
        benchmark::DoNotOptimize(make_model("ddb22", stack));
    state.SetLabel("rough absorbing coat over a Lambertian");
}
BENCHMARK(BM_Ddb22Construct)->Unit(benchmark::kMicrosecond);

/// lamina-coat's function itself (lamina_coat_eval, what docs/lamina-coat.md and its GLSL give an
/// engine), without the Model interface: the cost per evaluation to set beside the production
/// coats' (the summary's "For engine developers").
void BM_LaminaCoatFunction(benchmark::State& state, bool conductor) {
    LaminaCoatMaterial m;
    m.eta = 1.5;
    m.alpha_coat = 0.1;
    m.tau = Rgbd(0.05, 0.1, 0.2);
    m.conductor = conductor;
    m.albedo = Rgbd(0.8);
    m.base_eta = Rgbd(0.18, 0.42, 1.37) / 1.5;
    m.base_k = Rgbd(3.4, 2.35, 1.85) / 1.5;
    m.alpha_base = 0.2;
    const LaminaCoatPrepared p = lamina_coat_prepare(m);
    static const Pairs pairs;
    std::size_t n = 0;
    for (auto _ : state) {
        const std::size_t i = n++ & 4095;
        benchmark::DoNotOptimize(lamina_coat_eval(p, pairs.wi[i], pairs.wo[i]));
    }
    state.SetItemsProcessed(state.iterations());
    state.SetLabel(conductor ? "coated gold" : "plastic");
}
BENCHMARK_CAPTURE(BM_LaminaCoatFunction, coated_gold, true);
BENCHMARK_CAPTURE(BM_LaminaCoatFunction, plastic, false);

/// lamina-1 as a renderer uses it: the header library's Bsdf (include/lamina1/lamina1.h), built
/// from its Layers, its eval(wi, wo) and sample(wi, u) in the header's own types, without lamina's
/// Model interface: the cost per evaluation to set beside the production coats' BM_CoatEval and
/// lamina-coat's function (docs/performance.md, "lamina-1 as a header"). The same materials as
/// BM_LaminaCoatFunction; the tables are the ones `lamina export --lamina1-tables` writes.
void BM_Lamina1Header(benchmark::State& state, bool conductor, bool sample) {
    lamina1::Layers layers;
    layers.eta0 = 1.5;
    layers.alpha0 = 0.1;
    layers.tau_a = {0.05, 0.1, 0.2};
    if (conductor) {
        layers.base = lamina1::Base::Conductor;
        layers.base_eta = {0.18 / 1.5, 0.42 / 1.5, 1.37 / 1.5};
        layers.base_k = {3.4 / 1.5, 2.35 / 1.5, 1.85 / 1.5};
        layers.alpha1 = 0.2;
    } else {
        layers.albedo = lamina1::Rgb{0.8};
    }
    // With the multiple-scattering table: the default restores the orders ≥ 2.
    const lamina1::Bsdf bsdf(layers, lamina1_tables(lamina1::Masking::Smith, true));
    if (!bsdf.support().brdf) {
        state.SkipWithError(bsdf.support().reason.c_str());
        return;
    }
    static const Pairs pairs;
    std::vector<lamina1::Vec3> wi, wo;
    for (std::size_t i = 0; i < pairs.wi.size(); ++i) {
        wi.push_back({pairs.wi[i].x, pairs.wi[i].y, pairs.wi[i].z});
        wo.push_back({pairs.wo[i].x, pairs.wo[i].y, pairs.wo[i].z});
    }
    std::size_t n = 0;
    for (auto _ : state) {
        const std::size_t i = n++ & 4095;
        if (sample)
            benchmark::DoNotOptimize(
                bsdf.sample(wi[i], {wo[i].x * 0.5 + 0.5, wo[i].y * 0.5 + 0.5, wo[i].z}));
        else
            benchmark::DoNotOptimize(bsdf.eval(wi[i], wo[i]));
    }
    state.SetItemsProcessed(state.iterations());
    state.SetLabel(std::string(conductor ? "coated gold" : "plastic") + (sample ? ", sample" : ""));
}
BENCHMARK_CAPTURE(BM_Lamina1Header, coated_gold, true, false);
BENCHMARK_CAPTURE(BM_Lamina1Header, plastic, false, false);
BENCHMARK_CAPTURE(BM_Lamina1Header, coated_gold_sample, true, true);
BENCHMARK_CAPTURE(BM_Lamina1Header, plastic_sample, false, true);

const int registered = [] {
    for (const auto& e : model_registry()) {
        if (e.stochastic) continue;  // binning 8100 noisy queries is not a model benchmark
        benchmark::RegisterBenchmark(("BM_ModelEval/" + e.name).c_str(), BM_ModelEval, e.name,
                                     bench_stack(e.name));
        benchmark::RegisterBenchmark(("BM_ModelPreparedEval/" + e.name).c_str(),
                                     BM_ModelPreparedEval, e.name, bench_stack(e.name));
        benchmark::RegisterBenchmark(
            ("BM_BinnedTable/" + e.name + "/" + bench_stack_name(e.name)).c_str(),
            BM_StackBinnedTable, e.name, bench_stack(e.name))
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    // lamina-1's reflection of the rough slab (its incidence included): the inside light in bins
    // (the default) against slab-orders=series.
    benchmark::RegisterBenchmark("BM_Lamina1SlabEval/bins", BM_ModelEvalWith,
                                 std::string("lamina-1"), typical_stack(true),
                                 std::vector<std::string>{});
    benchmark::RegisterBenchmark("BM_Lamina1SlabEval/series", BM_ModelEvalWith,
                                 std::string("lamina-1"), typical_stack(true),
                                 std::vector<std::string>{"slab-orders=series"});
    // The same three measurements on the milky coat (scattering media: tm6's six fluxes,
    // lamina-1's single scattering and adding remainder).
    for (const char* name : {"tm6", "bel-prime", "lamina-1"}) {
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
    // ddb22 with two coats (the only model here that represents them over a Lambertian).
    benchmark::RegisterBenchmark("BM_ModelEval/ddb22/layered-plastic", BM_ModelEval,
                                 std::string("ddb22"), layered_plastic_stack());
    benchmark::RegisterBenchmark("BM_ModelPreparedEval/ddb22/layered-plastic", BM_ModelPreparedEval,
                                 std::string("ddb22"), layered_plastic_stack());
    benchmark::RegisterBenchmark("BM_BinnedTable/ddb22/layered-plastic", BM_StackBinnedTable,
                                 std::string("ddb22"), layered_plastic_stack())
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    // The plastic, side by side: ddb22 against the models that also represent it.
    for (const char* name : {"ww-prime", "lamina-1"}) {
        benchmark::RegisterBenchmark(("BM_ModelEval/" + std::string(name) + "/plastic").c_str(),
                                     BM_ModelEval, std::string(name), plastic_stack());
        benchmark::RegisterBenchmark(
            ("BM_ModelPreparedEval/" + std::string(name) + "/plastic").c_str(),
            BM_ModelPreparedEval, std::string(name), plastic_stack());
        benchmark::RegisterBenchmark(("BM_BinnedTable/" + std::string(name) + "/plastic").c_str(),
                                     BM_StackBinnedTable, std::string(name), plastic_stack())
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
    }
    // The coats engines ship, as shipped and with lamina's exact leaves, beside lamina-coat, on the
    // plastic and the coated gold (BM_ModelEval: one eval per pair through the Model interface).
    for (const auto& e : model_registry()) {
        if (e.group != "production" && e.name != "lamina-coat") continue;
        for (const bool exact : {false, true}) {
            const auto options = e.options();
            if (exact && std::none_of(options.begin(), options.end(),
                                      [](const OptionSpec& o) { return o.key == "leaves"; }))
                continue;
            const std::string spec = exact ? e.name + ":leaves=exact" : e.name;
            for (const auto& [stack_name, stack] :
                 {std::pair{std::string("plastic"), plastic_stack()},
                  std::pair{std::string("coated-gold"), typical_stack(false)}}) {
                if (!make_model(spec, stack)->support().brdf) continue;
                benchmark::RegisterBenchmark(("BM_CoatEval/" + spec + "/" + stack_name).c_str(),
                                             BM_ModelEval, spec, stack);
            }
        }
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

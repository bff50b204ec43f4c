// lamina-1 behind lamina's Model interface: the header library's Bsdf (include/lamina1/) over
// lamina's own tables; every formula of the model is the header's.
#include "models/lamina1/lamina1.h"

#include "core/math.h"
#include "lamina1/lamina1.h"
#include "models/tables/coat_transmittance.h"
#include "models/tables/fgd_table.h"
#include "models/tables/multiple_scattering_albedo.h"
#include "models/tables/slope_sum_table.h"

#include <fmt/format.h>

#include <optional>

namespace lamina {

namespace {

lamina1::Vec3 to_header(const Vec3d& v) {
    return {v.x, v.y, v.z};
}
Vec3d from_header(const lamina1::Vec3& v) {
    return {v.x, v.y, v.z};
}
lamina1::Rgb to_header(const Rgbd& c) {
    return {c[0], c[1], c[2]};
}
Rgbd from_header(const lamina1::Rgb& c) {
    return {c[0], c[1], c[2]};
}

lamina1::Tables make_tables(lamina1::Masking masking, bool multiple, bool bins) {
    lamina1::Tables t;
    t.set_transmittance(lamina1::Masking::Smith,
                        CoatTransmittanceTable::get(TransmissionMasking::Smith).values().data());
    if (masking == lamina1::Masking::Walter)
        t.set_transmittance(lamina1::Masking::Walter,
                            CoatTransmittanceTable::get(TransmissionMasking::Pbrt).values().data());
    if (bins) {
        t.set_fgd_bins(FgdTable::bins());
    } else {
        t.set_fgd_nodes(FgdTable::get().data());
    }
    t.set_slope_sum(SlopeSumTable::get().values().data());
    if (multiple) t.set_multiple_scattering(MultipleScatteringAlbedo::get().values().data());
    return t;
}

class Lamina1Evaluator;

class Lamina1 final : public Model {
  public:
    Lamina1(const Stack& stack, const Lamina1Choices& choices) {
        lamina1::Layers layers;
        std::string why;
        if (!lamina1_layers(stack, layers, why)) {
            support_.reason = fmt::format("lamina-1 {}", why);
            return;
        }
        bsdf_.emplace(layers, lamina1_tables(choices), choices);
        support_.brdf = bsdf_->support().brdf;
        support_.btdf = bsdf_->support().btdf;
        support_.reason = bsdf_->support().reason;
    }

    std::string name() const override { return "lamina-1"; }
    Support support() const override { return support_; }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        if (!bsdf_) return Rgbd(0.0);
        return from_header(bsdf_->eval(to_header(wi), to_header(wo)));
    }
    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override;

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        std::vector<DeltaLobe> out;
        if (!bsdf_) return out;
        for (const lamina1::DeltaLobe& d : bsdf_->delta_lobes(to_header(wi)))
            out.push_back({from_header(d.direction), from_header(d.energy)});
        return out;
    }
    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> out;
        if (!bsdf_) return {mirror_direction(wi)};
        for (const lamina1::Vec3& d : bsdf_->peak_directions(to_header(wi)))
            out.push_back(from_header(d));
        return out;
    }

    bool has_sampling() const override { return support_.brdf; }
    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!bsdf_) return std::nullopt;
        const auto s = bsdf_->sample(to_header(wi), to_header(u));
        if (!s) return std::nullopt;
        return ModelSample{from_header(s->wo), from_header(s->weight), s->pdf};
    }
    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        return bsdf_ ? bsdf_->pdf(to_header(wi), to_header(wo)) : 0.0;
    }

  private:
    friend class Lamina1Evaluator;
    Support support_;
    std::optional<lamina1::Bsdf> bsdf_;
};

/// The per-incidence state, kept for many wo.
class Lamina1Evaluator final : public IncidentEvaluator {
  public:
    Lamina1Evaluator(const lamina1::Bsdf& bsdf, const Vec3d& wi)
        : bsdf_(bsdf), incident_(bsdf.incident(to_header(wi))) {}
    Rgbd eval(const Vec3d& wo) const override {
        return from_header(bsdf_.eval_with(incident_, to_header(wo)));
    }

  private:
    const lamina1::Bsdf& bsdf_;
    lamina1::Bsdf::Incident incident_;
};

std::unique_ptr<IncidentEvaluator> Lamina1::prepare(const Vec3d& wi) const {
    if (!bsdf_) return Model::prepare(wi);
    return std::make_unique<Lamina1Evaluator>(*bsdf_, wi);
}

}  // namespace

bool lamina1_layers(const Stack& stack, lamina1::Layers& layers, std::string& why) {
    CoatedStack coat;
    if (!coated_stack(stack, coat, why)) return false;
    layers.eta0 = coat.eta0;
    layers.alpha0 = coat.alpha0;
    layers.tau_a = to_header(coat.tau_a);
    layers.tau_s = to_header(coat.tau_s);
    layers.g = to_header(coat.g);
    switch (coat.base_type) {
        case InterfaceType::Lambertian:
            layers.base = lamina1::Base::Lambertian;
            break;
        case InterfaceType::Conductor:
            layers.base = lamina1::Base::Conductor;
            break;
        case InterfaceType::Dielectric:
            layers.base = lamina1::Base::Dielectric;
            break;
    }
    layers.base_eta = to_header(coat.base_eta);
    layers.base_k = to_header(coat.base_k);
    layers.alpha1 = coat.base_alpha;
    layers.albedo = to_header(coat.albedo);
    // Anisotropic interfaces (alpha = [alpha_x, alpha_y]): α_x is the stack's alpha (above).
    const InterfaceSpec& top = stack.layers[0].interface;
    const InterfaceSpec& base = stack.layers[1].interface;
    if (top.is_anisotropic()) {
        layers.alpha0_y = top.alpha_b();
        layers.tangent0 = deg_to_rad(top.tangent_deg);
    }
    if (base.is_anisotropic()) {
        layers.alpha1_y = base.alpha_b();
        layers.tangent1 = deg_to_rad(base.tangent_deg);
    }
    return true;
}

const lamina1::Tables& lamina1_tables(lamina1::Masking masking, bool multiple) {
    // One set per need, so that a table nobody asked for (the Walter masking's, the walks of
    // the multiple-scattering albedos) is never computed. Thread-safe (magic statics).
    if (masking == lamina1::Masking::Walter) {
        if (multiple) {
            static const lamina1::Tables t = make_tables(masking, true, false);
            return t;
        }
        static const lamina1::Tables t = make_tables(masking, false, false);
        return t;
    }
    if (multiple) {
        static const lamina1::Tables t = make_tables(masking, true, false);
        return t;
    }
    static const lamina1::Tables t = make_tables(masking, false, false);
    return t;
}

const lamina1::Tables& lamina1_tables(const Lamina1Choices& choices) {
    return lamina1_tables(choices.masking,
                          choices.microsurface != lamina1::Options::Microsurface::Single);
}

std::string lamina1_tables_file() {
    return make_tables(lamina1::Masking::Walter, true, true).serialize();
}

std::vector<float> lamina1_gpu_state(const Stack& stack, const ModelOptions& options,
                                     std::string& why) {
    const Lamina1Choices choices = lamina1_option_table().parse(options);
    lamina1::Layers layers;
    if (!lamina1_layers(stack, layers, why)) return {};
    const lamina1::Bsdf bsdf(layers, lamina1_tables(choices), choices);
    return bsdf.gpu_state(&why);
}

Lamina1GpuStates lamina1_gpu_states(const Stack& stack, const ModelOptions& options,
                                    std::string& why) {
    Lamina1GpuStates out;
    const Lamina1Choices choices = lamina1_option_table().parse(options);
    lamina1::Layers layers;
    if (!lamina1_layers(stack, layers, why)) return out;
    const lamina1::Tables& tables = lamina1_tables(choices);
    out.state = lamina1::Bsdf(layers, tables, choices).gpu_state(&why);
    if (out.state.empty()) return out;
    out.head = lamina1::kGpuSlopeSum;
    out.tail = out.state.size() - std::size_t(lamina1::kGpuSize);
    struct Variant {
        const char* parameter;
        double value;
        lamina1::Layers layers;
        std::vector<float> state;
    };
    std::vector<Variant> variants;
    auto add = [&](const char* parameter, double value, const lamina1::Layers& l) {
        variants.push_back({parameter, value, l, {}});
    };
    // The values offered: roughnesses from smooth (a delta lobe: lamina1_delta) through nearly
    // smooth to rough, the indices of common coats, optical depths over three decades, albedos
    // from dark to white.
    for (double v : {0.0, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5}) {
        lamina1::Layers l = layers;
        l.alpha0 = v;
        if (l.alpha0_y >= 0) l.alpha0_y = v;
        add("alpha0", v, l);
    }
    for (double v : {1.2, 1.33, 1.5, 1.8, 2.2}) {
        lamina1::Layers l = layers;
        l.eta0 = v;
        if (layers.base != lamina1::Base::Lambertian) {
            const double scale = layers.eta0 / v;  // the base's index relative to the new coat
            l.base_eta = layers.base_eta * scale;
            l.base_k = layers.base_k * scale;
        }
        add("eta0", v, l);
    }
    for (double v : {0.0, 0.1, 0.3, 1.0, 3.0}) {
        lamina1::Layers l = layers;
        l.tau_a = lamina1::Rgb(v);
        add("tau_a", v, l);
    }
    if (layers.base == lamina1::Base::Lambertian) {
        for (double v : {0.05, 0.2, 0.5, 0.8, 0.95}) {
            lamina1::Layers l = layers;
            l.albedo = lamina1::Rgb(v);
            add("albedo", v, l);
        }
    } else {
        for (double v : {0.02, 0.05, 0.1, 0.2, 0.4}) {
            lamina1::Layers l = layers;
            l.alpha1 = v;
            if (l.alpha1_y >= 0) l.alpha1_y = v;
            add("alpha1", v, l);
        }
    }
    // Each variant is a whole construction (a slab's takes milliseconds): side by side on the
    // threads, kept in the order above.
#pragma omp parallel for schedule(dynamic, 1)
    for (long i = 0; i < long(variants.size()); ++i) {
        std::string ignored;
        Variant& v = variants[std::size_t(i)];
        v.state = lamina1::Bsdf(v.layers, tables, choices).gpu_state(&ignored);
    }
    for (const Variant& v : variants) {
        // A variant of another layout (a slab's bins present or not) cannot share the stack's.
        if (v.state.size() != out.state.size()) continue;
        out.variants.push_back({v.parameter, v.value});
        out.heads.insert(out.heads.end(), v.state.begin(), v.state.begin() + lamina1::kGpuSlopeSum);
        out.heads.insert(out.heads.end(), v.state.end() - std::ptrdiff_t(out.tail), v.state.end());
    }
    return out;
}

std::unique_ptr<Model> make_lamina1(const Stack& stack, const ModelOptions& options) {
    return std::make_unique<Lamina1>(stack, lamina1_option_table().parse(options));
}

}  // namespace lamina

#include "models/model.h"

#include "core/check.h"

#include <fmt/format.h>

namespace lamina {

namespace {
class ForwardingEvaluator final : public IncidentEvaluator {
  public:
    ForwardingEvaluator(const Model& model, const Vec3d& wi) : model_(model), wi_(wi) {}
    Rgbd eval(const Vec3d& wo) const override { return model_.eval(wi_, wo); }

  private:
    const Model& model_;
    Vec3d wi_;
};
}  // namespace

std::unique_ptr<IncidentEvaluator> Model::prepare(const Vec3d& wi) const {
    return std::make_unique<ForwardingEvaluator>(*this, wi);
}

std::vector<Vec3d> Model::peak_directions(const Vec3d& wi) const {
    return {mirror_direction(wi)};
}

const std::string& option_value(const ModelOptions& options, const std::string& key) {
    const auto it = options.find(key);
    LAMINA_CHECK(it != options.end());  // the registry fills in every default
    return it->second;
}

bool coated_stack(const Stack& stack, CoatedStack& out, std::string& why) {
    if (stack.has_film()) {  // a CoatedStack has no film: reading one would describe another stack
        why = "thin films are not supported";
        return false;
    }
    if (stack.layers.size() != 2) {
        why = fmt::format(
            "needs exactly two interfaces (a dielectric coat over a base), the stack has {}",
            stack.layers.size());
        return false;
    }
    const Layer& coat = stack.layers[0];
    if (coat.interface.type != InterfaceType::Dielectric) {
        why = "the top interface must be a dielectric coat";
        return false;
    }
    out = CoatedStack{};
    out.eta0 = model_relative_eta(coat.interface.eta / stack.ambient_eta);
    out.alpha0 = coat.interface.alpha;
    if (coat.has_medium) {
        out.tau_a = coat.medium.tau_a;
        out.tau_s = coat.medium.tau_s;
        out.g = coat.medium.g;
    }
    const InterfaceSpec& base = stack.layers[1].interface;
    out.base_type = base.type;
    out.base_alpha = base.alpha;
    out.albedo = base.albedo;
    const double eta_coat = coat.interface.eta;
    if (base.type == InterfaceType::Conductor) {
        out.base_eta = model_relative_eta(base.eta_rgb / eta_coat);
        out.base_k = model_relative_k(base.k / eta_coat);
    } else if (base.type == InterfaceType::Dielectric) {
        out.base_eta = Rgbd(model_relative_eta(base.eta / eta_coat));
    }
    return true;
}

}  // namespace lamina

#include "models/spectral_projection.h"

#include "layers/colorimetry.h"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <memory>
#include <vector>

namespace lamina {

namespace {

bool has_dispersive_dielectric(const Stack& stack) {
    for (const Layer& l : stack.layers)
        if (l.interface.type == InterfaceType::Dielectric && l.interface.eta_spectrum) return true;
    return false;
}

class SpectralProjection final : public Model {
  public:
    static constexpr int kCells = 16;

    SpectralProjection(const ModelFactory& factory, const Stack& stack,
                       const SpectralQuadrature& q) {
        const int n = std::max(3, q.n - q.n % 3);
        const double step = (q.max_nm - q.min_nm) / n;
        auto node = [&](int j) { return q.min_nm + (j + 0.5) * step; };
        // Each node stands for its interval: its weight is ∫ S (x̄, ȳ, z̄) dλ over the interval,
        // by the midpoint rule on 16 cells per interval.
        std::vector<Rgbd> xyz(n, Rgbd(0.0));
        for (int j = 0; j < n; ++j)
            for (int cell = 0; cell < kCells; ++cell)
                xyz[j] += d65_xyz_weights(q.min_nm + (j + (cell + 0.5) / kCells) * step) *
                          (step / kCells);
        const double norm = d65_y_integral();  // over 360–830 nm, as the goniophotometer's
        auto srgb_weights = [&](int j) { return xyz_to_linear_srgb(xyz[j] * (1 / norm)); };
        if (has_dispersive_dielectric(stack)) {
            // One wavelength per model: its refraction follows that wavelength's index. Each of
            // its (equal) channels carries a third of the node's weight.
            for (int j = 0; j < n; ++j) {
                const Rgbd w = srgb_weights(j);
                Member m{factory(stack.at_wavelengths(Rgbd(node(j)), 1)), {}};
                for (int c = 0; c < 3; ++c)
                    m.weights[c] = {w[0] / 3, w[1] / 3, w[2] / 3};
                members_.push_back(std::move(m));
            }
        } else {
            const int k = n / 3;
            for (int t = 0; t < k; ++t) {
                const Rgbd lambdas(node(t), node(t + k), node(t + 2 * k));
                Member m{factory(stack.at_wavelengths(lambdas, 1)), {}};
                for (int c = 0; c < 3; ++c)
                    m.weights[c] = srgb_weights(t + c * k);
                members_.push_back(std::move(m));
            }
        }
        name_ = members_.front().model->name();
        support_ = members_.front().model->support();
        for (const Member& m : members_) {
            const Support s = m.model->support();
            support_.brdf = support_.brdf && s.brdf;
            support_.btdf = support_.btdf && s.btdf;
            if (support_.reason.empty()) support_.reason = s.reason;
        }
        sampling_ = std::all_of(members_.begin(), members_.end(),
                                [](const Member& m) { return m.model->has_sampling(); });
    }

    std::string name() const override { return name_; }
    Support support() const override { return support_; }

    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override {
        Rgbd sum(0.0);
        for (const Member& m : members_)
            sum = sum + m.project(m.model->eval(wi, wo));
        return sum;
    }

    /// The members' own prepared evaluators (what depends on wi alone computed once per member,
    /// e.g. lamina-1's incident statistics), summed in eval's order: the same values bit for bit.
    std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const override {
        std::vector<std::unique_ptr<IncidentEvaluator>> prepared;
        prepared.reserve(members_.size());
        for (const Member& m : members_)
            prepared.push_back(m.model->prepare(wi));
        return std::make_unique<Evaluator>(members_, std::move(prepared));
    }

    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override {
        // The lobes of every wavelength, projected; lobes along one direction merged.
        std::vector<DeltaLobe> out;
        for (const Member& m : members_)
            for (const DeltaLobe& lobe : m.model->delta_lobes(wi)) {
                const Rgbd energy = m.project(lobe.energy);
                auto same = std::find_if(out.begin(), out.end(), [&](const DeltaLobe& o) {
                    return o.direction.x == lobe.direction.x && o.direction.y == lobe.direction.y &&
                           o.direction.z == lobe.direction.z;
                });
                if (same != out.end())
                    same->energy = same->energy + energy;
                else
                    out.push_back({lobe.direction, energy});
            }
        return out;
    }

    std::vector<Vec3d> peak_directions(const Vec3d& wi) const override {
        std::vector<Vec3d> out;
        for (const Member& m : members_) {
            const std::vector<Vec3d> peaks = m.model->peak_directions(wi);
            out.insert(out.end(), peaks.begin(), peaks.end());
        }
        return out;
    }

    bool has_sampling() const override { return sampling_; }

    std::optional<ModelSample> sample(const Vec3d& wi, const Vec3d& u) const override {
        if (!sampling_) return std::nullopt;
        // Pick a wavelength model with the first number, rescaled to a fresh uniform.
        const double pick = u.z * double(members_.size());
        const size_t i = std::min(members_.size() - 1, size_t(pick));
        const auto s = members_[i].model->sample(wi, Vec3d(u.x, u.y, pick - double(i)));
        if (!s) return std::nullopt;
        const double density = pdf(wi, s->wo);
        if (!(density > 0)) return std::nullopt;
        return ModelSample{s->wo, eval(wi, s->wo) * (std::abs(s->wo.z) / density), density};
    }

    double pdf(const Vec3d& wi, const Vec3d& wo) const override {
        if (!sampling_) return 0;
        double sum = 0;
        for (const Member& m : members_)
            sum += m.model->pdf(wi, wo);
        return sum / double(members_.size());
    }

  private:
    struct Member {
        std::unique_ptr<Model> model;
        /// weights[c]: the sRGB of one unit in channel c.
        std::array<Rgbd, 3> weights;
        Rgbd project(const Rgbd& f) const {
            return weights[0] * f[0] + weights[1] * f[1] + weights[2] * f[2];
        }
    };
    class Evaluator final : public IncidentEvaluator {
      public:
        Evaluator(const std::vector<Member>& members,
                  std::vector<std::unique_ptr<IncidentEvaluator>> prepared)
            : members_(members), prepared_(std::move(prepared)) {}
        Rgbd eval(const Vec3d& wo) const override {
            Rgbd sum(0.0);
            for (std::size_t i = 0; i < members_.size(); ++i)
                sum = sum + members_[i].project(prepared_[i]->eval(wo));
            return sum;
        }
        /// Each member's evaluator for one thread where it has one (keeping what depends on
        /// wo.z alone), else a forwarding one to the shared evaluator.
        std::unique_ptr<IncidentEvaluator> for_one_thread() const override {
            std::vector<std::unique_ptr<IncidentEvaluator>> own;
            own.reserve(prepared_.size());
            bool any = false;
            for (const auto& p : prepared_) {
                std::unique_ptr<IncidentEvaluator> one = p->for_one_thread();
                any = any || one != nullptr;
                own.push_back(one ? std::move(one) : std::make_unique<Shared>(*p));
            }
            if (!any) return nullptr;
            return std::make_unique<Evaluator>(members_, std::move(own));
        }

      private:
        /// A member evaluator that serves every thread, used through a reference.
        class Shared final : public IncidentEvaluator {
          public:
            explicit Shared(const IncidentEvaluator& e) : e_(e) {}
            Rgbd eval(const Vec3d& wo) const override { return e_.eval(wo); }

          private:
            const IncidentEvaluator& e_;
        };
        const std::vector<Member>& members_;
        std::vector<std::unique_ptr<IncidentEvaluator>> prepared_;
    };

    std::vector<Member> members_;
    std::string name_;
    Support support_;
    bool sampling_ = false;
};

}  // namespace

std::unique_ptr<Model> make_spectral_projection(const ModelFactory& factory, const Stack& stack,
                                                const SpectralQuadrature& quadrature) {
    std::unique_ptr<Model> at_channels = factory(stack);
    if (at_channels->integrates_spectrum()) return at_channels;
    return std::make_unique<SpectralProjection>(factory, stack, quadrature);
}

}  // namespace lamina

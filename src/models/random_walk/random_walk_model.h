#pragma once
// The `random-walk` model: the stack's per-query stochastic estimator (randomwalk/random_walk.h)
// behind the Model interface, so that `lamina eval`, the binned comparisons and the renderer find
// it in the one registry table. The estimator itself lives in lamina_randomwalk, which knows
// nothing of models; the models library wraps it (docs/architecture.md).
//
// eval(wi, wo) is a deterministic function of (wi, wo, seed): the walks of one query use the
// counter-based generator keyed by (seed, hash of the two directions' bits, walk index).

#include "models/model.h"
#include "randomwalk/random_walk.h"

#include <cstdint>
#include <memory>

namespace lamina {

class RandomWalkModel final : public Model {
  public:
    /// `transport`: the physics the walks follow (layers/transport_settings.h); its named
    /// settings are the model's options (`microsurface`, `transmission-masking`).
    RandomWalkModel(const Stack& stack, std::uint64_t samples, std::uint64_t seed,
                    const TransportSettings& transport = {});

    std::string name() const override { return "random-walk"; }
    Support support() const override;
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const override;
    std::vector<DeltaLobe> delta_lobes(const Vec3d& wi) const override;

    /// The estimate with its standard error (what `lamina eval` prints).
    RandomWalkEstimate estimate(const Vec3d& wi, const Vec3d& wo) const;

    /// The exit density of the walk's sampling at wo (RandomWalkStack::pdf; `lamina eval --pdf`),
    /// with the same walks count and a stream of its own. Model has no pdf in its interface (the
    /// analytic models do not sample), so this lives here.
    RandomWalkPdf pdf_estimate(const Vec3d& wi, const Vec3d& wo) const;

    void set_samples(std::uint64_t n) { samples_ = n; }
    void set_seed(std::uint64_t s) { seed_ = s; }
    const RandomWalkStack& walker() const { return walker_; }
    /// The stack seen from below (flipped_stack), for light meeting a transmitting stack from
    /// its bottom side (the renderer's transparent spheres); null for an opaque base.
    const RandomWalkStack* flipped_walker() const { return flipped_.get(); }

  private:
    RandomWalkStack walker_;
    std::unique_ptr<RandomWalkStack> flipped_;
    std::uint64_t samples_, seed_;
};

/// The model options that name `transport` (random_walk_options's), as KEY=VALUE assignments.
std::vector<std::string> random_walk_assignments(const TransportSettings& transport);

/// The stream of a query: a hash of the two directions' bits (splitmix64 finalizer, Steele et al.
/// 2014), so that different queries use independent walks.
std::uint64_t query_stream(const Vec3d& wi, const Vec3d& wo);

/// The registry's entry points. The options are the walks per query (`samples`), their `seed`,
/// and the transport settings that take named values (every enum and on/off switch of
/// TransportSettings, under its setting's name with '-' for '_'); the numbers among them keep
/// their defaults.
std::vector<OptionSpec> random_walk_options();
std::unique_ptr<Model> make_random_walk(const Stack& stack, const ModelOptions& options);

}  // namespace lamina

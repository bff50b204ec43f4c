#pragma once
// The analytic layered BRDF models lamina compares (docs/models.md).
//
// A Model is built for one Stack and one set of Options (the documented ablation flags) and then
// evaluated like any BSDF in lamina (physics/bsdf.h): eval(wi, wo) is the radiance BSDF from the
// light direction wi to the viewer wo, in 1/sr, cosine excluded; wo below the surface is the BTDF.
// Construction never fails for a well-formed stack: a configuration the model cannot represent
// reports support().brdf/btdf = false with the reason, and the callers (eval, the study) report
// "not supported: reason" instead of using its (zero) values.
//
// Smooth interfaces give delta lobes, which eval() leaves out (their value is infinite at one
// direction); delta_lobes(wi) lists them with their energies so that bin averages can add
// energy / Ω⊥ to the bin they hit. Virtual calls are fine here: this is not the particle hot path.
// Nothing in eval/prepare/delta_lobes throws.

#include "core/rgb.h"
#include "core/vec.h"
#include "layers/stack.h"

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace lamina {

/// The ablation flags of a model: key → value, validated against the model's OptionSpecs.
using ModelOptions = std::map<std::string, std::string>;

/// One flag a model accepts: its key, allowed values, default, and what it changes.
struct OptionSpec {
    std::string key;
    std::vector<std::string> values;
    std::string default_value;
    std::string help;
};

/// What a model can represent for its stack.
struct Support {
    bool brdf = false;
    bool btdf = false;
    /// Why brdf or btdf is false (empty when both are supported).
    std::string reason;
};

/// A delta lobe (smooth interfaces): all its energy leaves along `direction`.
struct DeltaLobe {
    Vec3d direction;
    /// ∫ f |cos θo| dωo over the lobe: the flux fraction it carries (RGB).
    Rgbd energy;
};

/// A direction drawn by Model::sample: wo, its density (solid angle) and eval·|cos θo|/pdf.
struct ModelSample {
    Vec3d wo;
    Rgbd weight;
    double pdf = 0.0;
};

/// A model with everything that depends only on the incident direction already computed (e.g.
/// the lobe statistics of the forward Belcour variants). eval(wo) == Model::eval(wi, wo).
/// eval may be called from several threads at once.
class IncidentEvaluator {
  public:
    virtual ~IncidentEvaluator() = default;
    virtual Rgbd eval(const Vec3d& wo) const = 0;

    /// An evaluator of the same incidence for one thread's run of evaluations (bin_model takes
    /// one per block of θ rows, whose nodes come a line of one cos θo at a time), or null where
    /// this one serves every thread as well. It may keep what depends on wo.z alone between calls,
    /// and returns the same values as this one, bit for bit.
    virtual std::unique_ptr<IncidentEvaluator> for_one_thread() const { return nullptr; }
};

/// The IncidentEvaluator of a model that splits its evaluation in two, `typename M::Incident
/// M::incident(wi)` (everything that depends on wi alone) and `Rgbd M::eval_with(incident, wo)`:
/// the WW family, the production coats and lamina-1 return one from prepare().
template <typename M>
class SplitIncidentEvaluator final : public IncidentEvaluator {
  public:
    SplitIncidentEvaluator(const M& model, const Vec3d& wi)
        : model_(model), incident_(model.incident(wi)) {}
    Rgbd eval(const Vec3d& wo) const override { return model_.eval_with(incident_, wo); }

  private:
    const M& model_;
    typename M::Incident incident_;
};

/// The IncidentEvaluator of a split model (as SplitIncidentEvaluator) with a part of its
/// evaluation that depends on wo.z alone: `typename M::View M::view(double mu_o)` for μo > 0 and
/// `Rgbd M::eval_in_view(incident, wo, view)`, equal to `eval_with(incident, wo)` bit for bit
/// when view = view(wo.z) (so neither is inlined: with FMA contraction an inlined copy may round
/// differently). Its evaluator for one thread keeps the last few views it computed.
template <typename M>
class ViewKeepingEvaluator final : public IncidentEvaluator {
  public:
    ViewKeepingEvaluator(const M& model, const Vec3d& wi, bool keep_views = false)
        : model_(model), wi_(wi), incident_(model.incident(wi)), keep_views_(keep_views) {}

    Rgbd eval(const Vec3d& wo) const override {
        if (!keep_views_ || !(wo.z > 0)) return model_.eval_with(incident_, wo);
        for (const Kept& kept : kept_)
            if (kept.filled && kept.mu_o == wo.z)
                return model_.eval_in_view(incident_, wo, kept.view);
        Kept& slot = kept_[next_];
        next_ = (next_ + 1) % kKept;
        slot = {true, wo.z, model_.view(wo.z)};
        return model_.eval_in_view(incident_, wo, slot.view);
    }

    std::unique_ptr<IncidentEvaluator> for_one_thread() const override {
        return std::make_unique<ViewKeepingEvaluator>(model_, wi_, true);
    }

  private:
    /// A rectangle's three cosines and, bisected in θ, its children's six.
    static constexpr std::size_t kKept = 6;
    struct Kept {
        bool filled = false;
        double mu_o = 0;
        typename M::View view{};
    };
    const M& model_;
    Vec3d wi_;
    typename M::Incident incident_;
    bool keep_views_;
    mutable Kept kept_[kKept]{};
    mutable std::size_t next_ = 0;
};

class Model {
  public:
    virtual ~Model() = default;

    virtual std::string name() const = 0;
    virtual Support support() const = 0;

    /// Radiance BSDF (1/sr, no cosine), delta lobes excluded. wi.z > 0; wo on either side. Zero
    /// on a side the model does not support (check support() first).
    virtual Rgbd eval(const Vec3d& wi, const Vec3d& wo) const = 0;

    /// Per-incidence precomputation; the default simply forwards to eval(wi, ·).
    virtual std::unique_ptr<IncidentEvaluator> prepare(const Vec3d& wi) const;

    /// Delta lobes for incidence wi (empty when every interface the model uses is rough).
    virtual std::vector<DeltaLobe> delta_lobes(const Vec3d& /*wi*/) const { return {}; }

    /// Directions where the model's lobes peak (narrow lobes hide there): binned quadrature always
    /// refines towards them. Default: the mirror direction of wi.
    virtual std::vector<Vec3d> peak_directions(const Vec3d& wi) const;

    /// Importance sampling, for models a renderer can sample (physics/bsdf.h conventions):
    /// sample(wi, u) draws wo from the density pdf(wi, wo) (solid angle, 1/sr, either side) from
    /// three uniforms in [0, 1); the sample's weight is eval(wi, wo)·|cos θo| / pdf. Delta lobes
    /// are not sampled here. Models without a sampler keep the defaults: has_sampling() false,
    /// sample() empty, pdf() 0. Nothing here throws.
    virtual bool has_sampling() const { return false; }
    virtual std::optional<ModelSample> sample(const Vec3d& /*wi*/, const Vec3d& /*u*/) const {
        return std::nullopt;
    }
    virtual double pdf(const Vec3d& /*wi*/, const Vec3d& /*wo*/) const { return 0.0; }
    /// Whether eval already returns a colour (linear sRGB) rather than values at the stack's
    /// channel wavelengths: a shipped film that integrates its spectrum against the CIE functions
    /// itself (three.js's, Cycles'). On a spectral stack such a model is evaluated once, on the
    /// stack at its channels' wavelengths, not projected (models/spectral_projection.h).
    virtual bool integrates_spectrum() const { return false; }
};

/// Mirror direction of wi about the macro normal.
inline Vec3d mirror_direction(const Vec3d& wi) {
    return {-wi.x, -wi.y, wi.z};
}

/// Reads an option's value (the registry has already validated and filled in every default).
const std::string& option_value(const ModelOptions& options, const std::string& key);

/// The stack shape of the Weidlich–Wilkie family and of WW' (docs/models.md): ambient | dielectric
/// coat (eta0, alpha0) | optional medium | base. Indices are relative: eta0 = η_coat/η_ambient;
/// the base's eta/k are relative to the coat (docs/physics.md §2).
struct CoatedStack {
    double eta0 = 1.5;
    double alpha0 = 0.0;
    Rgbd tau_a{0.0};
    Rgbd tau_s{0.0};
    Rgbd g{0.0};
    InterfaceType base_type = InterfaceType::Lambertian;
    Rgbd base_eta{1.0};  ///< relative to the coat (conductor: RGB; dielectric: all equal)
    Rgbd base_k{0.0};
    double base_alpha = 0.0;
    Rgbd albedo{0.0};
};

/// The relative indices the analytic models compute with: the real part η of an index relative to
/// the medium above in [1e-3, 1e3], the extinction κ in [0, 1e3] (NaN goes to the lower bound).
/// Every stack a file may hold (docs/stack-format.md, "Ranges") lies well inside (relative η in
/// [0.002, 10], κ ≤ 10): this changes nothing for them. It keeps squares, Jacobians and table
/// coordinates finite for stacks built in code with absurd indices (η = 1e308 or 1e-320).
inline constexpr double kRelativeEtaMin = 1e-3, kRelativeEtaMax = 1e3, kRelativeKMax = 1e3;
inline double model_relative_eta(double eta) {
    return eta >= kRelativeEtaMin ? (eta <= kRelativeEtaMax ? eta : kRelativeEtaMax)
                                  : kRelativeEtaMin;
}
inline double model_relative_k(double k) {
    return k >= 0 ? (k <= kRelativeKMax ? k : kRelativeKMax) : 0.0;
}
inline Rgbd model_relative_eta(const Rgbd& eta) {
    return {model_relative_eta(eta[0]), model_relative_eta(eta[1]), model_relative_eta(eta[2])};
}
inline Rgbd model_relative_k(const Rgbd& k) {
    return {model_relative_k(k[0]), model_relative_k(k[1]), model_relative_k(k[2])};
}

/// Extracts the coated shape, or explains (in `why`) why the stack has another shape. The
/// relative indices are those of model_relative_eta / model_relative_k. A stack with a thin film
/// has no coated shape ("thin films are not supported").
bool coated_stack(const Stack& stack, CoatedStack& out, std::string& why);

/// exp of each channel.
inline Rgbd exp_rgb(const Rgbd& x) {
    return {std::exp(x[0]), std::exp(x[1]), std::exp(x[2])};
}

/// The Beer–Lambert transmittance exp(−τ·path) of each channel, for a path length path = Σ 1/μ ≥ 0
/// in units of the medium's thickness (+∞ along the horizon or past total internal reflection): 1
/// where τ = 0 whatever the path (never 0·∞), 0 where τ > 0 and the path is infinite.
inline Rgbd beer_lambert(const Rgbd& tau, double path) {
    Rgbd t;
    for (int c = 0; c < 3; ++c)
        t[c] = tau[c] > 0 ? std::exp(-tau[c] * path) : 1.0;
    return t;
}

}  // namespace lamina

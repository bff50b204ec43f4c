#pragma once
// The study's error metrics (docs/study.md, "Metrics"; docs/formats.md): a model's binned
// lobe against the reference's, one channel at a time.

#include "core/grid.h"
#include "core/rgb.h"

#include <cmath>
#include <vector>

namespace lamina {

/// The energy below which misplaced_floor stops dividing by the reference's own energy: 5% of the
/// incident light (a directional albedo of 0.05).
inline constexpr double kMisplacedFloorEnergy = 0.05;

struct LobeMetrics {
    /// Σ|f − f̂|Ω⊥ / Σ f̂ Ω⊥: the fraction of the reference's energy misplaced, added or removed.
    /// NaN when the reference lobe holds no energy; unbounded where it holds almost none (a
    /// tinted slab's blue transmission at grazing incidence).
    double misplaced_energy = NAN;
    /// Σ|f − f̂|Ω⊥ / max(Σ f̂ Ω⊥, kMisplacedFloorEnergy): the misplaced energy relative to the
    /// reference's energy where that is at least 5% of the incident light, relative to 5% of it
    /// below. Always finite for finite tables; the study ranks models by it.
    double misplaced_floor = 0;
    double albedo_ref = 0;    ///< Σ f̂ Ω⊥
    double albedo_model = 0;  ///< Σ f Ω⊥
    /// (albedo_model − albedo_ref) / albedo_ref; NaN when albedo_ref = 0.
    double albedo_error = NAN;
    /// √(Σ Ω⊥ (f − f̂)² / Σ Ω⊥), 1/sr.
    double rmse = 0;
    /// The same on log(1 + f).
    double log_rmse = 0;
};

/// Metrics of `model` against `reference` (cos-weighted bin averages on `grid`) for one channel.
LobeMetrics lobe_metrics(const HemisphereGrid& grid, const std::vector<Rgbd>& reference,
                         const std::vector<Rgbd>& model, int channel);

/// The noise floor of a reference averaged from two independent halves a and b: the metrics
/// between the halves, halved (docs/formats.md explains the factor): what noise alone gives a
/// perfect model against (a + b)/2.
LobeMetrics noise_floor(const HemisphereGrid& grid, const std::vector<Rgbd>& half_a,
                        const std::vector<Rgbd>& half_b, int channel);

}  // namespace lamina

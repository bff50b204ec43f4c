#pragma once
// The study's error metrics (docs/study.md, "Metrics"; docs/formats.md): a model's binned
// lobe against the reference's, one channel at a time.

#include "core/grid.h"
#include "core/rgb.h"

#include <cmath>
#include <vector>

namespace lamina {

struct LobeMetrics {
    /// Σ|f − f̂|Ω⊥ / Σ f̂ Ω⊥: the fraction of the reference's energy misplaced, added or removed.
    /// NaN when the reference lobe holds no energy.
    double misplaced_energy = NAN;
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

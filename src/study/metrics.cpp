#include "study/metrics.h"

#include "core/check.h"

#include <algorithm>

namespace lamina {

LobeMetrics lobe_metrics(const HemisphereGrid& grid, const std::vector<Rgbd>& reference,
                         const std::vector<Rgbd>& model, int channel) {
    LAMINA_CHECK(reference.size() == grid.size() && model.size() == grid.size());
    double abs_diff = 0, ref_energy = 0, model_energy = 0, sq = 0, log_sq = 0, omega_total = 0;
    for (std::size_t j = 0; j < grid.size(); ++j) {
        const double omega = grid.projected_solid_angle(j);
        const double f_ref = reference[j][channel], f = model[j][channel];
        abs_diff += std::abs(f - f_ref) * omega;
        ref_energy += f_ref * omega;
        model_energy += f * omega;
        sq += (f - f_ref) * (f - f_ref) * omega;
        const double dl = std::log1p(std::max(f, 0.0)) - std::log1p(std::max(f_ref, 0.0));
        log_sq += dl * dl * omega;
        omega_total += omega;
    }
    LobeMetrics m;
    m.albedo_ref = ref_energy;
    m.albedo_model = model_energy;
    m.misplaced_floor = abs_diff / std::max(ref_energy, kMisplacedFloorEnergy);
    if (ref_energy > 0) {
        m.misplaced_energy = abs_diff / ref_energy;
        m.albedo_error = (model_energy - ref_energy) / ref_energy;
    }
    m.rmse = std::sqrt(sq / omega_total);
    m.log_rmse = std::sqrt(log_sq / omega_total);
    return m;
}

LobeMetrics noise_floor(const HemisphereGrid& grid, const std::vector<Rgbd>& half_a,
                        const std::vector<Rgbd>& half_b, int channel) {
    // Metrics of b against a, with a's energy as the normalizer, then halved: each bin's
    // difference of halves has twice the variance of one half; their mean has half of it, so
    // the noise of the mean is half the noise of the difference (in standard deviation: 1/2).
    LobeMetrics m = lobe_metrics(grid, half_a, half_b, channel);
    m.misplaced_energy /= 2;
    m.misplaced_floor /= 2;
    m.albedo_error /= 2;
    m.rmse /= 2;
    m.log_rmse /= 2;
    return m;
}

}  // namespace lamina

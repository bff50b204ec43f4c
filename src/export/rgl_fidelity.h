#pragma once
// How close a renderer reading an RGL .bsdf file gets to the file's source (docs/formats.md,
// "How close a renderer gets"): the two figures `lamina export --check` reports and the tests
// hold the default export settings to.
//
//   albedo  for each incidence θi ≤ 85°, the directional albedo of the file as a renderer reads it
//           (rgl_reader.h) against the source's, |a_file/a_source − 1| in the channel where it is
//           largest. Goal: ≤ 2% at every incidence. An anisotropic source is lit from φi = 0°,
//           45°, 90° and 135° at each θi (its BRDF is the same at φi + 180°: every interface's
//           distribution of normals is symmetric under a half turn).
//   values  at random direction pairs, ωi and ωo independent and uniform in solid angle over
//           θ ≤ 85°, |Y_file/Y_source − 1| of the luminance Y of f. Goal: ≤ 5% for 90% of pairs.
// A source given only at some incidences (a binned table) is compared at those (≤ 85°) alone.

#include "core/rgb.h"
#include "export/brdf_source.h"
#include "export/rgl_reader.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace lamina {

/// The goals (one owner: the CLI's report, the tests and docs/formats.md quote them).
struct RglFidelityGoals {
    static constexpr double kMaxThetaDeg = 85;  ///< both directions within this of the normal
    static constexpr double kAlbedo = 0.02;     ///< at every incidence
    static constexpr double kValue = 0.05;      ///< for kValueQuantile of the pairs
    static constexpr double kValueQuantile = 0.9;
};

struct RglFidelityOptions {
    double max_theta_deg = RglFidelityGoals::kMaxThetaDeg;
    double albedo_step_deg = 5;  ///< a model's albedo incidences: 0, step, … ≤ max_theta_deg
    int pairs = 20000;
    std::uint64_t seed = 1;
};

struct RglAlbedoRow {
    double theta_i_deg, phi_i_deg;
    Rgbd source, file;
    double error;  ///< |file/source − 1| in the worst channel (channels where source > 0)
};

struct RglFidelity {
    std::vector<RglAlbedoRow> albedo;
    std::vector<double> value_errors;  ///< sorted, one per pair where the source is > 0
    std::size_t pairs_skipped = 0;     ///< pairs where the source is 0

    double worst_albedo_error() const;
    /// The q-quantile of value_errors (0 when there are none).
    double value_error(double q) const;
    bool meets_goals() const;
};

/// The directional albedo ∫ f(wi, wo) cos θo dωo of a BRDF (the source's, or the file's as a
/// renderer reads it: what its estimate converges to), by quadrature over the half vector:
/// dωo = 4 (ωi·ωm) J(u) du, with u_x = t². Every specular lobe sits at ωm ≈ n whatever θi, and t
/// crowds the nodes there (θm ∝ t⁴), so that a lobe of α = 0.001 is resolved; 6-point
/// Gauss–Legendre on 48 × 48 cells of (t, u_y). Thread-safe if f is.
Rgbd directional_albedo(const std::function<Rgbd(const Vec3d&, const Vec3d&)>& f, const Vec3d& wi);

/// The figures for `file` against `source`. Parallel over incidences and pairs (OpenMP); the
/// result does not depend on the thread count. InputError naming `where` when the source is
/// given at no incidence ≤ max_theta_deg.
RglFidelity rgl_fidelity(const RglReader& file, const BrdfSource& source,
                         const RglFidelityOptions& options, const std::string& where);

}  // namespace lamina

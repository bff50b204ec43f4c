#pragma once
// The study's findings at a glance (summary.md, summary.json): per category and overall, each
// model's mean and worst misplaced energy (floored, the ranking metric, and relative) and albedo
// error, the ranking, the challenging cases, what is not supported, and the approximations
// assessment (errors by the factors that stress each approximation: coat roughness, base albedo,
// incidence).
//
// Two steps: compute_findings aggregates the metric rows into StudyFindings (plain data, nothing
// written); the writers turn the findings into JSON and Markdown. `lamina study` prints the
// headline from the same findings.
//
// Adding a section (e.g. findings per production engine): a member of StudyFindings below, filled
// in compute_findings, and one writer per format in summary.cpp, listed in the writers' section
// tables there (kJsonSections, kMarkdownSections) — nothing else changes.

#include "core/rgb.h"
#include "study/configurations.h"
#include "study/engine_findings.h"
#include "study/settings.h"

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace lamina {

/// A configuration is "challenging" when even its best supporting model misplaces more than this
/// fraction of the reference's reflected energy (misplaced_floor, so that a channel where the
/// reference holds almost nothing cannot make it so) on average over incidences and channels, and
/// more than twice the noise floor (so that noise alone never makes a case challenging).
inline constexpr double kChallengingThreshold = 0.2;

/// Per configuration id, per incidence of the settings: the fraction of the incident energy (RGB)
/// the reference loses to its single-scattering microfacet interfaces (the energy budget's
/// lost_microsurface). Energy on neither side of the reference: a model that conserves it errs by
/// it, which the summary says next to the errors.
using ReferenceLoss = std::map<std::string, std::vector<Rgbd>>;

/// Where a worst value is: configuration, incidence, side, channel (0 r, 1 g, 2 b).
struct RowPlace {
    std::string config;
    double theta_i = 0;
    char side = 'R';
    int channel = 0;
    double phi_i = 0;  ///< the light's azimuth (said only where it is not 0)
};

/// One model over the supported rows of a group (NaN where no row has the value).
struct ModelAggregate {
    int rows = 0;  ///< supported rows (each has a misplaced_floor)
    double mean_misplaced_floor = NAN, worst_misplaced_floor = NAN;
    std::optional<RowPlace> worst_misplaced_floor_at;
    double mean_misplaced_floor_noise = NAN;  ///< the noise floor of misplaced_floor
    double mean_misplaced_energy = NAN, worst_misplaced_energy = NAN;
    std::optional<RowPlace> worst_misplaced_energy_at;
    double mean_noise_floor = NAN;  ///< the noise floor of misplaced_energy
    double mean_abs_albedo_error = NAN, worst_albedo_error = NAN;
    std::optional<RowPlace> worst_albedo_error_at;
    std::size_t configurations_supported = 0;
};

/// A group of rows: a category's BRDF, its BTDF ("<category> BTDF"), "all" or "all BTDF".
struct GroupFindings {
    std::string name;
    int configurations = 0;
    std::map<std::string, ModelAggregate> models;
    /// The models with rows in the group, by mean misplaced_floor (each over what *it* supports).
    std::vector<std::string> ranking;
};

/// Like for like: the BRDF rows of the configurations whose BRDF every model supports (every
/// model but `left_out` when no configuration is supported by all).
struct CommonFindings {
    std::vector<std::string> ids;
    std::vector<std::string> ranking;  ///< by mean misplaced_floor; empty when `ids` is
    std::map<std::string, ModelAggregate> models;
    /// The models left out so that some configurations are common (fewest supported first).
    std::vector<std::string> left_out;
};

/// What the reference loses to its single-scattering microsurfaces over a category (or "all").
struct LossFindings {
    double mean = 0, worst = 0;
    RowPlace worst_at;  ///< side unused
};

struct ChallengingCase {
    std::string config, best_model;
    double best_mean_misplaced_floor = NAN, mean_misplaced_floor_noise = NAN;
    double best_mean_misplaced_energy = NAN;
};

/// A factor of the approximations assessment: its levels and each model's BRDF rows per level.
struct FactorFindings {
    std::string title, explanation;
    std::vector<std::string> levels;
    std::map<std::string, std::vector<ModelAggregate>> models;  ///< [model][level]
};

struct StudyFindings {
    // What was run.
    std::string preset, grid, microsurface;
    std::string physics;        ///< exact, bpb19 or custom (layers/transport_settings.h)
    bool polarization = false;  ///< the reference's light polarized (docs/physics.md §8)
    std::uint64_t particles = 0;
    std::vector<double> theta_i;
    std::vector<std::string> models, categories;
    std::size_t configurations = 0;
    std::map<std::string, std::string> category_of;  ///< configuration id → category

    // The sections, in the order summary.md shows them.
    std::vector<GroupFindings> groups;  ///< categories, their BTDFs, "all", "all BTDF"
    CommonFindings common;
    std::map<std::string, LossFindings> reference_loss;  ///< per category and "all"
    std::vector<ChallengingCase> challenging;
    std::vector<FactorFindings> assessment;
    /// model → configuration → the sides it does not support ("R", "T" or "RT").
    std::map<std::string, std::map<std::string, std::string>> not_supported;
    /// For engine developers (study/engine_findings.h): empty when no production coat ran.
    EngineFindings engine;

    /// The group called `name`, or nullptr.
    const GroupFindings* group(const std::string& name) const;
};

/// Aggregates the rows (nothing is written). `lost` may lack configurations (then nothing is said
/// of their loss).
StudyFindings compute_findings(const std::vector<StudyConfiguration>& configs,
                               const StudySettings& settings,
                               const std::vector<std::string>& models,
                               const std::vector<MetricRow>& rows, const ReferenceLoss& lost = {});

/// summary.json of the findings (docs/formats.md).
nlohmann::json findings_json(const StudyFindings& findings);
/// summary.md of the findings.
std::string findings_markdown(const StudyFindings& findings);
/// The "## Findings" section of summary.md alone: what `lamina study` prints.
std::string findings_headline(const StudyFindings& findings);

/// Writes summary.md and summary.json into out_dir (atomically; a file whose content is unchanged
/// is not rewritten). Returns how many of the two it wrote.
int write_summary(const std::filesystem::path& out_dir, const StudyFindings& findings);

}  // namespace lamina

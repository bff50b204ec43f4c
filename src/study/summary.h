#pragma once
// The study's findings at a glance (summary.md, summary.json): per category and overall, each
// model's mean and worst misplaced energy and albedo error, the ranking, the challenging cases,
// what is not supported, and the approximations assessment (errors by the factors that stress
// each approximation: coat roughness, base albedo, incidence).

#include "study/configurations.h"
#include "study/study.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace lamina {

/// A configuration is "challenging" when even its best supporting model misplaces more than this
/// fraction of the reference's reflected energy on average over incidences and channels (and more
/// than twice the noise floor, so that noise alone never makes a case challenging).
inline constexpr double kChallengingThreshold = 0.2;

/// Per configuration id, per incidence of the settings: the fraction of the incident energy (RGB)
/// the reference loses to its single-scattering microfacet interfaces (the energy budget's
/// lost_microsurface). Energy on neither side of the reference: a model that conserves it errs by
/// it, which the summary says next to the errors.
using ReferenceLoss = std::map<std::string, std::vector<Rgbd>>;

/// Writes summary.md and summary.json into out_dir (atomically). `lost` may lack configurations
/// (then nothing is said of their loss).
void write_summary(const std::filesystem::path& out_dir,
                   const std::vector<StudyConfiguration>& configs, const StudySettings& settings,
                   const std::vector<std::string>& models, const std::vector<MetricRow>& rows,
                   const ReferenceLoss& lost = {});

}  // namespace lamina

#pragma once
// The study (docs/study.md): for every configuration, the reference (the
// goniophotometer, resumable, as two halves for the noise floor) and every model on the same bins,
// compared by the study's metrics. Writes the study directory of docs/formats.md.

#include "study/configurations.h"
#include "study/reference.h"
#include "study/settings.h"
#include "study/summary.h"

#include <chrono>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace lamina {

/// Particles per incidence of the presets: quick 10⁶ (demo and CI), standard 10⁷, paper 1.6·10⁸
/// (the original study's budget). InputError naming --preset otherwise.
std::uint64_t preset_particles(const std::string& preset);

/// The models the study compares: settings.models, or every deterministic model of the registry
/// when empty; with settings.ablations, then the one-flag variants of each production model
/// among them; then the external models. Names may carry flags ("openpbr:darkening=off",
/// models/registry.h). InputError naming --models for a name the registry lacks or a flag it
/// does not have, and naming --model-table for an external name already taken.
std::vector<std::string> study_models(const StudySettings& settings);

/// The reference piece of `config` lit at `incidence` in a study with `settings`
/// (study/reference.h): with Stokes tallies where settings.reference_stokes and the reference is
/// polarized and not spectral.
ReferenceKey study_reference_key(const StudyConfiguration& config, const StudyIncidence& incidence,
                                 const StudySettings& settings);

/// Where a study in `out_dir` keeps its reference pieces (study/reference.h).
std::filesystem::path reference_cache_dir(const std::filesystem::path& out_dir);

/// What a run did, to tell an incremental re-run from a fresh one: every count is of work done in
/// this run, not of what it found done.
struct StudyWork {
    std::size_t reference_pieces_computed = 0;  ///< (configuration, incidence) simulated
    std::size_t model_tables_computed = 0;      ///< (configuration, model) binned and compared
    std::size_t model_tables_reused = 0;        ///< (configuration, model) read from the cache
    std::size_t configurations_written = 0;     ///< configs/<id>/ with a file (re)written
    std::size_t configurations_unchanged = 0;   ///< configs/<id>/ whose inputs did not change
    std::size_t files_written = 0;  ///< study.json, metrics.csv, summary.json, summary.md
};

/// Where a run's time went (describe_times): per phase and per model, the wall time and the
/// process's CPU time (all threads) in seconds. Measured, not stored: a re-run's are its own.
struct StudyTimes {
    struct Span {
        double wall = 0, cpu = 0;
    };
    Span reference;    ///< the reference pieces (simulated or read from the cache)
    Span models;       ///< the models' binned tables, every model
    Span comparisons;  ///< the models' metrics and albedos against the reference
    Span outputs;      ///< configs/<id>/ (tables packed, config.json) and the state
    Span summary;      ///< study.json, metrics.csv, the findings, summary.md and summary.json
    Span explorer;     ///< the explorer page (written after run_study, by the command)
    Span figures;      ///< the figures (likewise)
    std::vector<std::pair<std::string, Span>> per_model;  ///< the binned tables, in study order
};

/// Wall and process CPU time (all threads) from construction; add_to adds both to a span.
class PhaseTimer {
  public:
    PhaseTimer() : wall_(std::chrono::steady_clock::now()), cpu_(std::clock()) {}
    void add_to(StudyTimes::Span& span) const {
        span.wall +=
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
        span.cpu += double(std::clock() - cpu_) / CLOCKS_PER_SEC;
    }

  private:
    std::chrono::steady_clock::time_point wall_;
    std::clock_t cpu_;
};

struct StudyResult {
    std::vector<MetricRow> rows;  ///< metrics.csv
    StudyFindings findings;       ///< summary.md, summary.json
    StudyWork work;
    StudyTimes times;
};

/// InputError unless the reference has two particles per incidence at least: each piece is
/// simulated in two halves, whose difference is the noise floor (study/reference.h). run_study
/// checks it; a caller that computes pieces before (the processes under mpirun) checks it first.
void check_reference_particles(const StudySettings& settings);

/// Runs (or resumes) the study into `out_dir`; each configuration at its incidences, on its grid
/// (study_incidences, study_grid: an anisotropic one, or any under --phi-i ≠ 0, unfolded).
/// Incremental: each configuration's outputs carry the digest of their inputs (the reference
/// pieces' keys, each model's name, options and lamina version, the stack, incidences, grid and
/// table format; cache/study/<id>.json), and work whose inputs are unchanged is read back, not
/// redone; a file whose content is unchanged is not rewritten. Progress with an overall ETA goes to
/// stderr when it is a terminal.
StudyResult run_study(const std::vector<StudyConfiguration>& configs, const StudySettings& settings,
                      const std::filesystem::path& out_dir);

/// One line saying what a run did ("0 reference pieces simulated, 0 model tables computed (420
/// reused), 0 configurations written (60 unchanged), 0 summary files written").
std::string describe_work(const StudyWork& work);

/// Where a run's time went, one line per phase and the `slowest` models' tables, each as wall /
/// CPU seconds ("Time (wall / CPU s): reference 42.0 / 83.1, ...").
std::string describe_times(const StudyTimes& times, std::size_t slowest = 5);

/// Checks an external model's table against the study's grid and incidences and the stack's sides
/// (InputError naming `where`, saying what differs).
void check_external_table(const BinnedTable& table, const HemisphereGrid& grid,
                          const std::vector<double>& theta_i_deg, bool transmits,
                          const std::string& where);

/// The table of a configuration's incidences (in order) from tables of one light azimuth each:
/// `at_azimuth(theta_i_deg, phi_i_deg)` gives the table of the incidences lit from phi_i_deg (their
/// θi in the incidences' order), called once per distinct azimuth, in order of first appearance
/// (once for a folded configuration); its lobes are gathered back in the incidences' order. A
/// table with neither side is returned as it is (not supported). InputError naming `where` when the
/// tables of two azimuths differ in grid or sides, or one has not as many incidences as asked for.
BinnedTable gather_azimuths(const std::vector<StudyIncidence>& incidences, const std::string& where,
                            const std::function<BinnedTable(const std::vector<double>& theta_i_deg,
                                                            double phi_i_deg)>& at_azimuth);

/// metrics.csv text of the rows.
std::string metrics_csv(const std::vector<MetricRow>& rows);

}  // namespace lamina

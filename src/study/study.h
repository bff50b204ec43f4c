#pragma once
// The study (issue 5; ../shared/study.md): for every configuration, the reference (the
// goniophotometer, resumable, as two halves for the noise floor) and every model on the same bins,
// compared by the study's metrics. Writes the study directory of docs/formats.md.

#include "core/grid.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"
#include "study/metrics.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace lamina {

struct StudySettings {
    std::string preset = "quick";
    std::uint64_t particles = 1'000'000;  ///< per incidence (both halves together)
    std::uint64_t seed = 1;
    std::vector<double> theta_i_deg{0, 15, 30, 45, 60, 70, 80};
    HemisphereGrid grid{90, 90};
    std::vector<std::string> models;                   ///< registry names; empty: every model
    int threads = 0;                                   ///< 0: all cores
    Kernel kernel = Kernel::Simd;                      ///< the reference's particle kernel
    Microsurface microsurface = Microsurface::Single;  ///< the reference's rough interfaces
    /// The reference's refraction masking on single-scattering rough dielectrics.
    TransmissionMasking transmission_masking = TransmissionMasking::Smith;
    bool quiet = false;  ///< no per-configuration lines on stdout
};

/// Particles per incidence of the presets: quick 10⁶ (demo and CI), standard 10⁷, paper 1.6·10⁸
/// (the original study's budget). InputError naming --preset otherwise.
std::uint64_t preset_particles(const std::string& preset);

/// One row of metrics.csv.
struct MetricRow {
    std::string config, category, model;
    double theta_i = 0;
    char side = 'R';
    int channel = 0;
    bool supported = false;
    LobeMetrics metrics;  ///< model against the reference (when supported)
    LobeMetrics floor;    ///< the reference's noise floor
};

inline constexpr const char* kMetricsCsvHeader =
    "config,category,model,theta_i,side,channel,misplaced_energy,albedo_ref,albedo_model,"
    "albedo_error,rmse,log_rmse,noise_floor,supported";

/// The models the study compares: settings.models, or every deterministic model of the registry
/// when empty. InputError naming --models for a name the registry lacks.
std::vector<std::string> study_models(const StudySettings& settings);

/// Where a study in `out_dir` keeps its reference pieces (study/reference.h).
std::filesystem::path reference_cache_dir(const std::filesystem::path& out_dir);

/// Runs (or resumes) the study into `out_dir`; returns the metric rows it wrote. Progress with an
/// overall ETA goes to stderr when it is a terminal.
std::vector<MetricRow> run_study(const std::vector<StudyConfiguration>& configs,
                                 const StudySettings& settings,
                                 const std::filesystem::path& out_dir);

/// metrics.csv text of the rows.
std::string metrics_csv(const std::vector<MetricRow>& rows);

}  // namespace lamina

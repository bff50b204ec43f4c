#pragma once
// What a study runs with (StudySettings) and one row of what it measures (MetricRow, a line of
// metrics.csv): shared by the study (study.h) and its findings (summary.h).

#include "core/grid.h"
#include "core/incidences.h"
#include "core/table.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"
#include "study/metrics.h"

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lamina {

/// How the study stores configs/<id>/tables.lza and reference_se.lza (packed arrays,
/// docs/formats.md): float32, float16 (half the size; 11 significant bits, values below 6.1·10⁻⁵
/// 1/sr lose relative precision, below 6·10⁻⁸ become 0, above 65504 are clamped to it), or not at
/// all (metrics and summary only: no slices, albedo figures or explorer page).
enum class TablesFormat { Full, Half, None };
inline constexpr std::array<EnumName<TablesFormat>, 3> enum_names(TablesFormat) {
    return {{{TablesFormat::Full, "full", "float32"},
             {TablesFormat::Half, "half", "float16, half the size"},
             {TablesFormat::None, "none", "metrics and summary only"}}};
}
inline const char* enum_noun(TablesFormat) {
    return "a table format";
}

/// One incidence of a configuration in the study: θi and the azimuth φi the light comes from
/// (degrees; wi = (sin θi cos φi, sin θi sin φi, cos θi), as the goniophotometer's --phi-i).
struct StudyIncidence {
    double theta_i = 0, phi_i = 0;
};

/// A model evaluated elsewhere that joins the study as binned tables, like a built-in model: a
/// `--model-table NAME=FILE.csv` (a renderer's or a fit's values in the brdf.csv format) or a
/// Python model binned by the Python module. Each table must have the configuration's grid and
/// incidences (checked: InputError naming `source`).
struct ExternalModel {
    std::string name;
    std::string source;  ///< where the tables come from (a file, a pattern, "python"), for messages
    /// Whether `table` can answer an unfolded configuration (an anisotropic stack, or light from
    /// φi ≠ 0: its incidences' azimuths and the unfolded grid): a Python model can, evaluated at
    /// any wi; a model table cannot (brdf.csv rows carry θi alone), and such a configuration
    /// reports it not supported.
    bool unfolded = false;
    /// The table of one configuration at its incidences (in order) on its grid (study_incidences,
    /// study_grid): its R side (and T for a slab). A table with neither side (has_reflection and
    /// has_transmission both false) means the model does not cover the configuration (reported
    /// as not supported).
    std::function<BinnedTable(const StudyConfiguration&,
                              const std::vector<StudyIncidence>& incidences,
                              const HemisphereGrid& grid)>
        table;
};

struct StudySettings {
    std::string preset = "quick";
    /// The reference's settings (the goniophotometer's): incidences, particles per incidence (both
    /// halves together), seed, threads, grid, kernel and transport.
    SimulationSettings reference;
    std::vector<std::string> models;  ///< registry names; empty: every model
    /// Also every production model's one-flag ablations (models/registry.h ablation_variants),
    /// "NAME:KEY=VALUE": the summary's engine-developer section says which heuristic helps.
    bool ablations = false;
    TablesFormat tables = TablesFormat::Half;  ///< configs/<id>/tables.lza
    /// Ignore what an earlier run left (model tables, metrics, outputs) and compute it again; the
    /// reference pieces, keyed by everything they depend on, are still reused.
    bool recompute = false;
    bool quiet = false;                          ///< no per-configuration lines on stdout
    std::vector<ExternalModel> external_models;  ///< compared after the registry's models
    bool registry_models = true;  ///< false: no registry model unless named in `models`
    /// Tally the Stokes vectors of the light the reference reflects and transmits for unpolarized
    /// incident light and store them (configs/<id>/reference_stokes.lza, the explorer's
    /// polarization view), where the reference is polarized (transport.polarization, not a
    /// spectral run); study_reference_key. Off by default: the tallies cost about a third of
    /// the reference's time (docs/study.md).
    bool reference_stokes = false;

    /// The study's own settings (core/setting.h); the reference's are SimulationSettings'.
    template <typename Self, typename Visit>
    static void fields(Self& s, Visit&& visit) {
        visit({.name = "tables",
               .help = "configs/ID/tables.lza (compressed): full (float32), half (float16) or "
                       "none (metrics and summary only: no explorer page, slices or albedo "
                       "figures)",
               .key = SettingInfo::Key::No},
              s.tables);
        visit({.name = "reference_stokes",
               .help = "Store the polarized reference's Stokes vectors for unpolarized light "
                       "(configs/ID/reference_stokes.lza: the explorer's degree of polarization; "
                       "about a third more reference time)",
               .key = SettingInfo::Key::No},
              s.reference_stokes);
    }
};

/// The azimuths φi an anisotropic configuration is lit from (docs/study.md, "Brushed"): along
/// the +x axis, diagonally and across it. A configuration's tangents are set against this axis.
inline constexpr std::array<double, 3> kAnisotropicPhiIDeg = {0, 45, 90};

/// The incidences the study compares a configuration at, in order: for an isotropic stack, each
/// θi of reference.theta_i_deg at reference.phi_i_deg; for an anisotropic one, each θi at each
/// azimuth of kAnisotropicPhiIDeg (θi = 0 once: every azimuth is the same light there), θi
/// first. A configuration whose incidences are all at φi = 0 and whose stack is isotropic is
/// compared on the folded grid, any other on the unfolded one (study_grid).
std::vector<StudyIncidence> study_incidences(const Stack& stack,
                                             const SimulationSettings& reference);

/// The grid the study compares a configuration on: the goniophotometer's (simulation_grid):
/// reference.grid, unfolded over φ ∈ [0°, 360°) for an anisotropic stack or φi ≠ 0.
HemisphereGrid study_grid(const Stack& stack, const SimulationSettings& reference);

/// One row of metrics.csv.
struct MetricRow {
    std::string config, category, model;
    double theta_i = 0;
    double phi_i = 0;  ///< the incidence's azimuth (metrics.csv's phi_i column, when present)
    char side = 'R';
    int channel = 0;
    bool supported = false;
    LobeMetrics metrics;  ///< model against the reference (when supported)
    LobeMetrics floor;    ///< the reference's noise floor
};

/// metrics.csv's header; a study with a row at φi ≠ 0 has a phi_i column after theta_i
/// (metrics_csv, docs/formats.md).
inline constexpr const char* kMetricsCsvHeader =
    "config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,albedo_ref,"
    "albedo_model,albedo_error,rmse,log_rmse,noise_floor,misplaced_floor_noise,supported";

}  // namespace lamina

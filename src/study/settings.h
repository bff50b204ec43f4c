#pragma once
// What a study runs with (StudySettings) and one row of what it measures (MetricRow, a line of
// metrics.csv): shared by the study (study.h) and its findings (summary.h).

#include "core/grid.h"
#include "core/incidences.h"
#include "core/table.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"
#include "study/metrics.h"

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

/// A model evaluated elsewhere that joins the study as binned tables, like a built-in model: a
/// `--model-table NAME=FILE.csv` (a renderer's or a fit's values in the brdf.csv format) or a
/// Python plugin binned by the Python module. Each table must have the study's grid and
/// incidences (checked: InputError naming `source`).
struct ExternalModel {
    std::string name;
    std::string source;  ///< where the tables come from (a file, a pattern, "python"), for messages
    /// The table of one configuration: its R side (and T for a slab). A table with neither side
    /// (has_reflection and has_transmission both false) means the model does not cover the
    /// configuration (reported as not supported).
    std::function<BinnedTable(const StudyConfiguration&)> table;
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

    /// The study's own settings (core/setting.h); the reference's are SimulationSettings'.
    template <typename Self, typename Visit>
    static void fields(Self& s, Visit&& visit) {
        visit({.name = "tables",
               .help = "configs/ID/tables.lza (compressed): full (float32), half (float16) or "
                       "none (metrics and summary only: no explorer page, slices or albedo "
                       "figures)",
               .key = SettingInfo::Key::No},
              s.tables);
    }
};

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
    "config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,albedo_ref,"
    "albedo_model,albedo_error,rmse,log_rmse,noise_floor,misplaced_floor_noise,supported";

}  // namespace lamina

#pragma once
// The summary's section for engine developers (summary.md "For engine developers", summary.json
// "engine_developers"): for each production coat (models/registry.h group "production") and
// category, the albedo error against θi (is the coat too dark or too bright, and where), the
// lobe error (mean misplaced_floor, the ranking metric), what each heuristic does (its one-flag
// ablation "NAME:KEY=VALUE" against the model as shipped, on the same rows), each specification
// beside its shipped implementations (ModelEntry::specification), and the most accurate
// production coat per category. Computed from the metric rows alone (BRDF rows: the production
// coats have no BTDF); the summary calls it with the rows it already has.

#include "study/settings.h"

#include <nlohmann/json.hpp>

#include <map>
#include <string>
#include <vector>

namespace lamina {

struct EngineFindings {
    /// One production coat in one category, over its supported BRDF rows.
    struct Cell {
        std::string model, category;
        int configurations = 0;
        double mean_misplaced = 0;  ///< mean misplaced energy with the 5% floor (misplaced_floor)
        /// Mean signed albedo error (model − reference)/reference at each of theta_i (NaN where
        /// no row).
        std::vector<double> albedo_error;
    };
    /// A heuristic switched: the variant against its model as shipped, on the rows both support.
    struct Ablation {
        std::string variant, model, flag, category;
        int rows = 0;
        double shipped = 0, switched = 0;                ///< mean misplaced_floor of each
        double shipped_albedo = 0, switched_albedo = 0;  ///< mean |albedo error| of each
    };
    /// A production coat against what could replace it, on the rows all three cover: as shipped,
    /// with lamina's exact leaves (its `leaves=exact` variant, NaN where it was not run) and
    /// lamina-coat (docs/lamina-coat.md).
    struct Replacement {
        std::string model, category;
        int rows = 0;
        double shipped = 0, exact_leaves = 0, lamina_coat = 0;  ///< mean misplaced_floor
    };
    /// A specification (openpbr) and one implementation of it (openpbr-adobe), on the rows both
    /// support: each one's errors against the reference and how far their albedos are apart.
    struct Implementation {
        std::string specification, implementation, category;
        int rows = 0;
        double specification_error = 0, implementation_error = 0;    ///< mean misplaced_floor
        double specification_albedo = 0, implementation_albedo = 0;  ///< mean |albedo error|
        /// mean |a_implementation − a_specification| / a_reference: the two models' albedos
        /// apart, in units of the reference's
        double albedo_difference = 0;
    };
    std::vector<double> theta_i;
    std::vector<std::string> categories;
    std::vector<Replacement> replacements;  ///< when lamina-coat ran
    std::vector<Cell> cells;  ///< categories × production models, in the study's model order
    std::vector<Ablation> ablations;
    std::vector<Implementation> implementations;  ///< where a specification and its code ran
    /// Per category: the production coat with the lowest mean misplaced_floor, and the model of
    /// any family with the lowest (for scale).
    std::map<std::string, std::string> best_production, best_overall;
    std::map<std::string, double> best_production_error, best_overall_error;

    bool empty() const { return cells.empty(); }
};

/// Aggregates the rows (`models`: the study's, in its order). Empty when no production coat ran.
EngineFindings compute_engine_findings(const std::vector<MetricRow>& rows,
                                       const std::vector<std::string>& models);

/// The Markdown section (empty string when `f` is empty).
std::string engine_findings_markdown(const EngineFindings& f);

/// The same as JSON (null when `f` is empty).
nlohmann::json engine_findings_json(const EngineFindings& f);

}  // namespace lamina

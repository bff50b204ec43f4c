#pragma once
// The one table of analytic models (docs/style.md §12: an explicit registry, like Tungsten's
// BsdfFactory, no static self-registration). `lamina models`, `lamina eval`, the study and the
// explorer all find models here. Adding a model = its family's folder (or a new variant of a
// family: its default choices) + one row in registry.cpp (docs/architecture.md).

#include "models/model.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace lamina {

struct ModelEntry {
    std::string name;
    std::string description;  ///< one line
    std::string supports;     ///< bases and sides, one line
    std::function<std::vector<OptionSpec>()> options;
    std::function<std::unique_ptr<Model>(const Stack& stack, const ModelOptions& options)> make;
    /// A stochastic estimator (the random walk): its eval is noisy and slow, so the study's
    /// default model list and the analytic-model sweeps leave it out.
    bool stochastic = false;
    /// The family a reader compares it within (the explorer's model groups): "2019" (the
    /// models of the 2019 study), "successors" (Belcour 2018's statistical successors),
    /// "production" (the coats engines ship), "films" (a thin film's own model, on one
    /// interface), "lamina" (lamina's own model) or "reference" (the stochastic estimator).
    std::string group = "2019";
    /// The model represents anisotropic interfaces (alpha = [alpha_x, alpha_y], docs/physics.md
    /// §3): it is built for such a stack and evaluated on the unfolded grid. Otherwise it reports
    /// the stack as not supported.
    bool represents_anisotropy = false;
    /// The model represents a thin film (InterfaceSpec::film) on the stacks it supports, in its
    /// own form (docs/models.md, "Thin films"); for every other model the registry builds none
    /// for a filmed stack.
    bool films = false;
    /// A production coat as one implementation ships it: the registry name of the specification
    /// it implements, which lamina also has (openpbr-adobe and openpbr-materialx: "openpbr");
    /// the summary sets the two side by side. Empty otherwise.
    std::string specification = "";
};

/// The groups of ModelEntry::group, in the order the explorer shows them.
const std::vector<std::string>& model_groups();

/// Every model, in the order `lamina models` lists them.
const std::vector<ModelEntry>& model_registry();

/// The entry called `name`; InputError (naming `field`) listing the known names otherwise.
const ModelEntry& find_model(const std::string& name, const std::string& field = "--model");

/// Refuses a stochastic model (ModelEntry::stochastic) where it would be tabulated (lamina eval
/// --binned, export, compare, study, the Python module's binned): the adaptive quadrature of
/// models/numerics/binned.h reads a noisy estimator's scatter as quadrature error and would spend
/// its whole evaluation budget on every bin (on a coarse grid, without end), and an export grid
/// would hold noise. The random walk's table is the goniophotometer's, which traces the same
/// transport: InputError naming `file` and `field`, saying so.
void require_tabulable(const ModelEntry& entry, const std::string& file, const std::string& field);

/// Validates `key=value` assignments against the model's options and fills in the defaults.
/// InputError naming `field` for a malformed assignment, an unknown key (listing the known ones),
/// a value outside the allowed ones or a key given twice.
ModelOptions resolve_options(const ModelEntry& entry, const std::vector<std::string>& assignments,
                             const std::string& field = "--option");

/// A model named with its flags in one word, "NAME[:KEY=VALUE]..." (e.g. openpbr:darkening=off):
/// how the study names its ablation variants (no commas: the name is a CSV field and a list
/// item of --models). InputError naming `field` as find_model and resolve_options do.
struct ModelSpec {
    const ModelEntry* entry = nullptr;
    std::vector<std::string> assignments;
};
ModelSpec parse_model_spec(const std::string& spec, const std::string& field = "--model");

/// The one-flag ablations of a model: for each flag, each value other than the default, as
/// specs "NAME:KEY=VALUE" (the study's --ablations).
std::vector<std::string> ablation_variants(const ModelEntry& entry);

/// parse_model_spec + resolve_options (the spec's flags, then `assignments`) + make.
std::unique_ptr<Model> make_model(const std::string& name, const Stack& stack,
                                  const std::vector<std::string>& assignments = {});

}  // namespace lamina

#pragma once
// The study's configurations (docs/study.md): 60 two-interface stacks under air — plastics,
// metallic paints, frosted metals and slabs — built into lamina, the iridescent, brushed and
// dispersive categories of the larger presets, plus a user's own list.

#include "layers/stack.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace lamina {

struct StudyConfiguration {
    std::string id;        ///< stable, readable, used as a file name (e.g. plastic-P1-a0.05)
    std::string category;  ///< plastic, metallic-paint, frosted-metal, slab (or the user's)
    Stack stack;
    /// The parameters a reader filters by (the original explorer's widgets): alpha0, eta0, tau,
    /// base, alpha1, eta1, kappa1, rho — as display strings.
    std::map<std::string, std::string> parameters;
};

/// The 60 configurations of docs/study.md, in a fixed order.
std::vector<StudyConfiguration> builtin_configurations();

/// The "iridescent" category (docs/study.md): a clear coat over a metal carrying a thin film
/// (oxides, protective and interference films; absorbing, of varying thickness, on smooth and
/// rough metals), traced spectrally. The standard and paper presets add its six configurations to
/// the 60; the quick one (make demo) three of them (quick_only): a film on a rough metal, an
/// interference pigment under a rough coat and an absorbing oxide.
std::vector<StudyConfiguration> iridescent_configurations(bool quick_only = false);

/// The "brushed" category (docs/study.md): brushed aluminium, steel and gold (anisotropic GGX,
/// α_x ≠ α_y) under a smooth, a rough and a brushed clear coat, the coat's and the metal's
/// tangents aligned or turned 45° or 90° against each other. Compared on the unfolded grid, lit
/// from several azimuths (study_incidences). The standard and paper presets add it; the quick one
/// leaves it out.
std::vector<StudyConfiguration> brushed_configurations();

/// The "dispersive" category (docs/study.md): the slab category's glass over air with a dense
/// flint's index as a spectrum (n_d 1.785, Abbe number 25.7), smooth and rough; traced over
/// wavelengths, as the iridescent category. The standard and paper presets add it; the quick one
/// leaves it out.
std::vector<StudyConfiguration> dispersive_configurations();

/// The configurations a study runs by default at `preset`: builtin_configurations(), and
/// iridescent_configurations(), brushed_configurations() and dispersive_configurations() for every
/// preset but "quick", which adds iridescent_configurations(true) alone.
std::vector<StudyConfiguration> preset_configurations(const std::string& preset);

/// A configuration's id names a folder, a CSV cell and an --only item: InputError unless it is
/// non-empty without spaces, slashes, commas, quotes, control characters or a leading dot.
void check_configuration_id(const std::string& id, const std::string& where,
                            const std::string& field);
/// A category or a model's name is a CSV cell and a heading: InputError (naming it `what`) unless
/// it is non-empty without commas, quotes or control characters.
void check_study_label(const std::string& label, const char* what, const std::string& where,
                       const std::string& field);

/// What two configuration ids must differ in: their ASCII letters' case aside (ids name folders,
/// and two ids that differ in case only name one folder on a case-insensitive file system).
std::string configuration_id_key(const std::string& id);
/// The message for an id given twice (in that sense).
inline constexpr const char* kIdTwice =
    "appears twice (ids that differ only in case count as the same: they name one folder on "
    "some file systems)";

/// The largest configurations file load_configurations reads (64 MiB: four full-size stack
/// files' worth; core/atomic_file.h, read_file_bounded).
inline constexpr std::size_t kMaxConfigurationsFileBytes = std::size_t(64) << 20;

/// A user's list: {"configurations": [{"id": ..., "category": ..., "stack": {...}}, ...]}
/// (`category` optional, default "custom"), read as stack files are (parse_json_strict).
/// InputError naming the file and the JSON pointer, also for a file that cannot be read or holds
/// more than kMaxConfigurationsFileBytes.
std::vector<StudyConfiguration> load_configurations(const std::filesystem::path& path);

/// Keeps the configurations whose id matches `pattern` (a glob with * and ?; several patterns
/// separated by commas). InputError if none matches.
std::vector<StudyConfiguration> filter_configurations(std::vector<StudyConfiguration> configs,
                                                      const std::string& pattern);

/// The parameters of a stack of the study's shape, derived from it (for user configurations).
std::map<std::string, std::string> describe_parameters(const Stack& stack);

}  // namespace lamina

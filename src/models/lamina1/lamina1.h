#pragma once
// lamina-1 as a lamina Model: the header library include/lamina1/ (lamina-1 itself: the
// precomputation, eval, sample, pdf) over lamina's own tables, behind the Model interface, and
// its flags. docs/models.md, "lamina-1", derives the model; include/lamina1/bsdf.h lists its
// terms; each approximation is a choice of lamina1::Options (include/lamina1/options.h), which
// is this model's choices struct.

#include "lamina1/options.h"
#include "lamina1/tables.h"
#include "models/model.h"
#include "models/model_options.h"

#include <memory>
#include <vector>

namespace lamina {

/// The model's choices: the header library's options, declared once there.
using Lamina1Choices = lamina1::Options;

/// The model's flags.
const ModelOptionTable<Lamina1Choices>& lamina1_option_table();

/// The registry's entry points.
std::vector<OptionSpec> lamina1_options();
std::unique_ptr<Model> make_lamina1(const Stack& stack, const ModelOptions& options);

/// lamina's tables (FGD, the transmittance for `masking` and for the Smith masking, the slope
/// sums and, with `multiple`, the multiple-scattering albedos) as lamina-1 reads them: views of
/// the process-wide tables, computed or loaded from the cache on first use.
const lamina1::Tables& lamina1_tables(lamina1::Masking masking, bool multiple);
/// The process-wide tables that `choices` may read (the multiple-scattering table unless the
/// microsurfaces are single-scattering).
const lamina1::Tables& lamina1_tables(const Lamina1Choices& choices);

/// The data file a renderer ships beside the header (include/lamina1/tables.h describes it):
/// every table, both maskings, the FGD table as its bins.
std::string lamina1_tables_file();

/// The state of lamina-1's GLSL form for this stack and these flags (include/lamina1/gpu.h), or
/// nothing and why (a stack it does not cover).
std::vector<float> lamina1_gpu_state(const Stack& stack, const ModelOptions& options,
                                     std::string& why);

/// lamina-1's GLSL states for the explorer's live spheres (docs/explorer.md, "Live spheres"): the
/// stack's own state, and the per-material part of the state (its first lamina1::kGpuSlopeSum
/// floats and, for a slab with its bins, the `tail` floats after the slope-sum table; the table is
/// the same for every material) with one parameter at a time set to each of a few values, the
/// others the stack's: coat roughness `alpha0`, coat index `eta0` (a conductor or dielectric base
/// keeps its absolute index), grey coat absorption `tau_a`, base roughness `alpha1` (conductor and
/// dielectric bases) and grey base albedo `albedo` (Lambertian base). A value the GLSL form does
/// not cover is left out. Empty `state` and why where it does not cover the stack itself.
struct Lamina1GpuVariant {
    std::string parameter;
    double value = 0;
};
struct Lamina1GpuStates {
    std::vector<float> state;                 ///< the stack's own (include/lamina1/gpu.h)
    std::vector<Lamina1GpuVariant> variants;  ///< in the order of `heads`
    std::vector<float> heads;                 ///< `head` then `tail` floats per variant
    std::size_t head = 0;                     ///< lamina1::kGpuSlopeSum
    std::size_t tail = 0;  ///< the state's last floats: a slab's bins (0 without them)
};
Lamina1GpuStates lamina1_gpu_states(const Stack& stack, const ModelOptions& options,
                                    std::string& why);

/// A stack of the coated shape (coated_stack) as lamina-1's layers; false and why otherwise.
bool lamina1_layers(const Stack& stack, lamina1::Layers& layers, std::string& why);

}  // namespace lamina

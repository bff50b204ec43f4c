#pragma once
// What `lamina export` tabulates: a BRDF f(wi, wo) (1/sr, no cosine, reflection side, lamina's
// frame) from a model or from a binned table (a `simulate` output or a study configuration's
// source), and the incidences at which it is known.

#include "core/table.h"
#include "models/model.h"

#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace lamina {

struct BrdfSource {
    std::string name;
    /// f(wi, wo) for wi.z > 0, wo.z > 0 (thread-safe).
    std::function<Rgbd(const Vec3d& wi, const Vec3d& wo)> f;
    /// The incidences (degrees) the source is given at; empty: any (a model).
    std::vector<double> theta_i_deg;
    /// Whether f depends on the azimuths only through φo − φi (an isotropic stack); false for an
    /// anisotropic one, whose .bsdf file then holds slices in φi (rgl_bsdf.h).
    bool isotropic = true;
};

/// The BRDF of `model`, built for `stack` (which says whether it is isotropic). InputError naming
/// `where` when the model does not support the BRDF of its stack, or when it has delta lobes (a
/// smooth interface: no table format holds a Dirac).
BrdfSource model_brdf(std::shared_ptr<const Model> model, const Stack& stack,
                      const std::string& where);

/// A binned table's reflection side as a continuous BRDF at its incidences: f(wi, wo) bilinear in
/// (θo, φo) between the bins' centres (clamped to the edge centres), at the table's incidence
/// nearest θi, negative values (a spectral run's linear sRGB in a bin few particles reached) read
/// as 0. InputError naming `where` when the table has no reflection side, or when it is
/// unfolded (an anisotropic stack or light from φi ≠ 0): it holds one φi, and a BRDF file needs
/// every one.
BrdfSource table_brdf(const BinnedTable& table, const std::string& name, const std::string& where);

/// Y of linear sRGB / Rec. 709 primaries (ITU-R BT.709 luma weights).
inline double luminance(const Rgbd& c) {
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

}  // namespace lamina

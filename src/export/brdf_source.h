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
};

/// A model's BRDF. InputError naming `where` when the model does not support the BRDF of its stack,
/// or when it has delta lobes (a smooth interface: no table format holds a Dirac).
BrdfSource model_brdf(std::shared_ptr<const Model> model, const std::string& where);

/// A binned table's reflection side as a continuous BRDF at its incidences: f(wi, wo) bilinear in
/// (θo, φo) between the bins' centres (clamped to the edge centres), at the table's incidence
/// nearest θi. InputError naming `where` when the table has no reflection side.
BrdfSource table_brdf(const BinnedTable& table, const std::string& name, const std::string& where);

/// Y of linear sRGB / Rec. 709 primaries (ITU-R BT.709 luma weights).
inline double luminance(const Rgbd& c) {
    return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
}

}  // namespace lamina

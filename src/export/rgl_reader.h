#pragma once
// An RGL .bsdf file evaluated as pbrt-v4's MeasuredBxDF and Mitsuba 3's `measured` plugin
// evaluate it (docs/formats.md, "Exports"), so that `lamina export --check` can say how close a
// renderer gets to the file's source.
//
// With ωi the direction that parameterizes the tables (pbrt-v4's wo, Mitsuba 3's wi) and ωo the
// other, ωm = (ωi + ωo)/|ωi + ωo|:
//   f(ωi, ωo) |cos θo| = S(s) D(u(ωm)) / (4 σ(u(ωi))),
// u(ωm) with φm taken relative to φi in an isotropic file (one or two φi slices), as it is in an
// anisotropic one; s = the inverse of the VNDF warp at u(ωm), the warps of the incidence nodes
// around (φi, θi) blended by interpolating their masses (as the readers' PiecewiseLinear2D /
// Marginal2D do: bilinear_warp.h, BilinearWarp::masses), bilinearly in φi and θi (linearly in θi
// alone in an isotropic file, whose first slice is read); S bilinear in s and interpolated in the
// same way; θi past the last node reads the last node. Both readers divide by |cos θo|, the
// cosine of the direction that does NOT parameterize the tables. An anisotropic file whose φi
// slices span 2π/k (k = 2 or 4, Mitsuba 3's "reduction") holds one half or quarter of the
// azimuths: Mitsuba 3 mirrors ωi (and ωo with it) across the x axis (k = 2), and the y axis
// (k = 4), into the slices' range, and so does this reader.
//
// The colour is read from the spectra at 450, 550 and 650 nm, where lamina's upsampling of RGB
// puts blue, green and red exactly (a spectral renderer interpolates the same values), or from an
// `rgb` field when there is one.

#include "core/rgb.h"
#include "core/vec.h"
#include "export/bilinear_warp.h"
#include "export/tensor_file.h"

#include <string>
#include <vector>

namespace lamina {

class RglReader {
  public:
    /// A file check_rgl_bsdf accepts, with spectra at 450, 550 and 650 nm (or an `rgb` field) and
    /// φi increasing (an anisotropic file: its span 2π, π or π/2); InputError naming `where` and
    /// the field otherwise.
    RglReader(const TensorFile& file, const std::string& where);

    /// f(ωi, ωo) in 1/sr, cosine excluded, as a renderer reads it; 0 unless both are above the
    /// surface. Thread-safe.
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const;

    /// The incidence nodes (degrees).
    std::vector<double> theta_i_deg() const;

  private:
    std::vector<double> theta_nodes_, phi_nodes_;  ///< radians; phi_nodes_: {0} if isotropic
    bool isotropic_;
    int reduction_ = 1;                     ///< 2π over the span of an anisotropic file's φi
    std::vector<float> ndf_, sigma_, rgb_;  ///< rgb_: [φi, θi, channel, s_y, s_x]
    std::size_t ndf_nx_, ndf_ny_, sigma_nx_, sigma_ny_, s_nx_, s_ny_, vndf_nx_, vndf_ny_;
    std::vector<BilinearWarp> vndf_;  ///< one per (φi, θi), θi fastest
};

}  // namespace lamina

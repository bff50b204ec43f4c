#pragma once
// MERL BRDF database files, `.binary` (Matusik, Pfister, Brand & McMillan 2003, "A data-driven
// reflectance model", ACM TOG 22(3)), which BRDF Explorer, pbrt-v2 and layerlab read.
//
// Isotropic BRDFs in Rusinkiewicz's half/difference angles (1998): ωh = (ωi + ωo)/|ωi + ωo| with
// angles (θh, φh); ωd = ωi expressed in the frame of ωh (rotated by −φh about z, then by −θh
// about y), with angles (θd, φd). The file: three int32 (90, 90, 180), then 90·90·180 float64 per
// channel (red, green, blue planes), index ((θh index)·90 + θd index)·180 + φd index, with
//   θh index = ⌊√(θh/(π/2))·90⌋, θd index = ⌊θd/(π/2)·90⌋, φd index = ⌊φd/π·180⌋ (φd + π when
//   φd < 0: reciprocity), each clamped to its range,
// and values stored divided by the channel scales 1/1500, 1.15/1500, 1.66/1500 (a reader
// multiplies them back). Writing evaluates f at each bin's centre in these coordinates; a bin
// whose centre has ωi or ωo below the horizon holds 0.

#include "export/brdf_source.h"

#include <array>
#include <string>
#include <vector>

namespace lamina {

inline constexpr int kMerlThetaH = 90, kMerlThetaD = 90, kMerlPhiD = 180;
inline constexpr std::array<double, 3> kMerlScale = {1.0 / 1500, 1.15 / 1500, 1.66 / 1500};

struct MerlBrdf {
    std::vector<double> values;  ///< [channel][θh][θd][φd], already multiplied by kMerlScale

    /// f(ωi, ωo) by the file's nearest-bin lookup (0 below the horizon).
    Rgbd eval(const Vec3d& wi, const Vec3d& wo) const;
};

/// (θh, θd, φd) of a pair of directions (radians; φd in [0, π)).
std::array<double, 3> merl_half_diff(const Vec3d& wi, const Vec3d& wo);
/// The pair (ωi, ωo) of given half/difference angles with φh = 0.
std::array<Vec3d, 2> merl_directions(double theta_h, double theta_d, double phi_d);

/// The file's bytes for the BRDF. InputError naming the BRDF when it is anisotropic: the format's
/// half/difference angles drop φh, so it holds isotropic BRDFs only.
std::string merl_binary(const BrdfSource& brdf);
/// Parses a file (InputError naming `where` for a wrong size, wrong dimensions, or values that
/// are not finite).
MerlBrdf parse_merl(const std::string& bytes, const std::string& where);

}  // namespace lamina

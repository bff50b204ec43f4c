#pragma once
// Binned BRDF/BTDF tables: what the goniophotometer measures and what a model averaged over the
// same bins produces, in one format (docs/formats.md, `brdf.csv`):
//   theta_i,side,theta_lo,theta_hi,phi_lo,phi_hi,f_r,f_g,f_b,se_r,se_g,se_b
// one row per (incidence, side, θ bin, φ bin); angles in degrees; f is the cos-weighted bin
// average of the BSDF (1/sr), se its standard error (0 for deterministic models).

#include "core/grid.h"
#include "core/rgb.h"
#include "core/spherical.h"

#include <filesystem>
#include <string>
#include <vector>

namespace lamina {

/// One hemisphere of one incidence.
struct BinnedLobe {
    std::vector<Rgbd> f;   ///< cos-weighted bin averages, 1/sr, indexed by grid bin
    std::vector<Rgbd> se;  ///< standard errors (0 when deterministic)
};

struct BinnedTable {
    HemisphereGrid grid;
    std::vector<double> theta_i_deg;  ///< incidences, degrees
    bool has_reflection = true;
    bool has_transmission = false;
    /// lobes[incidence][0] = reflection, [1] = transmission (empty vectors when absent).
    std::vector<std::array<BinnedLobe, 2>> lobes;

    /// A table of zeros for these incidences and sides.
    static BinnedTable zeros(const HemisphereGrid& grid, const std::vector<double>& theta_i_deg,
                             bool reflection, bool transmission);

    BinnedLobe& lobe(std::size_t incidence, Side side) {
        return lobes[incidence][side == Side::Reflection ? 0 : 1];
    }
    const BinnedLobe& lobe(std::size_t incidence, Side side) const {
        return lobes[incidence][side == Side::Reflection ? 0 : 1];
    }

    /// Directional albedo Σ_j f_j Ω⊥_j of a lobe (RGB).
    Rgbd albedo(std::size_t incidence, Side side) const;

    /// The CSV text of the table (`brdf.csv` format), full round-trip precision.
    std::string to_csv() const;
    /// Reads a table written by to_csv (InputError naming `where`, the line and the column):
    /// values finite with |f| ≤ kMaxBinValue (a spectral run's sRGB may be negative), standard
    /// errors in [0, kMaxBinValue].
    static BinnedTable from_csv(const std::string& text, const std::string& where);
};

inline constexpr const char* kBrdfCsvHeader =
    "theta_i,side,theta_lo,theta_hi,phi_lo,phi_hi,f_r,f_g,f_b,se_r,se_g,se_b";

/// The largest bin value (1/sr) a table read back may hold (BinnedTable::from_csv).
inline constexpr double kMaxBinValue = 1e12;

}  // namespace lamina

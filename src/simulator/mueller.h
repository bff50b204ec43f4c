#pragma once
// The Mueller BRDF/BTDF of a stack per bin (docs/physics.md §8, docs/formats.md "mueller.npy"):
// the 4 × 4 matrix that turns the Stokes vector of the incident light (in the bin frame of the
// incident direction) into the Stokes vector leaving into each bin (in the bin frame of the exit
// direction), per channel, with standard errors, in 1/sr as the tables' f: its (0, 0) entry is the
// table of unpolarized light.
//
// Estimator. Four polarized runs of the goniophotometer with Stokes tallies, the incident light
// unpolarized (e0) and fully polarized along e1, e2 and e3 (s-polarized, linear at +45°,
// circular; SimulationSettings::incident_polarization 0–3), each with its own random numbers. By
// linearity column 0 is run 0's exit Stokes vector and column j is run j's minus run 0's. A bin
// folds the mirror-image patches φ and −φ (core/grid.h); mirroring the stack in its plane of
// incidence maps the Mueller matrix M of one patch to D M D on the other, D = diag(1, 1, −1, −1),
// in the bin frames (x ∝ ẑ × d flips with the mirror, so S2 and S3 change sign), so the exits into
// the patch y < 0 are counted as their mirror images: with U and L the flux sums of a run over the
// patches y ≥ 0 and y < 0,
//     M_ij = [U_i(run j) + D_ii D_jj L_i(run j) − (j > 0)(U_i(run 0) + D_ii D_jj L_i(run 0))] / (N
//     Ω⊥),
// whose per-particle values square to S_i² on either patch: the standard error of each run's term
// from its sums of S_i², added in quadrature across the independent runs.

#include "layers/stack.h"
#include "simulator/goniophotometer.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace lamina {

struct MuellerTable {
    HemisphereGrid grid;
    std::vector<double> theta_i_deg;
    bool transmits = false;
    /// Per [incidence][side][bin][channel] (index ((i · 2 + side) · n_bins + bin) · 3 + channel),
    /// the 16 entries row-major (m[4 i + j] = M_ij), 1/sr; zero for the transmission side of an
    /// opaque stack.
    std::vector<std::array<double, 16>> m, se;

    std::size_t index(std::size_t incidence, int side, std::size_t bin, int channel) const {
        return ((incidence * 2 + std::size_t(side)) * grid.size() + bin) * 3 + std::size_t(channel);
    }
};

/// The Stokes vectors of one run per bin, per channel: the flux sums over the patch y ≥ 0 (U) and
/// y < 0 (L) and the second moments over both, as fractions of the N incident particles.
struct BinStokes {
    std::array<double, 4> upper{}, lower{}, second{};
};
BinStokes bin_stokes(const IncidenceSums& sums, std::size_t entry, int channel, std::uint64_t n);

/// One run's term of a Mueller entry (i, j): the mean over the N particles of S_i leaving into the
/// bin, the exits into the patch y < 0 counted as their mirror images (`sign` = D_ii D_jj), and
/// the variance of that mean (the per-particle values square to S_i² on either patch).
struct StokesTerm {
    double mean = 0, var = 0;
};
StokesTerm folded_stokes_term(const BinStokes& b, int i, double sign, std::uint64_t n);

/// The Stokes vector leaving into each bin for unpolarized incident light: the Mueller table's
/// first column (below), which one run lit unpolarized (incident_polarization 0) with Stokes
/// tallies gives alone. Per channel, S0..S3 in 1/sr as the tables' f (S0 is f) and their
/// standard errors, in the bin's tabulation frame (docs/physics.md §8).
struct BinStokesVector {
    std::array<Rgbd, 4> s, se;
};
/// That vector for entry `entry` (side · n_bins + bin) of `sums`, a bin of projected solid angle
/// `projected_solid_angle`, from N = `n` particles.
BinStokesVector unpolarized_stokes(const IncidenceSums& sums, std::size_t entry,
                                   double projected_solid_angle, std::uint64_t n);

/// The Mueller table from four runs of the same stack and settings with Stokes tallies, run j lit
/// with incident_polarization j (checked).
MuellerTable mueller_table(const std::array<const SimulationResult*, 4>& runs);

/// Runs the goniophotometer four times (the settings' polarization must be on; run 0 is
/// `settings` itself with Stokes tallies, so its tables are the run without them) and returns the
/// runs; `on_progress` as simulate's.
std::array<SimulationResult, 4> simulate_mueller_runs(
    const Stack& stack, const SimulationSettings& settings,
    const std::function<void(std::uint64_t)>& on_progress = {});

/// mueller.npy and mueller_se.npy (float32 [incidence, side, θ bin, φ bin, channel, 4, 4]).
std::string mueller_npy(const MuellerTable& table, bool standard_error);

}  // namespace lamina

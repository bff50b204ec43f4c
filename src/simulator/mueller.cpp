#include "simulator/mueller.h"

#include "core/check.h"
#include "core/error.h"
#include "core/npy.h"
#include "simulator/tally.h"

#include <cmath>

namespace lamina {

namespace {
// D = diag(1, 1, −1, −1): the mirror image of a Stokes vector in the bin frames.
constexpr double kMirror[4] = {1, 1, -1, -1};
}  // namespace

BinStokes bin_stokes(const IncidenceSums& sums, std::size_t entry, int channel, std::uint64_t n) {
    LAMINA_CHECK(entry < sums.stokes.size());
    const auto& acc = sums.stokes[entry];
    const double inv_n = 1.0 / double(n);
    BinStokes b;
    for (int k = 0; k < 4; ++k) {
        b.upper[k] = double(acc[std::size_t(channel * 12 + k)]) / kSumScale * inv_n;
        b.lower[k] = double(acc[std::size_t(channel * 12 + 4 + k)]) / kSumScale * inv_n;
        b.second[k] = double(acc[std::size_t(channel * 12 + 8 + k)]) / kSqScale * inv_n;
    }
    return b;
}

StokesTerm folded_stokes_term(const BinStokes& b, int i, double sign, std::uint64_t n) {
    const double dn = n > 1 ? double(n - 1) : 1.0;
    StokesTerm t;
    t.mean = b.upper[std::size_t(i)] + sign * b.lower[std::size_t(i)];
    t.var = std::max(0.0, b.second[std::size_t(i)] - t.mean * t.mean) / dn;
    return t;
}

BinStokesVector unpolarized_stokes(const IncidenceSums& sums, std::size_t entry,
                                   double projected_solid_angle, std::uint64_t n) {
    BinStokesVector v;
    for (int c = 0; c < 3; ++c) {
        const BinStokes b = bin_stokes(sums, entry, c, n);
        for (int i = 0; i < 4; ++i) {
            // Column 0: the incident light unpolarized, D_00 = 1.
            const StokesTerm t = folded_stokes_term(b, i, kMirror[i], n);
            v.s[std::size_t(i)][c] = t.mean / projected_solid_angle;
            v.se[std::size_t(i)][c] = std::sqrt(t.var) / projected_solid_angle;
        }
    }
    return v;
}

MuellerTable mueller_table(const std::array<const SimulationResult*, 4>& runs) {
    const SimulationResult& base = *runs[0];
    const SimulationSettings& s = base.settings;
    for (int j = 0; j < 4; ++j) {
        const SimulationSettings& r = runs[j]->settings;
        LAMINA_CHECK(r.transport.polarization && r.stokes_tallies && r.incident_polarization == j);
        LAMINA_CHECK(r.particles == s.particles && r.theta_i_deg == s.theta_i_deg &&
                     r.grid.n_theta() == s.grid.n_theta() && r.grid.n_phi() == s.grid.n_phi());
        LAMINA_CHECK(runs[j]->sums.size() == s.theta_i_deg.size());
    }
    MuellerTable t;
    t.grid = s.grid;
    t.theta_i_deg = s.theta_i_deg;
    t.transmits = base.table.has_transmission;
    const std::size_t n_bins = s.grid.size();
    t.m.assign(s.theta_i_deg.size() * 2 * n_bins * 3, {});
    t.se.assign(t.m.size(), {});
    const std::uint64_t n = s.particles;
    for (std::size_t inc = 0; inc < s.theta_i_deg.size(); ++inc)
        for (int side = 0; side < (t.transmits ? 2 : 1); ++side)
            for (std::size_t bin = 0; bin < n_bins; ++bin) {
                const double omega = s.grid.projected_solid_angle(bin);
                const std::size_t entry = std::size_t(side) * n_bins + bin;
                for (int c = 0; c < 3; ++c) {
                    BinStokes b[4];
                    for (int j = 0; j < 4; ++j)
                        b[j] = bin_stokes(runs[j]->sums[inc], entry, c, n);
                    std::array<double, 16>& m = t.m[t.index(inc, side, bin, c)];
                    std::array<double, 16>& se = t.se[t.index(inc, side, bin, c)];
                    for (int i = 0; i < 4; ++i)
                        for (int j = 0; j < 4; ++j) {
                            // Run j's term, folded with the sign of entry (i, j), less run 0's
                            // for j > 0; the runs are independent.
                            const double sign = kMirror[i] * kMirror[j];
                            const StokesTerm run = folded_stokes_term(b[j], i, sign, n);
                            const StokesTerm run0 =
                                j > 0 ? folded_stokes_term(b[0], i, sign, n) : StokesTerm{};
                            m[std::size_t(4 * i + j)] = (run.mean - run0.mean) / omega;
                            se[std::size_t(4 * i + j)] = std::sqrt(run.var + run0.var) / omega;
                        }
                }
            }
    return t;
}

std::array<SimulationResult, 4> simulate_mueller_runs(
    const Stack& stack, const SimulationSettings& settings,
    const std::function<void(std::uint64_t)>& on_progress) {
    if (!settings.transport.polarization)
        throw InputError("command line", "--mueller", "the Mueller tables need --polarization on");
    std::array<SimulationResult, 4> runs;
    for (int j = 0; j < 4; ++j) {
        SimulationSettings s = settings;
        s.stokes_tallies = true;
        s.incident_polarization = j;
        runs[std::size_t(j)] = simulate(stack, s, on_progress);
    }
    return runs;
}

std::string mueller_npy(const MuellerTable& table, bool standard_error) {
    const std::vector<std::array<double, 16>>& src = standard_error ? table.se : table.m;
    std::vector<float> data;
    data.reserve(src.size() * 16);
    for (const auto& m : src)
        for (double x : m)
            data.push_back(float(x));
    return npy_float32(data, {table.theta_i_deg.size(), 2, std::size_t(table.grid.n_theta()),
                              std::size_t(table.grid.n_phi()), 3, 4, 4});
}

}  // namespace lamina

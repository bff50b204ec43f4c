// The Mueller tables (simulator/mueller.h) against closed forms, reciprocity, the scalar tables and
// the bound on the degree of polarization, on both kernels. Suites ending in Stat are `stat`.
#include "simulator/mueller.h"

#include "core/error.h"
#include "core/math.h"
#include "core/spherical.h"
#include "support/closed_forms.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

namespace lamina {
namespace {

class MuellerStat : public ::testing::TestWithParam<Kernel> {};
std::string kernel_test_name(const ::testing::TestParamInfo<Kernel>& info) {
    return enum_text(info.param);
}
INSTANTIATE_TEST_SUITE_P(Kernels, MuellerStat, ::testing::Values(Kernel::Scalar, Kernel::Simd),
                         kernel_test_name);

SimulationSettings settings(Kernel kernel, std::vector<double> theta_i, std::uint64_t n,
                            HemisphereGrid grid) {
    SimulationSettings s;
    s.kernel = kernel;
    s.theta_i_deg = std::move(theta_i);
    s.particles = n;
    s.grid = grid;
    s.seed = 11;
    s.transport.polarization = true;
    return s;
}

MuellerTable table_of(const std::array<SimulationResult, 4>& runs) {
    return mueller_table({&runs[0], &runs[1], &runs[2], &runs[3]});
}

// One smooth interface (η = 1.5, light at 50° from above): every particle leaves in the mirror bin
// or the straight-through bin, so Ω⊥ times those bins' Mueller matrices are the interface's
// reflection and refraction Mueller matrices, in the block form
//     [[a, b, 0, 0], [b, a, 0, 0], [0, 0, c, d], [0, 0, −d, c]],
// reflection a ± b = R_s, R_p and c − id = r_s* r_p; refraction a ± b = T_s, T_p and c = the flux
// factor (η cos θt)/(cos θi) times t_s t_p, d = 0 (support/closed_forms.h PolarizedFresnel, Born &
// Wolf's amplitudes with std::complex). Both directions lie in the plane of incidence, where the
// bin frames are the s/p frames. Each entry within 5 of its standard errors.
TEST_P(MuellerStat, OneSmoothInterface) {
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.0)});
    const HemisphereGrid grid(18, 18);
    const double theta_i = 50;
    const auto runs = simulate_mueller_runs(stack, settings(GetParam(), {theta_i}, 200'000, grid));
    const MuellerTable t = table_of(runs);
    const double mu_i = std::cos(deg_to_rad(theta_i));
    const test::PolarizedFresnel f(mu_i, 1.5);
    const double mu_t = std::sqrt(1 - (1 - mu_i * mu_i) / 2.25);
    const Vec3f wi_f(incident_direction(deg_to_rad(theta_i)));
    const std::size_t mirror = grid.bin_of(Vec3f(-wi_f.x, -wi_f.y, wi_f.z));
    const std::size_t straight = grid.bin_of(Vec3d(-std::sqrt(1 - mu_t * mu_t), 0, -mu_t));
    auto block = [](double a, double b, std::complex<double> z) {
        return std::array<double, 16>{a, b, 0,        0,         b, a, 0,        0,
                                      0, 0, z.real(), -z.imag(), 0, 0, z.imag(), z.real()};
    };
    const double T_s = 1 - f.Rs(), T_p = 1 - f.Rp();
    const std::array<double, 16> expected[2] = {
        block((f.Rs() + f.Rp()) / 2, (f.Rs() - f.Rp()) / 2, f.reflected_phase()),
        block((T_s + T_p) / 2, (T_s - T_p) / 2, f.transmitted_phase())};
    EXPECT_NEAR(f.transmitted_phase().imag(), 0.0, 1e-15);
    for (int side = 0; side < 2; ++side) {
        const std::size_t bin = side == 0 ? mirror : straight;
        const double omega = grid.projected_solid_angle(bin);
        for (int c = 0; c < 3; ++c) {
            const auto& m = t.m[t.index(0, side, bin, c)];
            const auto& se = t.se[t.index(0, side, bin, c)];
            for (int k = 0; k < 16; ++k)
                EXPECT_LT(std::abs(m[k] * omega - expected[side][k]), 5 * se[k] * omega + 1e-9)
                    << "side " << side << " channel " << c << " entry " << k / 4 << k % 4 << ": "
                    << m[k] * omega << " ± " << se[k] * omega << ", exact " << expected[side][k];
        }
    }
}

// A stack with everything (a rough absorbing coat over a rough coloured conductor, multiple
// scattering on both microsurfaces, one polarization state per channel).
Stack rough_coat_over_gold() {
    return test::make_stack(
        {test::with_medium(test::dielectric_layer(1.5, 0.3), Rgbd(0.2, 0.05, 0.5)),
         test::conductor_layer(Rgbd(0.143, 0.374, 1.442), Rgbd(3.983, 2.385, 1.603), 0.4)});
}

// The column of unpolarized light is the table of unpolarized light: M_00 holds the same
// particles' fluxes as f, tallied in other sums (equal to their fixed-point rounding).
TEST_P(MuellerStat, FirstEntryIsTheTable) {
    SimulationSettings s = settings(GetParam(), {30}, 50'000, HemisphereGrid(9, 9));
    s.transport.microsurface = Microsurface::Multiple;
    const auto runs = simulate_mueller_runs(rough_coat_over_gold(), s);
    const MuellerTable t = table_of(runs);
    for (std::size_t bin = 0; bin < s.grid.size(); ++bin)
        for (int c = 0; c < 3; ++c) {
            const double f = runs[0].table.lobe(0, Side::Reflection).f[bin][c];
            EXPECT_NEAR(t.m[t.index(0, 0, bin, c)][0], f, 1e-9 * (1 + f));
        }
}

// Every particle's Stokes vector has √(S1² + S2² + S3²) ≤ S0 (its state has a degree of
// polarization ≤ 1: smooth interfaces keep it, depolarizing events lower it), so the sums over a
// bin's exits do too (the triangle inequality): checked in every bin, patch, channel and run, up
// to the float rounding of the states (1e-5 relative).
TEST_P(MuellerStat, DegreeOfPolarizationAtMostOne) {
    for (const Microsurface microsurface : {Microsurface::Single, Microsurface::Multiple}) {
        SimulationSettings s = settings(GetParam(), {0, 45, 80}, 50'000, HemisphereGrid(9, 9));
        s.transport.microsurface = microsurface;
        for (const Stack& stack :
             {rough_coat_over_gold(),
              test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.0),
                                                  Rgbd(0.5), Rgbd(0.6)),
                                test::dielectric_layer(1.0, 0.2)})}) {
            const auto runs = simulate_mueller_runs(stack, s);
            for (const SimulationResult& run : runs)
                for (std::size_t inc = 0; inc < 3; ++inc)
                    for (std::size_t entry = 0; entry < 2 * s.grid.size(); ++entry)
                        for (int c = 0; c < 3; ++c) {
                            const BinStokes b = bin_stokes(run.sums[inc], entry, c, s.particles);
                            for (const auto& patch : {b.upper, b.lower}) {
                                const double dop =
                                    std::sqrt(sqr(patch[1]) + sqr(patch[2]) + sqr(patch[3]));
                                EXPECT_LE(dop, patch[0] * (1 + 1e-5) + 1e-15);
                            }
                        }
        }
    }
}

// Reciprocity of the Mueller tables. Lorentz reciprocity makes the scattering amplitude of the
// reversed path the transpose of the forward one (Saxon 1955, "Tensor scattering matrix for the
// electromagnetic field", Phys. Rev. 100(6)): with the bin frames x ∝ ẑ × d, the reversed beams
// keep the x axes and reverse the y axes (y = d × x), so the reversed Jones matrix is Σ Jᵀ Σ,
// Σ = diag(1, −1). In Mueller form, Σ is D = diag(1, 1, −1, −1), and the transpose of a Jones
// matrix becomes P Mᵀ P with P = diag(1, 1, 1, −1) (with S3 = −2 Im(E_x E_y*): Jᵀ swaps E_x* E_y
// and E_x E_y* in the products, which flips S3 and nothing else), so
//     M(wo → wi) = D P Mᵀ P D = Q M(wi → wo)ᵀ Q,  Q = diag(1, 1, −1, 1).
// The tables see the reversed path turned about z so that its light comes from φ = 0: its exit
// lies at −φ, in the patch that the folded bin reports mirrored (D M D, simulator/mueller.h). Hence
// for incidences θa, θb at bin centres, at every φ bin,
//     M_tab(θb → bin θa)_ij = D_ii D_jj Q_ii Q_jj M_tab(θa → bin θb)_ji = P_ii P_jj M_tab(…)_ji,
// within the combined standard errors (the bin-averaging asymmetry is second order in the bin
// width). A χ² over every entry, channel and φ bin.
TEST_P(MuellerStat, Reciprocity) {
    const HemisphereGrid grid(18, 18);
    SimulationSettings s = settings(GetParam(), {22.5, 52.5}, 1'000'000, grid);
    s.transport.microsurface = Microsurface::Multiple;
    const MuellerTable t = table_of(simulate_mueller_runs(rough_coat_over_gold(), s));
    const int ta = 4, tb = 10;  // the θ bins [20°, 25°] and [50°, 55°]
    constexpr double kP[4] = {1, 1, 1, -1};
    test::TableComparison cmp;
    for (int p = 0; p < grid.n_phi(); ++p)
        for (int c = 0; c < 3; ++c) {
            const std::size_t ja = std::size_t(tb) * grid.n_phi() + p;  // from θa into θb's bin
            const std::size_t jb = std::size_t(ta) * grid.n_phi() + p;
            const auto& ma = t.m[t.index(0, 0, ja, c)];
            const auto& sa = t.se[t.index(0, 0, ja, c)];
            const auto& mb = t.m[t.index(1, 0, jb, c)];
            const auto& sb = t.se[t.index(1, 0, jb, c)];
            for (int i = 0; i < 4; ++i)
                for (int j = 0; j < 4; ++j) {
                    const double a = kP[i] * kP[j] * ma[4 * j + i], b = mb[4 * i + j];
                    const double se = std::hypot(sa[4 * j + i], sb[4 * i + j]);
                    ASSERT_GT(se, 0);
                    const double z = (a - b) / se;
                    ++cmp.bins;
                    cmp.chi2 += z * z;
                    if (std::abs(z) > cmp.max_abs_z) {
                        cmp.max_abs_z = std::abs(z);
                        cmp.worst = ::testing::PrintToString(std::array<int, 4>{p, c, i, j});
                    }
                }
        }
    test::expect_agreement(cmp);
}

// --mueller needs polarization.
TEST(Mueller, NeedsPolarization) {
    SimulationSettings s = settings(Kernel::Scalar, {30}, 100, HemisphereGrid(9, 9));
    s.transport.polarization = false;
    EXPECT_THROW(simulate_mueller_runs(test::make_stack({test::dielectric_layer(1.5, 0.0)}), s),
                 InputError);
    s.stokes_tallies = true;
    EXPECT_THROW(validate_settings(s), InputError);
}

}  // namespace
}  // namespace lamina

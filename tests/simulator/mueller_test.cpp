// The Mueller tables (simulator/mueller.h) against closed forms, reciprocity, the scalar tables and
// the bound on the degree of polarization, on both kernels. Suites ending in Stat are `stat`.
#include "simulator/mueller.h"

#include "core/error.h"
#include "core/math.h"
#include "core/spherical.h"
#include "core/stokes.h"
#include "support/closed_forms.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

namespace lamina {
namespace {

class MuellerStat : public ::testing::TestWithParam<Kernel> {};
INSTANTIATE_TEST_SUITE_P(Kernels, MuellerStat, ::testing::Values(Kernel::Scalar, Kernel::Simd),
                         test::kernel_test_name);

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
// ---- The outgoing Stokes vectors of unpolarized light (unpolarized_stokes) -------------------

// One run lit unpolarized with Stokes tallies, as the study's reference runs it.
SimulationResult unpolarized_run(const Stack& stack, SimulationSettings s) {
    s.stokes_tallies = true;
    return simulate(stack, s);
}

// The polarization (core/stokes.h) of channel c of a bin's vector.
StokesPolarization polarization_of(const BinStokesVector& v, int c) {
    return stokes_polarization({v.s[0][c], v.s[1][c], v.s[2][c], v.s[3][c]},
                               {v.se[0][c], v.se[1][c], v.se[2][c], v.se[3][c]});
}

class UnpolarizedStokesStat : public MuellerStat {};
INSTANTIATE_TEST_SUITE_P(Kernels, UnpolarizedStokesStat,
                         ::testing::Values(Kernel::Scalar, Kernel::Simd), test::kernel_test_name);

// A smooth dielectric interface (η = 1.5) lit with unpolarized light reflects into the mirror bin
// only, every particle with the Stokes vector R (1, (R_s − R_p)/(R_s + R_p), 0, 0) of the
// reflection Mueller matrix's first column (docs/physics.md §8; the bin frame's x axis is the s
// axis there): degree of polarization (R_s − R_p)/(R_s + R_p), with R_s and R_p from Born & Wolf's
// amplitudes (support/closed_forms.h), 1 at Brewster's angle atan 1.5 where R_p = 0, and the
// light s-polarized (S1 > 0). Every particle in the bin carries the same state, so the ratio is
// exact up to float rounding of the states.
TEST_P(UnpolarizedStokesStat, SmoothDielectricMirror) {
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.0)});
    const double brewster = rad_to_deg(std::atan(1.5));
    const std::vector<double> theta_i = {32, brewster, 72};  // mirror bins away from bin edges
    SimulationSettings s = settings(GetParam(), theta_i, 20'000, HemisphereGrid(18, 18));
    const SimulationResult run = unpolarized_run(stack, s);
    for (std::size_t inc = 0; inc < theta_i.size(); ++inc) {
        const double mu_i = std::cos(deg_to_rad(theta_i[inc]));
        const test::PolarizedFresnel f(mu_i, 1.5);
        const double expected = (f.Rs() - f.Rp()) / (f.Rs() + f.Rp());
        const Vec3f wi(incident_direction(deg_to_rad(theta_i[inc])));
        const std::size_t mirror = s.grid.bin_of(Vec3f(-wi.x, -wi.y, wi.z));
        const BinStokesVector v =
            unpolarized_stokes(run.sums[inc], mirror, s.grid.projected_solid_angle(mirror), 20'000);
        for (int c = 0; c < 3; ++c) {
            const double f_table = run.table.lobe(inc, Side::Reflection).f[mirror][c];
            EXPECT_NEAR(v.s[0][c], f_table, 1e-9 * (1 + f_table));  // S0 is the table's f
            const StokesPolarization p = polarization_of(v, c);
            EXPECT_NEAR(p.dop, expected, 1e-5) << "θi " << theta_i[inc] << " channel " << c;
            EXPECT_GT(v.s[1][c], 0.0);
            EXPECT_NEAR(v.s[2][c], 0.0, 1e-6 * v.s[0][c]);
            EXPECT_NEAR(v.s[3][c], 0.0, 1e-6 * v.s[0][c]);
        }
        if (inc == 1) {
            EXPECT_NEAR(polarization_of(v, 1).dop, 1.0, 1e-5);  // Brewster's angle
        }
    }
}

// A Lambertian base is an ideal depolarizer (ρ diag(1, 0, 0, 0), docs/physics.md §8): the light
// it reflects has S1 = S2 = S3 = 0 in every bin, degree 0. Under a smooth coat (η = 1.5, no
// medium) every exit is that unpolarized light refracted out once (light reflected back inside
// meets the base again before it leaves), so away from the mirror bin a bin's Stokes vector is
// the refraction Mueller matrix's first column, ∝ (T_s + T_p, T_s − T_p, 0, 0)/2 at the exit
// angle, averaged over the bin with the exit density ∝ (T_s + T_p) cos θ sin θ (uniform radiance
// under the coat): S1/S0 = ∫ (T_s − T_p) cos θ sin θ dθ / ∫ (T_s + T_p) cos θ sin θ dθ over the
// bin's θ range (negative: p-polarized), within 4 standard errors of the degree (core/stokes.h,
// an overestimate), and S2, S3 within 4 of theirs.
TEST_P(UnpolarizedStokesStat, LambertianBase) {
    SimulationSettings s = settings(GetParam(), {0, 45, 75}, 40'000, HemisphereGrid(9, 9));
    const SimulationResult bare =
        unpolarized_run(test::make_stack({test::lambertian_layer(Rgbd(0.8, 0.5, 0.2))}), s);
    for (std::size_t inc = 0; inc < 3; ++inc)
        for (std::size_t bin = 0; bin < s.grid.size(); ++bin) {
            const BinStokesVector v = unpolarized_stokes(
                bare.sums[inc], bin, s.grid.projected_solid_angle(bin), s.particles);
            for (int c = 0; c < 3; ++c) {
                EXPECT_GT(v.s[0][c], 0.0);
                for (int k = 1; k < 4; ++k)
                    EXPECT_EQ(v.s[std::size_t(k)][c], 0.0);
                EXPECT_EQ(polarization_of(v, c).dop, 0.0);
            }
        }

    s.particles = 200'000;
    const SimulationResult coated = unpolarized_run(
        test::make_stack({test::dielectric_layer(1.5, 0.0), test::lambertian_layer(Rgbd(0.8))}), s);
    // ∫ g(θ) cos θ sin θ dθ over [a, b], midpoint rule on 2000 steps.
    auto integral = [](double a, double b, auto g) {
        const int steps = 2000;
        double sum = 0;
        for (int k = 0; k < steps; ++k) {
            const double t = a + (b - a) * (k + 0.5) / steps;
            sum += g(std::cos(t)) * std::cos(t) * std::sin(t);
        }
        return sum * (b - a) / steps;
    };
    int checked = 0;
    for (std::size_t inc = 0; inc < 3; ++inc) {
        const Vec3f wi(incident_direction(deg_to_rad(s.theta_i_deg[inc])));
        const std::size_t mirror = s.grid.bin_of(Vec3f(-wi.x, -wi.y, wi.z));
        for (std::size_t bin = 0; bin < s.grid.size(); ++bin) {
            if (bin == mirror) continue;
            const int row = int(bin) / s.grid.n_phi();
            const double a = deg_to_rad(10.0 * row), b = deg_to_rad(10.0 * (row + 1));
            const double s1 = integral(a, b, [](double mu) {
                const test::PolarizedFresnel f(mu, 1.5);
                return f.Rp() - f.Rs();  // T_s − T_p
            });
            const double s0 = integral(a, b, [](double mu) {
                const test::PolarizedFresnel f(mu, 1.5);
                return 2 - f.Rs() - f.Rp();  // T_s + T_p
            });
            const BinStokesVector v = unpolarized_stokes(
                coated.sums[inc], bin, s.grid.projected_solid_angle(bin), s.particles);
            for (int c = 0; c < 3; ++c) {
                const StokesPolarization p = polarization_of(v, c);
                EXPECT_NEAR(v.s[1][c] / v.s[0][c], s1 / s0, 4 * p.dop_se)
                    << "θi " << s.theta_i_deg[inc] << " bin " << bin << " channel " << c;
                EXPECT_NEAR(v.s[2][c], 0.0, 4 * v.se[2][c] + 1e-6 * v.s[0][c]);  // float states
                EXPECT_NEAR(v.s[3][c], 0.0, 4 * v.se[3][c] + 1e-6 * v.s[0][c]);
                EXPECT_LE(p.dop, 1.0);
                ++checked;
            }
        }
    }
    EXPECT_EQ(checked, 3 * (81 - 1) * 3);
}

// The degree of polarization of every bin is at most 1 (the bin's vector is a sum of states of
// degree ≤ 1), on rough stacks with every kind of event, reflection and transmission.
TEST_P(UnpolarizedStokesStat, DegreeAtMostOne) {
    SimulationSettings s = settings(GetParam(), {0, 45, 80}, 50'000, HemisphereGrid(9, 9));
    s.transport.microsurface = Microsurface::Multiple;
    for (const Stack& stack : {rough_coat_over_gold(),
                               test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4),
                                                                   Rgbd(0.0), Rgbd(0.5), Rgbd(0.6)),
                                                 test::dielectric_layer(1.0, 0.2)})}) {
        const SimulationResult run = unpolarized_run(stack, s);
        int polarized = 0;
        for (std::size_t inc = 0; inc < 3; ++inc)
            for (std::size_t entry = 0; entry < 2 * s.grid.size(); ++entry) {
                const BinStokesVector v = unpolarized_stokes(
                    run.sums[inc], entry, s.grid.projected_solid_angle(entry % s.grid.size()),
                    s.particles);
                for (int c = 0; c < 3; ++c) {
                    const StokesPolarization p = polarization_of(v, c);
                    if (!(v.s[0][c] > 0)) continue;
                    EXPECT_LE(p.dop, 1 + 1e-5);
                    polarized += p.dop > 0.05;
                }
            }
        EXPECT_GT(polarized, 0);  // the stacks polarize: the bound is not met by zeros
    }
}

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

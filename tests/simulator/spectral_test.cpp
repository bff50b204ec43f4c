// Spectral transport (docs/physics.md §10) against exact solutions, with tolerances from the
// standard errors it reports, on both kernels (kernel_simd_test.cpp compares their spectral tables
// by a two-sample chi-square test). Suites ending in Stat are the `stat` label.
#include "core/error.h"
#include "layers/colorimetry.h"
#include "layers/stack.h"
#include "physics/fresnel.h"
#include "simulator/goniophotometer.h"
#include "simulator/output.h"
#include "support/closed_forms.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test::expect_within_se;

constexpr Kernel kKernels[] = {Kernel::Scalar, Kernel::Simd};

SimulationSettings spectral_settings(std::vector<double> theta_i, std::uint64_t n,
                                     HemisphereGrid grid, std::uint64_t seed = 11,
                                     Kernel kernel = Kernel::Auto) {
    SimulationSettings s;
    s.kernel = kernel;
    s.spectral = SpectralMode::On;
    s.theta_i_deg = std::move(theta_i);
    s.particles = n;
    s.grid = grid;
    s.seed = seed;
    s.threads = 2;
    return s;
}

/// The budget term t of incidence i in wavelength bin l, and the standard errors of R and T.
double budget(const SimulationResult& r, std::size_t i, std::size_t l, int t) {
    const std::size_t bins = r.spectral.bin_edges_nm.size() - 1;
    return r.spectral.budget[i * bins + l][std::size_t(t)];
}

/// The vacuum wavelengths of the lattice points of wavelength bin l (tally.h: the middles of
/// kSpectralLattice equal cells per bin).
std::vector<double> bin_lattice(const SpectralTables& sp, std::size_t l) {
    std::vector<double> out;
    const double lo = sp.bin_edges_nm[l], width = sp.bin_edges_nm[l + 1] - lo;
    for (int k = 0; k < kSpectralLattice; ++k)
        out.push_back(lo + (k + 0.5) * width / kSpectralLattice);
    return out;
}

Stack bk7_slab(double alpha_top, double alpha_bottom) {
    Stack s = test::make_stack(
        {test::dielectric_layer(1.5, alpha_top), test::dielectric_layer(1.0, alpha_bottom)});
    s.layers[0].interface.eta_spectrum = glass_material_eta("BK7");
    s.layers[0].interface.eta_spectrum->given = R"({"material":"BK7"})";
    return s;
}

// The white furnace per wavelength: nothing absorbs, rough interfaces scatter on their whole
// microsurface, so every wavelength bin reflects and transmits all its light — exactly (each
// particle keeps its flux) where no interface is dispersive, and within the standard error where
// one is (the hero carries its terminated secondaries).
TEST(SpectralStat, WhiteFurnaceEveryWavelength) {
    const Stack grey =
        test::make_stack({test::dielectric_layer(1.5, 0.3), test::lambertian_layer(Rgbd(1.0))});
    for (const Kernel kernel : kKernels)
        for (const bool polarization : {false, true}) {
            SimulationSettings s =
                spectral_settings({0, 60}, 60'000, HemisphereGrid(9, 9), 11, kernel);
            s.transport.polarization = polarization;
            for (const Stack& stack : {grey, bk7_slab(0.3, 0.5)}) {
                SCOPED_TRACE(describe(stack) + " on the " + enum_text(kernel) + " kernel");
                const auto r = simulate(stack, s);
                const bool dispersive = stack.is_spectral();
                for (std::size_t i = 0; i < 2; ++i)
                    for (std::size_t l = 0; l < std::size_t(s.spectral_bins); ++l) {
                        const double rt = budget(r, i, l, int(BudgetTerm::Reflected)) +
                                          budget(r, i, l, int(BudgetTerm::Transmitted));
                        EXPECT_EQ(budget(r, i, l, int(BudgetTerm::LostMicrosurface)), 0.0);
                        EXPECT_EQ(budget(r, i, l, int(BudgetTerm::CutOff)), 0.0);
                        if (!dispersive) {
                            EXPECT_NEAR(rt, 1.0, 1e-6) << "bin " << l;
                        } else {
                            const double se = std::hypot(budget(r, i, l, kBudgetTerms),
                                                         budget(r, i, l, kBudgetTerms + 1));
                            expect_within_se(rt, 1.0, se, "R + T in bin " + std::to_string(l));
                        }
                    }
            }
        }
}

// A grey stack (every value the same at every wavelength) traced spectrally gives, in every
// wavelength bin, the RGB mode's table within the noise of both, on both kernels: a scattering
// and absorbing coat over a rough conductor, and the coat only absorbing.
TEST(SpectralStat, GreyStackIsTheRgbTable) {
    const Stack scattering = test::make_stack(
        {test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.3), Rgbd(0.5), Rgbd(0.4)),
         test::conductor_layer(Rgbd(0.2), Rgbd(3.0), 0.3)});
    Stack absorbing = scattering;
    absorbing.layers[0].medium.tau_s = Rgbd(0.0);
    const HemisphereGrid grid(6, 6);
    for (const auto& [stack, kernel] :
         {std::pair{scattering, Kernel::Scalar}, std::pair{scattering, Kernel::Simd},
          std::pair{absorbing, Kernel::Simd}}) {
        SCOPED_TRACE(describe(stack) + " on the " + enum_text(kernel) + " kernel");
        SimulationSettings rgb = spectral_settings({30}, 300'000, grid, 5);
        rgb.spectral = SpectralMode::Off;
        const auto a = simulate(stack, rgb);
        SimulationSettings spectral = spectral_settings({30}, 1'500'000, grid, 6, kernel);
        spectral.spectral_bins = 6;
        const auto b = simulate(stack, spectral);
        // A direction's six wavelength bins share one expectation, the RGB table's. They are two
        // estimates, not six: bin c·2 + g holds channel c of the particles of wavelength group g
        // (docs/physics.md §10), and in a grey stack a particle's three wavelengths follow one path
        // with equal fluxes, so the three channels of a group are the same number (checked
        // exactly). The RGB table is compared with the groups' mean, and the two groups with each
        // other: (g0 − g1)² / (s0² + s1²), one degree of freedom per direction.
        constexpr std::size_t kBins = 6, kGroups = 2;
        test::TableComparison against_rgb, spread;
        const BinnedLobe& lobe = a.table.lobe(0, Side::Reflection);
        for (std::size_t j = 0; j < grid.size(); ++j) {
            double group_f[kGroups], group_se[kGroups];
            for (std::size_t g = 0; g < kGroups; ++g) {
                group_f[g] = b.spectral.f[b.spectral.index(0, 0, j, g)];
                group_se[g] = b.spectral.se[b.spectral.index(0, 0, j, g)];
                for (std::size_t c = 1; c < kBins / kGroups; ++c) {
                    const std::size_t at = b.spectral.index(0, 0, j, c * kGroups + g);
                    EXPECT_EQ(b.spectral.f[at], group_f[g]) << "bin " << j << " group " << g;
                    EXPECT_EQ(b.spectral.se[at], group_se[g]) << "bin " << j << " group " << g;
                }
            }
            const double mean = (group_f[0] + group_f[1]) / 2;
            const double variance = (group_se[0] * group_se[0] + group_se[1] * group_se[1]) / 4;
            const double se = std::sqrt(lobe.se[j][0] * lobe.se[j][0] + variance);
            if (se == 0) continue;
            const double z = (mean - lobe.f[j][0]) / se;
            ++against_rgb.bins;
            against_rgb.chi2 += z * z;
            against_rgb.max_abs_z = std::max(against_rgb.max_abs_z, std::abs(z));
            if (variance == 0) continue;
            const double z_groups = (group_f[0] - group_f[1]) / (2 * std::sqrt(variance));
            ++spread.bins;
            spread.chi2 += z_groups * z_groups;
            spread.max_abs_z = std::max(spread.max_abs_z, std::abs(z_groups));
        }
        test::expect_agreement(against_rgb);
        test::expect_agreement(spread);
        // The channels of a grey RGB run agree exactly; the spectral budget per bin is the RGB one.
        for (std::size_t l = 0; l < 6; ++l) {
            const EnergyBudget& e = a.incidences[0].budget;
            expect_within_se(budget(b, 0, l, int(BudgetTerm::Reflected)),
                             e[BudgetTerm::Reflected][0],
                             std::hypot(budget(b, 0, l, kBudgetTerms), e.reflected_se[0]), "R");
        }
    }
}

// A smooth dispersive slab (BK7 in air, nothing absorbing): per wavelength the incoherent series
// of docs/physics.md §6.4 with F at the wavelength's index, R = F + (1 − F)² F / (1 − F²) and
// T = (1 − F)² / (1 − F²) unpolarized, the mean over s and p polarized (closed_forms.h). A
// wavelength bin estimates the mean over its lattice points.
TEST(SpectralStat, DispersiveSmoothSlabPerWavelength) {
    const Stack stack = bk7_slab(0.0, 0.0);
    const Spectrum bk7 = glass_material_eta("BK7");
    for (const Kernel kernel : kKernels)
        for (const bool polarization : {false, true}) {
            SCOPED_TRACE(std::string(enum_text(kernel)) + (polarization ? " polarized" : ""));
            SimulationSettings s =
                spectral_settings({0, 70}, 300'000, HemisphereGrid(9, 9), 11, kernel);
            s.transport.polarization = polarization;
            const auto r = simulate(stack, s);
            for (std::size_t i = 0; i < 2; ++i) {
                const double mu_i = std::cos(deg_to_rad(r.settings.theta_i_deg[i]));
                for (std::size_t l = 0; l < std::size_t(s.spectral_bins); ++l) {
                    double R = 0, T = 0;
                    const std::vector<double> lattice = bin_lattice(r.spectral, l);
                    for (double lambda : lattice) {
                        const double eta = bk7.at(lambda);
                        if (polarization) {
                            const test::PolarizedSlab slab(mu_i, eta, 1.0);
                            R += slab.R;
                            T += slab.T;
                        } else {
                            const double F = fresnel_dielectric(mu_i, eta);
                            R += F + (1 - F) * (1 - F) * F / (1 - F * F);
                            T += (1 - F) * (1 - F) / (1 - F * F);
                        }
                    }
                    R /= double(lattice.size());
                    T /= double(lattice.size());
                    expect_within_se(budget(r, i, l, int(BudgetTerm::Reflected)), R,
                                     budget(r, i, l, kBudgetTerms),
                                     "R in bin " + std::to_string(l));
                    expect_within_se(budget(r, i, l, int(BudgetTerm::Transmitted)), T,
                                     budget(r, i, l, kBudgetTerms + 1),
                                     "T in bin " + std::to_string(l));
                }
            }
        }
}

// The colour of a constant spectrum is the illuminant's: a white Lambertian (albedo 1 at every
// wavelength) reflects the XYZ of D65 normalized to Y = 1, whose chromaticity is D65's white point
// (x, y) = (0.3127, 0.3290) (CIE 015:2018, Table 5), and its linear sRGB is (1, 1, 1).
TEST(SpectralStat, ConstantSpectrumIsTheWhitePoint) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(1.0))});
    for (const Kernel kernel : kKernels) {
        SCOPED_TRACE(enum_text(kernel));
        const auto r =
            simulate(stack, spectral_settings({20}, 400'000, HemisphereGrid(6, 6), 11, kernel));
        const EnergyBudget& xyz = r.spectral.xyz_budget[0];
        // The lattice's own projection (the estimator's expectation): a midpoint sum of S x̄ over
        // the range, over ∫ S ȳ.
        Rgbd expected(0.0), norm(0.0);
        const int points = r.settings.spectral_bins * kSpectralLattice;
        for (int p = 0; p < points; ++p)
            expected += d65_xyz_weights(360 + (p + 0.5) * 470.0 / points) * (470.0 / points);
        for (int i = 0; i < 47000; ++i)
            norm += d65_xyz_weights(360 + (i + 0.5) * 0.01) * 0.01;
        for (int c = 0; c < 3; ++c)
            expect_within_se(xyz[BudgetTerm::Reflected][c], expected[c] / norm[1],
                             xyz.reflected_se[c], "XYZ");
        const Rgbd& v = xyz[BudgetTerm::Reflected];
        const double sum = v[0] + v[1] + v[2];
        EXPECT_NEAR(v[0] / sum, 0.3127, 2e-3);
        EXPECT_NEAR(v[1] / sum, 0.3290, 2e-3);
        const EnergyBudget& srgb = r.incidences[0].budget;
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(srgb[BudgetTerm::Reflected][c], 1.0, 5 * srgb.reflected_se[c] + 2e-3);
    }
}

// A coloured albedo given as RGB numbers, traced spectrally: each wavelength bin reflects the
// number of the channel whose wavelength (630, 532, 465 nm) is nearest its own, so red's 0.8
// above 581 nm and blue's 0.2 below 498.5 nm (not the first number in the shortest third of the
// range): exactly, a Lambertian keeping each particle's flux times its albedo. Both kernels; the
// bins that straddle an edge hold their lattice points' mix.
TEST(Spectral, RgbAlbedoIsTheNearestChannelsNumber) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(0.8, 0.5, 0.2))});
    for (const Kernel kernel : kKernels) {
        SCOPED_TRACE(enum_text(kernel));
        const auto r =
            simulate(stack, spectral_settings({20}, 30'000, HemisphereGrid(4, 4), 3, kernel));
        const std::size_t bins = r.spectral.bin_edges_nm.size() - 1;
        int checked = 0;
        for (std::size_t l = 0; l < bins; ++l) {
            double want = 0, low = 1, high = 0;
            for (const double lambda : bin_lattice(r.spectral, l)) {
                const double albedo = lambda > 581 ? 0.8 : lambda > 498.5 ? 0.5 : 0.2;
                want += albedo / kSpectralLattice;
                low = std::min(low, albedo);
                high = std::max(high, albedo);
            }
            const double got = budget(r, 0, l, int(BudgetTerm::Reflected));
            if (low == high) {  // every lattice point on one side: exact
                EXPECT_NEAR(got, low, 1e-6) << "bin " << l;
                checked += low != 0.5;
            } else {  // the particles' lattice points sample the mix
                expect_within_se(got, want, budget(r, 0, l, kBudgetTerms), "straddling bin");
            }
        }
        EXPECT_GT(checked, 20);
        // Its colour is red's: the sRGB albedo's red above its blue.
        const EnergyBudget& e = r.incidences[0].budget;
        EXPECT_GT(e[BudgetTerm::Reflected][0], 2 * e[BudgetTerm::Reflected][2]);
    }
}

// The tables do not depend on the thread count, bit for bit, on either kernel, with both
// references: a rough dispersive slab, gold under a coat, a filmed metal (titanium's oxide) and
// a scattering coat.
TEST(Spectral, BitwiseIdenticalAcrossThreadCounts) {
    for (const Stack& stack : {bk7_slab(0.2, 0.4), test::example("gold-under-coat"),
                               test::example("titania-on-gold"), test::example("milky-coat")})
        for (const Kernel kernel : kKernels)
            for (const auto physics : {ReferencePhysics::Exact, ReferencePhysics::Bpb19}) {
                SCOPED_TRACE(stack.name + " on the " + enum_text(kernel) + " kernel, " +
                             enum_text(physics));
                SimulationSettings s =
                    spectral_settings({10, 50}, 20'000, HemisphereGrid(6, 6), 11, kernel);
                apply_physics(physics, s.transport);
                s.threads = 1;
                const auto a = simulate(stack, s);
                s.threads = 3;
                const auto b = simulate(stack, s);
                EXPECT_EQ(a.spectral.f, b.spectral.f);
                EXPECT_EQ(a.spectral.se, b.spectral.se);
                EXPECT_EQ(a.spectral.budget, b.spectral.budget);
                for (std::size_t i = 0; i < 2; ++i)
                    for (const Side side : {Side::Reflection, Side::Transmission}) {
                        if (side == Side::Transmission && !a.table.has_transmission) continue;
                        EXPECT_EQ(a.table.lobe(i, side).f, b.table.lobe(i, side).f);
                        EXPECT_EQ(a.spectral.xyz.lobe(i, side).se, b.spectral.xyz.lobe(i, side).se);
                    }
            }
}

// A run split into particle ranges (processes, Python's chunks) adds up to one run, bit for bit:
// a particle's wavelength group is its global index mod B/3. Both kernels.
TEST(Spectral, SplitRangesAddUpToOneRun) {
    const Stack stack = bk7_slab(0.2, 0.0);
    for (const Kernel kernel : kKernels) {
        SCOPED_TRACE(enum_text(kernel));
        SimulationSettings s =
            spectral_settings({30}, 3 * kParticlesPerBlock + 77, HemisphereGrid(6, 6), 11, kernel);
        const SimulationSums whole = simulate_sums(stack, s);
        SimulationSettings part = s;
        part.particles = kParticlesPerBlock;
        SimulationSums sums = simulate_sums(stack, part);
        part.first_particle = kParticlesPerBlock;
        part.particles = s.particles - kParticlesPerBlock;
        sums.incidences[0].add(simulate_sums(stack, part).incidences[0]);
        const auto a = finalize_simulation(stack, s, whole),
                   b = finalize_simulation(stack, s, sums);
        EXPECT_EQ(a.spectral.f, b.spectral.f);
        EXPECT_EQ(a.spectral.se, b.spectral.se);
        EXPECT_EQ(a.spectral.budget, b.spectral.budget);
        EXPECT_EQ(a.spectral.xyz.lobe(0, Side::Transmission).f,
                  b.spectral.xyz.lobe(0, Side::Transmission).f);
    }
}

// A spectral run is the SIMD kernel's (auto picks it), scattering media included; the bins must
// be a multiple of 3.
TEST(Spectral, KernelAndBinsChecked) {
    const Stack stack = bk7_slab(0.1, 0.1);
    SimulationSettings s = spectral_settings({0}, 1000, HemisphereGrid(3, 3));
    s.spectral = SpectralMode::Auto;
    EXPECT_TRUE(is_spectral_run(stack, s));
    EXPECT_EQ(kernel_for(s, stack), Kernel::Simd);
    EXPECT_EQ(kernel_for(s, test::example("milky-coat")), Kernel::Simd);  // scattering too
    s.spectral_bins = 10;
    EXPECT_THROW(simulate(stack, s), InputError);
    s.spectral_bins = 30;
    s.spectral = SpectralMode::Off;
    EXPECT_FALSE(is_spectral_run(stack, s));
    EXPECT_TRUE(simulate(stack, s).spectral.bin_edges_nm.empty());
}

// A spectral run whose coat is index-matched to the air at some wavelengths only (η = 1 below
// 500 nm) is handed to the scalar kernel, and result.json names the kernel that traced it; a
// uniform one stays on the SIMD kernel.
TEST(Spectral, TheKernelNamedIsTheOneThatTraced) {
    const Stack matched_in_blue = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "alpha": 0.1, "eta": {"spectrum":
            [[360, 1.0], [500, 1.0], [600, 1.5], [830, 1.5]]}}},
            {"interface": {"type": "lambertian", "albedo": 0.5}}]})",
        "test");
    SimulationSettings s = spectral_settings({30}, 2000, HemisphereGrid(3, 3));
    s.spectral = SpectralMode::Auto;
    for (const Kernel kernel : {Kernel::Auto, Kernel::Simd}) {
        s.kernel = kernel;
        EXPECT_EQ(traced_kernel(s, matched_in_blue), Kernel::Scalar);
        const SimulationResult r = simulate(matched_in_blue, s);
        EXPECT_EQ(result_json(matched_in_blue, r)["kernel_description"], "scalar");
    }
    s.kernel = Kernel::Auto;
    const Stack uniform = bk7_slab(0.1, 0.1);
    EXPECT_EQ(traced_kernel(s, uniform), Kernel::Simd);
    s.spectral = SpectralMode::Off;  // RGB: the SIMD kernel
    EXPECT_EQ(traced_kernel(s, matched_in_blue), Kernel::Simd);
}

}  // namespace
}  // namespace lamina

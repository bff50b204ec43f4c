// The goniophotometer against exact solutions (docs/physics.md §6), with tolerances from the
// standard errors it reports. Suites ending in Stat are the `stat` label.
#include "simulator/goniophotometer.h"
#include "core/error.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "simulator/mueller.h"
#include "support/adding_doubling.h"
#include "support/closed_forms.h"
#include "support/quadrature.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace lamina {
namespace {

using test::expect_budget_closes;
using test::expect_within_se;

using test::compare_lobe;
using test::expect_agreement;

// Every exact-solution test runs on both kernels (the fixtures set the kernel under test).
Kernel g_kernel = Kernel::Scalar;

SimulationSettings settings(std::vector<double> theta_i, std::uint64_t n, HemisphereGrid grid,
                            std::uint64_t seed = 7) {
    SimulationSettings s;
    s.kernel = g_kernel;
    s.theta_i_deg = std::move(theta_i);
    s.particles = n;
    s.grid = grid;
    s.seed = seed;
    // The closed forms below are those of unpolarized Fresnel factors and single-scattering
    // interfaces (the 2019 reference); a test of the exact reference says so.
    apply_physics(ReferencePhysics::Bpb19, s.transport);
    return s;
}

class GoniophotometerStat : public ::testing::TestWithParam<Kernel> {
  protected:
    void SetUp() override { g_kernel = GetParam(); }
};
class Goniophotometer : public ::testing::TestWithParam<Kernel> {
  protected:
    void SetUp() override { g_kernel = GetParam(); }
};
INSTANTIATE_TEST_SUITE_P(Kernels, GoniophotometerStat,
                         ::testing::Values(Kernel::Scalar, Kernel::Simd), test::kernel_test_name);
INSTANTIATE_TEST_SUITE_P(Kernels, Goniophotometer, ::testing::Values(Kernel::Scalar, Kernel::Simd),
                         test::kernel_test_name);

// Standard error of a budget term from its own estimate; the closed forms are exact, so
// |estimate − exact| < 5 se holds with probability 1 − 6e-7.

// A white furnace with microsurface multiple scattering: every particle is reflected or
// transmitted (nothing lost in a microsurface, nothing cut off) but for degenerate samples. A walk
// that meets a facet exactly at grazing — a visible normal drawn at the rim of its cap, u2 within
// float rounding of 1, about 2^-23 of the facet samples — rounds the facet's cosine to ≤ 0 and
// loses its particle as a counted degenerate sample: measure zero in exact arithmetic, a few in
// 10^7 particles in float (seen: one of 3·10^5 on an AMD EPYC). The loss must be exactly those
// samples, and at most 3 of an incidence's particles (at most a few facets a particle, the mean is
// below 0.1 per 10^5 particles: 4 or more has a probability below 10^-5).
void expect_white_furnace_loses_nothing(const SimulationResult& r) {
    for (const IncidenceStats& st : r.incidences) {
        const EnergyBudget& b = st.budget;
        const double degenerate = double(st.degenerate_samples) / double(r.settings.particles);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(b[BudgetTerm::Reflected][c] + b[BudgetTerm::Transmitted][c],
                        1.0 - degenerate, 1e-6);
            EXPECT_NEAR(b[BudgetTerm::LostMicrosurface][c], degenerate, 1e-12);
            EXPECT_EQ(b[BudgetTerm::CutOff][c], 0.0);
        }
        EXPECT_LE(st.degenerate_samples, 3u);
    }
}

// §6.2: a Lambertian base alone reflects albedo/π in every direction; every particle leaves
// with flux exactly ρ, so the reflected budget is ρ exactly. It holds with polarization too (the
// base depolarizes, and the flux is S0).
void check_lambertian_alone(bool polarization) {
    const Rgbd albedo(0.8, 0.5, 0.2);
    const Stack stack = test::make_stack({test::lambertian_layer(albedo)});
    SimulationSettings s = settings({40}, 400'000, HemisphereGrid(9, 9));
    s.transport.polarization = polarization;
    const auto r = simulate(stack, s);
    expect_agreement(compare_lobe(
        r.table, 0, Side::Reflection, [&](std::size_t) { return albedo * kInvPi<double>; },
        400'000));
    // The tracer holds ρ in float: exact to its rounding, 2^-24 relative.
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(r.incidences[0].budget[BudgetTerm::Reflected][c], albedo[c], 1e-7);
        EXPECT_NEAR(r.incidences[0].budget[BudgetTerm::AbsorbedBase][c], 1 - albedo[c], 1e-7);
    }
    expect_budget_closes(r);
}
TEST_P(GoniophotometerStat, LambertianAlone) {
    check_lambertian_alone(false);
}

// §6.3: smooth coat (η) over a Lambertian (ρ) with absorption τ between, all orders:
//   f = ρ/(πη²) (1 − F(μi)) e^{−τ/μi'} (1 − F(μo)) e^{−τ/μo'} / (1 − ρ r),
//   r = 2∫₀¹ F_inside(μ) e^{−2τ/μ} μ dμ (relative index 1/η, TIR → 1),
// plus the mirror reflection F(μi) in the bin of the mirror direction. Its albedo is
//   F(μi) + (1 − F(μi)) e^{−τ/μi'} ρ t / (1 − ρ r), t = 2∫₀¹ (1 − F_inside(μ)) e^{−τ/μ} μ dμ.
// With polarization the series still holds: light meets the coat unpolarized every time (from
// outside, and from inside after the depolarizing base), where its reflectance is the mean of the
// s and p reflectances, and the absorbing medium keeps the state.
void check_smooth_coat_over_lambertian(bool polarization) {
    const double eta = 1.5, theta_i = 35.0;
    const Rgbd tau(0.1, 0.5, 0.0), rho(0.8, 0.5, 1.0);
    const Stack stack = test::make_stack(
        {test::with_medium(test::dielectric_layer(eta, 0.0), tau), test::lambertian_layer(rho)});
    const HemisphereGrid grid(18, 18);
    SimulationSettings s = settings({theta_i}, 1'000'000, grid);
    s.transport.polarization = polarization;
    const auto r = simulate(stack, s);

    const test::CoatedLambertianSeries series(eta, tau, rho);
    const double mu_i = std::cos(deg_to_rad(theta_i));
    const double F_i = series.specular(mu_i);
    auto diffuse = [&](const Vec3d& wo) { return series.diffuse(mu_i, std::abs(wo.z)); };
    // The tracer's mirror direction, in its own float arithmetic, decides the bin.
    const Vec3f wi_f(incident_direction(deg_to_rad(theta_i)));
    const std::size_t mirror_bin = grid.bin_of(Vec3f(-wi_f.x, -wi_f.y, wi_f.z));
    expect_agreement(compare_lobe(
        r.table, 0, Side::Reflection,
        [&](std::size_t j) {
            Rgbd e = test::bin_average(grid, j, Side::Reflection, diffuse);
            if (j == mirror_bin) e += Rgbd(F_i / grid.projected_solid_angle(j));
            return e;
        },
        1e6));
    const EnergyBudget& b = r.incidences[0].budget;
    const Rgbd albedo = series.albedo(mu_i);
    for (int c = 0; c < 3; ++c)
        expect_within_se(b[BudgetTerm::Reflected][c], albedo[c], b.reflected_se[c], "albedo");
    // Blue: τ = 0 and ρ = 1: nothing is absorbed, every particle leaves (white furnace).
    EXPECT_NEAR(b[BudgetTerm::Reflected][2] + b[BudgetTerm::CutOff][2], 1.0, 1e-9);
    EXPECT_LT(b[BudgetTerm::CutOff][2], 1e-9);
    expect_budget_closes(r);
}
TEST_P(GoniophotometerStat, SmoothCoatOverLambertianSeries) {
    check_smooth_coat_over_lambertian(false);
}

// Light entering a smooth coat of index η at θi: cos θi, the refracted cos θt and the Fresnel
// reflectance F(μi) of the unpolarized closed forms (docs/physics.md §6).
struct SmoothEntry {
    double mu_i, mu_t, F;
};
SmoothEntry smooth_coat_entry(double theta_i_deg, double eta) {
    const double mu_i = std::cos(deg_to_rad(theta_i_deg));
    return {mu_i, std::sqrt(1 - (1 - mu_i * mu_i) / (eta * eta)), fresnel_dielectric(mu_i, eta)};
}

// §6.4: smooth slab of index η and absorption τ in air, with F = F(μi), a = e^{−τ/μi'}:
//   R = F + (1 − F)² F a² / (1 − F² a²),  T = (1 − F)² a / (1 − F² a²).
// All reflected flux leaves in the mirror bin, all transmitted flux straight through.
TEST_P(GoniophotometerStat, SmoothSlab) {
    const double eta = 1.5;
    const Rgbd tau(0.0, 0.2, 1.0);
    const Stack stack = test::make_stack({test::with_medium(test::dielectric_layer(eta, 0.0), tau),
                                          test::dielectric_layer(1.0, 0.0)});
    const auto r = simulate(stack, settings({30, 75}, 400'000, HemisphereGrid(18, 18)));
    for (std::size_t i = 0; i < 2; ++i) {
        const auto [mu_i, mu_t, F] = smooth_coat_entry(r.settings.theta_i_deg[i], eta);
        const EnergyBudget& b = r.incidences[i].budget;
        for (int c = 0; c < 3; ++c) {
            const double a = std::exp(-tau[c] / mu_t);
            const double R = F + sqr(1 - F) * F * a * a / (1 - sqr(F * a));
            const double T = sqr(1 - F) * a / (1 - sqr(F * a));
            expect_within_se(b[BudgetTerm::Reflected][c], R, b.reflected_se[c], "R");
            expect_within_se(b[BudgetTerm::Transmitted][c], T, b.transmitted_se[c], "T");
            EXPECT_NEAR(b[BudgetTerm::LostMicrosurface][c], 0.0, 1e-12);
        }
        // Delta lobes: one bin each holds all of R and of T.
        for (const Side side : {Side::Reflection, Side::Transmission}) {
            int hit = 0;
            for (const Rgbd& f : r.table.lobe(i, side).f)
                hit += f[0] > 0;
            EXPECT_EQ(hit, 1);
        }
    }
    expect_budget_closes(r);
}

// §6.5: smooth coat over a smooth conductor: R = F + (1 − F)² Rc a² / (1 − F Rc a²), Rc the
// conductor's Fresnel at μi' for the relative index (η_c + i k_c)/η, a = e^{−τ/μi'}.
TEST_P(GoniophotometerStat, CoatedSmoothConductor) {
    const double eta = 1.5;
    const Rgbd tau(0.1, 0.3, 0.0), eta_c(0.143, 0.374, 1.442), k_c(3.983, 2.385, 1.603);
    const Stack stack = test::make_stack({test::with_medium(test::dielectric_layer(eta, 0.0), tau),
                                          test::conductor_layer(eta_c, k_c, 0.0)});
    const auto r = simulate(stack, settings({20, 60}, 400'000, HemisphereGrid(18, 18)));
    for (std::size_t i = 0; i < 2; ++i) {
        const auto [mu_i, mu_t, F] = smooth_coat_entry(r.settings.theta_i_deg[i], eta);
        const EnergyBudget& b = r.incidences[i].budget;
        for (int c = 0; c < 3; ++c) {
            const double a = std::exp(-tau[c] / mu_t);
            const double Rc = fresnel_conductor_complex(mu_t, eta_c[c] / eta, k_c[c] / eta);
            const double R = F + sqr(1 - F) * Rc * a * a / (1 - F * Rc * a * a);
            expect_within_se(b[BudgetTerm::Reflected][c], R, b.reflected_se[c], "R");
        }
    }
    expect_budget_closes(r);
}

// The transmitted albedo of one rough dielectric (relative index eta, light from wi), as the
// expectation of the sampling process over the visible normals, without Walter's Jacobian:
// T = ∫ D_wi(wm) (1 − F(wi·wm)) G2(wi, wt)/G1(wi) dωm over the normals whose refraction wt
// crosses, with the masking's G2 written independently (std::beta for Smith). Product
// Gauss–Legendre rule in (u1, u2) of the visible-normal sampler's map (the integrand is
// continuous: G2 → 0 where wt reaches the horizon, 1 − F → 0 at total reflection): 16 × 16 nodes
// in each of 32 × 32 panels (halving the panels changes the result by < 1e-7 here).
double transmitted_albedo(double eta, double alpha, const Vec3d& wi, TransmissionMasking masking) {
    const GGX<double> ggx{alpha};
    const auto nodes = test::gauss_legendre(16);
    double sum = 0;
    const int panels = 32;
    for (int p1 = 0; p1 < panels; ++p1)
        for (int p2 = 0; p2 < panels; ++p2)
            for (const auto& [x1, w1] : nodes)
                for (const auto& [x2, w2] : nodes) {
                    const double u1 = (p1 + 0.5 * (x1 + 1)) / panels;
                    const double u2 = (p2 + 0.5 * (x2 + 1)) / panels;
                    const double weight = 0.25 * w1 * w2 / (panels * panels);
                    const Vec3d wm = ggx.sample_visible_normal(wi, u1, u2);
                    const auto wt = refract(wi, wm, eta);
                    if (!wt || wt->z * wi.z >= 0) continue;
                    const double F = fresnel_dielectric(dot(wi, wm), eta);
                    const double li = ggx.lambda(wi), lo = ggx.lambda(*wt);
                    const double g2 = masking == TransmissionMasking::Smith
                                          ? std::beta(1 + li, 1 + lo)
                                          : 1 / (1 + li + lo);
                    sum += weight * (1 - F) * g2 * (1 + li);
                }
    return sum;
}

// §6.6: one rough interface: the table equals the Walter et al. 2007 BSDF (with the height-
// correlated G2 of the chosen refraction masking) averaged over the bins, reflection and
// transmission, from both sides. `tweak` adjusts the settings (the microsurface walk's first order
// must give the same table as the default, Smith, masking).
using Tweak = std::function<void(SimulationSettings&)>;

// `masking`: the refraction lobe's masking-shadowing, the simulation's and the expectation's.
// pbrt: 1/(1 + Λi + Λo), as the reflection lobe (pbrt-v4). Smith: the microsurface's own
// height-correlated form for refraction, B(1 + Λi, 1 + Λo) (Euler's Beta function; a ray entering
// at height h with C1(h) = c is followed by one leaving below with probability (1 − c)^Λo, and c
// has density (1 + Λi) c^Λi: ∫ (1 + Λi) c^Λi (1 − c)^Λo dc = (1 + Λi) B(1 + Λi, 1 + Λo) = G2/G1).
// The expectation is the pbrt-form Walter BSDF times std::beta(1 + Λi, 1 + Λo)(1 + Λi + Λo): the
// C++ library's Beta function, independent of the program's (core/beta_function.h).
// `pieces`: sub-rectangles per axis of a bin's average (a lobe that ends inside a bin, as at
// grazing incidence, needs a composite rule).
// `reflection_only`: the transmission lobe's bin averages need the refraction Jacobian's
// integrable singularity at the lobe's edge resolved, which Gauss rules do not do at grazing
// incidence; the transmitted albedo is then checked against E[(1 − F) G2/G1] over the visible
// normals (no Jacobian) instead (transmitted_albedo).
void check_single_rough_dielectric(double ambient_eta, double eta, double alpha, double theta_i,
                                   const Tweak& tweak = {},
                                   TransmissionMasking masking = TransmissionMasking::Smith,
                                   int pieces = 1, bool reflection_only = false,
                                   std::uint64_t particles = 1'000'000) {
    Stack stack = test::make_stack({test::dielectric_layer(eta, alpha)});
    stack.ambient_eta = ambient_eta;
    SimulationSettings s = settings({theta_i}, particles, HemisphereGrid(18, 18));
    s.transport.transmission_masking = masking;
    if (tweak) tweak(s);
    const HemisphereGrid grid = s.grid;
    const auto r = simulate(stack, s);
    DielectricInterface<double> interface { eta / ambient_eta, alpha };
    interface.transmission_masking = TransmissionMasking::Pbrt;
    const Vec3d wi = incident_direction(deg_to_rad(theta_i));
    const GGX<double> ggx{alpha};
    for (const Side side : {Side::Reflection, Side::Transmission}) {
        SCOPED_TRACE(side == Side::Reflection ? "reflection" : "transmission");
        const EnergyBudget& b = r.incidences[0].budget;
        if (reflection_only && side == Side::Transmission) {
            const double T = transmitted_albedo(eta / ambient_eta, alpha, wi, masking);
            expect_within_se(b[BudgetTerm::Transmitted][0], T, b.transmitted_se[0], "T");
            continue;
        }
        std::vector<Rgbd> expected(grid.size());
        double albedo = 0;  // Σ_j f̄_j Ω⊥_j: the lobe's directional albedo by quadrature
        for (std::size_t j = 0; j < grid.size(); ++j) {
            expected[j] = test::bin_average(
                grid, j, side,
                [&](const Vec3d& wo) {
                    double f = interface.eval(wi, wo);
                    if (masking == TransmissionMasking::Smith && side == Side::Transmission &&
                        f > 0) {
                        const double li = ggx.lambda(wi), lo = ggx.lambda(wo);
                        f *= std::beta(1 + li, 1 + lo) * (1 + li + lo);
                    }
                    return Rgbd(f);
                },
                12, pieces);
            albedo += expected[j][0] * grid.projected_solid_angle(j);
        }
        expect_agreement(compare_lobe(
            r.table, 0, side, [&](std::size_t j) { return expected[j]; }, double(s.particles)));
        if (side == Side::Reflection)
            expect_within_se(b[BudgetTerm::Reflected][0], albedo, b.reflected_se[0], "R");
        else
            expect_within_se(b[BudgetTerm::Transmitted][0], albedo, b.transmitted_se[0], "T");
    }
    expect_budget_closes(r);
}

TEST_P(GoniophotometerStat, SingleRoughDielectricFromAbove) {
    check_single_rough_dielectric(1.0, 1.5, 0.3, 40);
}

TEST_P(GoniophotometerStat, SingleRoughDielectricFromDenseSide) {
    // η = 1/1.5 seen by the light: total internal reflection beyond ~41.8°.
    check_single_rough_dielectric(1.5, 1.0, 0.3, 50);
}

// The Smith refraction masking where it matters most (T = 0.738 with the pbrt form against 0.505
// with Smith's at α = 0.6, θi = 80°): with either masking, bin by bin for reflection, and for
// transmission at α = 0.3 (where the Gauss rules resolve the lobe; the Smith form is
// SingleRoughDielectricFromAbove); on rough and very rough interfaces at oblique and grazing
// incidence the transmitted albedo (at α = 0.6, θi = 60°, the transmission lobe's bins next to
// the horizon hold the Jacobian's edge singularity, which a 2 × 2 composite rule overestimates by
// 12 % in one bin for either masking).
TEST_P(GoniophotometerStat, SingleRoughDielectricSmithAndPbrtMasking) {
    for (const TransmissionMasking masking :
         {TransmissionMasking::Smith, TransmissionMasking::Pbrt}) {
        SCOPED_TRACE(enum_text(masking));
        if (masking == TransmissionMasking::Pbrt) {
            SCOPED_TRACE("alpha 0.3, 40 degrees");
            check_single_rough_dielectric(1.0, 1.5, 0.3, 40, {}, masking);
        }
        {
            SCOPED_TRACE("alpha 0.6, 60 degrees");
            check_single_rough_dielectric(1.0, 1.5, 0.6, 60, {}, masking, 2, true);
        }
        {
            SCOPED_TRACE("alpha 0.6, 80 degrees");
            check_single_rough_dielectric(1.0, 1.5, 0.6, 80, {}, masking, 4, true);
        }
        {
            SCOPED_TRACE("alpha 1, 80 degrees, from the dense side");
            check_single_rough_dielectric(1.5, 1.0, 1.0, 80, {}, masking, 4, true);
        }
    }
}

void check_single_rough_conductor(const Tweak& tweak = {}, double alpha = 0.25, double theta_i = 55,
                                  int pieces = 1) {
    const Rgbd eta_c(0.143, 0.374, 1.442), k_c(3.983, 2.385, 1.603);
    const Stack stack = test::make_stack({test::conductor_layer(eta_c, k_c, alpha)});
    SimulationSettings s = settings({theta_i}, 1'000'000, HemisphereGrid(18, 18));
    if (tweak) tweak(s);
    const HemisphereGrid grid = s.grid;
    const auto r = simulate(stack, s);
    const ConductorInterface<double> interface { eta_c, k_c, alpha };
    const Vec3d wi = incident_direction(deg_to_rad(theta_i));
    expect_agreement(compare_lobe(
        r.table, 0, Side::Reflection,
        [&](std::size_t j) {
            return test::bin_average(
                grid, j, Side::Reflection, [&](const Vec3d& wo) { return interface.eval(wi, wo); },
                12, pieces);
        },
        double(s.particles)));
    expect_budget_closes(r);
}

TEST_P(GoniophotometerStat, SingleRoughConductor) {
    check_single_rough_conductor();
}

// The white furnace's stacks: a rough slab, a rough coat over a white Lambertian, three rough
// interfaces, and a rough coat with a white scattering medium over `scattering_base`.
std::vector<Stack> white_furnace_stacks(const Layer& scattering_base) {
    return {
        test::make_stack({test::dielectric_layer(1.5, 0.3), test::dielectric_layer(1.0, 0.5)}),
        test::make_stack({test::dielectric_layer(1.5, 0.5), test::lambertian_layer(Rgbd(1.0))}),
        test::make_stack({test::dielectric_layer(1.3, 0.2), test::dielectric_layer(1.7, 0.4),
                          test::dielectric_layer(1.0, 0.1)}),
        test::make_stack(
            {test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.0), Rgbd(0.7), Rgbd(0.3)),
             scattering_base}),
    };
}

// §6.7: white furnace: with nothing absorbing, R + T + microsurface loss = 1 for every
// configuration, nothing is cut off, and the loss is what single scattering loses (> 0 for rough).
TEST_P(GoniophotometerStat, WhiteFurnace) {
    const std::vector<Stack> stacks = white_furnace_stacks(test::lambertian_layer(Rgbd(1.0)));
    for (const Stack& stack : stacks) {
        const auto r = simulate(stack, settings({0, 45, 80}, 100'000, HemisphereGrid(9, 9)));
        for (const IncidenceStats& st : r.incidences) {
            const EnergyBudget& b = st.budget;
            for (int c = 0; c < 3; ++c) {
                EXPECT_NEAR(b[BudgetTerm::Reflected][c] + b[BudgetTerm::Transmitted][c] +
                                b[BudgetTerm::LostMicrosurface][c],
                            1.0, 1e-6);
                EXPECT_NEAR(b[BudgetTerm::AbsorbedMedium][c], 0.0, 1e-9);
                EXPECT_EQ(b[BudgetTerm::CutOff][c], 0.0);
                EXPECT_GT(b[BudgetTerm::LostMicrosurface][c], 0.0);
                if (!stack.transmits()) {
                    EXPECT_EQ(b[BudgetTerm::Transmitted][c], 0.0);
                }
            }
        }
    }
}

// §6.9: reciprocity of the tabulated BRDF: with incidences at bin centres, f(θa → bin of θb) =
// f(θb → bin of θa) at every φ bin, within the combined standard errors (the bin-averaging
// asymmetry is second order in the 5° bin width, far below the noise here).
void expect_tabulated_reciprocity(const Stack& stack, const Tweak& tweak = {}) {
    const HemisphereGrid grid(18, 18);
    SimulationSettings s = settings({22.5, 52.5}, 2'000'000, grid);
    if (tweak) tweak(s);
    const auto r = simulate(stack, s);
    const int ta = 4, tb = 10;  // the θ bins [20°, 25°] and [50°, 55°]
    test::TableComparison cmp;
    for (int p = 0; p < grid.n_phi(); ++p) {
        const std::size_t ja = std::size_t(tb) * grid.n_phi() + p;  // from θa into θb's bin
        const std::size_t jb = std::size_t(ta) * grid.n_phi() + p;
        for (int c = 0; c < 3; ++c) {
            const double fa = r.table.lobe(0, Side::Reflection).f[ja][c];
            const double fb = r.table.lobe(1, Side::Reflection).f[jb][c];
            const double se = std::hypot(r.table.lobe(0, Side::Reflection).se[ja][c],
                                         r.table.lobe(1, Side::Reflection).se[jb][c]);
            ASSERT_GT(se, 0);
            const double z = (fa - fb) / se;
            ++cmp.bins;
            cmp.chi2 += z * z;
            cmp.max_abs_z = std::max(cmp.max_abs_z, std::abs(z));
        }
    }
    expect_agreement(cmp);
}

TEST_P(GoniophotometerStat, TabulatedReciprocity) {
    expect_tabulated_reciprocity(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.3), Rgbd(0.2, 0.05, 0.5)),
                          test::lambertian_layer(Rgbd(0.7, 0.9, 0.5))}));
}

// §6.8: a scattering medium against adding–doubling (support/adding_doubling.h): an index-matched
// slab (smooth interfaces of relative index 1 are pass-throughs), per channel its own τ, ω and g —
// which exercises the spectral MIS of free flights and of the phase function.
TEST_P(GoniophotometerStat, ScatteringSlabAgainstAddingDoubling) {
    const Rgbd tau_s(1.0, 0.5, 2.0), tau_a(0.0, 0.5, 0.1), g(0.0, 0.5, -0.3);
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.0, 0.0), tau_a, tau_s, g),
                          test::dielectric_layer(1.0, 0.0)});
    // Incidences on the reference's quadrature nodes, so it needs no interpolation.
    const test::AddingDoubling probe(1.0, 1.0, 0.0, 24);
    const std::vector<int> nodes = {0, 6, 15};  // μ ≈ 1.0, 0.82, 0.38
    std::vector<double> theta_i;
    for (int j : nodes)
        theta_i.push_back(rad_to_deg(std::acos(probe.mu(j))));
    const auto r = simulate(stack, settings(theta_i, 400'000, HemisphereGrid(9, 9)));
    for (int c = 0; c < 3; ++c) {
        const double tau = tau_s[c] + tau_a[c];
        const test::AddingDoubling ad(tau, tau_s[c] / tau, g[c], 24);
        for (std::size_t i = 0; i < nodes.size(); ++i) {
            const EnergyBudget& b = r.incidences[i].budget;
            // The reference's own accuracy (checked by ReferenceConservesEnergy) is < 1e-5.
            EXPECT_LT(std::abs(b[BudgetTerm::Reflected][c] - ad.albedo_reflected(nodes[i])),
                      5 * b.reflected_se[c] + 1e-5)
                << "channel " << c << " θi " << theta_i[i] << ": R " << b[BudgetTerm::Reflected][c]
                << " ± " << b.reflected_se[c] << " vs " << ad.albedo_reflected(nodes[i]);
            EXPECT_LT(std::abs(b[BudgetTerm::Transmitted][c] - ad.albedo_transmitted(nodes[i])),
                      5 * b.transmitted_se[c] + 1e-5)
                << "channel " << c << " θi " << theta_i[i] << ": T "
                << b[BudgetTerm::Transmitted][c] << " ± " << b.transmitted_se[c] << " vs "
                << ad.albedo_transmitted(nodes[i]);
        }
    }
    expect_budget_closes(r);
}

// Thick media (docs/stack-format.md, "Ranges"): a white-paint-like layer of τs = 10⁴ (g 0.5, with
// τa = 10: ω = 0.999) is semi-infinite for light (its diffusion length is ~20 optical depths), so
// nothing is transmitted, and its R is adding–doubling's (37 doublings: a starting layer of
// 7e-8, as the other tests'); the cost is bounded (events per particle ≤ --max-events) and what
// the cap stops is reported as cut_off, here negligible (the absorption leaves ω^(10⁴) = e^−10 of
// a walk that long). Without absorption (ω = 1) a walk can wander far longer: the cap then stops
// a reported fraction of the flux (the rest is reflected, R + cut_off = 1, nothing transmitted),
// and raising --max-events lowers it.
TEST_P(GoniophotometerStat, ThickScatteringLayer) {
    const test::AddingDoubling probe(1.0, 1.0, 0.0, 16);
    const double theta_i = rad_to_deg(std::acos(probe.mu(4)));
    const double tau_s = 1e4, tau_a = 10, g = 0.5;
    const Stack absorbing = test::make_stack(
        {test::with_medium(test::dielectric_layer(1.0, 0.0), Rgbd(tau_a), Rgbd(tau_s), Rgbd(g)),
         test::dielectric_layer(1.0, 0.0)});
    const auto r = simulate(absorbing, settings({theta_i}, 40'000, HemisphereGrid(9, 9)));
    const test::AddingDoubling ad(tau_s + tau_a, tau_s / (tau_s + tau_a), g, 16, 37);
    const EnergyBudget& b = r.incidences[0].budget;
    for (int c = 0; c < 3; ++c) {
        // The reference's own accuracy (as ScatteringSlabAgainstAddingDoubling's) is < 1e-5.
        EXPECT_LT(std::abs(b[BudgetTerm::Reflected][c] - ad.albedo_reflected(4)),
                  5 * b.reflected_se[c] + 1e-5)
            << "R " << b[BudgetTerm::Reflected][c] << " ± " << b.reflected_se[c] << " vs "
            << ad.albedo_reflected(4);
        EXPECT_LT(ad.albedo_transmitted(4), 1e-12);
        EXPECT_EQ(b[BudgetTerm::Transmitted][c], 0.0);
        EXPECT_LT(b[BudgetTerm::CutOff][c], 1e-4);
    }
    EXPECT_LE(r.incidences[0].events_per_particle, 10'000.0);
    EXPECT_GT(r.incidences[0].events_per_particle, 10.0);
    expect_budget_closes(r);

    const Stack white = test::make_stack(
        {test::with_medium(test::dielectric_layer(1.0, 0.0), Rgbd(0.0), Rgbd(tau_s), Rgbd(0.0)),
         test::dielectric_layer(1.0, 0.0)});
    SimulationSettings s = settings({theta_i}, 4'000, HemisphereGrid(9, 9));
    s.transport.max_events = 2'000;
    const auto capped = simulate(white, s);
    const EnergyBudget& bw = capped.incidences[0].budget;
    for (int c = 0; c < 3; ++c) {
        EXPECT_GT(bw[BudgetTerm::CutOff][c], 0.0);
        EXPECT_NEAR(bw[BudgetTerm::Reflected][c] + bw[BudgetTerm::CutOff][c], 1.0, 1e-6);
        EXPECT_EQ(bw[BudgetTerm::Transmitted][c], 0.0);
    }
    EXPECT_LE(capped.incidences[0].events_per_particle, 2'000.0);
    s.transport.max_events = 20'000;
    const auto longer = simulate(white, s);
    EXPECT_LT(longer.incidences[0].budget[BudgetTerm::CutOff][0], bw[BudgetTerm::CutOff][0]);
}

// The reference itself: conservative scattering (ω = 1) must give R + T = 1, and the thin slab
// limit must match single scattering to first order.
TEST(AddingDoublingReference, ConservesEnergy) {
    for (const double g : {0.0, 0.5, -0.3}) {
        const test::AddingDoubling ad(1.0, 1.0, g, 24);
        for (int j = 0; j < ad.size(); ++j)
            EXPECT_NEAR(ad.albedo_reflected(j) + ad.albedo_transmitted(j), 1.0, 2e-6) << g;
    }
    // No scattering: T = e^{−τ/μ} exactly.
    const test::AddingDoubling clear(0.7, 0.0, 0.0, 16);
    for (int j = 0; j < clear.size(); ++j) {
        // 24 doublings multiply e^{−Δτ/μ} by itself: rounding grows to ~2^24 ulp.
        EXPECT_NEAR(clear.albedo_transmitted(j), std::exp(-0.7 / clear.mu(j)), 1e-8);
        EXPECT_NEAR(clear.albedo_reflected(j), 0.0, 1e-15);
    }
}

// Reproducibility: the same stack, grid, N and seed give bitwise-identical output for any thread
// count, with either microsurface model (the walk draws a lane's numbers whatever the other lanes
// do, in the block's fixed order); a different seed gives different output.
TEST_P(Goniophotometer, BitwiseIdenticalAcrossThreadCounts) {
    const std::vector<Stack> stacks = {
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.1, 0.0, 0.9),
                                            Rgbd(0.3), Rgbd(0.2)),
                          test::lambertian_layer(Rgbd(0.8))}),
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.6)}),
    };
    for (const Stack& stack : stacks)
        for (const Microsurface microsurface : {Microsurface::Single, Microsurface::Multiple}) {
            SCOPED_TRACE(enum_text(microsurface));
            SimulationSettings s = settings({0, 60}, 50'000, HemisphereGrid(30, 30));
            s.transport.microsurface = microsurface;
            s.threads = 1;
            const auto one = simulate(stack, s);
            s.threads = 2;
            const auto two = simulate(stack, s);
            s.threads = 3;
            const auto three = simulate(stack, s);
            for (std::size_t i = 0; i < 2; ++i) {
                EXPECT_EQ(one.table.lobe(i, Side::Reflection).f,
                          two.table.lobe(i, Side::Reflection).f);
                EXPECT_EQ(one.table.lobe(i, Side::Reflection).se,
                          two.table.lobe(i, Side::Reflection).se);
                EXPECT_EQ(one.table.lobe(i, Side::Reflection).f,
                          three.table.lobe(i, Side::Reflection).f);
                EXPECT_EQ(one.incidences[i].budget.term, two.incidences[i].budget.term);
                EXPECT_EQ(one.incidences[i].budget.term, three.incidences[i].budget.term);
            }
            s.seed = 8;
            const auto other = simulate(stack, s);
            EXPECT_NE(one.table.lobe(0, Side::Reflection).f,
                      other.table.lobe(0, Side::Reflection).f);
        }
}

TEST_P(Goniophotometer, RejectsBadSettings) {
    SimulationSettings s;
    s.theta_i_deg = {90};
    EXPECT_THROW(validate_settings(s), InputError);
    s.theta_i_deg = {-1};
    EXPECT_THROW(validate_settings(s), InputError);
    s.theta_i_deg = {30};
    s.particles = 0;
    EXPECT_THROW(validate_settings(s), InputError);
}

// ---- Multiple scattering on the microsurfaces (physics/microsurface_walk.h, both kernels) -----

// The walk is one lane template (microsurface_walk.h) run by both kernels: every test below runs
// on each (the kernel under test is the suite's parameter, set by the fixture).
class MicrosurfaceWalkStat : public ::testing::TestWithParam<Kernel> {
  protected:
    void SetUp() override { g_kernel = GetParam(); }
};
INSTANTIATE_TEST_SUITE_P(Kernels, MicrosurfaceWalkStat,
                         ::testing::Values(Kernel::Scalar, Kernel::Simd), test::kernel_test_name);

void multiple_scattering(SimulationSettings& s) {
    s.kernel = g_kernel;
    s.transport.microsurface = Microsurface::Multiple;
}
void first_order_only(SimulationSettings& s) {
    multiple_scattering(s);
    s.transport.max_microsurface_order = 1;
}

// The first order on a coarser grid: the walk's first-order exits all carry flux 1 (the
// single-scattering sampler's carry G2/G1 < 1), so a bin holds fewer, whole exits, and the
// standard error estimated from a bin's own few exits is biased low where they fluctuate low;
// 10° bins and 2·10⁶ particles keep every bin's expected count above ~100.
void first_order_table(SimulationSettings& s) {
    first_order_only(s);
    s.grid = HemisphereGrid(9, 9);
    s.particles = 2'000'000;
}

// The walk's first order is the single-scattering interface with the height-correlated Smith
// masking-shadowing (Heitz et al. 2016; microsurface_walk.h derives it): cut after one facet, the
// walk must reproduce the Walter et al. 2007 BSDF bin by bin, from both sides of a dielectric and
// on a conductor — with 1/(1 + Λi + Λo) for reflection and B(1 + Λi, 1 + Λo) for refraction (see
// check_single_rough_dielectric). This tests the walk's height sampling, its visible normals and
// its Fresnel choices against closed forms. (At the dense side's θi = 50°, Λi ≈ 0.03, the two
// transmission forms differ by 4 % at grazing exits: the test tells them apart.)
TEST_P(MicrosurfaceWalkStat, FirstOrderIsTheSingleScatteringInterface) {
    {
        SCOPED_TRACE("dielectric from above");
        check_single_rough_dielectric(1.0, 1.5, 0.3, 40, first_order_table);
    }
    {
        SCOPED_TRACE("dielectric from the dense side");
        check_single_rough_dielectric(1.5, 1.0, 0.3, 50, first_order_table);
    }
    {
        SCOPED_TRACE("conductor");
        check_single_rough_conductor(first_order_table);
    }
    // Grazing incidence on very rough interfaces (Λi ≈ 0.7–1.0): where the first hit's height
    // distribution, (1 + Λi) c^Λi, shapes the result (at the angles above Λi is a few hundredths;
    // a walk with 0.7 Λi for downward rays passes those and fails these). Reflection only for the
    // dielectric (see check_single_rough_dielectric).
    {
        SCOPED_TRACE("dielectric at grazing incidence");
        check_single_rough_dielectric(1.0, 1.5, 0.6, 75, first_order_table,
                                      TransmissionMasking::Smith, 4, true);
    }
    {
        SCOPED_TRACE("conductor at grazing incidence");
        check_single_rough_conductor(first_order_table, 0.5, 80, 4);
    }
}

// The multiple-scattering BSDF is reciprocal (Heitz et al. 2016 prove it for the walk): the
// tabulated BRDF of a very rough dielectric and of a very rough conductor, where the higher orders
// carry 10–20 % of the energy at these angles, and of a rough coat over a Lambertian.
TEST_P(MicrosurfaceWalkStat, TabulatedReciprocity) {
    {
        SCOPED_TRACE("rough dielectric");
        expect_tabulated_reciprocity(test::make_stack({test::dielectric_layer(1.5, 0.8)}),
                                     multiple_scattering);
    }
    {
        SCOPED_TRACE("rough conductor");
        expect_tabulated_reciprocity(test::make_stack({test::conductor_layer(
                                         Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.9)}),
                                     multiple_scattering);
    }
    {
        SCOPED_TRACE("rough coat over a Lambertian");
        expect_tabulated_reciprocity(
            test::make_stack(
                {test::with_medium(test::dielectric_layer(1.5, 0.6), Rgbd(0.2, 0.05, 0.5)),
                 test::lambertian_layer(Rgbd(0.7, 0.9, 0.5))}),
            multiple_scattering);
    }
}

// White furnace with multiple scattering: nothing is lost on the microsurfaces, so with nothing
// absorbing R + T = 1 exactly (each particle's flux stays 1), where single scattering loses a
// positive fraction (GoniophotometerStat.WhiteFurnace). The higher orders also change where the
// energy goes: a very rough dielectric reflects more than its first order.
TEST_P(MicrosurfaceWalkStat, WhiteFurnaceLosesNothing) {
    const std::vector<Stack> stacks = {
        test::make_stack({test::dielectric_layer(1.5, 0.3), test::dielectric_layer(1.0, 0.5)}),
        test::make_stack({test::dielectric_layer(1.5, 0.5), test::lambertian_layer(Rgbd(1.0))}),
        test::make_stack({test::dielectric_layer(1.3, 0.2), test::dielectric_layer(1.7, 0.4),
                          test::dielectric_layer(1.0, 0.1)}),
        test::make_stack({test::dielectric_layer(1.5, 0.9)}),
    };
    for (const Stack& stack : stacks) {
        SimulationSettings s = settings({0, 45, 80}, 100'000, HemisphereGrid(9, 9));
        multiple_scattering(s);
        expect_white_furnace_loses_nothing(simulate(stack, s));
    }
}

// A very rough dielectric: the higher orders add reflection (light that single scattering loses
// after a first facet sends it back down into the microsurface, then up again). R with multiple
// scattering exceeds R of the first order by more than the noise.
TEST_P(MicrosurfaceWalkStat, HigherOrdersAddReflection) {
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.9)});
    SimulationSettings s = settings({60}, 400'000, HemisphereGrid(9, 9));
    first_order_only(s);
    const auto first = simulate(stack, s);
    multiple_scattering(s);
    s.transport.max_microsurface_order = TransportSettings{}.max_microsurface_order;
    const auto all = simulate(stack, s);
    const EnergyBudget &b1 = first.incidences[0].budget, &b = all.incidences[0].budget;
    const double se = std::hypot(b1.reflected_se[0], b.reflected_se[0]);
    EXPECT_GT(b[BudgetTerm::Reflected][0] - b1[BudgetTerm::Reflected][0], 10 * se);
    EXPECT_GT(b1[BudgetTerm::LostMicrosurface][0], 0.05);
}

TEST(MicrosurfaceWalk, RunsOnBothKernels) {
    SimulationSettings s;
    s.transport.microsurface = Microsurface::Multiple;
    s.kernel = Kernel::Simd;
    EXPECT_NO_THROW(validate_settings(s));
    s.kernel = Kernel::Scalar;
    EXPECT_NO_THROW(validate_settings(s));
    s.transport.max_microsurface_order = 0;
    EXPECT_THROW(validate_settings(s), InputError);
    const SettingInfo info{.name = "microsurface", .help = ""};
    EXPECT_EQ(SettingCodec<Microsurface>::from_text("multiple", info, "test", "microsurface"),
              Microsurface::Multiple);
    EXPECT_THROW(SettingCodec<Microsurface>::from_text("heitz", info, "test", "microsurface"),
                 InputError);
}

// Fuzz seed 1214, case 2100: particles trapped in a dense scattering layer (τs = 100 under an
// η = 5 rough coat, multiple scattering on the microsurfaces, so nothing is lost there) lose their
// flux in thousands of small pieces; the scalar kernel summed a particle's pieces in float and its
// budget came to 0.9999988. Summed in double (simulator/tally.h PathLosses), both kernels close
// the budget to 1e-12 (it measured 8e-16 scalar, 5e-12 SIMD with its float lane sums).
// Polarized, every Fresnel event also reweights the flux by the ratio of the polarized
// reflectance to the probability it was chosen with; both are computed from the same Stokes
// vector, but in the SIMD kernel in float, so the ratio is 1 to float rounding at each event
// (it measured 3e-9 over these paths): there the budget closes to a float weight's precision.
TEST(Goniophotometer, BudgetClosesForLongTrappedPaths) {
    const Stack stack = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 5, "alpha": 0.8955043569454005}, "medium": {"tau_a": 1, "tau_s": [99.99999999999999, 99.99999999999999, 100]}}, {"interface": {"type": "dielectric", "eta": 1.0000000000000002, "alpha": 0}, "medium": {"tau_a": [99.99999999999999, 5e-324, 1e-20], "g": [-0.99, 0.9899999999999999, -0.06751035881917672]}}, {"interface": {"type": "conductor", "eta": [10, 2.0769384783680316, 2.3127355907747273], "k": 0.0, "alpha": 1}}]})",
        "fuzz-1214-2100");
    for (const Kernel kernel : {Kernel::Scalar, Kernel::Simd})
        for (const bool polarization : {false, true}) {
            SimulationSettings s;
            s.theta_i_deg = {0.0, 45.0, 89.999999};
            s.particles = 1024;
            s.seed = 3;
            s.threads = 1;
            s.grid = HemisphereGrid(3, 4);
            s.kernel = kernel;
            s.transport.microsurface = Microsurface::Multiple;
            s.transport.polarization = polarization;
            const double tolerance =
                polarization && kernel == Kernel::Simd ? 1e-7 : 1e-10;  // float weights
            const SimulationResult r = simulate(stack, s);
            for (const IncidenceStats& st : r.incidences)
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(st.budget.sum()[c], 1.0, tolerance)
                        << enum_text(kernel) << " polarization " << polarization;
        }
}

// ---- Polarized transport (docs/physics.md §8, both kernels) ------------------------------------

class PolarizationStat : public ::testing::TestWithParam<Kernel> {
  protected:
    void SetUp() override { g_kernel = GetParam(); }
};
INSTANTIATE_TEST_SUITE_P(Kernels, PolarizationStat, ::testing::Values(Kernel::Scalar, Kernel::Simd),
                         test::kernel_test_name);

SimulationSettings polarized(std::vector<double> theta_i, std::uint64_t n, HemisphereGrid grid,
                             int incident = 0) {
    SimulationSettings s = settings(std::move(theta_i), n, grid);
    s.transport.polarization = true;
    s.incident_polarization = incident;
    return s;
}

// A smooth slab (§6.4) with polarization: s and p never mix (every event lies in the plane of
// incidence), so the exact R and T are the means over s and p of the incoherent series
// (support/closed_forms.h PolarizedSlab). η = 1.5 at 60° gives R = 0.151872, T = 0.848128, where
// averaging s and p at every bounce (the unpolarized tracer) gives 0.163768 and 0.836232: the
// difference is 20 standard errors here. Several indices, angles and absorptions.
TEST_P(PolarizationStat, SmoothSlabStokesSums) {
    const double mu60 = 0.5;
    EXPECT_NEAR(test::PolarizedSlab(mu60, 1.5, 1.0).R, 0.151872, 1e-6);
    EXPECT_NEAR(test::PolarizedSlab(mu60, 1.5, 1.0).T, 0.848128, 1e-6);
    struct Case {
        double eta;
        Rgbd tau;
        std::vector<double> theta_i;
    };
    for (const Case& k :
         {Case{1.5, Rgbd(0.0, 0.2, 1.0), {45, 60, 75}}, Case{2.4, Rgbd(0.0, 0.0, 0.3), {30, 70}},
          Case{1.33, Rgbd(0.0), {56, 85}}}) {
        const Stack stack =
            test::make_stack({test::with_medium(test::dielectric_layer(k.eta, 0.0), k.tau),
                              test::dielectric_layer(1.0, 0.0)});
        const auto r = simulate(stack, polarized(k.theta_i, 300'000, HemisphereGrid(18, 18)));
        for (std::size_t i = 0; i < k.theta_i.size(); ++i) {
            const double mu_i = std::cos(deg_to_rad(k.theta_i[i]));
            const double mu_t = std::sqrt(1 - (1 - mu_i * mu_i) / (k.eta * k.eta));
            const EnergyBudget& b = r.incidences[i].budget;
            for (int c = 0; c < 3; ++c) {
                const test::PolarizedSlab exact(mu_i, k.eta, std::exp(-k.tau[c] / mu_t));
                SCOPED_TRACE(::testing::Message() << "η " << k.eta << " θi " << k.theta_i[i]);
                expect_within_se(b[BudgetTerm::Reflected][c], exact.R, b.reflected_se[c], "R");
                expect_within_se(b[BudgetTerm::Transmitted][c], exact.T, b.transmitted_se[c], "T");
            }
        }
        expect_budget_closes(r);
    }
}

// Brewster's angle (tan θB = η): p-polarized light is not reflected at all (R_p = 0: every
// particle refracts), s-polarized light is reflected with R_s = ((1 − η²)/(1 + η²))² = 25/169 for
// η = 1.5, and unpolarized light with R_s/2.
TEST_P(PolarizationStat, BrewsterAngle) {
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.0)});
    const double theta_b = rad_to_deg(std::atan(1.5));
    const double rs = 25.0 / 169.0;
    const auto p_light = simulate(stack, polarized({theta_b}, 200'000, HemisphereGrid(9, 9), 4));
    const auto s_light = simulate(stack, polarized({theta_b}, 200'000, HemisphereGrid(9, 9), 1));
    const auto unpolarized = simulate(stack, polarized({theta_b}, 200'000, HemisphereGrid(9, 9)));
    for (int c = 0; c < 3; ++c) {
        // R_p is zero to the rounding of a − b in float (≤ 1e-7): no particle is reflected.
        EXPECT_LT(p_light.incidences[0].budget[BudgetTerm::Reflected][c], 1e-6);
        const EnergyBudget& bs = s_light.incidences[0].budget;
        expect_within_se(bs[BudgetTerm::Reflected][c], rs, bs.reflected_se[c], "R_s");
        const EnergyBudget& bu = unpolarized.incidences[0].budget;
        expect_within_se(bu[BudgetTerm::Reflected][c], rs / 2, bu.reflected_se[c], "R_s/2");
    }
}

// A smooth coat (η, absorption a per crossing) over a smooth conductor of per-channel index
// (η_c + ik_c)/η relative to the coat, with the phases of every reflection (§6.5 polarized):
// every event lies in the plane of incidence, each acts on the Stokes vector in the block form of
// physics/polarization.h, so s and p intensities follow their own series
//     I_x = R_x + (1 − R_x)² Rc_x a² / (1 − R_x Rc_x a²)   (x = s, p; the coat's R_x at μi, the
//                                                          same inside at μi', Rc_x at μi')
// and S2 + iS3 is multiplied by the complex series of the events' factors A* B (a Jones matrix
// diag(A, B) multiplies S2 + iS3 = 2E_x* E_y by A* B):
//     z = z_R + z_T z_C z_T' a² / (1 − z_R' z_C a²),
// z_R = r_s* r_p of the coat from outside, z_R' from inside, z_C of the conductor (complex: its
// phase), z_T, z_T' the flux factors times t_s t_p. For incident light (1, q, u, v): S0 =
// ((1 + q) I_s + (1 − q) I_p)/2, S1 = ((1 + q) I_s − (1 − q) I_p)/2, S2 + iS3 = z (u + iv), all
// in the mirror bin. Checked for unpolarized, s-polarized, +45° and circular incident light
// (incident_polarization 0–3) at 20° and 60°, per channel (the conductor's colour makes the
// channels' states differ: the per-channel states and the coat's reweighted branch choice).
TEST_P(PolarizationStat, CoatOverMirrorConductorWithBothPhases) {
    const double eta = 1.5;
    const Rgbd tau(0.1, 0.3, 0.0), eta_c(0.143, 0.374, 1.442), k_c(3.983, 2.385, 1.603);
    const Stack stack = test::make_stack({test::with_medium(test::dielectric_layer(eta, 0.0), tau),
                                          test::conductor_layer(eta_c, k_c, 0.0)});
    const HemisphereGrid grid(18, 18);
    const std::uint64_t n = 300'000;
    constexpr double kIncident[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (int state = 0; state < 4; ++state) {
        SimulationSettings s = polarized({20, 60}, n, grid, state);
        s.stokes_tallies = true;
        const auto r = simulate(stack, s);
        for (std::size_t i = 0; i < 2; ++i) {
            const double mu_i = std::cos(deg_to_rad(r.settings.theta_i_deg[i]));
            const double mu_t = std::sqrt(1 - (1 - mu_i * mu_i) / (eta * eta));
            const test::PolarizedFresnel outer(mu_i, eta), inner(mu_t, 1 / eta);
            const Vec3f wi_f(incident_direction(deg_to_rad(r.settings.theta_i_deg[i])));
            const std::size_t mirror_bin = grid.bin_of(Vec3f(-wi_f.x, -wi_f.y, wi_f.z));
            for (int c = 0; c < 3; ++c) {
                SCOPED_TRACE(::testing::Message() << "state " << state << " θi "
                                                  << r.settings.theta_i_deg[i] << " channel " << c);
                const double a = std::exp(-tau[c] / mu_t);
                const test::PolarizedFresnel cond(mu_t,
                                                  std::complex<double>(eta_c[c], k_c[c]) / eta);
                const double is = outer.Rs() + sqr(1 - outer.Rs()) * cond.Rs() * a * a /
                                                   (1 - inner.Rs() * cond.Rs() * a * a);
                const double ip = outer.Rp() + sqr(1 - outer.Rp()) * cond.Rp() * a * a /
                                                   (1 - inner.Rp() * cond.Rp() * a * a);
                const std::complex<double> z =
                    outer.reflected_phase() +
                    outer.transmitted_phase() * cond.reflected_phase() * inner.transmitted_phase() *
                        a * a / (1.0 - inner.reflected_phase() * cond.reflected_phase() * a * a);
                const double q = kIncident[state][0];
                const std::complex<double> w =
                    z * std::complex<double>(kIncident[state][1], kIncident[state][2]);
                const double expected[4] = {((1 + q) * is + (1 - q) * ip) / 2,
                                            ((1 + q) * is - (1 - q) * ip) / 2, w.real(), w.imag()};
                const BinStokes got = bin_stokes(r.sums[i], mirror_bin, c, n);
                for (int k = 0; k < 4; ++k) {
                    const double se =
                        std::sqrt(std::max(0.0, got.second[k] - sqr(got.upper[k])) / double(n - 1));
                    expect_within_se(got.upper[k], expected[k], se, "S_k in the mirror bin");
                    EXPECT_EQ(got.lower[k], 0.0);  // the mirror direction lies in the plane, y = 0
                }
                // The reflected budget is S0.
                expect_within_se(r.incidences[i].budget[BudgetTerm::Reflected][c], expected[0],
                                 r.incidences[i].budget.reflected_se[c], "R");
            }
        }
        expect_budget_closes(r);
    }
}

// Where the depolarizing base makes the unpolarized series exact, polarization must reproduce it.
TEST_P(PolarizationStat, LambertianAlone) {
    check_lambertian_alone(true);
}
TEST_P(PolarizationStat, SmoothCoatOverLambertianSeries) {
    check_smooth_coat_over_lambertian(true);
}

// White furnace, polarized, with multiple scattering on the microsurfaces: every dielectric
// event keeps the particle's flux (its branch probability is the state's reflected fraction, which
// cancels it), a white Lambertian base keeps it, so R + T = 1 to rounding and nothing is lost.
TEST_P(PolarizationStat, WhiteFurnaceLosesNothing) {
    const std::vector<Stack> stacks = white_furnace_stacks(test::dielectric_layer(1.0, 0.6));
    for (const Stack& stack : stacks) {
        SimulationSettings s = polarized({0, 45, 80}, 100'000, HemisphereGrid(9, 9));
        s.transport.microsurface = Microsurface::Multiple;
        expect_white_furnace_loses_nothing(simulate(stack, s));
    }
}

// Polarized runs are bitwise reproducible for any thread count too, their Stokes tallies
// included (a coloured rough conductor under a rough coat: one state per channel).
TEST_P(Goniophotometer, PolarizedBitwiseIdenticalAcrossThreadCounts) {
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.6)});
    for (const Microsurface microsurface : {Microsurface::Single, Microsurface::Multiple}) {
        SCOPED_TRACE(enum_text(microsurface));
        SimulationSettings s = polarized({0, 60}, 50'000, HemisphereGrid(30, 30), 2);
        s.stokes_tallies = true;
        s.transport.microsurface = microsurface;
        s.threads = 1;
        const auto one = simulate(stack, s);
        s.threads = 3;
        const auto three = simulate(stack, s);
        for (std::size_t i = 0; i < 2; ++i) {
            EXPECT_EQ(one.table.lobe(i, Side::Reflection).f,
                      three.table.lobe(i, Side::Reflection).f);
            EXPECT_EQ(one.incidences[i].budget.term, three.incidences[i].budget.term);
            EXPECT_TRUE(one.sums[i].stokes == three.sums[i].stokes);
        }
    }
}

}  // namespace
}  // namespace lamina

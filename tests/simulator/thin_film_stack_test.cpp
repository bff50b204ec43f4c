// Filmed stacks on the goniophotometer's scalar kernel (docs/physics.md §9) against closed forms,
// with tolerances from the standard errors it reports: a smooth filmed interface (the film's Airy
// R and T, polarized and not), a filmed smooth slab (the incoherent series of the film's and the
// back face's intensities, per polarization), a filmed smooth conductor, a film whose thickness
// spans one period (the incoherent slab), the white furnace of a rough filmed dielectric, a film of
// thickness 0 against the bare stack. Suites ending in Stat are the `stat` label.
#include "core/error.h"
#include "core/math.h"
#include "models/registry.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/thin_film.h"
#include "randomwalk/random_walk.h"
#include "simulator/goniophotometer.h"
#include "support/quadrature.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>

namespace lamina {
namespace {

using C = std::complex<double>;
using test::compare_lobe;
using test::expect_agreement;

SimulationSettings scalar_settings(std::vector<double> theta_i, std::uint64_t n, bool polarization,
                                   std::uint64_t seed = 11) {
    SimulationSettings s;
    s.kernel = Kernel::Scalar;
    s.theta_i_deg = std::move(theta_i);
    s.particles = n;
    s.grid = HemisphereGrid(9, 9);
    s.seed = seed;
    s.transport.polarization = polarization;
    return s;
}

Layer with_film(Layer layer, double thickness_nm, double eta, double k = 0.0,
                double thickness_max_nm = -1) {
    layer.interface.has_film = true;
    layer.interface.film.thickness_nm = thickness_nm;
    layer.interface.film.thickness_max_nm = thickness_max_nm < 0 ? thickness_nm : thickness_max_nm;
    layer.interface.film.eta = eta;
    layer.interface.film.k = k;
    return layer;
}

// |estimate − exact| < 5 se (+1e-7, the float kernel's rounding of a budget); budgets close to
// 1e-5.
void expect_within_se_of_float(double estimate, double exact, double se, const std::string& what) {
    test::expect_within_se(estimate, exact, se, what, 1e-7);
}
void expect_budget_closes_float(const SimulationResult& r) {
    test::expect_budget_closes(r, 1e-5);
}

// The film's s and p intensities: reflection and transmission.
struct SP {
    double Rs, Rp, Ts, Tp;
};
SP intensities(const ThinFilmMueller<double>& m) {
    return {m.reflection.a + m.reflection.b, m.reflection.a - m.reflection.b,
            m.transmission.a + m.transmission.b, m.transmission.a - m.transmission.b};
}

// A smooth filmed interface, air | film | glass: every particle meets it once, so R and T are the
// film's Airy R and T for unpolarized light (polarized tracing or not), and for s-polarized
// incident light R_s, T_s. A high-index film (2.2, 150 nm) at normal and oblique incidence.
TEST(ThinFilmStackStat, SmoothFilmedInterface) {
    const Stack stack = test::make_stack({with_film(test::dielectric_layer(1.52, 0.0), 150, 2.2)});
    const std::vector<double> angles = {0, 45, 70};
    for (const int mode : {0, 1, 2}) {  // unpolarized tracing; polarized; polarized, s light
        SimulationSettings s = scalar_settings(angles, 200'000, mode > 0);
        if (mode == 2) s.incident_polarization = 1;
        const SimulationResult r = simulate(stack, s);
        for (std::size_t i = 0; i < angles.size(); ++i) {
            const double mu = std::cos(deg_to_rad(angles[i]));
            const EnergyBudget& b = r.incidences[i].budget;
            for (int c = 0; c < 3; ++c) {
                const SP sp = intensities(
                    thin_film_mueller(mu, C(2.2), C(1.52), 150.0 / stack.wavelengths_nm[c]));
                const double R = mode == 2 ? sp.Rs : (sp.Rs + sp.Rp) / 2;
                const double T = mode == 2 ? sp.Ts : (sp.Ts + sp.Tp) / 2;
                const std::string what =
                    "mode " + std::to_string(mode) + " θ " + std::to_string(angles[i]);
                expect_within_se_of_float(b[BudgetTerm::Reflected][c], R, b.reflected_se[c],
                                          "R " + what);
                expect_within_se_of_float(b[BudgetTerm::Transmitted][c], T, b.transmitted_se[c],
                                          "T " + what);
            }
        }
        expect_budget_closes_float(r);
    }
}

// A filmed smooth slab: air | film (1.38, 120 nm) | glass 1.5, absorbing | air. s and p never mix
// (every event lies in the plane of incidence), so with the film's intensities from above (R1, T1)
// and from inside (R1', T1'), the back face's R2, T2 at the inside angle and a = e^{−τ/μ'}:
//   R = R1 + T1 T1' R2 a² / (1 − R1' R2 a²),  T = T1 T2 a / (1 − R1' R2 a²)
// per polarization, averaged over s and p (polarized), or the same series with the averages of s
// and p at every event (--polarization off). At 70° the two differ by many standard errors.
TEST(ThinFilmStackStat, FilmedSmoothSlab) {
    const double eta = 1.5, d = 120, nf = 1.38;
    const Rgbd tau(0.0, 0.1, 0.4);
    const Stack stack = test::make_stack(
        {test::with_medium(with_film(test::dielectric_layer(eta, 0.0), d, nf), tau),
         test::dielectric_layer(1.0, 0.0)});
    const std::vector<double> angles = {20, 70};
    for (const bool polarization : {false, true}) {
        const SimulationResult r = simulate(stack, scalar_settings(angles, 300'000, polarization));
        for (std::size_t i = 0; i < angles.size(); ++i) {
            const double mu = std::cos(deg_to_rad(angles[i]));
            const double mu_t = std::sqrt(1 - (1 - mu * mu) / (eta * eta));
            const EnergyBudget& b = r.incidences[i].budget;
            double unpolarized_gap = 0;
            for (int c = 0; c < 3; ++c) {
                const double lambda = stack.wavelengths_nm[c];
                const double a = std::exp(-tau[c] / mu_t);
                const SP top = intensities(thin_film_mueller(mu, C(nf), C(eta), d / lambda));
                const SP inside =
                    intensities(thin_film_mueller(mu_t, C(nf / eta), C(1 / eta), d * eta / lambda));
                const DielectricMueller<double> back =
                    fresnel_dielectric_mueller(mu_t, 1 / eta, eta);
                const double R2s = back.reflection.a + back.reflection.b,
                             R2p = back.reflection.a - back.reflection.b;
                auto series = [&](double R1, double T1, double R1i, double T1i, double R2,
                                  double T2, double& R, double& T) {
                    const double den = 1 - R1i * R2 * a * a;
                    R = R1 + T1 * T1i * R2 * a * a / den;
                    T = T1 * T2 * a / den;
                };
                double Rs, Ts, Rp, Tp, Ru, Tu;
                series(top.Rs, top.Ts, inside.Rs, inside.Ts, R2s, 1 - R2s, Rs, Ts);
                series(top.Rp, top.Tp, inside.Rp, inside.Tp, R2p, 1 - R2p, Rp, Tp);
                series((top.Rs + top.Rp) / 2, (top.Ts + top.Tp) / 2, (inside.Rs + inside.Rp) / 2,
                       (inside.Ts + inside.Tp) / 2, back.reflection.a, 1 - back.reflection.a, Ru,
                       Tu);
                const double R = polarization ? (Rs + Rp) / 2 : Ru;
                const double T = polarization ? (Ts + Tp) / 2 : Tu;
                const std::string what = std::string(polarization ? "polarized" : "unpolarized") +
                                         " θ " + std::to_string(angles[i]);
                expect_within_se_of_float(b[BudgetTerm::Reflected][c], R, b.reflected_se[c],
                                          "R " + what);
                expect_within_se_of_float(b[BudgetTerm::Transmitted][c], T, b.transmitted_se[c],
                                          "T " + what);
                unpolarized_gap =
                    std::max(unpolarized_gap, std::abs((Rs + Rp) / 2 - Ru) / b.reflected_se[c]);
            }
            // Polarization matters at 70° (the s/p series differ from the averaged one).
            if (angles[i] == 70) {
                EXPECT_GT(unpolarized_gap, 10);
            }
        }
        expect_budget_closes_float(r);
    }
}

// A smooth conductor under an oxide film: R is the film's reflectance over the metal, the rest
// absorbed at the base, polarized or not; an absorbing film over a metal too. On both kernels (the
// SIMD kernel traces films on conductors).
TEST(ThinFilmStackStat, FilmedSmoothConductor) {
    const Rgbd eta_c(2.74, 2.54, 2.26), k_c(3.79, 3.43, 3.07);
    for (const double k_film : {0.0, 0.3}) {
        const Stack stack =
            test::make_stack({with_film(test::conductor_layer(eta_c, k_c, 0.0), 60, 2.5, k_film)});
        for (const auto& [polarization, kernel] :
             {std::pair{false, Kernel::Scalar}, std::pair{true, Kernel::Scalar},
              std::pair{false, Kernel::Simd}, std::pair{true, Kernel::Simd}}) {
            SCOPED_TRACE(enum_text(kernel));
            SimulationSettings s = scalar_settings({0, 60}, 50'000, polarization);
            s.kernel = kernel;
            const SimulationResult r = simulate(stack, s);
            for (std::size_t i = 0; i < 2; ++i) {
                const double mu = std::cos(deg_to_rad(r.settings.theta_i_deg[i]));
                for (int c = 0; c < 3; ++c) {
                    const double R = thin_film_mueller(mu, C(2.5, k_film), C(eta_c[c], k_c[c]),
                                                       60.0 / stack.wavelengths_nm[c])
                                         .reflection.a;
                    // Every particle reflects with the same factor: exact to float rounding.
                    EXPECT_NEAR(r.incidences[i].budget[BudgetTerm::Reflected][c], R, 1e-6);
                    EXPECT_NEAR(r.incidences[i].budget[BudgetTerm::AbsorbedBase][c], 1 - R, 1e-6);
                }
            }
            expect_budget_closes_float(r);
        }
    }
}

// Single scattering on a rough filmed interface (one facet: --physics bpb19's microsurface), bin
// by bin: Walter et al. 2007's BSDF with the film's R and T at the facet in place of the bare
// Fresnel factors, f_r = R_film(wi·h) D(h) G2 / (4 μi μo) (their Eq. 20) and
// f_t = |wi·h| |wo·h| η_o² T_film(wi·h) D(h) G2 / (μi |μo| (η_i wi·h + η_o wo·h)²) (Eq. 21), with
// the Smith refraction masking B(1 + Λi, 1 + Λo) from the C++ library's Beta function. The first
// facet sees unpolarized light, so polarized tracing gives the same tables. A rough conductor under
// an oxide film and a rough glass under a high-index film.
TEST(ThinFilmStackStat, RoughFilmedInterfaceIsWaltersBsdfWithTheFilm) {
    const double alpha = 0.3, theta_i = 40, d = 130, nf = 2.1;
    const Vec3d wi = incident_direction(deg_to_rad(theta_i));
    const GGX<double> ggx{alpha};
    const Rgbd eta_c(0.143, 0.374, 1.442), k_c(3.983, 2.385, 1.603);
    const Stack conductor =
        test::make_stack({with_film(test::conductor_layer(eta_c, k_c, alpha), d, nf)});
    const Stack glass = test::make_stack({with_film(test::dielectric_layer(1.5, alpha), d, nf)});
    const DielectricInterface<double> bare{1.5, alpha};
    for (const bool polarization : {false, true}) {
        SCOPED_TRACE(polarization ? "polarized" : "unpolarized");
        SimulationSettings s = scalar_settings({theta_i}, 1'000'000, polarization);
        // 9 × 9 bins: the polar caps of a finer grid hold a few particles each, too few for the
        // normal approximation of their z-scores.
        s.grid = HemisphereGrid(9, 9);
        s.transport.microsurface = Microsurface::Single;
        for (const Kernel kernel : {Kernel::Scalar, Kernel::Simd}) {
            SCOPED_TRACE(::testing::Message() << "conductor, " << enum_text(kernel));
            SimulationSettings sk = s;
            sk.kernel = kernel;
            const SimulationResult r = simulate(conductor, sk);
            expect_agreement(compare_lobe(
                r.table, 0, Side::Reflection,
                [&](std::size_t j) {
                    return test::bin_average(
                        s.grid, j, Side::Reflection,
                        [&](const Vec3d& wo) {
                            if (wo.z <= 0) return Rgbd(0.0);
                            const Vec3d h = normalize(wi + wo);
                            const double g = ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
                            Rgbd f;
                            for (int c = 0; c < 3; ++c)
                                f[c] = g * thin_film_mueller(dot(wi, h), C(nf), C(eta_c[c], k_c[c]),
                                                             d / conductor.wavelengths_nm[c])
                                               .reflection.a;
                            return f;
                        },
                        12, 1);
                },
                double(s.particles)));
        }
        SCOPED_TRACE("dielectric");
        const SimulationResult r = simulate(glass, s);
        for (const Side side : {Side::Reflection, Side::Transmission}) {
            SCOPED_TRACE(side == Side::Reflection ? "reflection" : "transmission");
            expect_agreement(compare_lobe(
                r.table, 0, side,
                [&](std::size_t j) {
                    return test::bin_average(
                        s.grid, j, side,
                        [&](const Vec3d& wo) {
                            const auto h = bare.half_vector(wi, wo);
                            if (!h || wo.z == 0) return Rgbd(0.0);
                            const double cos_h = dot(wi, *h);
                            Rgbd f;
                            if (side == Side::Reflection) {
                                const double g = ggx.D(*h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
                                for (int c = 0; c < 3; ++c)
                                    f[c] = g * thin_film_mueller(cos_h, C(nf), C(1.5),
                                                                 d / glass.wavelengths_nm[c])
                                                   .reflection.a;
                                return f;
                            }
                            const double li = ggx.lambda(wi), lo = ggx.lambda(wo);
                            const double g2 = std::beta(1 + li, 1 + lo);
                            const double g =
                                std::abs(cos_h * dot(wo, *h)) * 1.5 * 1.5 * ggx.D(*h) * g2 /
                                (std::abs(wi.z * wo.z) * sqr(cos_h + 1.5 * dot(wo, *h)));
                            for (int c = 0; c < 3; ++c)
                                f[c] = g * thin_film_mueller(cos_h, C(nf), C(1.5),
                                                             d / glass.wavelengths_nm[c])
                                               .transmission.a;
                            return f;
                        },
                        12, 1);
                },
                double(s.particles)));
        }
    }
}

// A film between a coat and a metal: a smooth coat (1.5, absorbing) over a smooth conductor under
// an oxide film, whose incident medium is the coat. s and p decouple, so with the coat's F_x at μi,
// the film over the metal seen from inside the coat R_x at μi' (indices relative to the coat,
// thickness in wavelengths inside it) and a = e^{−τ/μi'}:
//   R = F_x + (1 − F_x)² R_x a² / (1 − F_x R_x a²)   (§6.5 with the film),
// averaged over s and p (polarized), or the same series with the averages (unpolarized).
TEST(ThinFilmStackStat, FilmUnderACoat) {
    const double eta = 1.5, d = 90, nf = 2.3;
    const Rgbd tau(0.1, 0.0, 0.2), eta_c(0.143, 0.374, 1.442), k_c(3.983, 2.385, 1.603);
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(eta, 0.0), tau),
                          with_film(test::conductor_layer(eta_c, k_c, 0.0), d, nf)});
    const std::vector<double> angles = {0, 50, 75};
    for (const bool polarization : {false, true}) {
        const SimulationResult r = simulate(stack, scalar_settings(angles, 200'000, polarization));
        for (std::size_t i = 0; i < angles.size(); ++i) {
            const double mu = std::cos(deg_to_rad(angles[i]));
            const double mu_t = std::sqrt(1 - (1 - mu * mu) / (eta * eta));
            const DielectricMueller<double> top = fresnel_dielectric_mueller(mu, eta, 1 / eta);
            const double Fs = top.reflection.a + top.reflection.b,
                         Fp = top.reflection.a - top.reflection.b;
            const EnergyBudget& b = r.incidences[i].budget;
            for (int c = 0; c < 3; ++c) {
                const double a = std::exp(-tau[c] / mu_t);
                const SP film =
                    intensities(thin_film_mueller(mu_t, C(nf / eta), C(eta_c[c], k_c[c]) / eta,
                                                  d * eta / stack.wavelengths_nm[c]));
                auto series = [&](double F, double Rc) {
                    return F + (1 - F) * (1 - F) * Rc * a * a / (1 - F * Rc * a * a);
                };
                const double R = polarization ? (series(Fs, film.Rs) + series(Fp, film.Rp)) / 2
                                              : series(top.reflection.a, (film.Rs + film.Rp) / 2);
                expect_within_se_of_float(b[BudgetTerm::Reflected][c], R, b.reflected_se[c],
                                          std::string(polarization ? "polarized" : "unpolarized") +
                                              " θ " + std::to_string(angles[i]));
            }
        }
        expect_budget_closes_float(r);
    }
}

// A thickness uniform over one period of the film's phase (at normal incidence, λ/(2 η_f)) gives
// the incoherent slab R12 + T12² R23/(1 − R12 R23) of the boundaries' intensities: all channels at
// one wavelength so that one range is a period for each.
TEST(ThinFilmStackStat, ThicknessOverOnePeriodIsTheIncoherentSlab) {
    const double nf = 2.0, n3 = 1.5, lambda = 550, period = lambda / (2 * nf);
    Stack stack =
        test::make_stack({with_film(test::dielectric_layer(n3, 0.0), 300, nf, 0.0, 300 + period)});
    stack.wavelengths_nm = Rgbd(lambda);
    const SimulationResult r = simulate(stack, scalar_settings({0}, 400'000, true));
    const double R12 = std::pow((1 - nf) / (1 + nf), 2), R23 = std::pow((nf - n3) / (nf + n3), 2);
    const double R = R12 + (1 - R12) * (1 - R12) * R23 / (1 - R12 * R23);
    const EnergyBudget& b = r.incidences[0].budget;
    for (int c = 0; c < 3; ++c) {
        expect_within_se_of_float(b[BudgetTerm::Reflected][c], R, b.reflected_se[c], "R");
        expect_within_se_of_float(b[BudgetTerm::Transmitted][c], 1 - R, b.transmitted_se[c], "T");
    }
    // Far from the coherent film at the range's lower end (300 nm: R = 0.0957, the slab 0.1272).
    EXPECT_GT(std::abs(thin_film_mueller(1.0, C(nf), C(n3), 300 / lambda).reflection.a - R), 0.02);
}

// A rough filmed dielectric (a free-standing film on a rough interface between equal media, and a
// film on rough glass, seen from both sides) with a lossless film: nothing is absorbed with
// multiple scattering on the microsurface (R + T = 1 within the standard errors, the channels'
// reweighting zero in expectation), polarized or not, and with a range of thicknesses.
TEST(ThinFilmStackStat, RoughFilmedDielectricWhiteFurnace) {
    struct Case {
        double eta, alpha, d0, d1;
    };
    for (const Case& k : {Case{1.0, 0.3, 300, 300}, Case{1.5, 0.5, 80, 240}}) {
        const Stack stack = test::make_stack(
            {with_film(test::dielectric_layer(k.eta, k.alpha), k.d0, 1.33, 0.0, k.d1)});
        for (const bool polarization : {false, true}) {
            const SimulationResult r =
                simulate(stack, scalar_settings({10, 60, 85}, 100'000, polarization));
            for (const IncidenceStats& st : r.incidences)
                for (int c = 0; c < 3; ++c) {
                    const double total =
                        st.budget[BudgetTerm::Reflected][c] + st.budget[BudgetTerm::Transmitted][c];
                    expect_within_se_of_float(
                        total, 1.0, st.budget.reflected_se[c] + st.budget.transmitted_se[c],
                        "R + T");
                    EXPECT_NEAR(st.budget[BudgetTerm::LostMicrosurface][c], 0.0, 1e-4);
                    EXPECT_NEAR(st.budget[BudgetTerm::CutOff][c], 0.0, 1e-12);
                }
            expect_budget_closes_float(r);
        }
    }
    // From the dense side (a slab whose back face carries the film).
    const Stack slab = test::make_stack(
        {test::dielectric_layer(1.5, 0.0), with_film(test::dielectric_layer(1.0, 0.4), 100, 2.0)});
    const SimulationResult r = simulate(slab, scalar_settings({30, 75}, 100'000, true));
    for (const IncidenceStats& st : r.incidences)
        for (int c = 0; c < 3; ++c)
            expect_within_se_of_float(
                st.budget[BudgetTerm::Reflected][c] + st.budget[BudgetTerm::Transmitted][c], 1.0,
                st.budget.reflected_se[c] + st.budget.transmitted_se[c], "R + T slab");
}

// A film of thickness 0 is the bare interface: the filmed stack's R and T equal the bare stack's
// within their standard errors (a coat over a rough conductor, and a rough slab; the default
// transport: polarized, multiple scattering).
TEST(ThinFilmStackStat, ThicknessZeroIsTheBareStack) {
    const Rgbd eta_c(0.2, 0.9, 1.1), k_c(3.9, 2.4, 1.8);
    const std::vector<Layer> coat = {
        test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.1, 0.2, 0.3)),
        test::conductor_layer(eta_c, k_c, 0.3)};
    const std::vector<Layer> slab = {test::dielectric_layer(1.5, 0.3),
                                     test::dielectric_layer(1.0, 0.1)};
    for (const auto& layers : {coat, slab}) {
        std::vector<Layer> filmed = layers;
        for (Layer& l : filmed)
            l = with_film(l, 0.0, 1.9, 0.2);
        const SimulationResult bare =
            simulate(test::make_stack(layers), scalar_settings({20, 70}, 100'000, true, 5));
        const SimulationResult film =
            simulate(test::make_stack(filmed), scalar_settings({20, 70}, 100'000, true, 6));
        for (std::size_t i = 0; i < 2; ++i)
            for (int c = 0; c < 3; ++c) {
                const EnergyBudget &a = bare.incidences[i].budget, &b = film.incidences[i].budget;
                expect_within_se_of_float(b[BudgetTerm::Reflected][c], a[BudgetTerm::Reflected][c],
                                          std::hypot(a.reflected_se[c], b.reflected_se[c]), "R");
                expect_within_se_of_float(
                    b[BudgetTerm::Transmitted][c], a[BudgetTerm::Transmitted][c],
                    std::hypot(a.transmitted_se[c], b.transmitted_se[c]), "T");
            }
    }
}

// Reproducible: a varying thickness is drawn from each particle's own stream, so the tables are
// bitwise identical for any thread count.
TEST(ThinFilmStack, VaryingThicknessIsBitwiseIdenticalAcrossThreads) {
    const Stack stack = test::make_stack(
        {test::with_medium(with_film(test::dielectric_layer(1.5, 0.2), 100, 1.4, 0.0, 400),
                           Rgbd(0.1)),
         with_film(test::conductor_layer(Rgbd(0.2), Rgbd(3.0), 0.1), 20, 2.0, 0.0, 80)});
    SimulationSettings s = scalar_settings({30, 60}, 20'000, true);
    s.threads = 1;
    const SimulationResult one = simulate(stack, s);
    s.threads = 3;
    const SimulationResult three = simulate(stack, s);
    for (std::size_t i = 0; i < 2; ++i) {
        EXPECT_EQ(one.table.lobe(i, Side::Reflection).f, three.table.lobe(i, Side::Reflection).f);
        EXPECT_EQ(one.incidences[i].budget.term, three.incidences[i].budget.term);
    }
}

// --kernel auto: the scalar kernel for a stack with a film on a dielectric, the SIMD kernel for
// one without, bit for bit.
TEST(ThinFilmStack, AutoKernelPicksScalarForFilms) {
    const Stack filmed = test::make_stack({with_film(test::dielectric_layer(1.5, 0.2), 100, 1.38)});
    const Stack bare = test::make_stack({test::dielectric_layer(1.5, 0.2)});
    // A film on a conductor: the SIMD kernel's (kernel_simd_test.cpp compares the two kernels).
    const Stack filmed_metal = test::make_stack(
        {test::dielectric_layer(1.5, 0.1),
         with_film(test::conductor_layer(Rgbd(0.2), Rgbd(3.0), 0.2), 80, 2.0, 0.1, 160)});
    SimulationSettings auto_settings;
    EXPECT_EQ(kernel_for(auto_settings, filmed_metal), Kernel::Simd);
    EXPECT_EQ(kernel_for(auto_settings, filmed), Kernel::Scalar);
    for (const Stack& stack : {filmed, bare}) {
        SimulationSettings s = scalar_settings({30}, 20'000, true);
        s.kernel = Kernel::Auto;
        const SimulationResult automatic = simulate(stack, s);
        s.kernel = stack.has_film() ? Kernel::Scalar : Kernel::Simd;
        const SimulationResult chosen = simulate(stack, s);
        SimulationSettings auto_kernel = s;
        auto_kernel.kernel = Kernel::Auto;
        EXPECT_EQ(kernel_for(auto_kernel, stack), s.kernel);
        EXPECT_EQ(automatic.table.lobe(0, Side::Reflection).f,
                  chosen.table.lobe(0, Side::Reflection).f);
        EXPECT_EQ(automatic.incidences[0].budget.term, chosen.incidences[0].budget.term);
    }
    SimulationSettings s;
    s.kernel = Kernel::Scalar;
    EXPECT_EQ(kernel_for(s, bare), Kernel::Scalar);
    s.kernel = Kernel::Simd;
    EXPECT_EQ(kernel_for(s, filmed), Kernel::Simd);  // refused by simulate
    // Light from φi ≠ 0 and anisotropy do not: both kernels trace them.
    s.kernel = Kernel::Auto;
    EXPECT_EQ(kernel_for(s, bare), Kernel::Simd);
    s.phi_i_deg = 30;
    EXPECT_EQ(kernel_for(s, bare), Kernel::Simd);
    const Stack brushed = test::make_stack(
        {layer_of(anisotropic(conductor_interface(Rgbd(0.2), Rgbd(3.0), 0.1), 0.1, 0.4, 20))});
    EXPECT_EQ(kernel_for(s, brushed), Kernel::Simd);
}

// Who does not trace a film on a glass says so: the SIMD kernel (an InputError naming --kernel),
// every model (not supported: a film on a glass is on no model's list), the random walk.
TEST(ThinFilmStack, RefusedWhereNotTraced) {
    const Stack stack =
        test::make_stack({with_film(test::dielectric_layer(1.5, 0.1), 100, 1.38)}, "coated glass");
    SimulationSettings s = scalar_settings({30}, 1000, true);
    s.kernel = Kernel::Simd;
    try {
        simulate(stack, s);
        ADD_FAILURE() << "the SIMD kernel traced a film";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--kernel scalar"), std::string::npos) << e.what();
    }
    for (const ModelEntry& entry : model_registry()) {
        const auto model = entry.make(stack, resolve_options(entry, {}));
        EXPECT_FALSE(model->support().brdf) << entry.name;
        EXPECT_FALSE(model->support().btdf) << entry.name;
        // A model that represents films (ModelEntry::films) says which films it does not.
        EXPECT_NE(model->support().reason.find(entry.films ? "thin film"
                                                           : "thin films are not supported"),
                  std::string::npos)
            << entry.name << ": " << model->support().reason;
    }
    EXPECT_THROW(RandomWalkStack(stack, TransportSettings{}), InputError);
}

}  // namespace
}  // namespace lamina

// The random walk's exit density (RandomWalkStack::pdf, docs/rendering.md §1.4): an unbiased
// stochastic estimate of the sub-probability density p(wo | wi) of sample(wi)'s non-delta exits.
// Proofs: (a) it integrates to the probability that sample() returns a non-delta exit; (b) the
// histogram of sample()'s exit directions matches it (chi-square with estimated cell masses);
// (c) it equals the density where that is known in closed form. Tolerances from standard errors,
// fixed seeds.
#include "randomwalk/random_walk.h"

#include "core/math.h"
#include "core/spherical.h"
#include "layers/stack.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "support/chi2.h"
#include "support/closed_forms.h"
#include "support/stacks.h"
#include "support/table_checks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace lamina {
namespace {

// ---- (c) Closed forms without noise ------------------------------------------------------------
// A stack of one rough interface or a Lambertian alone: every walk has exactly one non-delta
// vertex (the interface itself) and leaves from it, so the estimate is that interface's own
// sampling density — with zero variance, to rounding.
TEST(RandomWalkPdf, OneInterfaceIsItsOwnSamplingDensity) {
    const Vec3d wi = incident_direction(deg_to_rad(50.0));
    const std::vector<Vec3d> wos = {direction_from_angles(0.3, 2.0),
                                    direction_from_angles(1.2, 3.0),
                                    direction_from_angles(0.4, 3.1, Side::Transmission),
                                    direction_from_angles(1.0, 1.0, Side::Transmission)};
    {
        const RandomWalkStack rw(test::make_stack({test::dielectric_layer(1.5, 0.3)}),
                                 test::bpb19_transport());
        const DielectricInterface<double> d{1.5, 0.3};
        for (const Vec3d& wo : wos) {
            const RandomWalkPdf p = rw.pdf(wi, wo, 64, 1, 1);
            EXPECT_NEAR(p.pdf, d.pdf(wi, wo), 1e-12 * d.pdf(wi, wo));
            EXPECT_LE(p.se, 1e-7 * p.pdf);  // one-pass variance of equal values: √ε rounding
        }
    }
    {
        const RandomWalkStack rw(test::make_stack({test::lambertian_layer(Rgbd(0.2, 0.5, 0.9))}),
                                 test::bpb19_transport());
        for (const Vec3d& wo : wos) {
            const RandomWalkPdf p = rw.pdf(wi, wo, 64, 1, 1);
            EXPECT_NEAR(p.pdf, std::max(0.0, wo.z) / kPi<double>, 1e-15);
        }
    }
    {
        const Rgbd eta(0.2, 0.4, 1.4), k(3.9, 2.4, 1.6);
        const RandomWalkStack rw(test::make_stack({test::conductor_layer(eta, k, 0.25)}),
                                 test::bpb19_transport());
        const ConductorInterface<double> c{eta, k, 0.25};
        for (const Vec3d& wo : wos) {
            EXPECT_NEAR(rw.pdf(wi, wo, 64, 1, 1).pdf, c.pdf(wi, wo), 1e-12 * c.pdf(wi, wo));
        }
    }
    // Only smooth events: every exit is a delta exit, the density is zero everywhere.
    const RandomWalkStack smooth(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.0), Rgbd(0.2)),
                          test::dielectric_layer(1.0, 0.0)}),
        test::bpb19_transport());
    for (const Vec3d& wo : wos)
        EXPECT_EQ(smooth.pdf(wi, wo, 64, 1, 1).pdf, 0);
    // A black base kills every walk that reaches it.
    const RandomWalkStack black(test::make_stack({test::lambertian_layer(Rgbd(0.0))}),
                                test::bpb19_transport());
    EXPECT_EQ(black.pdf(wi, wos[0], 64, 1, 1).pdf, 0);
}

// ---- (c) Closed form with noise: a smooth coat over a Lambertian -------------------------------
// The walk transmits into the coat with probability 1 − F(μi), is cosine-reflected by the base,
// escapes with probability 1 − F(μ') or is reflected back (totally below the critical angle), and
// so on. Absorption and albedo are weights, not probabilities, so the exit density is the
// non-absorbing, white one: with r = 2∫₀¹ F_inside(μ) μ dμ and dω'/dωo = μo/(η² μo'),
//   p(wo) = Σ_n r^{n−1} (1 − F(μi)) (μo'/π) (1 − F(μo)) μo/(η² μo')
//         = (1 − F(μi)) (1 − F(μo)) μo / (π η² (1 − r)),
// which is docs/physics.md §6.3's diffuse f for ρ = 1, τ = 0, times μo (CoatedLambertianSeries).
TEST(RandomWalkPdfStat, SmoothCoatOverLambertianIsTheWhiteSeries) {
    const double eta = 1.5;
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(eta, 0.0), Rgbd(0.1, 0.6, 0.0)),
                          test::lambertian_layer(Rgbd(0.8, 0.5, 0.2))});
    const RandomWalkStack rw(stack, test::bpb19_transport());
    ASSERT_TRUE(rw.pdf_is_unbiased());
    const test::CoatedLambertianSeries white(eta, Rgbd(0.0), Rgbd(1.0));
    const int tests = 4 * 3 * 2;
    const double z_max = test::normal_quantile_upper((1 - std::pow(1 - 1e-3, 1.0 / tests)) /
                                                     2);  // Šidák: suite false alarm 1e-3
    std::uint64_t stream = 0;
    double worst = 0;
    for (double ti : {0.0, 30.0, 60.0, 85.0})
        for (double to : {10.0, 45.0, 80.0})
            for (double po : {0.0, 100.0}) {
                const Vec3d wi = incident_direction(deg_to_rad(ti));
                const Vec3d wo = direction_from_angles(deg_to_rad(to), deg_to_rad(po));
                const RandomWalkPdf p = rw.pdf(wi, wo, 20000, 4, ++stream);
                const double want = white.diffuse(wi.z, wo.z)[0] * wo.z;
                ASSERT_GT(p.se, 0);
                const double z = (p.pdf - want) / p.se;
                worst = std::max(worst, std::abs(z));
                EXPECT_LT(std::abs(z), z_max) << "θi " << ti << " θo " << to << " φo " << po << ": "
                                              << p.pdf << " ± " << p.se << " vs " << want;
            }
    RecordProperty("worst_z", std::to_string(worst));
}

// ---- (a) and (b): the histogram of sample() against the estimated density ----------------------
// Cell masses: `walks` single-walk pdf estimates at directions uniformly jittered over the cell,
// each from its own generator: m̂ = Ω_cell · mean, variance Ω_cell² s²/walks (unbiased, independent
// of the draws and of the other cells).
struct PdfCase {
    std::string name;
    Stack stack;
    Microsurface microsurface = Microsurface::Single;
};

void expect_sample_matches_pdf(const PdfCase& c, int test_count) {
    const RandomWalkStack rw(c.stack, {.microsurface = c.microsurface, .polarization = false});
    ASSERT_TRUE(rw.pdf_is_unbiased()) << c.name;
    const Vec3d wi = incident_direction(deg_to_rad(40.0));
    const std::uint64_t walks_per_cell = 3000;
    test::Chi2Options o;
    o.name = "random_walk_pdf_" + c.name;
    o.sample_count = 200'000;
    o.cos_theta_min = rw.transmits() ? -1 : 0;
    o.cos_theta_bins = rw.transmits() ? 24 : 12;
    o.phi_bins = 24;
    o.test_count = test_count;
    std::uint64_t draw = 0;
    const auto sample = [&](const std::array<double, 3>&) {
        ParticleRng rng(31, 0, draw++);
        const auto s = rw.sample(wi, rng);
        if (!s || s->is_delta) return test::Chi2Draw::none();
        return test::Chi2Draw::direction(s->wo);
    };
    const auto cell_mass = [&](int row, int col, double c0, double c1, double p0, double p1) {
        const std::uint64_t cell = std::uint64_t(row) * 1000 + std::uint64_t(col);
        double sum = 0, sum_sq = 0;
        for (std::uint64_t t = 0; t < walks_per_cell; ++t) {
            ParticleRng rng(47, cell, t);
            const double ct = c0 + (c1 - c0) * rng.uniform_double();
            const double phi = p0 + (p1 - p0) * rng.uniform_double();
            const double p = rw.pdf_once(wi, test::direction_of(ct, phi), rng);
            sum += p;
            sum_sq += p * p;
        }
        const double n = double(walks_per_cell), omega = (c1 - c0) * (p1 - p0);
        const double mean = sum / n;
        const double var = std::max(0.0, sum_sq / n - mean * mean) / (n - 1);
        return test::Chi2CellMass{omega * mean, omega * omega * var};
    };
    const test::Chi2Result r = test::run_chi2_estimated(o, sample, cell_mass);
    EXPECT_TRUE(r.passed) << r.message;
    // (a) ∫ p dω = P(sample returns a non-delta exit): the cells' summed masses against the
    // fraction of draws that land (binomial standard error), Šidák over the suite at 1e-3.
    const double landed = 1 - r.absent_fraction;
    const double se =
        std::hypot(r.pdf_integral_se, std::sqrt(landed * (1 - landed) / double(o.sample_count)));
    const double z_max =
        test::normal_quantile_upper((1 - std::pow(1 - 1e-3, 1.0 / test_count)) / 2);
    EXPECT_LT(std::abs(r.pdf_integral - landed), z_max * se)
        << c.name << ": ∫p = " << r.pdf_integral << " ± " << r.pdf_integral_se
        << ", non-delta exits " << landed;
    EXPECT_GT(landed, 0.05) << c.name;
    ::testing::Test::RecordProperty(c.name + "_p_value", std::to_string(r.p_value));
}

TEST(RandomWalkPdfStat, SampleHistogramMatchesThePdfAndItsIntegral) {
    std::vector<PdfCase> cases = {{"plastic", test::example("plastic")},
                                  {"slab", test::example("slab")}};
    // A smooth coat (delta chains, TIR) over a scattering medium with per-channel extinction and
    // g (the spectral-MIS flight probabilities of §1.4) over a coloured Lambertian.
    cases.push_back(
        {"smooth_coat_chromatic_scattering",
         test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.0), Rgbd(0.1, 0.0, 0.2),
                                             Rgbd(0.3, 0.8, 1.5), Rgbd(0.5, 0.2, -0.3)),
                           test::lambertian_layer(Rgbd(0.8, 0.4, 0.1))})});
    // A smooth scattering slab: non-delta exits only after scattering, on both sides.
    cases.push_back({"smooth_scattering_slab",
                     test::make_stack({test::with_medium(test::dielectric_layer(1.4, 0.0),
                                                         Rgbd(0.1), Rgbd(1.0), Rgbd(0.7)),
                                       test::dielectric_layer(1.0, 0.0)})});
    for (const PdfCase& c : cases)
        expect_sample_matches_pdf(c, int(cases.size()));
}

// Multiple-scattering interfaces (docs/rendering.md §1.6): the exit density of the microsurface
// walks, estimated by the same walks with a connection at every facet, against the histogram of
// sample()'s exits, which leave through those walks. A rough dielectric alone (both sides), a rough
// conductor, a rough coat over a Lambertian (the rough exit's two strategies), and a rough coat
// over a scattering medium with per-channel extinction over a rough conductor (the facets'
// per-channel Fresnel weights inside the spectral-MIS chain probabilities).
TEST(RandomWalkPdfStat, MultipleScatteringSampleHistogramMatchesThePdf) {
    using enum Microsurface;
    const Rgbd eta(0.2, 0.4, 1.4), k(3.9, 2.4, 1.6);
    std::vector<PdfCase> cases = {
        {"ms_rough_dielectric", test::make_stack({test::dielectric_layer(1.5, 0.6)}), Multiple},
        {"ms_rough_conductor", test::make_stack({test::conductor_layer(eta, k, 0.7)}), Multiple},
        {"ms_rough_coat_lambertian",
         test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.1)),
                           test::lambertian_layer(Rgbd(0.8, 0.5, 0.2))}),
         Multiple},
        {"ms_rough_coat_chromatic_scattering_conductor",
         test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.3), Rgbd(0.0),
                                             Rgbd(0.3, 0.8, 1.5), Rgbd(0.5)),
                           test::conductor_layer(eta, k, 0.5)}),
         Multiple}};
    for (const PdfCase& c : cases)
        expect_sample_matches_pdf(c, int(cases.size()));
}

// The exactness condition: a scattering medium with per-channel extinction under a smooth
// coloured conductor makes the chain probabilities non-linear in the weights.
TEST(RandomWalkPdf, ReportsWhenItsEstimateIsNotExact) {
    EXPECT_TRUE(
        RandomWalkStack(test::example("milky-coat"), test::bpb19_transport()).pdf_is_unbiased());
    EXPECT_TRUE(RandomWalkStack(test::example("metallic-paint"), test::bpb19_transport())
                    .pdf_is_unbiased());
    const Stack mixed = test::make_stack(
        {test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.0), Rgbd(0.2, 0.5, 1.0)),
         test::conductor_layer(Rgbd(0.2, 0.4, 1.4), Rgbd(3.9, 2.4, 1.6), 0.0)});
    EXPECT_FALSE(RandomWalkStack(mixed, test::bpb19_transport()).pdf_is_unbiased());
}

// Polarized walks: pdf() is the unpolarized walk's exit density (a proxy, random_walk.h), the
// same estimate bit for bit as without polarization, and says it is not exact.
TEST(RandomWalkPdf, PolarizedWalksKeepTheUnpolarizedDensity) {
    const Stack stack = test::example("frosted-gold");
    const RandomWalkStack plain(stack, test::bpb19_transport()),
        polarized(stack, {.microsurface = Microsurface::Single, .polarization = true});
    EXPECT_FALSE(polarized.pdf_is_unbiased());
    const Vec3d wi = incident_direction(0.6), wo = direction_from_angles(0.8, 2.8);
    EXPECT_EQ(plain.pdf(wi, wo, 200, 3, 0).pdf, polarized.pdf(wi, wo, 200, 3, 0).pdf);
}

}  // namespace
}  // namespace lamina

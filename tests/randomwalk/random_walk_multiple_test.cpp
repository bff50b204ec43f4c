// The random walk with multiple-scattering rough interfaces (Microsurface::
// Multiple, docs/rendering.md §1.6) against independent computations: its first order is the
// single-scattering Walter BSDF with the height-correlated Smith masking (conductor: G2,
// dielectric: B(1 + Λi, 1 + Λo)) of physics/dielectric.h and conductor.h; white furnaces
// (non-absorbing rough interfaces, coats and slabs lose nothing) from the eval integrated by
// quadrature and from sample(). The comparisons with the goniophotometer and the sample/pdf
// histograms are in random_walk_test.cpp and random_walk_pdf_test.cpp. Tolerances from standard
// errors, fixed seeds; suites ending in Stat are the `stat` label.
#include "randomwalk/random_walk.h"

#include "core/math.h"
#include "core/spherical.h"
#include "layers/stack.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/microsurface_walk.h"
#include "support/stacks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace lamina {
namespace {

using enum Microsurface;

// ---- The first order of the stochastic evaluation ----------------------------------------------
// Capped at one facet, a walk's estimate is the first facet's phase function towards wo times the
// height masking G1(wo, h) at the facet's random height: in expectation the single-scattering
// BSDF with the Smith microsurface's own height-correlated masking (microsurface_walk.h). The
// single-scattering stack's eval is that interface's Walter BSDF, deterministic. Both sides of a
// dielectric (the flipped stack's walks come from below), reflection and refraction.
TEST(RandomWalkMultiple, FirstOrderIsTheSingleScatteringInterface) {
    const std::vector<Vec3d> wos = {direction_from_angles(0.2, 2.0),
                                    direction_from_angles(0.9, 3.0),
                                    direction_from_angles(1.35, 0.4),
                                    direction_from_angles(0.3, 3.1, Side::Transmission),
                                    direction_from_angles(0.8, 1.0, Side::Transmission),
                                    direction_from_angles(1.3, 2.9, Side::Transmission)};
    const Rgbd eta(0.2, 0.4, 1.4), k(3.9, 2.4, 1.6);
    struct Case {
        std::string name;
        Stack stack;
    };
    std::vector<Case> cases;
    for (double alpha : {0.15, 0.5, 1.0}) {
        const std::string a = " α" + std::to_string(alpha);
        cases.push_back(
            {"dielectric 1.5" + a, test::make_stack({test::dielectric_layer(1.5, alpha)})});
        // From inside a denser medium (TIR beyond ~42°), i.e. the dielectric met from below.
        cases.push_back(
            {"dielectric 1/1.5" + a, test::make_stack({test::dielectric_layer(1 / 1.5, alpha)})});
        cases.push_back(
            {"conductor" + a, test::make_stack({test::conductor_layer(eta, k, alpha)})});
    }
    int checked = 0;
    for (const Case& c : cases) {
        const RandomWalkStack single(c.stack, {.microsurface = Single, .polarization = false});
        const RandomWalkStack first(
            c.stack,
            {.microsurface = Multiple, .max_microsurface_order = 1, .polarization = false});
        for (double ti : {0.4, 1.2})
            for (const Vec3d& wo : wos) {
                const Vec3d wi = incident_direction(ti);
                const Rgbd want = single.eval(wi, wo, 1, 1, 1).f;
                const RandomWalkEstimate got = first.eval(wi, wo, 20000, 3, 7);
                for (int ch = 0; ch < 3; ++ch) {
                    if (want[ch] == 0) {
                        EXPECT_EQ(got.f[ch], 0) << c.name;
                        continue;
                    }
                    ++checked;
                    // 4.5 σ: Šidák over ~300 comparisons at 1e-3.
                    EXPECT_NEAR(got.f[ch], want[ch], 4.5 * got.se[ch] + 1e-12 * want[ch])
                        << c.name << " θi " << ti << " wo (" << wo.x << ", " << wo.y << ", " << wo.z
                        << ") ch " << ch;
                }
            }
    }
    EXPECT_GT(checked, 150);
}

// The same at the level of the header (physics/microsurface_walk.h), with the interfaces' own
// eval·|cos θo| and the flux convention: the one-facet estimate of f·|cos θo|.
TEST(RandomWalkMultiple, FirstOrderOfTheHeaderIsWalterTimesCosine) {
    const DielectricInterface<double> d{1.5, 0.4};
    const Vec3d wi = incident_direction(0.7);
    for (const Vec3d& wo :
         {direction_from_angles(0.5, 2.5), direction_from_angles(0.6, 3.0, Side::Transmission)}) {
        double sum = 0, sum_sq = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            ParticleRng rng(5, 5, std::uint64_t(i));
            const double e = eval_rough_dielectric_multiple(
                d.distribution(), d.eta, wi, wo, [&] { return rng.uniform_double(); }, 1);
            sum += e;
            sum_sq += e * e;
        }
        const double mean = sum / n, se = std::sqrt((sum_sq / n - mean * mean) / (n - 1));
        const double want = d.eval(wi, wo) * std::abs(wo.z);
        EXPECT_GT(want, 0);
        EXPECT_NEAR(mean, want, 4.5 * se) << wo.z;
    }
}

// ---- White furnaces ----------------------------------------------------------------------------
// ∫ f |cos θo| dωo over one hemisphere by stratified quadrature in (z = |cos θ|, φ), uniform in
// solid angle (dω = dz dφ): 2π times the mean of f·z over n×n strata with two independent
// jittered points each, every point its own estimate of `walks` walks. (Uniform in solid angle,
// not in projected solid angle: the integrand f·z = the kernel is bounded, whereas f alone grows
// as 1/z at grazing exits, an infinite-variance quadrature whose mean falls short.) Two points per
// stratum give the unbiased variance estimate of the stratified mean, Σ_s (a_s − b_s)²/4 / S²
// (the walks' noise and the kernel's variation within the strata).
struct Albedo {
    double mean = 0, se = 0;
};
Albedo hemispherical_albedo(const RandomWalkStack& rw, const Vec3d& wi, Side side, int n,
                            std::uint64_t walks, std::uint64_t seed) {
    double sum = 0, var = 0;
    const int strata = n * n;
#pragma omp parallel for reduction(+ : sum, var) schedule(dynamic, 16)
    for (int i = 0; i < strata; ++i) {
        ParticleRng jitter(seed, 0xA1BE, std::uint64_t(i));
        double f[2];
        for (int k = 0; k < 2; ++k) {
            const double z = (i / n + jitter.uniform_double()) / n;
            const double phi = 2 * kPi<double> * (i % n + jitter.uniform_double()) / n;
            const double st = std::sqrt(std::max(0.0, 1 - z * z));
            const Vec3d wo(st * std::cos(phi), st * std::sin(phi),
                           side == Side::Reflection ? z : -z);
            f[k] =
                2 * kPi<double> * z * rw.eval(wi, wo, walks, seed, 2 * std::uint64_t(i) + k).f[1];
        }
        sum += 0.5 * (f[0] + f[1]);
        var += 0.25 * sqr(f[0] - f[1]);
    }
    return {sum / strata, std::sqrt(var) / strata};
}

Albedo total_albedo(const RandomWalkStack& rw, const Vec3d& wi, int n, std::uint64_t walks) {
    Albedo r = hemispherical_albedo(rw, wi, Side::Reflection, n, walks, 17);
    if (!rw.transmits()) return r;
    const Albedo t = hemispherical_albedo(rw, wi, Side::Transmission, n, walks, 19);
    return {r.mean + t.mean, std::hypot(r.se, t.se)};
}

// Non-absorbing stacks whose only non-delta events are rough interfaces and white Lambertians:
// with multiple scattering R + T = 1 (delta lobes: none, the top is rough). With single
// scattering the same quadrature falls short by the energy lost on the microsurfaces, by far more
// than its standard error (the test can tell the two apart).
TEST(RandomWalkMultipleStat, WhiteFurnaceByQuadratureOfTheEval) {
    struct Case {
        std::string name;
        Stack stack;
    };
    const std::vector<Case> cases = {
        {"rough dielectric 1.5 α0.6", test::make_stack({test::dielectric_layer(1.5, 0.6)})},
        {"rough dielectric 1/1.33 α1", test::make_stack({test::dielectric_layer(1 / 1.33, 1.0)})},
        {"rough white conductor α0.8",
         test::make_stack({test::conductor_layer(Rgbd(1.0), Rgbd(1e4), 0.8)})},
        {"rough coat α0.5 over white lambertian",
         test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.5), Rgbd(0.0)),
                           test::lambertian_layer(Rgbd(1.0))})},
        {"rough slab α0.4 | α0.7",
         test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.0)),
                           test::dielectric_layer(1.0, 0.7)})}};
    for (const Case& c : cases)
        for (double ti : {0.5, 1.3}) {
            const Vec3d wi = incident_direction(ti);
            const RandomWalkStack multiple(c.stack,
                                           {.microsurface = Multiple, .polarization = false});
            const Albedo a = total_albedo(multiple, wi, 48, 8);
            EXPECT_LT(std::abs(a.mean - 1), 4.5 * a.se)
                << c.name << " θi " << ti << ": " << a.mean << " ± " << a.se;
            EXPECT_LT(a.se, 0.02) << c.name;  // the test's resolution
            RecordProperty(c.name + " θi " + std::to_string(ti),
                           std::to_string(a.mean) + " ± " + std::to_string(a.se));
            const RandomWalkStack single(c.stack, {.microsurface = Single, .polarization = false});
            const Albedo s = total_albedo(single, wi, 48, 8);
            EXPECT_GT(1 - s.mean, 5 * s.se)
                << c.name << " θi " << ti << " single: " << s.mean << " ± " << s.se;
        }
}

// sample(): a dielectric walk carries all its flux, so the weights of a non-absorbing rough
// interface sum to the number of walks (none is given up at 100 facets in practice); the fraction
// that leaves above equals the eval's hemispherical reflectance (binomial SE ⊕ quadrature SE).
TEST(RandomWalkMultipleStat, WhiteFurnaceOfTheSampleWeights) {
    for (double alpha : {0.3, 1.0}) {
        const RandomWalkStack rw(test::make_stack({test::dielectric_layer(1.5, alpha)}),
                                 {.microsurface = Multiple, .polarization = false});
        for (double ti : {0.5, 1.3}) {
            const Vec3d wi = incident_direction(ti);
            const int n = 200000;
            double total = 0, up = 0;
            for (int i = 0; i < n; ++i) {
                ParticleRng rng(29, 0, std::uint64_t(i));
                const auto s = rw.sample(wi, rng);
                if (!s) continue;
                EXPECT_FALSE(s->is_delta);
                total += s->weight[1];
                if (s->wo.z > 0) up += s->weight[1];
            }
            EXPECT_GT(total / n, 1 - 1e-4) << "α " << alpha << " θi " << ti;
            const double r = up / n, se_r = std::sqrt(r * (1 - r) / n);
            const Albedo q = hemispherical_albedo(rw, wi, Side::Reflection, 40, 8, 23);
            EXPECT_LT(std::abs(r - q.mean), 4.5 * std::hypot(se_r, q.se))
                << "α " << alpha << " θi " << ti << ": sample " << r << ", eval " << q.mean;
        }
    }
}

// An index-matched rough interface with multiple scattering is a perfect pass-through (every
// facet refracts straight on, F = 0): a delta lobe with all the energy, like a smooth one; with
// single scattering it keeps G2/G1 < 1.
TEST(RandomWalkMultiple, IndexMatchedRoughInterfaceIsAPassThrough) {
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.0, 0.5), Rgbd(0.0)),
                          test::dielectric_layer(1.0, 0.0)});
    const Vec3d wi = incident_direction(1.0);
    const auto lobes =
        RandomWalkStack(stack, {.microsurface = Multiple, .polarization = false}).delta_lobes(wi);
    ASSERT_EQ(lobes.size(), 1u);
    EXPECT_LT(lobes[0].direction.z, 0);
    EXPECT_NEAR(lobes[0].energy[0], 1.0, 1e-12);
    const auto single = RandomWalkStack(stack, test::bpb19_transport()).delta_lobes(wi);
    ASSERT_EQ(single.size(), 1u);
    EXPECT_LT(single[0].energy[0], 0.99);
}

TEST(RandomWalkMultiple, DeterministicForASeedAndFinite) {
    const RandomWalkStack rw(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 0.4, 1.4), Rgbd(3.9, 2.4, 1.6), 0.3)}),
        {.microsurface = Multiple, .polarization = false});
    const Vec3d wi = incident_direction(0.6), wo = direction_from_angles(1.1, 2.0);
    const RandomWalkEstimate a = rw.eval(wi, wo, 500, 1, 7), b = rw.eval(wi, wo, 500, 1, 7);
    EXPECT_EQ(a.f, b.f);
    for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(std::isfinite(a.f[c]));
        EXPECT_GT(a.f[c], 0);
    }
    const RandomWalkPdf p = rw.pdf(wi, wo, 500, 1, 7);
    EXPECT_TRUE(std::isfinite(p.pdf));
    EXPECT_GT(p.pdf, 0);
    // Grazing and degenerate queries are zero, never NaN.
    EXPECT_EQ(rw.eval(wi, Vec3d(1, 0, 0), 10, 1, 1).f, Rgbd(0.0));
    const RandomWalkEstimate g = rw.eval(incident_direction(1.5707), wo, 200, 1, 1);
    EXPECT_TRUE(std::isfinite(g.f[0]));
}

}  // namespace
}  // namespace lamina

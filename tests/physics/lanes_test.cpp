// The lane tests of the interface events and the medium step (physics/dielectric.h
// dielectric_event, conductor.h conductor_event, lambertian.h lambertian_event, medium.h
// medium_free_flight and medium_scatter, with phase.h sample_hg_direction): each template
// instantiated on the dispatched instruction set's vectors (the SIMD kernel's instantiation,
// through the probes of tests/support/simd_probes.h; ctest's simd_AVX2 and simd_SSE4 runs repeat
// these tests with LAMINA_SIMD_TARGET, so every compiled instruction set is checked) against its
// scalar float instantiation (the one the scalar kernel runs), on the same inputs and random
// numbers: random directions on both sides and the edges (normal incidence, grazing at
// cos θ = 1e-3 and exactly, total internal reflection and the critical angle, α → 0, k = 0,
// g → ±1, a clear channel on a horizontal path).
//
// Both evaluate the same operations; they round differently where the vectors use Highway's
// log/exp/log1p (≤ 4 ulp), the refined reciprocal square root (2^-22), the Cephes azimuth
// (≤ 2 ulp of 1) or fused multiply-adds. Discrete choices (Fresnel reflection, leaving a medium)
// then flip only where a uniform number lies within rounding (~1e-6) of its threshold: at most 1
// in 10^3 lanes may choose differently (a different formula or draw order would change most).
// The bounds on the continuous results are stated with each test.
#include "core/rng.h"
#include "layers/compiled_stack.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/lambertian.h"
#include "physics/medium.h"
#include "physics/polarization.h"
#include "support/simd_probes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace lamina {
namespace {

// Random unit directions (both hemispheres when `both_sides`) and the edges first: the normal
// (from above and, both sides, below), grazing at cos θ = 1e-3 and exactly.
std::vector<float> directions(ParticleRng& rng, int n, bool both_sides) {
    std::vector<float> w = {0, 0, 1, 0.9999995f, 0, 1e-3f, 1, 0, 0, 0.6f, 0.8f, 0};
    if (both_sides) w.insert(w.end(), {0, 0, -1, 0.9999995f, 0, -1e-3f});
    for (int k = 0; k < n; ++k) {
        const float z = both_sides ? 2 * rng.uniform_float() - 1 : rng.uniform_float();
        const float phi = 2 * kPi<float> * rng.uniform_float();
        const float r = std::sqrt(std::max(0.f, 1 - z * z));
        w.insert(w.end(), {r * std::cos(phi), r * std::sin(phi), z});
    }
    return w;
}

// Uniform numbers for n lanes, k per lane (u[i·n + j]), their ends included.
std::vector<float> uniforms(ParticleRng& rng, std::size_t n, int k) {
    std::vector<float> u(n * std::size_t(k));
    for (std::size_t i = 0; i < u.size(); ++i)
        u[i] = i % 97 == 0 ? 0.f : i % 89 == 0 ? 1 - 0x1p-24f : rng.uniform_float();
    return u;
}

double component_error(const std::vector<float>& a, const LaneVec3<float>& b, std::size_t j) {
    return std::max({std::abs(double(a[3 * j]) - b.x), std::abs(double(a[3 * j + 1]) - b.y),
                     std::abs(double(a[3 * j + 2]) - b.z)});
}

// The tolerance of a float visible normal sampled from w with u1, u2 (1e-6 on a smooth
// interface): in double, wh (w on its side in the hemisphere configuration), the cap point c and
// the halfway vector h = c + wh, warped back to h' = (α h.x, α h.y, h.z), whose normalization
// divides the float rounding by |h'| (short when the cap point nears −wh, u2 → 1 with a tiny α,
// and up to 1/α shorter than |h| for a lying h): (4e-6 + 2^-23/sin θ_cap)/|h'|, with |h| in `h`
// (1 on a smooth interface).
double visible_normal_tolerance(float alpha, const LaneVec3<float>& w, float u1, float u2,
                                double& h) {
    h = 1;
    if (alpha == 0) return 1e-6;
    const float sign = w.z < 0 ? -1.f : 1.f;
    const double vx = double(alpha) * sign * w.x, vy = double(alpha) * sign * w.y,
                 vz = double(sign) * w.z;
    const double len = std::sqrt(vx * vx + vy * vy + vz * vz);
    const double whx = vx / len, why = vy / len, whz = vz / len;
    const double z_cap = (1 - double(u2)) * (1 + whz) - whz;
    const double sin_cap = std::sqrt(std::max(1 - z_cap * z_cap, 1e-12));
    const double phi = 2 * kPi<double> * double(u1);
    const double hx = sin_cap * std::cos(phi) + whx, hy = sin_cap * std::sin(phi) + why,
                 hz = z_cap + whz;
    h = std::sqrt(hx * hx + hy * hy + hz * hz);
    const double a2 = double(alpha) * alpha;
    return (4e-6 + 0x1p-23 / sin_cap) / std::sqrt(a2 * (hx * hx + hy * hy) + hz * hz);
}

// The dielectric event, smooth and rough (α from 10^-3 to 1), η above and below 1 and η = 1, both
// refraction maskings and the uncorrelated option. Degeneracy (grazing wi) is decided alike on
// both, exactly. Directions: the visible normal agrees within 4e-6 + 2^-23/sin θc (the GGX lane
// test's bound, sin θc of the cap point), divided by |h|, the length of the halfway vector the
// construction normalizes (the cap point near −wh, as u2 → 1 with a tiny α, leaves a short h and
// divides the float rounding by its length); the new direction, a mirror or Snell image of wi
// about the normal, within 4 times that. Where |h| < 0.05 the float construction itself, scalar
// and vector alike, has lost its digits: those lanes only need a unit direction. Refractions
// within 10^-3 of the critical angle (in sin²θt) have the square-root singularity of cos θt =
// √(1 − sin²θt), where 4 ulp in sin²θt become √(4 · 2^-24) ≈ 5e-4: 1e-3 absolute. The escape
// fraction: 2e-5 absolute (the Smith refraction form's Beta function, core/beta_function.h) plus
// 1e-5 relative (the reflection form: square roots and a division, ≤ 1 ulp each), plus the
// direction's difference times the escape's slope, which grows like 1/cos θo (the Smith root).
TEST(KernelSimdLanes, DielectricEvent) {
    ParticleRng rng(31, 0, 0);
    const std::vector<float> wi = directions(rng, 6000, true);
    const std::size_t n = wi.size() / 3;
    const std::vector<float> u = uniforms(rng, n, 3);
    struct Case {
        float eta, alpha;
        bool uncorrelated, smith;
    };
    const Case cases[] = {
        {1.5f, 0.f, false, true},      {1 / 1.5f, 0.f, false, true}, {1.5f, 1e-3f, false, true},
        {1.5f, 0.05f, false, true},    {1.5f, 0.3f, false, true},    {1.5f, 0.3f, false, false},
        {1 / 1.5f, 0.6f, false, true}, {2.4f, 1.f, false, true},     {1.5f, 0.3f, true, false},
        {1.f, 0.3f, false, true},      {1.f, 0.3f, false, false},    {1.f, 0.f, false, true}};
    for (const Case& cs : cases) {
        const DielectricEventShape shape{cs.alpha == 0, cs.eta == 1, cs.uncorrelated, cs.smith};
        const std::vector<std::int32_t> flags = {shape.smooth, shape.index_matched,
                                                 shape.uncorrelated, shape.smith_refraction};
        const SimdEventResult lanes = simd_interface_events(0, {cs.eta, cs.alpha}, flags, wi, u);
        std::size_t differ = 0, ill_conditioned = 0;
        double worst_wo = 0, worst_near_critical = 0, worst_shadowing = 0;
        for (std::size_t j = 0; j < n; ++j) {
            const LaneVec3<float> w = {wi[3 * j], wi[3 * j + 1], wi[3 * j + 2]};
            const InterfaceEventLanes<float, bool> s =
                dielectric_event<float>(cs.eta, 1 / cs.eta, ggx_isotropic_lanes<float>(cs.alpha),
                                        shape, w, u[j], u[n + j], u[2 * n + j], true);
            ASSERT_EQ(bool(lanes.degenerate[j]), s.degenerate) << j;
            if (s.degenerate) {
                EXPECT_EQ(w.z, 0.f) << j;
                continue;
            }
            if (bool(lanes.reflected[j]) != s.reflected) {
                ++differ;
                continue;
            }
            ASSERT_TRUE(std::isfinite(lanes.shadowing[j])) << j;
            const double norm2 = double(lanes.wo[3 * j]) * lanes.wo[3 * j] +
                                 double(lanes.wo[3 * j + 1]) * lanes.wo[3 * j + 1] +
                                 double(lanes.wo[3 * j + 2]) * lanes.wo[3 * j + 2];
            EXPECT_NEAR(norm2, 1.0, 1e-4) << j;
            // The facet the scalar event met, its refracted sin²θt, and the tolerance of its
            // normal (the GGX lane test's: 4e-6 plus 2^-23/sin θ of the cap point).
            const float sign = w.z < 0 ? -1.f : 1.f;
            double tolerance = 1e-6;
            LaneVec3<float> wm = {0, 0, 1};
            if (cs.alpha > 0) {
                wm = ggx_sample_visible_normal_complete<float>(ggx_isotropic_lanes<float>(cs.alpha),
                                                               {sign * w.x, sign * w.y, sign * w.z},
                                                               u[n + j], u[2 * n + j]);
                // In double: wh (w on its side in the hemisphere configuration), the cap point
                // c and the halfway vector h = c + wh, whose normalization divides the float
                // rounding by |h| (the cap point near −wh: u2 → 1 with a tiny α).
                double h;
                tolerance = visible_normal_tolerance(cs.alpha, w, u[n + j], u[2 * n + j], h);
                if (h < 0.05) {
                    ++ill_conditioned;
                    continue;
                }
            }
            const double cos_i_m = double(w.x) * wm.x + double(w.y) * wm.y + double(w.z) * wm.z;
            const double eta_crossed = cos_i_m < 0 ? 1 / double(cs.eta) : double(cs.eta);
            const double sin2_t = (1 - cos_i_m * cos_i_m) / (eta_crossed * eta_crossed);
            const double e = component_error(lanes.wo, s.wo, j) / (4 * tolerance);
            const double ds = std::abs(double(lanes.shadowing[j]) - s.shadowing);
            if (std::abs(1 - sin2_t) < 1e-3 && !s.reflected) {
                worst_near_critical = std::max(worst_near_critical, e * 4 * tolerance);
                EXPECT_LE(ds, 1e-3) << j;
            } else {
                worst_wo = std::max(worst_wo, e);
                // The escape fraction moves with wo's direction like the Smith root
                // r_o = √(1 + α² tan²θo), whose slope in cos θo grows like 1/cos θo.
                worst_shadowing = std::max(
                    worst_shadowing,
                    ds / (2e-5 + 1e-5 * s.shadowing + 4 * tolerance / std::abs(double(s.wo.z))));
            }
        }
        EXPECT_LE(double(differ), 1e-3 * double(n)) << "η " << cs.eta << " α " << cs.alpha;
        EXPECT_LE(worst_wo, 1.0) << "η " << cs.eta << " α " << cs.alpha;  // in units of the bound
        EXPECT_LE(worst_near_critical, 1e-3) << "η " << cs.eta << " α " << cs.alpha;
        EXPECT_LE(worst_shadowing, 1.0) << "η " << cs.eta << " α " << cs.alpha;
        std::printf(
            "[ lanes    ] %s dielectric η %g α %g%s%s: %zu differ, %zu ill-conditioned, |Δwo| ≤ "
            "%.2g of its bound (%.2g near the critical angle), |Δshadowing| ≤ %.2g of its bound\n",
            simd_target_name(), cs.eta, cs.alpha, cs.uncorrelated ? " uncorrelated" : "",
            cs.smith ? "" : " pbrt", differ, ill_conditioned, worst_wo, worst_near_critical,
            worst_shadowing);
    }
}

// The conductor event: gold-like (chromatic), a strong absorber, k = 0 with η < 1 (total
// reflection inside the Fresnel factor), smooth and rough, the uncorrelated option; light from
// above only (a wi below is degenerate on both, exactly). The direction and escape fraction as the
// dielectric's reflection (with the same conditioning of the visible normal); the Fresnel factors
// within 8 float ulps of 1 (the Fresnel lane test's bound) plus the facet cosine's difference
// times the factor's slope, at most 4/(cos θ + 10^-3) near grazing facets (its square roots).
TEST(KernelSimdLanes, ConductorEvent) {
    ParticleRng rng(32, 0, 0);
    std::vector<float> wi = directions(rng, 6000, false);
    wi.insert(wi.end(), {0, 0, -1, 0.6f, 0, -0.8f});  // from below: degenerate
    const std::size_t n = wi.size() / 3;
    const std::vector<float> u = uniforms(rng, n, 3);
    struct Case {
        float alpha, eta[3], k[3];
        bool uncorrelated;
    };
    const Case cases[] = {{0.f, {0.143f, 0.374f, 1.44f}, {3.98f, 2.38f, 1.80f}, false},
                          {0.5f, {0.143f, 0.374f, 1.44f}, {3.98f, 2.38f, 1.80f}, false},
                          {1e-3f, {2.9f, 2.9f, 2.9f}, {3.1f, 3.1f, 3.1f}, false},
                          {1.f, {1 / 1.5f, 1 / 1.5f, 1 / 1.5f}, {0, 0, 0}, false},
                          {0.3f, {0.2f, 0.2f, 0.2f}, {3.f, 3.f, 3.f}, true}};
    for (const Case& cs : cases) {
        const std::vector<float> params = {cs.alpha, cs.eta[0], cs.eta[1], cs.eta[2],
                                           cs.k[0],  cs.k[1],   cs.k[2]};
        const SimdEventResult lanes =
            simd_interface_events(1, params, {cs.alpha == 0, cs.uncorrelated}, wi, u);
        const ConductorInterface<float> iface{Rgbf(cs.eta[0], cs.eta[1], cs.eta[2]),
                                              Rgbf(cs.k[0], cs.k[1], cs.k[2]), cs.alpha};
        std::size_t ill_conditioned = 0;
        double worst_wo = 0, worst_shadowing = 0, worst_fresnel = 0;
        for (std::size_t j = 0; j < n; ++j) {
            const LaneVec3<float> w = {wi[3 * j], wi[3 * j + 1], wi[3 * j + 2]};
            float f[3];
            const auto fresnel = [&](float c, float* out) {
                const Rgbf r = iface.fresnel(c);
                out[0] = r[0], out[1] = r[1], out[2] = r[2];
            };
            const InterfaceEventLanes<float, bool> s = conductor_event<float>(
                ggx_isotropic_lanes<float>(cs.alpha), cs.alpha == 0, cs.uncorrelated, w, u[n + j],
                u[2 * n + j], true, fresnel, f);
            ASSERT_EQ(bool(lanes.degenerate[j]), s.degenerate) << j;
            if (s.degenerate) {
                EXPECT_LE(w.z, 0.f) << j;
                continue;
            }
            double tolerance = 1e-6, h = 1;
            if (cs.alpha > 0) {
                tolerance = visible_normal_tolerance(cs.alpha, w, u[n + j], u[2 * n + j], h);
            }
            if (h < 0.05) {
                ++ill_conditioned;
                continue;
            }
            worst_wo = std::max(worst_wo, component_error(lanes.wo, s.wo, j) / (4 * tolerance));
            const double ds = std::abs(double(lanes.shadowing[j]) - s.shadowing);
            if (s.wo.z > 0)
                worst_shadowing = std::max(
                    worst_shadowing, ds / (2e-5 + 1e-5 * s.shadowing + 4 * tolerance / s.wo.z));
            else
                EXPECT_EQ(lanes.shadowing[j] == 0.f, s.shadowing == 0.f) << j;
            // The facet cosine (w·wm = cos of half the angle between wi and wo).
            const double cos_half =
                std::sqrt(std::max(0.0, 0.5 * (1 + double(w.x) * s.wo.x + double(w.y) * s.wo.y +
                                               double(w.z) * s.wo.z)));
            for (int c = 0; c < 3; ++c)
                worst_fresnel = std::max(worst_fresnel,
                                         std::abs(double(lanes.fresnel[c * n + j]) - f[c]) /
                                             (8 * 0x1p-24 + 4 * 4 * tolerance / (cos_half + 1e-3)));
        }
        EXPECT_LE(worst_wo, 1.0) << "α " << cs.alpha;  // in units of the bounds
        EXPECT_LE(worst_shadowing, 1.0) << "α " << cs.alpha;
        EXPECT_LE(worst_fresnel, 1.0) << "α " << cs.alpha;
        std::printf(
            "[ lanes    ] %s conductor α %g η %g k %g%s: %zu ill-conditioned; |Δwo|, "
            "|Δshadowing|, |ΔF| ≤ %.2g, %.2g, %.2g of their bounds\n",
            simd_target_name(), cs.alpha, cs.eta[0], cs.k[0],
            cs.uncorrelated ? " uncorrelated" : "", ill_conditioned, worst_wo, worst_shadowing,
            worst_fresnel);
    }
}

// The polarized events (dielectric_event and conductor_event with their polarization,
// physics/polarization.h): random states (degree of polarization in [0, 1], random frames ⊥ the
// travel direction), random fluxes, one state for all channels and one per channel, on the cases
// of the unpolarized tests. The branch choice, the degeneracy and the direction as there; the
// state after the event is compared as light, not as numbers: both turned into a common frame
// (x ∝ a × wo, a the coordinate axis least aligned with the scalar's wo), because the facet's s
// axis, the frame the event leaves the state in, is ill-conditioned where the facet is met near
// normal incidence (where its choice does not matter). Its error: the float rounding of the
// rotations and of the Mueller matrix (≤ 1e-5), plus the facet normal's difference (the direction
// bound `tolerance` of the unpolarized tests) times the state's slope in it (≤ 8), both divided by
// the branch's intensity factor a + b q (the normalization; the lanes where it is below 1e-3
// carry less than 1e-3 of the flux and are counted, not compared). The flux factors: relative
// 1e-5 plus the same normal term.

// The state turned into the frame a × wo (double; physics/polarization.h stokes_rotate_frame).
StokesLanes<double> in_common_frame(const float* x, const float* stokes, const LaneVec3<double>& wo,
                                    int channels) {
    StokesLanes<double> st;
    st.x = {x[0], x[1], x[2]};
    for (int c = 0; c < 3; ++c) {
        st.q[c] = stokes[3 * c];
        st.u[c] = stokes[3 * c + 1];
        st.v[c] = stokes[3 * c + 2];
    }
    const double ax = std::abs(wo.x), ay = std::abs(wo.y), az = std::abs(wo.z);
    const LaneVec3<double> a = ax <= ay && ax <= az   ? LaneVec3<double>{1, 0, 0}
                               : ay <= ax && ay <= az ? LaneVec3<double>{0, 1, 0}
                                                      : LaneVec3<double>{0, 0, 1};
    stokes_rotate_frame<double>(st, wo, lane_cross<double>(a, wo), channels, true);
    return st;
}

TEST(KernelSimdLanes, PolarizedEvents) {
    ParticleRng rng(35, 0, 0);
    struct Case {
        int kind;  // 0 dielectric, 1 conductor
        float alpha, eta[3], k[3];
    };
    const Case cases[] = {{0, 0.3f, {1.5f}, {}},
                          {0, 0.6f, {1 / 1.5f}, {}},
                          {0, 0.f, {1.5f}, {}},
                          {0, 1.f, {2.4f}, {}},
                          {1, 0.5f, {0.143f, 0.374f, 1.44f}, {3.98f, 2.38f, 1.80f}},
                          {1, 0.f, {0.143f, 0.374f, 1.44f}, {3.98f, 2.38f, 1.80f}},
                          {1, 0.3f, {2.9f, 2.9f, 2.9f}, {3.1f, 3.1f, 3.1f}}};
    for (const Case& cs : cases)
        for (const int channels : {1, 3}) {
            const std::vector<float> wi = directions(rng, 4000, cs.kind == 0);
            const std::size_t n = wi.size() / 3;
            const std::vector<float> u = uniforms(rng, n, 3);
            std::vector<float> x(3 * n), stokes(9 * n), flux(3 * n);
            for (std::size_t j = 0; j < n; ++j) {
                const Vec3d d(-wi[3 * j], -wi[3 * j + 1], -wi[3 * j + 2]);
                const Vec3d r(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5,
                              rng.uniform_double() - 0.5);
                const Vec3d xj = normalize(cross(d, r));
                x[3 * j] = float(xj.x), x[3 * j + 1] = float(xj.y), x[3 * j + 2] = float(xj.z);
                for (int c = 0; c < 3; ++c) {
                    const double dop = rng.uniform_double(), z = 2 * rng.uniform_double() - 1;
                    const double phi = 2 * kPi<double> * rng.uniform_double(),
                                 rr = std::sqrt(1 - z * z);
                    stokes[9 * j + 3 * c] = float(dop * rr * std::cos(phi));
                    stokes[9 * j + 3 * c + 1] = float(dop * rr * std::sin(phi));
                    stokes[9 * j + 3 * c + 2] = float(dop * z);
                    flux[3 * j + c] = 0.05f + rng.uniform_float();
                }
            }
            std::vector<float> params;
            std::vector<std::int32_t> flags;
            if (cs.kind == 0) {
                params = {cs.eta[0], cs.alpha};
                flags = {cs.alpha == 0, 0, 0, 1};
            } else {
                params = {cs.alpha, cs.eta[0], cs.eta[1], cs.eta[2], cs.k[0], cs.k[1], cs.k[2]};
                flags = {cs.alpha == 0, 0};
            }
            const SimdPolarizedEventResult lanes = simd_polarized_interface_events(
                cs.kind, params, flags, wi, u, x, stokes, flux, channels);
            const ConductorInterface<float> iface{Rgbf(cs.eta[0], cs.eta[1], cs.eta[2]),
                                                  Rgbf(cs.k[0], cs.k[1], cs.k[2]), cs.alpha};
            std::size_t differ = 0, ill_conditioned = 0, dim = 0;
            double worst_state = 0, worst_factor = 0;
            for (std::size_t j = 0; j < n; ++j) {
                const LaneVec3<float> w = {wi[3 * j], wi[3 * j + 1], wi[3 * j + 2]};
                PolarizationLanes<float> pol;
                pol.channels = channels;
                pol.stokes.x = {x[3 * j], x[3 * j + 1], x[3 * j + 2]};
                for (int c = 0; c < 3; ++c) {
                    pol.stokes.q[c] = stokes[9 * j + 3 * c];
                    pol.stokes.u[c] = stokes[9 * j + 3 * c + 1];
                    pol.stokes.v[c] = stokes[9 * j + 3 * c + 2];
                }
                pol.flux = &flux[3 * j];
                InterfaceEventLanes<float, bool> e;
                if (cs.kind == 0) {
                    const DielectricEventShape shape{cs.alpha == 0, false, false, true};
                    e = dielectric_event<float, Lane<float>, true>(
                        cs.eta[0], 1 / cs.eta[0], ggx_isotropic_lanes<float>(cs.alpha), shape, w,
                        u[j], u[n + j], u[2 * n + j], true, &pol);
                } else {
                    float f[3];
                    const auto fresnel = [&](float c, float* out) {
                        const Rgbf r = iface.fresnel(c);
                        out[0] = r[0], out[1] = r[1], out[2] = r[2];
                    };
                    const auto mueller = [&](float c, InterfaceMueller<float>* m) {
                        iface.mueller(c, m);
                    };
                    e = conductor_event<float>(ggx_isotropic_lanes<float>(cs.alpha), cs.alpha == 0,
                                               false, w, u[n + j], u[2 * n + j], true, fresnel, f,
                                               &pol, mueller);
                }
                ASSERT_EQ(bool(lanes.event.degenerate[j]), e.degenerate) << j;
                if (e.degenerate) continue;
                if (bool(lanes.event.reflected[j]) != e.reflected) {
                    ++differ;
                    continue;
                }
                double h;
                const double tolerance =
                    visible_normal_tolerance(cs.alpha, w, u[n + j], u[2 * n + j], h);
                if (h < 0.05) {
                    ++ill_conditioned;
                    continue;
                }
                // The branch's intensity factor a + b q (the smallest over the states): a
                // conductor's flux factors; for a dielectric, from its facet (the half vector of
                // wi and wo: Walter et al. 2007, Eqs. 13 and 16) and the incoming state turned
                // into its plane of incidence, in double.
                double intensity = 1;
                // A dielectric's refracted cosine near the critical angle: √(1 − sin²θt) turns
                // the (1/η² + 3) ulps of sin²θt = (1 − cos²θ)/η² into that over 2 cos θt (over
                // 2√(sin²θt − 1) for the phase of a total reflection), which the Fresnel factors
                // take with a slope up to 4(η + 1/η)/cos θ (R_s, R_p: 4ηc|c − ηt|/(c + ηt)³
                // and 4ηc|ηc − t|/(ηc + t)³ ≤ 4η/c and 4/(ηc)); an evaluation that fuses
                // multiply-adds and one that does not (SSE4) differ by that.
                double critical = 0;
                if (cs.kind == 1) {
                    for (int c = 0; c < 3; ++c)
                        intensity = std::min(intensity, double(pol.factor[c]));
                } else {
                    const Vec3d wid(w.x, w.y, w.z), wod(e.wo.x, e.wo.y, e.wo.z);
                    const double eta_i = w.z > 0 ? 1.0 : cs.eta[0],
                                 eta_o = e.wo.z > 0 ? 1.0 : cs.eta[0];
                    Vec3d wm(0, 0, 1);
                    if (cs.alpha > 0) {
                        wm = normalize(e.reflected ? wid + wod : -(wid * eta_i + wod * eta_o));
                        if (wm.z < 0) wm = -wm;
                    }
                    const auto fm = fresnel_dielectric_mueller<double>(dot(wid, wm), cs.eta[0],
                                                                       1.0 / cs.eta[0]);
                    const double c = std::abs(dot(wid, wm));
                    const double n = dot(wid, wm) > 0 ? cs.eta[0] : 1.0 / cs.eta[0];
                    const double t = std::sqrt(std::abs(1 - (1 - c * c) / (n * n)));
                    critical = 4 * (n + 1 / n) / std::max(c, 1e-30) * (1 / (n * n) + 3) * 0x1p-24 /
                               (2 * std::max(t, 1e-30));
                    StokesLanes<double> in;
                    in.x = {x[3 * j], x[3 * j + 1], x[3 * j + 2]};
                    for (int c = 0; c < 3; ++c) {
                        in.q[c] = stokes[9 * j + 3 * c];
                        in.u[c] = stokes[9 * j + 3 * c + 1];
                        in.v[c] = stokes[9 * j + 3 * c + 2];
                    }
                    const Vec3d n_facet = cross(wid, wm);
                    stokes_rotate_frame<double>(in, {-wid.x, -wid.y, -wid.z},
                                                {n_facet.x, n_facet.y, n_facet.z}, channels, true);
                    const auto& m = e.reflected ? fm.reflection : fm.transmission;
                    for (int c = 0; c < channels; ++c)
                        intensity = std::min(intensity, m.a + m.b * in.q[c]);
                }
                if (intensity < 1e-3) {
                    ++dim;
                    continue;
                }
                const LaneVec3<double> wo = {e.wo.x, e.wo.y, e.wo.z};
                float s_stokes[9], s_x[3] = {pol.stokes.x.x, pol.stokes.x.y, pol.stokes.x.z};
                for (int c = 0; c < 3; ++c) {
                    s_stokes[3 * c] = pol.stokes.q[c];
                    s_stokes[3 * c + 1] = pol.stokes.u[c];
                    s_stokes[3 * c + 2] = pol.stokes.v[c];
                }
                const StokesLanes<double> a = in_common_frame(s_x, s_stokes, wo, channels);
                const StokesLanes<double> b =
                    in_common_frame(&lanes.x[3 * j], &lanes.stokes[9 * j], wo, channels);
                const double bound = (1e-5 + 8 * tolerance + critical) / intensity;
                for (int c = 0; c < channels; ++c)
                    worst_state = std::max(
                        worst_state, std::max({std::abs(a.q[c] - b.q[c]), std::abs(a.u[c] - b.u[c]),
                                               std::abs(a.v[c] - b.v[c])}) /
                                         bound);
                for (int c = 0; c < 3; ++c)
                    worst_factor =
                        std::max(worst_factor,
                                 std::abs(double(lanes.factor[3 * j + c]) - pol.factor[c]) /
                                     ((1e-5 + 8 * tolerance + critical) * (1 + pol.factor[c])));
            }
            EXPECT_LE(double(differ), 1e-3 * double(n)) << "case " << cs.kind << " α " << cs.alpha;
            EXPECT_LE(worst_state, 1.0) << "case " << cs.kind << " α " << cs.alpha;
            EXPECT_LE(worst_factor, 1.0) << "case " << cs.kind << " α " << cs.alpha;
            std::printf(
                "[ lanes    ] %s polarized %s α %g η %g, %d state(s): %zu differ, %zu "
                "ill-conditioned, %zu dim; |Δstate|, |Δfactor| ≤ %.2g, %.2g of their bounds\n",
                simd_target_name(), cs.kind == 0 ? "dielectric" : "conductor", cs.alpha, cs.eta[0],
                channels, differ, ill_conditioned, dim, worst_state, worst_factor);
        }
}

// The events on pairs of vectors (VecLane2: the kernel's two lane sets at one event) are the
// events on one vector (directions, masking, a conductor's Fresnel factors, the branch and
// degeneracy masks): the same operations on each lane, in the same order. The compiler may fuse a
// product and a sum into one multiply-add in one instantiation and not in the other
// (-ffp-contract=fast; seen in the conductor's Fresnel factors on AVX2), which moves a value by
// its last bits: within 4 float ulps, the masks exactly. A count of particles that leaves the
// last pair's second vector partly and then wholly empty (18 fixed directions are added to the
// count).
TEST(KernelSimdLanes, EventsOnPairsAreTheEventsOnVectors) {
    ParticleRng rng(37, 0, 0);
    for (const int count : {4099, 4083}) {
        const std::vector<float> wi = directions(rng, count, true);
        const std::size_t n = wi.size() / 3;
        const std::vector<float> u = uniforms(rng, n, 3);
        struct Case {
            int kind;
            float eta, alpha;
            bool uncorrelated, smith;
        };
        const Case cases[] = {{0, 1.5f, 0.f, false, true},   {0, 1.5f, 0.3f, false, true},
                              {0, 1.5f, 0.3f, false, false}, {0, 1 / 1.5f, 0.6f, false, true},
                              {0, 1.5f, 0.3f, true, false},  {0, 1.f, 0.3f, false, true},
                              {1, 1.f, 0.3f, false, false},  {1, 1.f, 0.f, false, false},
                              {1, 1.f, 0.3f, true, false},   {2, 1.f, 0.f, false, false}};
        for (const Case& cs : cases) {
            // A conductor: gold-like per channel (each channel its own Fresnel factor).
            const std::vector<std::int32_t> flags =
                cs.kind == 1 ? std::vector<std::int32_t>{cs.alpha == 0, cs.uncorrelated}
                             : std::vector<std::int32_t>{cs.alpha == 0, cs.eta == 1,
                                                         cs.uncorrelated, cs.smith};
            const std::vector<float> params =
                cs.kind == 0   ? std::vector<float>{cs.eta, cs.alpha}
                : cs.kind == 1 ? std::vector<float>{cs.alpha, 0.18f, 0.42f, 1.37f, 3.4f, 2.4f, 1.8f}
                               : std::vector<float>{};
            const SimdEventResult one = simd_interface_events(cs.kind, params, flags, wi, u);
            const SimdEventResult two = simd_interface_events(cs.kind, params, flags, wi, u, true);
            // The largest distance in float ulps (of the larger magnitude) between a and b.
            const auto ulps = [](const std::vector<float>& a, const std::vector<float>& b) {
                EXPECT_EQ(a.size(), b.size());
                double worst = 0;
                for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
                    const double ulp =
                        std::max({std::abs(double(std::nextafter(a[i], INFINITY)) - double(a[i])),
                                  std::abs(double(std::nextafter(b[i], INFINITY)) - double(b[i])),
                                  0x1p-149});
                    worst = std::max(worst, std::abs(double(a[i]) - double(b[i])) / ulp);
                }
                return worst;
            };
            EXPECT_LE(ulps(one.wo, two.wo), 4) << cs.kind << " α " << cs.alpha;
            EXPECT_LE(ulps(one.shadowing, two.shadowing), 4) << cs.kind << " α " << cs.alpha;
            EXPECT_LE(ulps(one.fresnel, two.fresnel), 4) << cs.kind << " α " << cs.alpha;
            EXPECT_EQ(one.reflected, two.reflected) << cs.kind << " α " << cs.alpha;
            EXPECT_EQ(one.degenerate, two.degenerate) << cs.kind << " α " << cs.alpha;
        }
    }
}

// The Lambertian event: the polar map's cos and sin of 2πu2 (the vectors' Cephes azimuth, ≤ 2
// float ulps of 1; the scalar rounds 2πu to a float, up to half an ulp of 2π, 2^-22, in the angle,
// before the C library's cos and sin, ≤ 1 ulp) times r = √u1 and the square root of 1 − u1 (both
// correctly rounded): every component within 2^-22 + 4·2^-24, on wi's side; wi.z = 0 is degenerate
// on the vectors (the scalar sampler returns nothing).
TEST(KernelSimdLanes, LambertianEvent) {
    ParticleRng rng(33, 0, 0);
    const std::vector<float> wi = directions(rng, 6000, true);
    const std::size_t n = wi.size() / 3;
    const std::vector<float> u = uniforms(rng, n, 3);
    const SimdEventResult lanes = simd_interface_events(2, {}, {}, wi, u);
    const LambertianInterface<float> iface{Rgbf(0.5f)};
    double worst = 0;
    for (std::size_t j = 0; j < n; ++j) {
        const Vec3f w(wi[3 * j], wi[3 * j + 1], wi[3 * j + 2]);
        const auto s = iface.sample(w, u[n + j], u[2 * n + j]);
        ASSERT_EQ(bool(lanes.degenerate[j]), !s.has_value()) << j;
        if (!s) continue;
        EXPECT_GT(double(lanes.wo[3 * j + 2]) * w.z, -1e-30) << j;  // on wi's side (or grazing)
        worst = std::max(worst, component_error(lanes.wo, {s->wo.x, s->wo.y, s->wo.z}, j));
    }
    EXPECT_LE(worst, 0x1p-22 + 4 * 0x1p-24) << simd_target_name();
}

// The medium step: a grey medium with strong forward scattering (g = 0.99), a chromatic one
// (per-channel extinction and g, spectral MIS for both the flight and the phase, g → ±1 at
// ±0.999), one with a clear channel (τ = 0) met on horizontal paths, and one with equal g but
// chromatic extinction; random directions (horizontal ones included), depths, fluxes (one black
// channel included) and draws. Leaving or not is decided alike but where the flight's length is
// within rounding of the boundary (≤ 1 in 10^3 lanes); the lanes that scatter draw the same
// numbers in the same order (their draw counts agree). The factors: e^{−τ t} through Highway's
// exp and log1p (≤ 1 and 2 ulp), the flight's length multiplying the log1p's error by τ t, so
// within (16 + 4 τt)·2^-24 relative plus 2^-24 of the mixture's other terms; the new direction as
// the HG sample's: the sampled cosine within Δc, the HG lane test's bound at the channels' g
// (hg_cos_tolerance_max, support/simd_probes.h), which the sine √(1 − cos²θ) spreads by
// min(|cos θ| Δc / sin θ, √(2 Δc)) (near the poles, cos θ → ±1), plus 16 ulps of the frame's
// rotation. The phase factors (spectral MIS over the channels' g): bounded as stated in the
// loop, from the HG lane test's bound.
TEST(KernelSimdLanes, MediumStep) {
    ParticleRng rng(34, 0, 0);
    CompiledMedium<float> grey, chromatic, clear, equal_g;
    auto finish = [](CompiledMedium<float>& m) {
        m.tau_t = m.tau_a + m.tau_s;
        m.scatters = true;
        m.absorbs = m.tau_a.max() > 0;
        m.uniform_g = m.g[0] == m.g[1] && m.g[1] == m.g[2];
        m.uniform_tau_t = m.tau_t[0] == m.tau_t[1] && m.tau_t[1] == m.tau_t[2];
        for (int c = 0; c < 3; ++c)
            m.single_scattering_albedo[c] = m.tau_t[c] > 0 ? m.tau_s[c] / m.tau_t[c] : 0.f;
    };
    grey.tau_a = Rgbf(0.1f), grey.tau_s = Rgbf(2.f), grey.g = Rgbf(0.99f);
    chromatic.tau_a = Rgbf(0.1f, 0.f, 0.9f), chromatic.tau_s = Rgbf(1.f, 3.f, 0.5f);
    chromatic.g = Rgbf(0.999f, -0.999f, 0.3f);
    clear.tau_a = Rgbf(0.f), clear.tau_s = Rgbf(0.f, 1.f, 4.f), clear.g = Rgbf(0.f, 0.5f, -0.5f);
    equal_g.tau_a = Rgbf(0.5f, 0.f, 0.f), equal_g.tau_s = Rgbf(1.f), equal_g.g = Rgbf(-0.7f);
    for (CompiledMedium<float>* m : {&grey, &chromatic, &clear, &equal_g})
        finish(*m);
    const char* names[] = {"grey", "chromatic", "clear channel", "equal g"};
    std::vector<float> d = directions(rng, 6000, true);
    const std::size_t n = d.size() / 3;
    std::vector<float> w(3 * n), depth(n);
    for (std::size_t j = 0; j < n; ++j) {
        for (int c = 0; c < 3; ++c)
            w[c * n + j] = j % 11 == 3 && c == 1 ? 0.f : 0.05f + rng.uniform_float();
        depth[j] = j % 13 == 0 ? 0.f : j % 17 == 0 ? 1.f : rng.uniform_float();
    }
    const std::vector<float> u = uniforms(rng, n, 5);
    int index = 0;
    for (const CompiledMedium<float>* m : {&grey, &chromatic, &clear, &equal_g}) {
        const SimdMediumResult lanes = simd_medium_step(*m, d, w, depth, u);
        std::size_t differ = 0, scattered = 0;
        double worst_factor = 0, worst_d = 0, worst_pole = 0, worst_phase = 0;
        double cos_tolerance = 0;  // Δc: the sampled cosine's, at the worst channel's g
        for (int c = 0; c < 3; ++c)
            cos_tolerance = std::max(cos_tolerance, hg_cos_tolerance_max(m->g[c]));
        for (std::size_t j = 0; j < n; ++j) {
            const LaneVec3<float> dj = {d[3 * j], d[3 * j + 1], d[3 * j + 2]};
            const float wj[3] = {w[j], w[n + j], w[2 * n + j]};
            int k = 0;
            auto uniform = [&] { return u[std::size_t(k++) * n + j]; };
            const MediumFlightLanes<float, bool> s =
                medium_free_flight<float>(*m, dj, wj, depth[j], uniform);
            if (bool(lanes.leaves[j]) != s.leaves) {
                ++differ;
                continue;
            }
            // The flight's optical depth bounds the exponentials' relative error.
            double tau_t_max = 0;
            for (int c = 0; c < 3; ++c)
                tau_t_max = std::max(tau_t_max, double(m->tau_t[c]));
            const double flight = -std::log1p(-double(u[n + j]));  // ≥ the optical depth used
            const double bound = (16 + 4 * tau_t_max * flight) * 0x1p-24;
            for (int c = 0; c < 3; ++c) {
                ASSERT_TRUE(std::isfinite(lanes.factor[c * n + j])) << j;
                worst_factor =
                    std::max(worst_factor, std::abs(double(lanes.factor[c * n + j]) - s.factor[c]) /
                                               (bound * std::max(double(s.factor[c]), 1.0)));
            }
            if (s.leaves) continue;
            ++scattered;
            LaneVec3<float> d_new;
            float phase[3];
            medium_scatter<float>(*m, dj, s.p, true, uniform, d_new, phase);
            EXPECT_EQ(lanes.draws[j], k) << j;
            EXPECT_NEAR(lanes.depth[j], s.depth, 1e-6 + 1e-5 * flight) << j;
            const double e = component_error(lanes.d, d_new, j);
            const double cos_theta =
                double(dj.x) * d_new.x + double(dj.y) * d_new.y + double(dj.z) * d_new.z;
            const double sin_theta = std::sqrt(std::max(0.0, 1 - cos_theta * cos_theta));
            const double bound_d =
                16 * 0x1p-24 + cos_tolerance +
                std::min(std::abs(cos_theta) * cos_tolerance / std::max(sin_theta, 1e-30),
                         std::sqrt(2 * cos_tolerance));
            (std::abs(cos_theta) > 0.99 ? worst_pole : worst_d) =
                std::max(std::abs(cos_theta) > 0.99 ? worst_pole : worst_d, e / bound_d);
            // Each phase value's bound: (1 + 1.5 κ) · 8 ulp (the HG lane test's, κ the condition
            // number of its denominator 1 + g² − 2g cos θ) plus the cosine's difference (Δc of
            // the sample, 3 times the direction's) times the relative slope 3|g| / denominator;
            // a factor HG_c / Σ_k p_k HG_k adds the mixture's, at most the largest of the bounds.
            double bound_phase[3], bound_mix = 0;
            for (int c = 0; c < 3; ++c) {
                const double g = m->g[c];
                const double denom = 1 + g * g - 2 * g * cos_theta;
                const double kappa = (1 + g * g + 2 * std::abs(g * cos_theta)) / denom;
                bound_phase[c] = (1 + 1.5 * kappa) * 8 * 0x1p-24 +
                                 3 * std::abs(g) / denom * (cos_tolerance + 3 * e);
                bound_mix = std::max(bound_mix, bound_phase[c]);
            }
            for (int c = 0; c < 3; ++c)
                worst_phase =
                    std::max(worst_phase, std::abs(double(lanes.phase[c * n + j]) / phase[c] - 1) /
                                              (m->uniform_g ? 1e-30 : bound_phase[c] + bound_mix));
        }
        EXPECT_LE(double(differ), 1e-3 * double(n)) << names[index];
        EXPECT_LE(worst_factor, 1.0) << names[index];  // in units of the bound
        EXPECT_LE(worst_d, 1.0) << names[index];       // in units of the bound
        EXPECT_LE(worst_pole, 1.0) << names[index];
        EXPECT_LE(worst_phase, 1.0) << names[index];
        EXPECT_GT(scattered, n / 10) << names[index];
        std::printf(
            "[ lanes    ] %s medium %s: %zu of %zu scatter, %zu differ; factors ≤ %.2g of their "
            "bound, |Δd| ≤ %.2g of its bound (%.2g near the poles), phase ≤ %.2g of its bound\n",
            simd_target_name(), names[index], scattered, n, differ, worst_factor, worst_d,
            worst_pole, worst_phase);
        ++index;
    }
}

}  // namespace
}  // namespace lamina

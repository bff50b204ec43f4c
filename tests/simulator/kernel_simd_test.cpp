// The SIMD kernel (simulator/kernel_simd.h): its random numbers and azimuths against the
// libraries and closed forms they stand for, and its tables against the scalar kernel's by a
// two-sample chi-square test. (Every exact-solution test of goniophotometer_test.cpp also runs on
// it.)
#include "support/simd_probes.h"

#include "core/error.h"
#include "core/rng.h"
#include "layers/stack.h"
#include "physics/fresnel.h"
#include "physics/medium.h"
#include "physics/microfacet.h"
#include "physics/microsurface_walk.h"
#include "physics/phase.h"
#include "physics/polarization.h"
#include "physics/thin_film.h"
#include "simulator/goniophotometer.h"
#include "support/chi2.h"
#include "support/stacks.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <string>
#include <tuple>

namespace lamina {
namespace {

// The lanes draw the very numbers of ParticleRng (Philox4x32-10 seeding PCG32, Random123 and
// pcg-cpp), bit for bit, for particles on both sides of a 32-bit index boundary and a stream with
// both 32-bit halves set.
TEST(KernelSimd, LanesDrawTheParticlesOwnNumbers) {
    const std::uint64_t seed = 0x0123456789abcdefull, stream = 0xfedcba9876543210ull;
    const std::uint64_t first = (std::uint64_t(1) << 32) - 21, n_particles = 45, n_draws = 70;
    const std::vector<float> lanes =
        simd_particle_uniforms(seed, stream, first, n_particles, n_draws);
    ASSERT_EQ(lanes.size(), n_particles * n_draws);
    for (std::uint64_t p = 0; p < n_particles; ++p) {
        ParticleRng rng(seed, stream, first + p);
        for (std::uint64_t i = 0; i < n_draws; ++i)
            ASSERT_EQ(lanes[p * n_draws + i], rng.uniform_float())
                << "particle " << first + p << ", draw " << i;
    }
}

// LAMINA_SIMD_TARGET (set by ctest's simd_AVX2 and simd_SSE4 runs) picks the instruction set.
TEST(KernelSimd, RunsOnTheRequestedInstructionSet) {
    const char* wanted = std::getenv("LAMINA_SIMD_TARGET");
    if (wanted == nullptr) GTEST_SKIP() << "LAMINA_SIMD_TARGET is not set";
    EXPECT_EQ(std::string(simd_target_name()), wanted);
    EXPECT_EQ(kernel_description(Kernel::Simd), std::string("simd ") + wanted);
}

// The lane test of the Smith refraction escape (physics/microfacet.h smith_refraction_escape, one
// template): its instantiation on the dispatched instruction set's vectors (ctest runs this on
// every compiled set through LAMINA_SIMD_TARGET) against the scalar float instantiation and the
// double one, on random roots r = 1 + 2Λ from 1 to 1e4 (log-uniform) and the edges: r = 1 (the
// normal), huge and infinite r (grazing); both of the float methods run (the Gamma functions for
// 1 + Λ ≤ 3, r ≤ 5, and Stirling's series beyond). The result is in [0, 1]; the series' exponent
// is a sum of terms up to ~50 in size that cancel, so its error is absolute, a few ulp of those
// terms (core/beta_function.h): vector and scalar float agree to 2e-5, and both are within 2e-5 of
// the double instantiation at the same arguments (beyond the float bound on 1 + Λ, 1e7, both are
// evaluated at the bound: the double reference is given the bounded arguments).
TEST(KernelSimd, SmithRefractionEscapeLanes) {
    ParticleRng rng(17, 0, 0);
    std::vector<float> r_i, r_o;
    const float edges[] = {1.f,  1.0000001f, 2.f,
                           1e4f, 1e9f,       std::numeric_limits<float>::infinity()};
    for (float a : edges)
        for (float b : edges) {
            r_i.push_back(a);
            r_o.push_back(b);
        }
    for (int k = 0; k < 20000; ++k) {
        r_i.push_back(std::pow(1e4f, rng.uniform_float()));
        r_o.push_back(std::pow(1e4f, rng.uniform_float()));
    }
    const std::vector<float> lanes = simd_smith_refraction_escape(r_i, r_o);
    ASSERT_EQ(lanes.size(), r_i.size());
    double worst_scalar = 0, worst_double = 0;
    for (std::size_t j = 0; j < r_i.size(); ++j) {
        const float scalar = smith_refraction_escape(r_i[j], r_o[j]);
        const double bound = 2 * Lane<float>::kBetaArgumentMax - 1;  // r of 1 + Λ at the bound
        const double exact = smith_refraction_escape(std::min(double(r_i[j]), bound),
                                                     std::min(double(r_o[j]), bound));
        ASSERT_TRUE(std::isfinite(lanes[j])) << r_i[j] << ' ' << r_o[j];
        ASSERT_GE(lanes[j], 0.f);
        ASSERT_LE(lanes[j], 1.f + 1e-5f);
        worst_scalar = std::max(worst_scalar, std::abs(double(lanes[j]) - scalar));
        worst_double = std::max(worst_double, std::abs(double(lanes[j]) - exact));
    }
    EXPECT_LT(worst_scalar, 2e-5) << simd_target_name();
    EXPECT_LT(worst_double, 2e-5) << simd_target_name();
    RecordProperty("worst_vs_scalar_float", std::to_string(worst_scalar));
    RecordProperty("worst_vs_double", std::to_string(worst_double));
    std::printf("[ lanes    ] %s: |vector − scalar float| ≤ %.2g, |vector − double| ≤ %.2g\n",
                simd_target_name(), worst_scalar, worst_double);
}

// The exit bins the SIMD kernel computes on vectors (simulator/lane_bins.h VectorBins: a float
// angle with an error bound, certain only where the bound keeps it inside one bin) against the
// grid's own rule, HemisphereGrid::bin_of, on several grids: every bin the lanes claim is bin_of's,
// on random directions of both hemispheres and on directions a few float ulps either side of every
// θ and φ edge (where a wrong bound would show), the normal, grazing directions and a subnormal
// azimuthal radius. On the default grid nearly every random exit is binned on the lanes (else the
// fast path would be dead code; measured 99.8 %). The unfolded grids (φ over [0°, 360°),
// core/grid.h) too: the directions below the plane y = 0 take the mirror bins.
TEST(KernelSimd, LaneBinsAreTheGridsBins) {
    ParticleRng rng(23, 0, 0);
    for (const auto& [n_theta, n_phi, unfolded] :
         std::vector<std::tuple<int, int, bool>>{{90, 90, false},
                                                 {30, 20, false},
                                                 {1, 1, false},
                                                 {2, 1, false},
                                                 {7, 3, false},
                                                 {360, 720, false},
                                                 {1000, 500, false},
                                                 {90, 90, true},
                                                 {18, 18, true},
                                                 {1, 1, true},
                                                 {7, 3, true},
                                                 {360, 720, true}}) {
        const HemisphereGrid grid =
            unfolded ? HemisphereGrid(n_theta, n_phi).unfolded() : HemisphereGrid(n_theta, n_phi);
        std::vector<float> d;
        auto push = [&](double x, double y, double z) {
            d.push_back(float(x));
            d.push_back(float(y));
            d.push_back(float(z));
        };
        const int n_random = 20000;
        for (int k = 0; k < n_random; ++k) {
            const double z = 2 * rng.uniform<double>() - 1,
                         phi = 2 * kPi<double> * rng.uniform<double>();
            const double s = std::sqrt(std::max(0.0, 1 - z * z));
            push(s * std::cos(phi), s * std::sin(phi), z);
        }
        // Directions at and a few ulps either side of the edges.
        for (int b = 0; b <= n_theta; ++b) {
            const float z_edge = float(std::cos(kPi<double> / 2 * b / n_theta));
            for (int ulps = -3; ulps <= 3; ++ulps) {
                float z = z_edge;
                for (int u = 0; u < std::abs(ulps); ++u)
                    z = std::nextafter(z, ulps > 0 ? 2.f : -2.f);
                z = std::clamp(z, 0.f, 1.f);
                const double s = std::sqrt(std::max(0.0, 1.0 - double(z) * z));
                const double phi = kPi<double> * rng.uniform<double>();
                push(s * std::cos(phi), s * std::sin(phi), z);
                push(s * std::cos(phi), -s * std::sin(phi), -z);
            }
        }
        for (int b = 0; b <= n_phi; ++b) {
            const double phi_edge = kPi<double> * b / n_phi;
            for (int ulps = -3; ulps <= 3; ++ulps) {
                const double z = rng.uniform<double>(), s = std::sqrt(1 - z * z);
                float x = float(s * std::cos(phi_edge));
                for (int u = 0; u < std::abs(ulps); ++u)
                    x = std::nextafter(x, ulps > 0 ? 2.f : -2.f);
                const double y = std::sqrt(std::max(0.0, s * s - double(x) * x));
                push(x, y, z);
                push(x, -y, -z);
                push(x, -y, z);
            }
        }
        push(0, 0, 1);
        push(0, 0, -1);
        push(1, 0, 0);
        push(-1, 0, 0);
        push(0, 1, 0);
        push(0, -1, 0);
        push(1e-20, 0, 1);
        push(-1e-20, 1e-21, -1);
        push(-1e-20, -1e-21, 1);
        push(0.6, -0.0, 0.8);
        const std::vector<std::int64_t> lanes = simd_lane_bins(grid, d);
        ASSERT_EQ(lanes.size(), d.size() / 3);
        int known_random = 0;
        for (std::size_t j = 0; j < lanes.size(); ++j) {
            if (lanes[j] < 0) continue;
            if (int(j) < n_random) ++known_random;
            const Vec3f w(d[3 * j], d[3 * j + 1], d[3 * j + 2]);
            ASSERT_EQ(std::size_t(lanes[j]), grid.bin_of(w))
                << grid.to_string() << " direction " << w.x << ' ' << w.y << ' ' << w.z << " ("
                << simd_target_name() << ")";
        }
        const double fraction = double(known_random) / n_random;
        std::printf("[ bins     ] %s %s: %.4f of random exits binned on the lanes\n",
                    simd_target_name(), grid.to_string().c_str(), fraction);
        if (n_theta == 90 && n_phi == 90) {
            EXPECT_GT(fraction, 0.99);
        }
        if (n_theta * n_phi == 1) {
            EXPECT_EQ(known_random, n_random);
        }
    }
}

// The lane test of the dielectric Fresnel factor (physics/fresnel.h fresnel_dielectric_full, one
// template): on the dispatched instruction set's vectors against the scalar float instantiation,
// for random cosines on both sides and the edges (normal and grazing incidence from either side,
// the critical angle, total internal reflection), for η above and below 1 and η = 1. The two
// evaluate the same operations, but one may fuse a multiply-add where the other does not (SSE4 has
// no fused multiply-add): sin²θt = (1 − cos²θi)/η² then differs by up to (1/η² + 3) ulps of 1, and
// cos θt = √(1 − sin²θt) by that over 2 cos θt (the cancellation near the critical angle); R moves
// by |dR/d cos θt| times that, |dR_s/dt| = 4ηc|c − ηt|/(c + ηt)³ and |dR_p/dt| = 4ηc|ηc − t|/(ηc +
// t)³ (c = cos θi, t = cos θt, η the index crossed), plus 4 ulps of 1 of R's own rounding (its
// values lie in [0, 1]). Total internal reflection gives exactly R = 1 and cos θt = 0.
TEST(KernelSimd, FresnelDielectricLanes) {
    ParticleRng rng(18, 0, 0);
    for (const float eta : {1.5f, 1 / 1.5f, 1.f, 2.4f, 1 / 2.4f}) {
        std::vector<float> cos_theta = {0.f, -0.f, 1.f, -1.f, 1e-7f, -1e-7f, 0.5f, -0.5f};
        const float critical = std::sqrt(std::max(0.f, 1 - eta * eta));  // from the side of 1/η
        for (const float d : {-1e-6f, 0.f, 1e-6f})
            cos_theta.insert(cos_theta.end(), {critical + d, -critical - d});
        for (int k = 0; k < 4000; ++k)
            cos_theta.push_back(2 * rng.uniform_float() - 1);
        std::vector<float> r, t;
        simd_fresnel_dielectric(cos_theta, eta, r, t);
        ASSERT_EQ(r.size(), cos_theta.size());
        double worst = 0;  // in units of the point's bound
        for (std::size_t j = 0; j < cos_theta.size(); ++j) {
            const FresnelDielectric<float> s = fresnel_dielectric_full(cos_theta[j], eta, 1 / eta);
            ASSERT_TRUE(std::isfinite(r[j]) && std::isfinite(t[j])) << cos_theta[j];
            const bool tir_scalar = s.reflectance == 1 && s.cos_theta_t == 0;
            const bool tir_lanes = r[j] == 1 && t[j] == 0;
            if (tir_scalar != tir_lanes) {
                // Within rounding of the critical angle one may call it total reflection and the
                // other not: cos θt = √(1 − sin²θt) is then at most √(4 ulp) ≈ 5e-4 and R within
                // a few times that of 1.
                EXPECT_LT(std::max(t[j], s.cos_theta_t), 1e-3f) << eta << ' ' << cos_theta[j];
                EXPECT_GT(std::min(r[j], s.reflectance), 0.99f) << eta << ' ' << cos_theta[j];
                continue;
            }
            if (tir_scalar) continue;  // both exactly R = 1, cos θt = 0
            constexpr double ulp = 0x1p-24;
            const double n = s.eta, c = std::abs(double(cos_theta[j]));
            const double ct = s.cos_theta_t;
            const double bound_t = 4 * ulp + (1 / (n * n) + 3) * ulp / (2 * ct);
            const double slope = (4 * n * c * std::abs(c - n * ct) / std::pow(c + n * ct, 3) +
                                  4 * n * c * std::abs(n * c - ct) / std::pow(n * c + ct, 3)) /
                                 2;
            const double bound_r = 4 * ulp + slope * bound_t;
            worst = std::max({worst, std::abs(double(r[j]) - s.reflectance) / bound_r,
                              std::abs(double(t[j]) - ct) / bound_t});
        }
        EXPECT_LE(worst, 1.0) << "η " << eta << " on " << simd_target_name();
    }
}

// The lane test of the conductor Fresnel factor (physics/fresnel.h fresnel_conductor, one
// template): on the dispatched instruction set's vectors against the scalar float instantiation,
// for random cosines in [0, 1] and the edges (normal and grazing incidence), gold, a strong
// absorber, a weak one and k = 0 (where it is the dielectric factor, total reflection included
// for η < 1): within 8 float ulps of 1 (three divisions and two square roots, each ≤ 1 ulp, the
// same operations on both, none cancelling — a metal's a² is not taken as a difference; results
// in [0, 1]).
TEST(KernelSimd, FresnelConductorLanes) {
    ParticleRng rng(19, 0, 0);
    struct Index {
        float eta, k;
    };
    for (const Index ik : {Index{0.143f, 3.983f}, Index{2.9f, 3.1f}, Index{1.5f, 0.01f},
                           Index{1.5f, 0.f}, Index{1 / 1.5f, 0.f}}) {
        std::vector<float> cos_theta = {0.f, 1.f, 1e-7f, 0.5f, 1 - 1e-7f};
        for (int j = 0; j < 4000; ++j)
            cos_theta.push_back(rng.uniform_float());
        const std::vector<float> r = simd_fresnel_conductor(cos_theta, ik.eta, ik.k);
        double worst = 0;
        for (std::size_t j = 0; j < cos_theta.size(); ++j) {
            ASSERT_TRUE(std::isfinite(r[j])) << cos_theta[j];
            worst = std::max(
                worst, std::abs(double(r[j]) - fresnel_conductor(cos_theta[j], ik.eta, ik.k)));
        }
        EXPECT_LE(worst, 8 * 0x1p-24)
            << "η " << ik.eta << " k " << ik.k << " on " << simd_target_name();
    }
}

// Beer–Lambert with a depth per lane (physics/medium.h beer_lambert_transmittance_lanes, a
// spectral run's absorption) against the scalar instantiation of the broadcast form, lane by lane:
// random depths and path lengths, depth 0 (exactly 1, also along a horizontal path, inv_mu = ∞,
// where 0 · ∞ would be NaN) and depths whose transmittance underflows. Both are the vectors' and
// the library's e^x of one product: within 4 float ulps of the value.
TEST(KernelSimd, BeerLambertLanes) {
    ParticleRng rng(23, 0, 0);
    std::vector<float> tau = {0.f, 0.f, 0.f, 1e4f, 50.f, 0.5f};
    std::vector<float> inv_mu = {1.f, std::numeric_limits<float>::infinity(), 1e30f, 1e4f,
                                 3.f, std::numeric_limits<float>::infinity()};
    for (int j = 0; j < 4000; ++j) {
        tau.push_back(j % 7 == 0 ? 0.f : 4 * rng.uniform_float());
        inv_mu.push_back(1 / std::max(1e-3f, rng.uniform_float()));
    }
    const std::vector<float> t = simd_beer_lambert_lanes(tau, inv_mu);
    for (std::size_t j = 0; j < tau.size(); ++j) {
        const float depth[3] = {tau[j], tau[j], tau[j]};
        float expected[3];
        beer_lambert_transmittance<float>(depth, inv_mu[j], expected);
        ASSERT_TRUE(std::isfinite(t[j])) << "τ " << tau[j] << " 1/μ " << inv_mu[j];
        if (tau[j] == 0) {
            EXPECT_EQ(t[j], 1.f) << "1/μ " << inv_mu[j];
            continue;
        }
        EXPECT_NEAR(t[j], expected[1], 4 * 0x1p-24 * double(expected[1]) + 1e-38)
            << "τ " << tau[j] << " 1/μ " << inv_mu[j] << " on " << simd_target_name();
    }
}

// The lane test of the polarized Fresnel terms (physics/polarization.h fresnel_dielectric_mueller
// and fresnel_conductor_mueller, one template each): on the dispatched instruction set's vectors
// against the scalar float instantiation, for dielectrics from both sides (total internal
// reflection and the critical angle included) and conductors, random cosines and the edges. The
// entries are sums of products of the amplitudes' parts divided by |D_s|²|D_p|² (no special
// functions): the vectors fuse multiply-adds where the scalar code may not, so they agree to
// 16 float ulps of 1 (entries lie in [−1, 1]; a handful of roundings in each product, doubled by
// the division). Within 1e-3 of the critical angle (in sin²θt) the refracted cosine's square-root
// singularity turns 4 ulp of sin²θt into √(4 · 2^-24) ≈ 5e-4 of cos θt, which every entry that
// depends on it inherits times its slope (≤ 4): 2e-3 there; farther away the same 4 ulp of
// δ = |1 − sin²θt| move cos θt = √δ by 4 ulp/(2√δ), again times a slope ≤ 4.
double mueller_lane_bound(double delta) {
    return 16 * 0x1p-24 + 4 * (4 * 0x1p-24) / (2 * std::sqrt(delta));
}
// A thin film's reflection on the lanes (simulator/lane_film.h: the Airy sums of
// physics/thin_film_airy.h on vectors of doubles) against FilmOptics::reflection_from_above on
// one lane, each entry's film its own as a spectral run's lanes have them. Both are double
// evaluations (their difference is ~1e-13 of the entries, the vector's exp, cos and sin within
// 3 ulp), each rounded to float once: they agree to one float ulp of entries in [−1, 1], 2^-24.
// The lanes the vectors leave to FilmOptics near the film's critical angle, where FilmOptics
// averages two sums, equal it exactly; each such case is put in every lane of a vector, so the
// routing of every lane is seen: a thick film near its critical angle (averaged and direct sums
// differ there by ~3e-6, far more than an ulp) and a film index-matched to the medium above at
// grazing (u2 = 0). An exit matched to the medium above at grazing (u3 = 0, where the vector's
// square root may be 0/0 and the lane is then left to FilmOptics too) is held to the ulp.
TEST(KernelSimd, FilmReflectionLanes) {
    using C = std::complex<double>;
    auto film = [](C eta_film, double above, C below0, C below1, C below2) {
        FilmOptics f;
        f.eta_film = eta_film;
        f.eta_above = above;
        f.eta_below[0] = below0;
        f.eta_below[1] = below1;
        f.eta_below[2] = below2;
        f.wavelength_nm[0] = 630;
        f.wavelength_nm[1] = 532;
        f.wavelength_nm[2] = 465;
        return f;
    };
    const std::vector<FilmOptics> films = {
        // An oxide of 2.5 on titanium under a coat of 1.5.
        film(C(2.5), 1.5, C(2.74, 3.79), C(2.54, 3.43), C(2.26, 3.0)),
        // MgF2 on aluminium in air.
        film(C(1.38), 1.0, C(1.2, 7.26), C(0.96, 6.69), C(0.65, 5.6)),
        // An absorbing oxide on iron under a coat.
        film(C(2.3, 0.1), 1.5, C(2.9, 2.9), C(2.8, 2.9), C(2.6, 2.8)),
        // A film of 1.2 under a coat of 1.5: its critical angle at sin²θ = 0.64.
        film(C(1.2), 1.5, C(0.2, 3.0), C(0.5, 2.3), C(1.2, 1.9)),
        // A film index-matched to the medium above, on gold: at grazing u2 = 0.
        film(C(1.0), 1.0, C(0.18, 3.4), C(0.5, 2.2), C(1.3, 1.8)),
        // A film of 4 under a coat of 5 (its critical angle at sin²θ = 0.64) over 4 + 0.5i.
        film(C(4.0), 5.0, C(4.0, 0.5), C(4.0, 0.5), C(4.0, 0.5)),
        // An exit of index 1, k = 0, under a film in air: at grazing u3 = 0.
        film(C(1.5), 1.0, C(1.0), C(1.0), C(1.0)),
    };
    constexpr std::size_t kVector = 16;  // a multiple of every instruction set's float lanes
    ParticleRng rng(23, 0, 0);
    std::vector<float> cos_theta;
    std::vector<const FilmOptics*> lane_films;
    std::vector<double> thickness;
    std::vector<char> routed;  // left to FilmOptics: equal to it exactly
    for (std::size_t j = 0; j < 6000; ++j) {
        cos_theta.push_back(j < 3 ? float(j) / 2 : rng.uniform_float());
        lane_films.push_back(&films[(j * 7 + j / 5) % 5]);
        thickness.push_back(j % 11 == 0 ? 0.0 : 800.0 * double(rng.uniform_float()));
        routed.push_back(0);
    }
    auto every_lane = [&](const FilmOptics& f, float cos_i, double d, bool exact) {
        for (std::size_t l = 0; l < kVector; ++l) {
            cos_theta.push_back(cos_i);
            lane_films.push_back(&f);
            thickness.push_back(d);
            routed.push_back(exact ? 1 : 0);
        }
    };
    // cos² − 0.36 within 1.5e-6 of 0: all within twice FilmOptics' band of 1e-6, some inside it.
    for (int k = -20; k <= 20; k += 4) {
        float c = 0.6f;
        for (int i = 0; i < std::abs(k); ++i)
            c = std::nextafter(c, k < 0 ? 0.f : 1.f);
        every_lane(films[5], c, 10000, true);
    }
    every_lane(films[4], 0.f, 300, true);
    every_lane(films[6], 0.f, 300, false);
    // Every other lane skipped in a second pass: the skipped lanes keep the identity.
    for (const std::uint64_t skip : {std::uint64_t(0), std::uint64_t(0xAAAAAAAAAAAAAAAA)}) {
        std::size_t n_lanes = 0;
        const std::vector<float> lanes =
            simd_film_reflection(lane_films, cos_theta, thickness, skip, n_lanes);
        ASSERT_EQ(kVector % n_lanes, 0u);
        double worst = 0;
        for (std::size_t j = 0; j < cos_theta.size(); ++j) {
            const float* e = &lanes[15 * j];
            if ((skip >> (j % n_lanes) & 1) != 0) {
                for (int c = 0; c < 3; ++c) {
                    EXPECT_EQ(e[4 * c], 1.f);
                    EXPECT_EQ(e[4 * c + 1], 0.f);
                    EXPECT_EQ(e[4 * c + 2], 1.f);
                    EXPECT_EQ(e[4 * c + 3], 0.f);
                    EXPECT_EQ(e[12 + c], 1.f);
                }
                continue;
            }
            const auto m = lane_films[j]->reflection_from_above(double(cos_theta[j]), thickness[j]);
            for (int c = 0; c < 3; ++c) {
                const float scalar[4] = {float(m[std::size_t(c)].a), float(m[std::size_t(c)].b),
                                         float(m[std::size_t(c)].c), float(m[std::size_t(c)].d)};
                for (int k = 0; k < 4; ++k) {
                    ASSERT_TRUE(std::isfinite(e[4 * c + k])) << j;
                    if (routed[j])
                        EXPECT_EQ(e[4 * c + k], scalar[k])
                            << "entry " << j << ", lane " << j % n_lanes << ", cos "
                            << cos_theta[j];
                    else
                        worst = std::max(worst, std::abs(double(e[4 * c + k]) - scalar[k]));
                }
                EXPECT_EQ(e[12 + c], e[4 * c]) << j;  // the unpolarized factor is a
            }
        }
        EXPECT_LE(worst, 0x1p-24) << simd_target_name();
    }
}

TEST(KernelSimd, FresnelMuellerLanes) {
    ParticleRng rng(21, 0, 0);
    for (const float eta : {1.5f, 1 / 1.5f, 1.f, 2.4f}) {
        std::vector<float> cos_theta = {0.f, -0.f, 1.f, -1.f, 1e-7f, -1e-7f, 0.5f, -0.5f};
        const float critical = std::sqrt(std::max(0.f, 1 - eta * eta));
        for (const float d : {-1e-6f, 0.f, 1e-6f})
            cos_theta.insert(cos_theta.end(), {critical + d, -critical - d});
        for (int k = 0; k < 4000; ++k)
            cos_theta.push_back(2 * rng.uniform_float() - 1);
        const std::vector<float> lanes = simd_fresnel_mueller(0, cos_theta, eta, 0);
        double worst = 0, worst_critical = 0;
        for (std::size_t j = 0; j < cos_theta.size(); ++j) {
            const DielectricMueller<float> m =
                fresnel_dielectric_mueller(cos_theta[j], eta, 1 / eta);
            const float scalar[9] = {m.reflection.a,   m.reflection.b,   m.reflection.c,
                                     m.reflection.d,   m.transmission.a, m.transmission.b,
                                     m.transmission.c, m.transmission.d, m.cos_theta_t};
            const double mu = std::abs(double(cos_theta[j]));
            const double crossed = cos_theta[j] < 0 ? 1 / double(eta) : double(eta);
            const double delta = std::abs(1 - (1 - mu * mu) / (crossed * crossed));
            const bool near_critical = delta < 1e-3;
            for (int e = 0; e < 9; ++e) {
                ASSERT_TRUE(std::isfinite(lanes[9 * j + e])) << cos_theta[j];
                const double d = std::abs(double(lanes[9 * j + e]) - scalar[e]);
                if (near_critical)
                    worst_critical = std::max(worst_critical, d);
                else
                    worst = std::max(worst, d / mueller_lane_bound(delta));
            }
        }
        EXPECT_LE(worst, 1.0) << "η " << eta << " on " << simd_target_name();  // of the bound
        EXPECT_LE(worst_critical, 2e-3) << "η " << eta << " on " << simd_target_name();
    }
    struct Index {
        float eta, k;
    };
    for (const Index ik :
         {Index{0.143f, 3.983f}, Index{2.9f, 3.1f}, Index{1.5f, 0.01f}, Index{1 / 1.5f, 0.f}}) {
        std::vector<float> cos_theta = {0.f, 1.f, 1e-7f, 0.5f, 1 - 1e-7f};
        for (int j = 0; j < 4000; ++j)
            cos_theta.push_back(rng.uniform_float());
        const std::vector<float> lanes = simd_fresnel_mueller(1, cos_theta, ik.eta, ik.k);
        double worst = 0;
        for (std::size_t j = 0; j < cos_theta.size(); ++j) {
            const InterfaceMueller<float> m = fresnel_conductor_mueller(cos_theta[j], ik.eta, ik.k);
            const float scalar[4] = {m.a, m.b, m.c, m.d};
            const double mu = double(cos_theta[j]);
            // Without absorption (k = 0) the root u = √(η² − sin²θ) has the critical angle's
            // singularity as a dielectric's; absorption keeps u away from 0.
            const double delta =
                ik.k == 0 ? std::abs(1 - (1 - mu * mu) / (double(ik.eta) * ik.eta)) : 1.0;
            for (int e = 0; e < 4; ++e) {
                ASSERT_TRUE(std::isfinite(lanes[4 * j + e])) << cos_theta[j];
                if (delta >= 1e-3)
                    worst = std::max(worst, std::abs(double(lanes[4 * j + e]) - scalar[e]) /
                                                mueller_lane_bound(delta));
            }
        }
        EXPECT_LE(worst, 1.0)  // of the bound
            << "η " << ik.eta << " k " << ik.k << " on " << simd_target_name();
    }
}

// The lane test of Henyey–Greenstein (physics/phase.h hg_phase and sample_hg_cos_theta, one
// template each): on the dispatched instruction set's vectors against the scalar float
// instantiation, for g from −0.99 to 0.99 with the isotropic edge (|g| < 1e-3, g = 0) and random
// cosines and uniforms including their ends. The phase value: its denominator 1 + g² − 2g cos θ
// cancels (down to (1 − |g|)² = 1e-4 for g = 0.99 in the forward direction), so rounding — fused
// multiply-adds on one side and not the other — is amplified by κ = (1 + g² + 2|g cos θ|)/denom,
// and p ∝ denom^{−3/2} by 3/2 of it: relative error ≤ (1 + 1.5 κ) · 8 ulp. The sampled cosine:
// hg_cos_tolerance's first-order bound (support/simd_probes.h: s is computed without cancellation,
// but (1 + g² − s²)/(2g) cancels by 1/|g| as g → 0).
TEST(KernelSimd, HenyeyGreensteinLanes) {
    ParticleRng rng(20, 0, 0);
    std::vector<float> g, x;
    for (const float gi : {0.f, 1e-4f, -5e-4f, 1e-3f, -1.5e-3f, 0.3f, -0.5f, 0.9f, -0.99f, 0.99f}) {
        for (const float xi : {0.f, 1 - 0x1p-24f, 0.5f, -1.f, 1.f})
            g.push_back(gi), x.push_back(xi);
        for (int k = 0; k < 500; ++k)
            g.push_back(gi), x.push_back(rng.uniform_float());
    }
    std::vector<float> phase, cos_theta;
    simd_henyey_greenstein(g, x, phase, cos_theta);
    double worst_phase = 0, worst_cos = 0;
    for (std::size_t j = 0; j < g.size(); ++j) {
        const float p = hg_phase(x[j], g[j]), c = sample_hg_cos_theta(g[j], x[j]);
        ASSERT_TRUE(std::isfinite(phase[j]) && std::isfinite(cos_theta[j])) << g[j] << ' ' << x[j];
        const double gd = g[j], xd = x[j];
        const double denom = 1 + gd * gd - 2 * gd * xd;
        const double kappa = (1 + gd * gd + 2 * std::abs(gd * xd)) / denom;
        worst_phase = std::max(
            worst_phase, std::abs(double(phase[j]) / p - 1) / ((1 + 1.5 * kappa) * 8 * 0x1p-24));
        worst_cos =
            std::max(worst_cos, std::abs(double(cos_theta[j]) - c) / hg_cos_tolerance(g[j], x[j]));
    }
    EXPECT_LE(worst_phase, 1.0) << simd_target_name();  // in units of the bound
    EXPECT_LE(worst_cos, 1.0) << simd_target_name();
}

// The lane test of the walk's GGX pieces (physics/microfacet.h ggx_lambda and
// ggx_sample_visible_normal_complete, one template each): on the dispatched instruction set's
// vectors against the scalar float instantiation (GGX<float>::lambda and
// sample_visible_normal_complete, which call them), for α from 1e-3 to 1, random directions on
// both hemispheres and the edges (both normals, grazing at cos θ = 1e-3 and exactly, both sides),
// uniforms including 0 and 1 − 2^-24. Λ: a square root and two divisions, ≤ 1 ulp each on both, so
// within 8 float ulps relative; ∞ exactly where the scalar one is (grazing). The normal: two
// normalizations by the refined reciprocal square root (2^-22 relative each) against the exact
// one, the Cephes azimuth (≤ 2 ulp) against the C library's, fused multiply-adds: within 4e-6 per
// component, plus 2^-23 / sin θ from the cap point's sin θ = √(1 − z²) (a 2-ulp difference in
// 1 − z², grown near the cap's pole), plus the cancellation of h.z at the cap's rim (below). Where
// the cap of visible normals shrinks to a point (w below the horizon with 1 + wh.z < 0.1, wh: w in
// the hemisphere configuration) the halfway vector h = c + wh cancels and the float construction
// itself, scalar and vector alike, loses its digits (at α = 10^-3 nothing is left): there only a
// finite unit normal in the upper hemisphere is required, and the difference is printed.
TEST(KernelSimd, GgxLanes) {
    ParticleRng rng(22, 0, 0);
    for (const float alpha : {1e-3f, 0.05f, 0.3f, 1.f}) {
        std::vector<float> w = {0,     0,          1, 0,      0, -1, 0.9999995f, 0,
                                1e-3f, 0.9999995f, 0, -1e-3f, 1, 0,  0};
        std::vector<float> u1 = {0.f, 0.5f, 1 - 0x1p-24f, 0.25f, 0.75f};
        std::vector<float> u2 = {0.f, 1 - 0x1p-24f, 0.5f, 0.f, 0.3f};
        for (int k = 0; k < 4000; ++k) {
            const float z = 2 * rng.uniform_float() - 1;
            const float phi = 2 * kPi<float> * rng.uniform_float();
            const float r = std::sqrt(std::max(0.f, 1 - z * z));
            w.insert(w.end(), {r * std::cos(phi), r * std::sin(phi), z});
            u1.push_back(rng.uniform_float());
            u2.push_back(rng.uniform_float());
        }
        std::vector<float> lambda, wm;
        simd_ggx_lanes(alpha, w, u1, u2, lambda, wm);
        const GGX<float> ggx{alpha};
        double worst_lambda = 0, worst_wm = 0, worst_wm_horizon = 0;
        for (std::size_t j = 0; j < u1.size(); ++j) {
            const Vec3f wj(w[3 * j], w[3 * j + 1], w[3 * j + 2]);
            const float l_scalar = ggx.lambda(wj);
            if (std::isinf(l_scalar)) {
                EXPECT_TRUE(std::isinf(lambda[j])) << alpha << ' ' << j;
            } else {
                ASSERT_TRUE(std::isfinite(lambda[j])) << alpha << ' ' << j;
                worst_lambda =
                    std::max(worst_lambda, std::abs(double(lambda[j]) - l_scalar) /
                                               std::max(double(l_scalar), 1e-30) / 0x1p-24);
            }
            const Vec3f m = ggx.sample_visible_normal_complete(wj, u1[j], u2[j]);
            // Straight down (w = −z) no facet is visible (A(w) = |cos θ| Λ = 0): outside the
            // sampler's domain, NaN on both (the walk never asks: such a ray escapes first).
            if (wj.z == -1) continue;
            const float m_scalar[3] = {m.x, m.y, m.z};
            // The cap's extent 1 + wh.z (wh: w in the hemisphere configuration, in double).
            const double ax = double(alpha) * wj.x, ay = double(alpha) * wj.y;
            const double extent = 1 + wj.z / std::sqrt(ax * ax + ay * ay + double(wj.z) * wj.z);
            const bool near_horizon = extent < 0.1;
            // sin θ = √(1 − z²) of the cap point: a rounding of 2 ulp in 1 − z² moves it by
            // 2^-23 / sin θ, unbounded at the cap's pole (z → 1, u2 → 0).
            const double z_cap = (1 - double(u2[j])) * extent - (extent - 1);
            const double sin_cap = std::sqrt(std::max(1 - z_cap * z_cap, 1e-12));
            // Near the cap's rim (u2 → 1) the halfway vector h' = (α h.x, α h.y, h.z) is short:
            // the rounding of the cap point (2^-24 |z| on either side; the sampler takes h.z as
            // (1 − u2)(1 + wh.z), without the cancelling z + wh.z) and the vector's 2^-22 in h.x,
            // h.y stay absolute, and the final normalization divides them by |h'| — in exact
            // arithmetic, from double here.
            const double whz = double(wj.z) / std::sqrt(ax * ax + ay * ay + double(wj.z) * wj.z);
            const double phi_cap = 2 * kPi<double> * double(u1[j]);
            const double hz = (1 - double(u2[j])) * (1 + whz),
                         hx = double(alpha) *
                              (sin_cap * std::cos(phi_cap) +
                               ax / std::sqrt(ax * ax + ay * ay + double(wj.z) * wj.z)),
                         hy = double(alpha) *
                              (sin_cap * std::sin(phi_cap) +
                               ay / std::sqrt(ax * ax + ay * ay + double(wj.z) * wj.z));
            const double h_norm = std::sqrt(hx * hx + hy * hy + hz * hz);
            const double cancellation =
                (0x1p-23 * (std::abs(z_cap) + hz) + double(alpha) * 0x1p-21) / h_norm;
            const double tolerance = 4e-6 + 0x1p-23 / sin_cap + cancellation;
            double norm2 = 0;
            for (int i = 0; i < 3; ++i) {
                ASSERT_TRUE(std::isfinite(wm[3 * j + i])) << alpha << ' ' << j;
                norm2 += double(wm[3 * j + i]) * wm[3 * j + i];
                const double d = std::abs(double(wm[3 * j + i]) - m_scalar[i]);
                if (near_horizon)
                    worst_wm_horizon = std::max(worst_wm_horizon, d);
                else
                    worst_wm = std::max(worst_wm, d / tolerance);
            }
            EXPECT_NEAR(norm2, 1.0, 1e-5) << alpha << ' ' << j;  // a unit normal everywhere
            EXPECT_GE(wm[3 * j + 2], 0.f) << alpha << ' ' << j;  // in the upper hemisphere
        }
        EXPECT_LE(worst_lambda, 8.0) << "α " << alpha << " on " << simd_target_name();
        EXPECT_LE(worst_wm, 1.0) << "α " << alpha << " on " << simd_target_name();
        std::printf(
            "[ lanes    ] %s α %g: Λ ≤ %.2g ulp, |Δwm| ≤ %.2g of its bound (%.2g where "
            "1 + wh.z < 0.1)\n",
            simd_target_name(), alpha, worst_lambda, worst_wm, worst_wm_horizon);
    }
}

// The lane test of the microsurface walk (physics/microsurface_walk.h microsurface_walk, one
// template): on the dispatched instruction set's vectors (ctest runs this on every compiled set
// through LAMINA_SIMD_TARGET) against the scalar instantiation the scalar kernel runs, particle by
// particle from the same random numbers (ParticleRng(seed, 0, p); a lane draws the scalar walk's
// sequence while it walks, whatever the other lanes do). Rough dielectrics from both sides (η
// above and below 1, α from 0.01 to 1), rough conductors (gold-like, k = 0 with η < 1: total
// reflection), random directions and the edges: normal incidence, grazing (cos θ = 1e-3), exactly
// grazing and, for a conductor, from below (both degenerate), and a facet cap of 2 besides 100.
// The two evaluate the same operations but round differently (Highway's log, exp and log1p ≤ 4
// ulp, the refined reciprocal square root 2^-22, the Cephes azimuth ≤ 2 ulp, fused multiply-adds):
// a walk's discrete choices (escape, Fresnel reflection, the cap) flip only where a uniform number
// lies within ~1e-6 of its threshold, a few times in 10^5 walks of a few facets, so at most 1 in
// 10^3 walks may end differently (a different formula or draw order would change most); walks
// that end alike have equal facet counts and leave along directions, with Fresnel weights, that
// differ by a few 1e-7 per facet except near a facet's critical angle: there the refracted cosine
// and the Fresnel factor have square-root singularities, cos θt = √(1 − sin²θt), and a rounding
// difference of 4 ulp in sin²θt becomes √(4 · 2^-24) ≈ 5e-4 (as the Fresnel lane test notes), so
// directions agree within 1e-3 absolute and weights within 1e-3 relative.
TEST(KernelSimd, MicrosurfaceWalkLanes) {
    struct Case {
        bool dielectric;
        float alpha, eta[3], k[3];
        int max_order;
    };
    const Case cases[] = {
        {true, 0.3f, {1.5f, 1.5f, 1.5f}, {0, 0, 0}, 100},
        {true, 1.0f, {1.5f, 1.5f, 1.5f}, {0, 0, 0}, 100},
        {true, 0.6f, {1 / 1.5f, 1 / 1.5f, 1 / 1.5f}, {0, 0, 0}, 100},
        {true, 0.01f, {1.33f, 1.33f, 1.33f}, {0, 0, 0}, 100},
        {true, 0.9f, {1.5f, 1.5f, 1.5f}, {0, 0, 0}, 2},
        {false, 0.5f, {0.143f, 0.374f, 1.44f}, {3.98f, 2.38f, 1.80f}, 100},
        {false, 1.0f, {1 / 1.5f, 1 / 1.5f, 1 / 1.5f}, {0, 0, 0}, 100},
        {false, 0.8f, {2.9f, 2.9f, 2.9f}, {3.1f, 3.1f, 3.1f}, 2},
    };
    ParticleRng dir_rng(21, 0, 0);
    int case_index = 0;
    for (const Case& cs : cases) {
        SCOPED_TRACE("case " + std::to_string(case_index));
        const std::uint64_t seed = 1000 + std::uint64_t(case_index++);
        std::vector<float> wi = {0, 0, 1, 0.9999995f, 0, 1e-3f, 1, 0, 0, 0, 0, -1};
        const int n = 20000;
        for (int p = 0; p < n; ++p) {
            const float z =
                cs.dielectric ? 2 * dir_rng.uniform_float() - 1 : dir_rng.uniform_float();
            const float phi = 2 * kPi<float> * dir_rng.uniform_float();
            const float r = std::sqrt(std::max(0.f, 1 - z * z));
            wi.insert(wi.end(), {r * std::cos(phi), r * std::sin(phi), z});
        }
        const std::size_t count = wi.size() / 3;
        const SimdWalkResult lanes =
            simd_microsurface_walk(wi, cs.alpha, cs.dielectric, cs.eta, cs.k, cs.max_order, seed);
        const GGX<float> ggx{cs.alpha};
        std::size_t differ = 0, escaped = 0, capped = 0, degenerate = 0;
        double worst_wo = 0, worst_weight = 0;
        for (std::size_t p = 0; p < count; ++p) {
            ParticleRng rng(seed, 0, p);
            auto uniform = [&] { return rng.uniform_float(); };
            const Vec3f w(wi[3 * p], wi[3 * p + 1], wi[3 * p + 2]);
            const std::optional<MicrosurfaceExit<float>> scalar =
                cs.dielectric ? walk_rough_dielectric(ggx, cs.eta[0], w, uniform, cs.max_order)
                              : walk_rough_conductor(
                                    ggx,
                                    [&](float c) {
                                        return Rgbf(fresnel_conductor(c, cs.eta[0], cs.k[0]),
                                                    fresnel_conductor(c, cs.eta[1], cs.k[1]),
                                                    fresnel_conductor(c, cs.eta[2], cs.k[2]));
                                    },
                                    w, uniform, cs.max_order);
            const int outcome = !scalar ? 2 : scalar->escaped ? 0 : 1;
            if (p < 4) {  // the edges: the degenerate arrivals must be degenerate on both
                const bool must_degenerate = w.z == 0 || (!cs.dielectric && w.z < 0);
                if (must_degenerate) {
                    EXPECT_EQ(outcome, 2) << "edge " << p;
                    EXPECT_EQ(lanes.outcome[p], 2) << "edge " << p;
                }
            }
            (outcome == 0 ? escaped : outcome == 1 ? capped : degenerate) += 1;
            if (outcome != lanes.outcome[p] || (scalar && scalar->order != lanes.order[p])) {
                ++differ;
                continue;
            }
            if (outcome != 0) continue;
            const float wo_scalar[3] = {scalar->wo.x, scalar->wo.y, scalar->wo.z};
            for (int i = 0; i < 3; ++i) {
                ASSERT_TRUE(std::isfinite(lanes.wo[3 * p + i]) &&
                            std::isfinite(lanes.weight[3 * p + i]))
                    << p;
                worst_wo = std::max(worst_wo,
                                    std::abs(double(lanes.wo[3 * p + i]) - double(wo_scalar[i])));
                const double ws = scalar->weight[i];
                if (ws > 0)
                    worst_weight =
                        std::max(worst_weight, std::abs(lanes.weight[3 * p + i] / ws - 1));
            }
        }
        EXPECT_LE(double(differ), 1e-3 * double(count))
            << differ << " of " << count << " walks end differently on " << simd_target_name();
        EXPECT_LE(worst_wo, 1e-3) << simd_target_name();
        EXPECT_LE(worst_weight, 1e-3) << simd_target_name();
        if (cs.max_order == 2) {
            EXPECT_GT(capped, 0u);  // the cap is exercised
        }
        std::printf(
            "[ lanes    ] %s case %d: %zu escaped, %zu capped, %zu degenerate; %zu differ, "
            "|Δwo| ≤ %.2g, |Δweight| ≤ %.2g\n",
            simd_target_name(), case_index - 1, escaped, capped, degenerate, differ, worst_wo,
            worst_weight);
    }
}

// The vectors' 1/√x is the scalar one bit for bit, 1/√x of a correctly rounded square root and
// division, on random x over 2^-60 to 2^60 and at the ends of the float range: no hardware
// estimate, whose bits differ between CPU vendors, so one instruction set traces the same tables
// on every CPU.
TEST(KernelSimd, InverseSquareRootIsCorrectlyRounded) {
    ParticleRng rng(29, 0, 0);
    std::vector<float> x = {1.f,
                            2.f,
                            0.25f,
                            std::numeric_limits<float>::min(),
                            std::numeric_limits<float>::denorm_min(),
                            std::numeric_limits<float>::max()};
    for (int j = 0; j < 20000; ++j)
        x.push_back(std::exp2(120 * rng.uniform_float() - 60) * (1 + rng.uniform_float()));
    const std::vector<float> y = simd_inv_sqrt(x);
    for (std::size_t j = 0; j < x.size(); ++j)
        ASSERT_EQ(y[j], 1.f / std::sqrt(x[j])) << "x = " << x[j] << " on " << simd_target_name();
}

// cos and sin of 2πu against double precision for every 2^-18 step of u and around every octant
// boundary, within 2 float ulps of 1.
TEST(KernelSimd, AzimuthCosineAndSine) {
    std::vector<float> u;
    for (int i = 0; i < (1 << 18); ++i)
        u.push_back(float(i) * 0x1p-18f);
    for (int j = 1; j < 8; ++j)
        for (int d = -4; d <= 4; ++d)
            u.push_back(float(j) * 0.125f + float(d) * 0x1p-24f);
    u.push_back(1.f - 0x1p-24f);
    std::vector<float> c, s;
    simd_cos_sin_2pi(u, c, s);
    double worst = 0;
    for (std::size_t i = 0; i < u.size(); ++i) {
        const double phi = 2 * M_PI * double(u[i]);
        worst = std::max(worst, std::abs(double(c[i]) - std::cos(phi)));
        worst = std::max(worst, std::abs(double(s[i]) - std::sin(phi)));
    }
    EXPECT_LT(worst, 2 * 0x1p-24) << "largest error";
}

// Two-sample chi-square: the scalar and SIMD kernels, with different seeds, tabulate the same
// distribution. Per bin and channel z = (f_a − f_b)/√(se_a² + se_b²) is standard normal when both
// come from the same distribution (central limit: bins with at least ~100 expected exits); Σ z²
// over the bins of one channel is χ² with as many degrees of freedom. Each channel is one test at
// the Šidák-corrected level of the suite (1 % overall for the 117 channel tests below). The bins
// are those of the run's grid (the unfolded one for an anisotropic stack or light from φi ≠ 0).
constexpr int kTwoSampleTests = 117;

// One test of a suite of n_tests: Σ z² = chi2 over dof bins against χ²(dof) at the Šidák level
// 1 − 0.99^(1/n_tests).
void expect_chi2_consistent(double chi2, int dof, int n_tests, const std::string& where) {
    ASSERT_GE(dof, 10) << "too few populated bins to test: " << where;
    const double level = 1 - std::pow(1 - 0.01, 1.0 / n_tests);
    EXPECT_GE(test::gamma_q(dof / 2.0, chi2 / 2.0), level)
        << where << ": χ² = " << chi2 << " for " << dof << " bins";
}

// `scalar_tweak` adjusts the scalar run's settings (the SIMD run keeps the defaults);
// `both_tweak` those of both runs.
void expect_same_distribution(const Stack& stack, std::vector<double> theta_i,
                              std::uint64_t particles,
                              const std::function<void(SimulationSettings&)>& scalar_tweak = {},
                              const std::function<void(SimulationSettings&)>& both_tweak = {}) {
    SimulationSettings s;
    s.theta_i_deg = std::move(theta_i);
    s.particles = particles;
    s.grid = HemisphereGrid(18, 18);
    s.kernel = Kernel::Scalar;
    s.seed = 11;
    apply_physics(ReferencePhysics::Bpb19, s.transport);  // the tweaks name what they add
    if (both_tweak) both_tweak(s);
    SimulationSettings scalar = s;
    if (scalar_tweak) scalar_tweak(scalar);
    const SimulationResult a = simulate(stack, scalar);
    s.kernel = Kernel::Simd;
    s.seed = 12;
    const SimulationResult b = simulate(stack, s);
    const HemisphereGrid& grid = a.table.grid;
    ASSERT_EQ(grid, b.table.grid);
    ASSERT_EQ(grid, simulation_grid(stack, s));
    for (std::size_t inc = 0; inc < s.theta_i_deg.size(); ++inc) {
        for (const Side side : {Side::Reflection, Side::Transmission}) {
            if (side == Side::Transmission && !a.table.has_transmission) continue;
            const BinnedLobe& la = a.table.lobe(inc, side);
            const BinnedLobe& lb = b.table.lobe(inc, side);
            for (int c = 0; c < 3; ++c) {
                double chi2 = 0;
                int dof = 0;
                for (std::size_t j = 0; j < grid.size(); ++j) {
                    // Expected exits ≈ N · f · Ω⊥ (flux fraction, weights of order one).
                    const double exits =
                        double(particles) * la.f[j][c] * grid.projected_solid_angle(j);
                    if (exits < 100) continue;
                    const double se2 = la.se[j][c] * la.se[j][c] + lb.se[j][c] * lb.se[j][c];
                    ASSERT_GT(se2, 0);
                    chi2 += (la.f[j][c] - lb.f[j][c]) * (la.f[j][c] - lb.f[j][c]) / se2;
                    ++dof;
                }
                expect_chi2_consistent(chi2, dof, kTwoSampleTests,
                                       fmt::format("θi {}° φi {}° side {} channel {}",
                                                   s.theta_i_deg[inc], s.phi_i_deg, int(side), c));
            }
            // The budgets too, within 5 combined standard errors.
            const EnergyBudget& ba = a.incidences[inc].budget;
            const EnergyBudget& bb = b.incidences[inc].budget;
            for (int c = 0; c < 3; ++c) {
                const double r_se = std::hypot(ba.reflected_se[c], bb.reflected_se[c]);
                EXPECT_LT(std::abs(ba[BudgetTerm::Reflected][c] - bb[BudgetTerm::Reflected][c]),
                          5 * r_se + 1e-12);
                const double t_se = std::hypot(ba.transmitted_se[c], bb.transmitted_se[c]);
                EXPECT_LT(std::abs(ba[BudgetTerm::Transmitted][c] - bb[BudgetTerm::Transmitted][c]),
                          5 * t_se + 1e-12);
            }
        }
    }
}

TEST(KernelSimdStat, SameTablesAsScalarPlastic) {
    // The benchmark plastic: rough coat, absorbing medium, Lambertian base.
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.1, 0.0, 0.9)),
                          test::lambertian_layer(Rgbd(0.8, 0.5, 1.0))}),
        {0, 60}, 1'000'000);
}

TEST(KernelSimdStat, SameTablesAsScalarMetallicPaint) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.05), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.3)}),
        {30, 75}, 1'000'000);
}

TEST(KernelSimdStat, SameTablesAsScalarRoughSlab) {
    // Reflection and transmission, total internal reflection inside.
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.3), Rgbd(0.1, 0.0, 0.9)),
                          test::dielectric_layer(1.0, 0.5)}),
        {10, 70}, 1'000'000);
}

// The microsurface walk cut after its first facet (scalar kernel) and the single-scattering
// interface with the default, Smith, refraction masking (SIMD kernel) are one BSDF
// (physics/microsurface_walk.h derives it): a very rough slab at grazing incidence, where the
// Smith and pbrt forms of the refraction masking differ by a third of the transmitted energy.
TEST(KernelSimdStat, WalkFirstOrderIsTheSmithMaskedInterface) {
    expect_same_distribution(test::make_stack({test::dielectric_layer(1.5, 0.7)}), {75}, 1'000'000,
                             [](SimulationSettings& s) {
                                 s.transport.microsurface = Microsurface::Multiple;
                                 s.transport.max_microsurface_order = 1;
                             });
}

// Multiple scattering on the microsurfaces (the walk, one template) on both kernels: the benchmark
// plastic, a very rough slab (reflection and transmission, walks from both sides, total internal
// reflection on facets inside) and a rough conductor under a rough coat (the conductor walk).
void multiple(SimulationSettings& s) {
    s.transport.microsurface = Microsurface::Multiple;
}

TEST(KernelSimdStat, SameTablesAsScalarMultiplePlastic) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.1, 0.0, 0.9)),
                          test::lambertian_layer(Rgbd(0.8, 0.5, 1.0))}),
        {0, 60}, 1'000'000, {}, multiple);
}

TEST(KernelSimdStat, SameTablesAsScalarMultipleRoughSlab) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.7), Rgbd(0.1, 0.0, 0.9)),
                          test::dielectric_layer(1.0, 0.5)}),
        {10, 70}, 1'000'000, {}, multiple);
}

TEST(KernelSimdStat, SameTablesAsScalarMultipleRoughConductor) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.3), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.8)}),
        {30, 75}, 1'000'000, {}, multiple);
}

TEST(KernelSimdStat, SameTablesAsScalarScatteringMediumSpectral) {
    // Per-channel extinction and anisotropy: the spectral MIS of free flights and phase functions.
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.3, 0.1), Rgbd(0.05, 0.2, 0.0),
                                            Rgbd(0.5, 1.5, 0.8), Rgbd(0.6, -0.2, 0.3)),
                          test::lambertian_layer(Rgbd(0.6))}),
        {45}, 400'000);
}

// Polarized transport (docs/physics.md §8) on both kernels: a rough slab with multiple scattering
// (one state for all channels, total internal reflection's retardance inside), a coloured rough
// conductor under a rough coat (one state per channel: the conductor's Mueller matrices per
// channel and the coat's reweighted branch choice) and a scattering medium (depolarizing HG
// events) over a rough slab.
void polarized_multiple(SimulationSettings& s) {
    s.transport.polarization = true;
    s.transport.microsurface = Microsurface::Multiple;
}
void polarized_single(SimulationSettings& s) {
    s.transport.polarization = true;
}

TEST(KernelSimdStat, SameTablesAsScalarPolarizedRoughSlab) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.1, 0.0, 0.9)),
                          test::dielectric_layer(1.0, 0.2)}),
        {10, 70}, 1'000'000, {}, polarized_multiple);
}

TEST(KernelSimdStat, SameTablesAsScalarPolarizedGoldUnderCoat) {
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.1), Rgbd(0.1)),
                          test::conductor_layer(Rgbd(0.2, 1.0, 1.45), Rgbd(3.0, 2.0, 0.01), 0.3)});
    expect_same_distribution(stack, {30, 75}, 1'000'000, {}, polarized_multiple);
    expect_same_distribution(stack, {50}, 1'000'000, {}, polarized_single);
}

TEST(KernelSimdStat, SameTablesAsScalarPolarizedScatteringMedium) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.3, 0.1), Rgbd(0.05, 0.2, 0.0),
                                            Rgbd(0.5, 1.5, 0.8), Rgbd(0.6, -0.2, 0.3)),
                          test::dielectric_layer(1.0, 0.05)}),
        {45}, 400'000, {}, polarized_single);
}

// ---- Anisotropic stacks and light from φi ≠ 0 (docs/physics.md §3, §5) -------------------------
// Both kernels take the general (anisotropic) instance of the GGX templates at every rough
// interface, each in its own tangent frame, and tabulate on the unfolded grid. Brushed metals
// (gold's indices: every channel reflects under the coat; α_x ≠ α_y) under a smooth and under a
// rough coat, the coat brushed too and turned against the base, a brushed rough slab (walks from
// both sides, transmission), polarized and not, single and multiple scattering on the
// microsurfaces, lit at φi = 0 and away from it.
Layer brushed_metal(double alpha_x, double alpha_y, double tangent_deg) {
    return layer_of(anisotropic(
        conductor_interface(Rgbd(0.143, 0.374, 1.442), Rgbd(3.983, 2.385, 1.603), alpha_x), alpha_x,
        alpha_y, tangent_deg));
}
Layer brushed_coat(double eta, double alpha_x, double alpha_y, double tangent_deg) {
    Layer coat = test::dielectric_layer(eta, alpha_x);
    coat.interface = anisotropic(coat.interface, alpha_x, alpha_y, tangent_deg);
    return coat;
}
std::function<void(SimulationSettings&)> lit_from(double phi_i_deg,
                                                  Microsurface microsurface = Microsurface::Single,
                                                  bool polarized = false) {
    return [=](SimulationSettings& s) {
        s.phi_i_deg = phi_i_deg;
        s.transport.microsurface = microsurface;
        s.transport.polarization = polarized;
    };
}

TEST(KernelSimdStat, SameTablesAsScalarBrushedUnderSmoothCoat) {
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.0), Rgbd(0.1)),
                          brushed_metal(0.08, 0.4, 30)});
    ASSERT_TRUE(stack.is_anisotropic());
    expect_same_distribution(stack, {30, 70}, 1'000'000, {}, lit_from(0));
    expect_same_distribution(stack, {50}, 1'000'000, {}, lit_from(130));
}

TEST(KernelSimdStat, SameTablesAsScalarBrushedUnderTurnedBrushedCoat) {
    const Stack stack =
        test::make_stack({test::with_medium(brushed_coat(1.5, 0.05, 0.25, 45), Rgbd(0.1)),
                          brushed_metal(0.35, 0.1, -20)});
    expect_same_distribution(stack, {40}, 1'000'000, {}, lit_from(0));
    expect_same_distribution(stack, {20, 65}, 1'000'000, {}, lit_from(250));
    expect_same_distribution(stack, {45}, 1'000'000, {}, lit_from(60, Microsurface::Multiple));
}

TEST(KernelSimdStat, SameTablesAsScalarBrushedRoughSlab) {
    // Reflection and transmission through two rough dielectrics, the upper one brushed.
    const Stack stack =
        test::make_stack({test::with_medium(brushed_coat(1.5, 0.5, 0.15, 70), Rgbd(0.1, 0.0, 0.9)),
                          test::dielectric_layer(1.0, 0.3)});
    expect_same_distribution(stack, {25}, 1'000'000, {}, lit_from(0));
    expect_same_distribution(stack, {60}, 1'000'000, {}, lit_from(30, Microsurface::Multiple));
}

TEST(KernelSimdStat, SameTablesAsScalarPolarizedBrushedUnderCoat) {
    // One polarization state per channel (the conductor's Mueller matrices per channel).
    const Stack stack =
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.1), Rgbd(0.1)),
                          brushed_metal(0.1, 0.45, 60)});
    expect_same_distribution(stack, {50}, 1'000'000, {}, lit_from(0, Microsurface::Single, true));
    expect_same_distribution(stack, {35}, 1'000'000, {}, lit_from(45, Microsurface::Single, true));
    expect_same_distribution(stack, {70}, 1'000'000, {},
                             lit_from(200, Microsurface::Multiple, true));
}

// An isotropic stack lit from φi ≠ 0 (the unfolded grid, the isotropic instance).
TEST(KernelSimdStat, SameTablesAsScalarIsotropicLitFromAnotherAzimuth) {
    expect_same_distribution(
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.2), Rgbd(0.1, 0.0, 0.9)),
                          test::lambertian_layer(Rgbd(0.8, 0.5, 1.0))}),
        {60}, 1'000'000, {}, lit_from(75));
}

// The SIMD kernel traced on 1 and 2 threads at θi = 0° and 55° (light from φi, 20,000 particles:
// five blocks): tables (both sides), budgets and, polarized, Stokes tallies bitwise identical.
// Returns the one-thread result and the settings it was traced with.
std::pair<SimulationResult, SimulationSettings> expect_same_for_1_and_2_threads(
    const Stack& stack, double phi_i_deg, bool polarized, Microsurface microsurface) {
    SimulationSettings s;
    s.theta_i_deg = {0, 55};
    s.phi_i_deg = phi_i_deg;
    s.particles = 20'000;
    s.grid = HemisphereGrid(18, 18);
    s.kernel = Kernel::Simd;
    s.transport.microsurface = microsurface;
    s.transport.polarization = polarized;
    s.stokes_tallies = polarized;
    s.threads = 1;
    SimulationResult one = simulate(stack, s);
    s.threads = 2;
    const SimulationResult two = simulate(stack, s);
    for (std::size_t i = 0; i < 2; ++i) {
        for (const Side side : {Side::Reflection, Side::Transmission}) {
            if (side == Side::Transmission && !one.table.has_transmission) continue;
            EXPECT_EQ(one.table.lobe(i, side).f, two.table.lobe(i, side).f);
            EXPECT_EQ(one.table.lobe(i, side).se, two.table.lobe(i, side).se);
        }
        EXPECT_EQ(one.incidences[i].budget.term, two.incidences[i].budget.term);
        if (polarized) {
            EXPECT_TRUE(one.sums[i].stokes == two.sums[i].stokes);
        }
    }
    return {std::move(one), s};
}

// Reproducibility on anisotropic stacks and light from φi ≠ 0: the SIMD kernel's tables, budgets
// and Stokes tallies are bitwise identical for 1 and 2 threads (a block's particles take the same
// lanes in the same order whatever thread traces it), polarized or not, with either microsurface
// model; another seed gives another table.
TEST(KernelSimd, AnisotropicTablesBitwiseIdenticalAcrossThreadCounts) {
    const std::vector<Stack> stacks = {
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.0), Rgbd(0.1)),
                          brushed_metal(0.08, 0.4, 30)}),
        test::make_stack({test::with_medium(brushed_coat(1.5, 0.05, 0.25, 45), Rgbd(0.1)),
                          brushed_metal(0.35, 0.1, -20)}),
        test::make_stack({test::with_medium(brushed_coat(1.5, 0.5, 0.15, 70), Rgbd(0.1)),
                          test::dielectric_layer(1.0, 0.3)}),
    };
    for (const Stack& stack : stacks)
        for (const bool polarized : {false, true})
            for (const Microsurface microsurface : {Microsurface::Single, Microsurface::Multiple}) {
                SCOPED_TRACE(::testing::Message()
                             << "polarized " << polarized << ' ' << enum_text(microsurface));
                auto [one, s] = expect_same_for_1_and_2_threads(stack, 35, polarized, microsurface);
                ASSERT_TRUE(one.table.grid.is_unfolded());
                s.seed = 8;
                const SimulationResult other = simulate(stack, s);
                EXPECT_NE(one.table.lobe(0, Side::Reflection).f,
                          other.table.lobe(0, Side::Reflection).f);
            }
}

// ---- Thin films on conductors (docs/physics.md §9) ----------------------------------------------
// The SIMD kernel traces a film on a conductor with the film's reflection (FilmOptics::mueller, in
// double, per lane) in place of the bare Fresnel terms; a film on a dielectric stays the scalar
// kernel's. An iridescent metal under a clear coat: an absorbing film whose thickness varies over
// the surface (one draw per event) on a rough gold, polarized with multiple scattering (the
// default reference) and unpolarized single scattering; a smooth filmed metal under a rough coat.
Layer with_conductor_film(Layer layer, double thickness_nm, double thickness_max_nm, double eta,
                          double k) {
    layer.interface.has_film = true;
    layer.interface.film.thickness_nm = thickness_nm;
    layer.interface.film.thickness_max_nm = thickness_max_nm;
    layer.interface.film.eta = eta;
    layer.interface.film.k = k;
    return layer;
}
Stack iridescent_gold(double alpha_metal) {
    return test::make_stack(
        {test::with_medium(test::dielectric_layer(1.5, 0.15), Rgbd(0.05)),
         with_conductor_film(test::conductor_layer(Rgbd(0.143, 0.374, 1.442),
                                                   Rgbd(3.983, 2.385, 1.603), alpha_metal),
                             90, 260, 2.3, 0.05)});
}

TEST(KernelSimdStat, SameTablesAsScalarFilmedConductorUnderCoat) {
    const Stack rough = iridescent_gold(0.3);
    ASSERT_TRUE(rough.has_film());
    expect_same_distribution(rough, {20, 65}, 1'000'000, {},
                             lit_from(0, Microsurface::Multiple, true));
    expect_same_distribution(rough, {45}, 1'000'000, {}, lit_from(0, Microsurface::Single, false));
    expect_same_distribution(iridescent_gold(0.0), {35}, 1'000'000, {},
                             lit_from(0, Microsurface::Single, true));
    expect_same_distribution(rough, {50}, 1'000'000, {},
                             lit_from(70, Microsurface::Multiple, false));
}

// Reproducibility with films on conductors: bitwise identical tables for 1 and 2 threads.
TEST(KernelSimd, FilmedConductorTablesBitwiseIdenticalAcrossThreadCounts) {
    for (const double alpha : {0.0, 0.3})
        for (const bool polarized : {false, true})
            for (const Microsurface microsurface : {Microsurface::Single, Microsurface::Multiple}) {
                SCOPED_TRACE(::testing::Message() << "α " << alpha << " polarized " << polarized
                                                  << ' ' << enum_text(microsurface));
                expect_same_for_1_and_2_threads(iridescent_gold(alpha), 0, polarized, microsurface);
            }
}

// ---- Spectral runs (docs/physics.md §10) --------------------------------------------------------
// The SIMD kernel traces a spectral particle's three wavelengths as the scalar kernel does, each
// lane gathering its stack's values; compared per wavelength bin by the two-sample chi-square
// test above (each wavelength bin and side of an incidence one test, Šidák-corrected to 1 % over
// the kSpectralTwoSampleTests below): a rough gold (measured indices) under a dispersive BK7 coat
// with a spectral absorption, polarized with multiple scattering (the default reference) and
// unpolarized single scattering; a plastic with a spectral albedo; an iridescent gold (a film of
// varying thickness) under a coat; a rough dispersive slab (transmission, total internal
// reflection); a milky coat (spectral absorption and scattering: free flights and HG events per
// lane) over a coloured Lambertian.
constexpr int kSpectralTwoSampleTests = 72;

const char* kSpectralGoldUnderBk7 = R"({"name": "gold under BK7", "layers": [
    {"interface": {"type": "dielectric", "eta": {"material": "BK7"}, "alpha": 0.15},
     "medium": {"tau_a": {"spectrum": [[360, 0.6], [550, 0.05], [830, 0.3]]}}},
    {"interface": {"type": "conductor", "material": "Au", "alpha": 0.3}}]})";
const char* kSpectralPlastic = R"({"name": "spectral plastic", "layers": [
    {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}, "medium": {"tau_a": 0.1}},
    {"interface": {"type": "lambertian",
                   "albedo": {"spectrum": [[360, 0.1], [500, 0.9], [830, 0.3]]}}}]})";
const char* kSpectralMilky = R"({"name": "spectral milky coat", "layers": [
    {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2},
     "medium": {"tau_a": {"spectrum": [[360, 0.4], [600, 0.05], [830, 0.2]]},
                "tau_s": {"spectrum": [[360, 2.0], [830, 0.5]]}, "g": 0.4}},
    {"interface": {"type": "lambertian",
                   "albedo": {"spectrum": [[360, 0.2], [830, 0.9]]}}}]})";
const char* kSpectralSlab = R"({"name": "BK7 slab", "layers": [
    {"interface": {"type": "dielectric", "eta": {"material": "BK7"}, "alpha": 0.4},
     "medium": {"tau_a": 0.05}},
    {"interface": {"type": "dielectric", "eta": 1.0, "alpha": 0.2}}]})";

void expect_same_spectral_distribution(const Stack& stack, std::vector<double> theta_i,
                                       std::uint64_t particles, bool exact) {
    SimulationSettings s;
    s.theta_i_deg = std::move(theta_i);
    s.particles = particles;
    s.grid = HemisphereGrid(18, 18);
    s.spectral = SpectralMode::On;
    s.spectral_bins = 6;
    s.kernel = Kernel::Scalar;
    s.seed = 11;
    apply_physics(exact ? ReferencePhysics::Exact : ReferencePhysics::Bpb19, s.transport);
    const SimulationResult a = simulate(stack, s);
    s.kernel = Kernel::Simd;
    s.seed = 12;
    const SimulationResult b = simulate(stack, s);
    const HemisphereGrid& grid = a.table.grid;
    const SpectralTables& sa = a.spectral;
    const SpectralTables& sb = b.spectral;
    ASSERT_EQ(sa.f.size(), sb.f.size());
    const std::size_t bins = sa.bin_edges_nm.size() - 1;
    // Particles per wavelength bin: each carries one wavelength of each third of the range.
    const double per_bin = double(particles) / double(bins / 3);
    for (std::size_t inc = 0; inc < s.theta_i_deg.size(); ++inc) {
        for (int side = 0; side < sa.sides; ++side)
            for (std::size_t l = 0; l < bins; ++l) {
                double chi2 = 0;
                int dof = 0;
                for (std::size_t j = 0; j < grid.size(); ++j) {
                    const std::size_t at = sa.index(inc, std::size_t(side), j, l);
                    if (per_bin * sa.f[at] * grid.projected_solid_angle(j) < 100) continue;
                    const double se2 = sa.se[at] * sa.se[at] + sb.se[at] * sb.se[at];
                    ASSERT_GT(se2, 0);
                    chi2 += (sa.f[at] - sb.f[at]) * (sa.f[at] - sb.f[at]) / se2;
                    ++dof;
                }
                expect_chi2_consistent(
                    chi2, dof, kSpectralTwoSampleTests,
                    fmt::format("θi {}° side {} wavelength bin {}", s.theta_i_deg[inc], side, l));
            }
        // The budgets per wavelength bin, within 5 combined standard errors.
        for (std::size_t l = 0; l < bins; ++l) {
            const auto& ba = sa.budget[inc * bins + l];
            const auto& bb = sb.budget[inc * bins + l];
            for (const auto& [term, se] : {std::pair{BudgetTerm::Reflected, kBudgetTerms},
                                           std::pair{BudgetTerm::Transmitted, kBudgetTerms + 1}}) {
                const double combined = std::hypot(ba[std::size_t(se)], bb[std::size_t(se)]);
                EXPECT_LT(std::abs(ba[std::size_t(term)] - bb[std::size_t(term)]),
                          5 * combined + 1e-12)
                    << "wavelength bin " << l;
            }
        }
    }
}

TEST(KernelSimdStat, SameSpectralTablesAsScalarGoldUnderDispersiveCoat) {
    const Stack stack = parse_stack(kSpectralGoldUnderBk7, "gold under BK7");
    expect_same_spectral_distribution(stack, {20, 70}, 1'000'000, true);  // 12 tests
    expect_same_spectral_distribution(stack, {45}, 1'000'000, false);     // 6
}

TEST(KernelSimdStat, SameSpectralTablesAsScalarPlastic) {
    expect_same_spectral_distribution(parse_stack(kSpectralPlastic, "plastic"), {0, 60}, 1'000'000,
                                      true);  // 12
}

TEST(KernelSimdStat, SameSpectralTablesAsScalarFilmedConductorUnderCoat) {
    expect_same_spectral_distribution(iridescent_gold(0.3), {30}, 1'000'000, true);  // 6
}

TEST(KernelSimdStat, SameSpectralTablesAsScalarScatteringMedium) {
    expect_same_spectral_distribution(parse_stack(kSpectralMilky, "milky"), {30, 70}, 1'000'000,
                                      true);  // 12
}

TEST(KernelSimdStat, SameSpectralTablesAsScalarDispersiveRoughSlab) {
    expect_same_spectral_distribution(parse_stack(kSpectralSlab, "slab"), {10, 65}, 1'000'000,
                                      true);  // 24
}

}  // namespace
}  // namespace lamina

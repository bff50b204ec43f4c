// The closed-form thickness average of a film's reflectance (physics/thin_film_average.h) against
// the Airy reflectance of physics/thin_film.h averaged numerically, the incoherent slab over whole
// periods, and the cases it declines.

#include "physics/thin_film_average.h"

#include "physics/fresnel.h"
#include "physics/thin_film.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

namespace lamina {
namespace {

using C = std::complex<double>;

// The mean of R_s and R_p over thickness_waves uniform in [w0, w1] by the midpoint rule on
// 200,000 points (the integrand is smooth and periodic: the rule's error is far below 1e-10).
std::pair<double, double> numeric_mean(double cos_i, C eta_film, C eta_exit, double w0, double w1) {
    constexpr int kSteps = 200000;
    double sum_s = 0, sum_p = 0;
    for (int i = 0; i < kSteps; ++i) {
        const ThinFilmMueller<double> m =
            thin_film_mueller(cos_i, eta_film, eta_exit, w0 + (w1 - w0) * (i + 0.5) / kSteps);
        sum_s += m.reflection.a + m.reflection.b;
        sum_p += m.reflection.a - m.reflection.b;
    }
    return {sum_s / kSteps, sum_p / kSteps};
}

TEST(ThinFilmAverage, MeanInverseCosineSumAgainstQuadrature) {
    // Ranges inside one period, across the poles of tan(y/2) at odd multiples of π, across many
    // periods, starting at negative angles, and a nearly resonant |c| = 0.99.
    struct Case {
        double A, B, y0, y1;
    };
    for (const Case& k : {Case{1.25, 1.0, 0.1, 1.3}, Case{1.25, -1.0, 2.9, 3.5},
                          Case{1.01, 0.2, -7.0, 40.0}, Case{1 + 0.99 * 0.99, 2 * 0.99, 3.0, 9.7},
                          Case{1.0, 0.0, 0.5, 0.6}, Case{2.0, 1.5, kPi<double>, 3 * kPi<double>}}) {
        constexpr int kSteps = 400000;
        double sum = 0;
        for (int i = 0; i < kSteps; ++i)
            sum += 1 / (k.A + k.B * std::cos(k.y0 + (k.y1 - k.y0) * (i + 0.5) / kSteps));
        const double numeric = sum / kSteps;
        EXPECT_NEAR(mean_inverse_cosine_sum(k.A - k.B, k.A + k.B, k.y0, k.y1), numeric,
                    1e-8 * numeric)
            << k.A << " " << k.B << " [" << k.y0 << ", " << k.y1 << "]";
    }
}

TEST(ThinFilmAverage, EqualsTheAiryReflectanceAveragedNumerically) {
    // Films over a dielectric and over conductors (copper and gold at 630 nm, an aluminium-like
    // one), films of higher and lower index than the exit, at normal, oblique and grazing light,
    // over part of a period, a few periods and a non-integer number of them.
    struct Case {
        double cos_i;
        C film, exit;
        double w0, w1;
    };
    for (const Case& k : {Case{1.0, C(1.38), C(1.52), 0.05, 0.21},
                          Case{std::cos(40 * kPi<double> / 180), C(1.45), C(2.0), 0.3, 1.9},
                          Case{std::cos(60 * kPi<double> / 180), C(1.5), C(0.27, 3.41), 0.3, 0.9},
                          Case{std::cos(75 * kPi<double> / 180), C(2.5), C(0.18, 3.1), 0.01, 0.02},
                          Case{std::cos(85 * kPi<double> / 180), C(1.2), C(1.2, 7.3), 0.0, 3.7},
                          Case{0.3, C(1.8), C(1.33), 1.1, 1.4}}) {
        const auto closed = thin_film_reflectance_mean(k.cos_i, k.film, k.exit, k.w0, k.w1);
        ASSERT_TRUE(closed.has_value());
        const auto [s, p] = numeric_mean(k.cos_i, k.film, k.exit, k.w0, k.w1);
        EXPECT_NEAR(closed->first, s, 1e-9) << k.cos_i << " " << k.film << " " << k.exit;
        EXPECT_NEAR(closed->second, p, 1e-9) << k.cos_i << " " << k.film << " " << k.exit;
    }
}

TEST(ThinFilmAverage, WholePeriodsGiveTheIncoherentSlab) {
    // Over n whole periods of the round-trip phase the mean is the incoherent sum of the two
    // boundaries' intensities, R12 + (1 − R12)² R23 / (1 − R12 R23), whatever the start.
    const double cos_i = std::cos(35 * kPi<double> / 180), sin2 = 1 - cos_i * cos_i;
    const C film(1.6), exit(0.47, 2.4);
    const C u2 = normal_wave_number(film, sin2);
    const double period = 1 / (2 * u2.real());
    const FresnelAmplitudes<double> b12 = fresnel_amplitudes<double>(C(1), C(cos_i), film, u2);
    const FresnelAmplitudes<double> b23 =
        fresnel_amplitudes<double>(film, u2, exit, normal_wave_number(exit, sin2));
    auto slab = [](double r12, double r23) {
        return r12 + (1 - r12) * (1 - r12) * r23 / (1 - r12 * r23);
    };
    for (double start : {0.0, 0.37, 2.9})
        for (int periods : {1, 3, 40}) {
            const auto m = thin_film_reflectance_mean(cos_i, film, exit, start * period,
                                                      (start + periods) * period);
            ASSERT_TRUE(m.has_value());
            EXPECT_NEAR(m->first, slab(std::norm(b12.r_s), std::norm(b23.r_s)), 1e-12);
            EXPECT_NEAR(m->second, slab(std::norm(b12.r_p), std::norm(b23.r_p)), 1e-12);
        }
}

TEST(ThinFilmAverage, DeclinesWhereNoClosedFormHolds) {
    // An absorbing film, a film beyond its critical angle (1.5 above 1.2 at 60°: the wave in the
    // film is evanescent), a range narrower than 1e-3 rad of phase, and an empty range.
    const double cos60 = 0.5;
    EXPECT_FALSE(thin_film_reflectance_mean(1.0, C(2.3, 0.1), C(2.9, 3.0), 0.1, 0.5).has_value());
    EXPECT_FALSE(
        thin_film_reflectance_mean(cos60, C(1.2 / 1.5), C(2.0 / 1.5), 0.1, 0.5).has_value());
    EXPECT_FALSE(thin_film_reflectance_mean(1.0, C(1.5), C(2.0), 0.2, 0.2 + 1e-5).has_value());
    EXPECT_FALSE(thin_film_reflectance_mean(1.0, C(1.5), C(2.0), 0.2, 0.2).has_value());
}

TEST(ThinFilmAverage, FiniteAndBoundedAtExtremes) {
    // Grazing and normal light, films of index just above the critical value and of index 10,
    // nearly totally reflecting exits, ranges of 10 µm: a reflectance in [0, 1], never NaN.
    for (double cos_i : {0.0, 1e-9, 0.5, 1.0})
        for (C film : {C(1.0005), C(1.5), C(10.0)})
            for (C exit : {C(1.0), C(0.01, 10.0), C(10.0), C(1e-3, 1e-3)})
                for (auto [w0, w1] : {std::pair{0.0, 1e-2}, std::pair{0.0, 20.0}}) {
                    const auto m = thin_film_reflectance_mean(cos_i, film, exit, w0, w1);
                    if (!m) continue;
                    for (double r : {m->first, m->second}) {
                        EXPECT_TRUE(std::isfinite(r)) << cos_i << " " << film << " " << exit;
                        EXPECT_GE(r, 0.0);
                        EXPECT_LE(r, 1.0);
                    }
                }
}

}  // namespace
}  // namespace lamina

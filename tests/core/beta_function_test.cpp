// core/beta_function.h against the C++ library's std::beta (an independent implementation) and
// closed forms, and the Smith refraction escape built on it (physics/microfacet.h).
#include "core/beta_function.h"
#include "physics/microfacet.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

namespace lamina {
namespace {

// Arguments from 1 to 1e4, denser near 1 where the shift and the series meet.
std::vector<double> arguments() {
    std::vector<double> x;
    for (double v = 1; v < 1e4; v *= 1.13)
        x.push_back(v);
    for (double v : {1.0, 1.5, 2.0, 4.999, 5.0, 9.5})
        x.push_back(v);
    return x;
}

// Closed forms: B(1, 1) = 1, B(a, 1) = 1/a, B(2, 3) = 1/12, B(½ + 1, ½ + 1) = π/8, to the stated
// 5e-11 (the series' truncation at the smallest shifted arguments, 5).
TEST(BetaFunction, ClosedForms) {
    EXPECT_NEAR(beta_function_scaled(1.0, 1.0, 1.0), 1.0, 5e-11);
    EXPECT_NEAR(beta_function_scaled(7.25, 1.0, 7.25), 1.0, 5e-11);
    EXPECT_NEAR(beta_function_scaled(2.0, 3.0, 12.0), 1.0, 5e-11);
    EXPECT_NEAR(beta_function_scaled(1.5, 1.5, 8.0 / kPi<double>), 1.0, 5e-11);
}

// Double: within the stated 5e-11 relative of std::beta wherever B is a normal number. Float, with
// scale = a (a B(a, b) ≤ 1, the masking's form): within 2e-5 absolute, the rounding of exponent
// terms up to ~50 in size (about 6 float ulps of them).
TEST(BetaFunction, AgreesWithTheLibrary) {
    double worst_double = 0, worst_float = 0;
    for (double a : arguments())
        for (double b : arguments()) {
            const double exact = std::beta(a, b);
            if (!(exact > 1e-300)) continue;
            const double scale = a;  // a B(a, b) ≤ 1, the form the masking uses
            const double d = beta_function_scaled(a, b, scale);
            worst_double = std::max(worst_double, std::abs(d / (scale * exact) - 1));
            const float f = beta_function_scaled(float(a), float(b), float(scale));
            // The float arguments are rounded: compare with the exact value at them.
            const double exact_f =
                double(float(scale)) * std::beta(double(float(a)), double(float(b)));
            worst_float = std::max(worst_float, std::abs(double(f) - exact_f));
        }
    EXPECT_LT(worst_double, 5e-11);
    EXPECT_LT(worst_float, 2e-5);
    std::printf("[ accuracy ] double: %.2g relative; float: %.2g absolute\n", worst_double,
                worst_float);
}

// Single precision near one (a, b ≤ 3, the Gamma functions by A & S Eq. 6.1.36's polynomial):
// relative to std::beta at the float arguments within 2e-6, the polynomial's 3e-7 absolute
// (3.4e-7 relative, Γ ≥ 0.885 on [1, 2]) in each of three Gamma functions plus about ten float
// roundings (6e-8 each). Across the switch at 3 the series takes over within its own 2e-5.
// Closed forms in float: B(1, b) = 1/b (the polynomial cancels), B(2, 3) = 1/12, B(1.5, 1.5) = π/8.
TEST(BetaFunction, SinglePrecisionNearOne) {
    double worst = 0;
    for (int i = 0; i <= 200; ++i)
        for (int j = 0; j <= 200; ++j) {
            const float a = 1.f + 2.f * float(i) / 200.f, b = 1.f + 2.f * float(j) / 200.f;
            const float f = beta_function_scaled(a, b, a);
            const double exact = double(a) * std::beta(double(a), double(b));
            worst = std::max(worst, std::abs(double(f) / exact - 1));
        }
    EXPECT_LT(worst, 2e-6);
    std::printf("[ accuracy ] float, a, b <= 3: %.2g relative\n", worst);
    for (float b : {1.f, 1.25f, 2.f, 2.9f, 3.f})
        EXPECT_NEAR(beta_function_scaled(1.f, b, b), 1.f, 3e-7f) << b;
    EXPECT_NEAR(beta_function_scaled(2.f, 3.f, 12.f), 1.f, 2e-6f);
    EXPECT_NEAR(beta_function_scaled(1.5f, 1.5f, float(8.0 / kPi<double>)), 1.f, 2e-6f);
    for (float b : {2.9999f, 3.f, 3.0001f}) {
        const double exact = 2.5 * std::beta(2.5, double(b));
        EXPECT_NEAR(beta_function_scaled(2.5f, b, 2.5f), exact, 2e-5) << b;
    }
}

// Past the argument bound the value is the bound's: finite, no NaN, and negligible or the limit.
TEST(BetaFunction, HugeAndInfiniteArguments) {
    const float inf = std::numeric_limits<float>::infinity();
    EXPECT_LT(beta_function_scaled(inf, 3.f, 1.f), 1e-20f);  // 2/(1e7)³ at the bound
    EXPECT_NEAR(beta_function_scaled(inf, 1.f, float(Lane<float>::kBetaArgumentMax)), 1.f, 1e-5f);
    EXPECT_TRUE(std::isfinite(beta_function_scaled(1e30f, 1.5f, 1.f)));
    EXPECT_EQ(beta_function_scaled(1e6f, 1e6f, 1.f), 0.f);
}

// G2/G1 of a refraction = (1 + Λi) B(1 + Λi, 1 + Λo) (microfacet.h), from the roots r = 1 + 2Λ:
// std::beta's value; at most 1; one when nothing masks the exit (r_o = 1); the pbrt form's
// 1/(1 + Λo) when nothing masks the entry (r_i = 1: B(1, 1 + Λo) = 1/(1 + Λo)); zero at a grazing
// exit.
TEST(SmithMasking, RefractionEscape) {
    for (double r_i : {1.0, 1.01, 1.7, 3.0, 40.0, 1e4})
        for (double r_o : {1.0, 1.2, 2.5, 11.0, 300.0}) {
            const double g = smith_refraction_escape(r_i, r_o);
            const double li = (r_i - 1) / 2, lo = (r_o - 1) / 2;
            EXPECT_NEAR(g, (1 + li) * std::beta(1 + li, 1 + lo), 5e-11 * g) << r_i << ' ' << r_o;
            EXPECT_LE(g, 1 + 5e-11);
            if (r_o == 1) {
                EXPECT_NEAR(g, 1.0, 1e-10);
            }
            if (r_i == 1) {
                EXPECT_NEAR(g, smith_reflection_escape(r_i, r_o), 1e-10);
            }
        }
    // A grazing exit, taken at the argument bound: (1 + Λi) B(1 + Λi, 1 + Λo) ~ Λo^−(1 + Λi).
    EXPECT_LT(smith_refraction_escape(2.0, std::numeric_limits<double>::infinity()), 1e-20);
    EXPECT_LT(smith_refraction_escape(2.f, std::numeric_limits<float>::infinity()), 1e-9f);
}

}  // namespace
}  // namespace lamina

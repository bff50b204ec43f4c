// The written-out complex helpers (core/complex_math.h) against the standard library's, which
// compute the same quantities by another route (hypot, Annex G division, csqrt, cexp).
#include "core/complex_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <limits>

namespace lamina {
namespace {

using C = std::complex<double>;

TEST(ComplexMath, SquaredModulusAndReciprocalAreTheLibrarys) {
    // Real, imaginary, both signs, small and large magnitudes of the Fresnel denominators' range.
    const C values[] = {C(1.0),        C(-2.5),          C(0.0, 3.0),      C(0.0, -1e-3),
                        C(0.3, 0.4),   C(-1.7, 2.9),     C(1e-40, -2e-40), C(3e40, 4e40),
                        C(1.0, 1e-17), C(-0.999, 0.0447)};
    for (const C z : values) {
        EXPECT_NEAR(squared_modulus(z), std::norm(z), 4e-16 * std::norm(z)) << z;
        const C r = reciprocal(z), expected = C(1.0) / z;
        EXPECT_NEAR(std::abs(r - expected), 0.0, 4e-16 * std::abs(expected)) << z;
    }
    // A zero denominator: non-finite, as 1/0 (the film's Airy sums test for it).
    EXPECT_FALSE(std::isfinite(std::norm(reciprocal(C(0.0)))));
    // Non-finite in, non-finite out.
    EXPECT_FALSE(std::isfinite(squared_modulus(C(std::numeric_limits<double>::infinity(), 1.0))));
}

TEST(ComplexMath, PrincipalSqrtIsTheLibrarys) {
    // Every quadrant, both axes with both signs of zero (the branch cut: −4 ± 0i → ±2i), the
    // normal wave numbers' range (η² − sin²θ of films and metals, near a critical angle), and
    // magnitudes past the fast form's range (the library's value there).
    const double inf = std::numeric_limits<double>::infinity();
    const C values[] = {C(4.0),          C(-4.0, 0.0),    C(-4.0, -0.0),     C(0.0, 2.0),
                        C(0.0, -2.0),    C(0.0),          C(-0.0, -0.0),     C(3.0, -4.0),
                        C(-3.0, 4.0),    C(-3.0, -4.0),   C(6.2, 0.5),       C(-0.04, 8.3),
                        C(-1e-12, 1e-7), C(1e-7, -1e-12), C(1e-300, 1e-300), C(3e200, -4e200),
                        C(1e-170, 0.0),  C(inf, 1.0),     C(-inf, 1.0),      C(1.0, inf)};
    for (const C z : values) {
        const C r = principal_sqrt(z), expected = std::sqrt(z);
        if (std::isfinite(std::abs(expected)))
            EXPECT_NEAR(std::abs(r - expected), 0.0, 1e-15 * std::abs(expected)) << z;
        else  // the library's own value
            EXPECT_TRUE(r.real() == expected.real() && r.imag() == expected.imag()) << z;
        EXPECT_EQ(std::signbit(r.imag()), std::signbit(expected.imag())) << z;
        EXPECT_GE(r.real(), 0.0) << z;
    }
    // A deterministic sweep of the plane: the root squared is z to the rounding.
    for (int i = -20; i <= 20; ++i)
        for (int j = -20; j <= 20; ++j) {
            const C z(0.37 * i, 0.53 * j), r = principal_sqrt(z);
            EXPECT_NEAR(std::abs(r * r - z), 0.0, 2e-15 * std::abs(z)) << z;
            EXPECT_NEAR(std::abs(r - std::sqrt(z)), 0.0, 1e-15 * std::abs(r)) << z;
        }
    EXPECT_TRUE(std::isnan(principal_sqrt(C(std::nan(""), 1.0)).real()));
}

TEST(ComplexMath, ExpOfITimesThetaIsTheLibrarys) {
    // A film's phase: advancing (Re θ, up to many turns) and decaying (Im θ ≥ 0), and a growing
    // wave's (Im θ < 0) for the form's sake.
    const C values[] = {C(0.0),        C(1.0),    C(-2.5, 0.0),  C(0.7, 0.3),
                        C(31.4, 0.02), C(3e3, 5), C(-0.2, -1.5), C(1e-9, 1e-9)};
    for (const C theta : values) {
        const C r = exp_i(theta), expected = std::exp(C(0.0, 1.0) * theta);
        EXPECT_NEAR(std::abs(r - expected), 0.0, 4e-16 * std::abs(expected) * (1 + std::abs(theta)))
            << theta;
    }
}

}  // namespace
}  // namespace lamina

// The written-out complex helpers (core/complex_math.h) against the standard library's, which
// compute the same quantities by another route (hypot, Annex G division).
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

}  // namespace
}  // namespace lamina

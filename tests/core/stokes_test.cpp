// The degree and angle of polarization of a Stokes vector (core/stokes.h) on vectors whose answers
// are known by hand.
#include "core/stokes.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

const std::array<double, 4> kNoError = {0, 0, 0, 0};

TEST(Stokes, DegreeOfKnownStates) {
    EXPECT_DOUBLE_EQ(stokes_polarization({1, 0.6, 0, 0.8}, kNoError).dop, 1.0);  // 0.36 + 0.64
    EXPECT_DOUBLE_EQ(stokes_polarization({2, 1, 0, 0}, kNoError).dop, 0.5);
    EXPECT_DOUBLE_EQ(stokes_polarization({4, 0, 0, 0}, kNoError).dop, 0.0);
    EXPECT_TRUE(std::isnan(stokes_polarization({0, 0, 0, 0}, kNoError).dop));  // no light
    EXPECT_TRUE(std::isnan(stokes_polarization({0, 0, 0, 0}, kNoError).dop_se));
}

// ½ atan2(S2, S1): along x (s-polarized) 0°, along y −90° or 90° (the same axis; 90° is the one
// in (−90°, 90°]), at +45° and −45°.
TEST(Stokes, AngleOfLinearPart) {
    EXPECT_DOUBLE_EQ(stokes_polarization({1, 1, 0, 0}, kNoError).aolp_deg, 0.0);
    EXPECT_DOUBLE_EQ(stokes_polarization({1, -1, 0, 0}, kNoError).aolp_deg, 90.0);
    EXPECT_DOUBLE_EQ(stokes_polarization({1, 0, 1, 0}, kNoError).aolp_deg, 45.0);
    EXPECT_DOUBLE_EQ(stokes_polarization({1, 0, -1, 0}, kNoError).aolp_deg, -45.0);
    EXPECT_DOUBLE_EQ(stokes_polarization({1, 0, 0, 1}, kNoError).aolp_deg, 0.0);  // circular
}

// First order: d = |S|/S0 with S = (1, 0.5, 0, 0), σ = (0.1, 0.2, 0.3, 0.4): ∂d/∂S1 = S1/(|S| S0)
// = 1, ∂d/∂S0 = −d/S0 = −0.5, the others 0 at S2 = S3 = 0, so σ_d² = 0.2² + (0.5 · 0.1)² =
// 0.0425. At |S| = 0 the noise scale √(σ1² + σ2² + σ3²)/S0 = √0.29 / 2.
TEST(Stokes, StandardErrorOfTheDegree) {
    const std::array<double, 4> se = {0.1, 0.2, 0.3, 0.4};
    EXPECT_NEAR(stokes_polarization({1, 0.5, 0, 0}, se).dop_se, std::sqrt(0.0425), 1e-15);
    EXPECT_NEAR(stokes_polarization({2, 0, 0, 0}, se).dop_se, std::sqrt(0.29) / 2, 1e-15);
}

}  // namespace
}  // namespace lamina

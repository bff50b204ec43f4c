#include "core/frame.h"
#include "core/spherical.h"

#include <gtest/gtest.h>

namespace lamina {
namespace {

TEST(Frame, IsOrthonormalAndRoundTrips) {
    for (const Vec3d n : {Vec3d(0, 0, 1), Vec3d(0, 0, -1), normalize(Vec3d(0.3, -0.2, 0.9)),
                          normalize(Vec3d(-0.6, 0.7, -0.1))}) {
        const auto f = Frame<double>::from_normal(n);
        EXPECT_NEAR(dot(f.s, f.t), 0, 1e-14);
        EXPECT_NEAR(dot(f.s, f.n), 0, 1e-14);
        EXPECT_NEAR(dot(f.t, f.n), 0, 1e-14);
        EXPECT_NEAR(length(f.s), 1, 1e-14);
        EXPECT_NEAR(length(f.t), 1, 1e-14);
        const Vec3d v(0.1, -0.4, 0.7);
        const Vec3d back = f.to_world(f.to_local(v));
        EXPECT_NEAR(back.x, v.x, 1e-14);
        EXPECT_NEAR(back.y, v.y, 1e-14);
        EXPECT_NEAR(back.z, v.z, 1e-14);
    }
}

TEST(Spherical, ConventionsOfPhysicsNotes) {
    // docs/physics.md §1: wi = (sin θi, 0, cos θi); mirror at φ = 180°.
    const double theta = deg_to_rad(30.0);
    const Vec3d wi = incident_direction(theta);
    EXPECT_NEAR(wi.x, 0.5, 1e-15);
    EXPECT_NEAR(wi.y, 0.0, 1e-15);
    const Vec3d mirror(-wi.x, -wi.y, wi.z);
    EXPECT_NEAR(rad_to_deg(phi_of(mirror)), 180.0, 1e-12);
    EXPECT_NEAR(rad_to_deg(theta_of(mirror)), 30.0, 1e-12);
    const Vec3d t = direction_from_angles(theta, kPi<double>, Side::Transmission);
    EXPECT_LT(t.z, 0);
    EXPECT_NEAR(rad_to_deg(theta_of(t)), 30.0, 1e-12);
}

}  // namespace
}  // namespace lamina

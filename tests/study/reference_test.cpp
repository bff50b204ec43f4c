// The reference's cache key (study/reference.h): a study's reference pieces are reused across runs
// and across lamina versions with the same reference code, so the text of a key must not change
// for the settings keys have always held, and a new setting must change it only away from the
// value the reference had before the setting existed.
#include "study/reference.h"

#include "lamina/version.h"
#include "support/stacks.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace lamina {
namespace {

SimulationSettings small_settings() {
    SimulationSettings s;
    s.particles = 4000;
    s.seed = 3;
    s.grid = HemisphereGrid(6, 6);
    s.kernel = Kernel::Scalar;
    s.transport = test::bpb19_transport();  // the settings the earlier keys were written for
    return s;
}

// The fixed part of a key, written out as the format has always been.
std::string fixed_part(const Stack& stack) {
    return fmt::format(
        "lamina {} | code {} | config c | stack {} | theta_i 30 | particles 4000 | seed 3 | grid "
        "6x6 | kernel scalar",
        kVersion, reference_code_digest(), stack_to_json(stack).dump());
}

TEST(StudyReference, KeyTextOfTheEarlierSettingsIsUnchanged) {
    const Stack rough =
        test::make_stack({test::dielectric_layer(1.5, 0.3), test::lambertian_layer(Rgbd(0.5))});
    const Stack smooth =
        test::make_stack({test::dielectric_layer(1.5, 0.0), test::lambertian_layer(Rgbd(0.5))});
    SimulationSettings s = small_settings();
    // Single scattering: the masking is said where it changes the table (a rough dielectric) and
    // is smith; caches of the pbrt form predate the setting.
    EXPECT_EQ(reference_key("c", rough, 30, s).canonical(),
              fixed_part(rough) + " | transmission masking smith");
    EXPECT_EQ(reference_key("c", smooth, 30, s).canonical(), fixed_part(smooth));
    s.transport.transmission_masking = TransmissionMasking::Pbrt;
    EXPECT_EQ(reference_key("c", rough, 30, s).canonical(), fixed_part(rough));
    // Multiple scattering: said; the masking of single scattering does not apply.
    s.transport.microsurface = Microsurface::Multiple;
    EXPECT_EQ(reference_key("c", rough, 30, s).canonical(),
              fixed_part(rough) + " | microsurface multiple");
    s.transport.transmission_masking = TransmissionMasking::Smith;
    EXPECT_EQ(reference_key("c", rough, 30, s).canonical(),
              fixed_part(rough) + " | microsurface multiple");
}

// The exact reference (the defaults) says both of its settings; the 2019 one neither.
TEST(StudyReference, TheExactReferenceIsSaidAndTheBpb19KeyIsTheEarlierOne) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(0.5))});
    SimulationSettings s = small_settings();
    s.transport = TransportSettings{};
    EXPECT_EQ(reference_key("c", stack, 30, s).canonical(),
              fixed_part(stack) + " | microsurface multiple | polarization on");
    apply_physics(ReferencePhysics::Bpb19, s.transport);
    EXPECT_EQ(reference_key("c", stack, 30, s).canonical(), fixed_part(stack));
}

TEST(StudyReference, LaterSettingsAreSaidOnlyAwayFromTheirEarlierValue) {
    const Stack stack = test::make_stack({test::lambertian_layer(Rgbd(0.5))});
    SimulationSettings s = small_settings();
    const std::string before = reference_key("c", stack, 30, s).canonical();
    EXPECT_EQ(before, fixed_part(stack));
    s.threads = 7;  // not part of the key: tables do not depend on it
    EXPECT_EQ(reference_key("c", stack, 30, s).canonical(), before);
    s.transport.max_events = 500;
    EXPECT_EQ(reference_key("c", stack, 30, s).canonical(), before + " | max_events 500");
    s.transport.max_events = TransportSettings{}.max_events;
    s.transport.max_microsurface_order = 3;
    EXPECT_EQ(reference_key("c", stack, 30, s).canonical(), before + " | max_microsurface_order 3");
}

}  // namespace
}  // namespace lamina

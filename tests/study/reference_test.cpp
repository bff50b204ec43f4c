// The reference's cache key (study/reference.h): a study's reference pieces are reused across runs
// and across lamina versions with the same reference code, so the text of a key must not change
// for the settings keys have always held, and a new setting must change it only away from the
// value the reference had before the setting existed.
#include "study/reference.h"

#include "core/math.h"
#include "core/spherical.h"
#include "lamina/version.h"
#include "support/closed_forms.h"
#include "support/stacks.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

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

// A piece asked for Stokes vectors (the key's settings.stokes_tallies: a study with
// --reference-stokes on) carries S1, S2, S3 per side and bin; a piece stored without them is not
// served to such a key but computed again, and the piece with them serves a key without. One
// smooth interface of 1.5 lit at 55°: its mirror bin holds light of degree (R_s − R_p)/(R_s + R_p)
// and its straight-through bin light of degree (T_p − T_s)/(T_s + T_p), p-polarized (S1 < 0),
// every particle with the same state (Born & Wolf's amplitudes, support/closed_forms.h).
TEST(StudyReference, PieceCarriesTheStokesVectorsWhenAsked) {
    const std::filesystem::path dir =
        std::filesystem::path(LAMINA_BINARY_DIR) / "test-output" / "reference-cache-stokes";
    std::filesystem::remove_all(dir);
    SimulationSettings s;
    s.particles = 20'000;
    s.seed = 5;
    s.grid = HemisphereGrid(9, 9);
    const Stack stack = test::make_stack({test::dielectric_layer(1.5, 0.0)});
    ReferenceKey plain = reference_key("interface", stack, 55, s);
    bool computed = false;
    const ReferencePiece without = reference_piece(dir, plain, 0, {}, &computed);
    EXPECT_TRUE(computed);
    EXPECT_TRUE(without.stokes[0].empty());
    ReferenceKey asked = plain;
    asked.settings.stokes_tallies = true;
    EXPECT_EQ(asked.canonical(), plain.canonical());  // the tables are the same
    EXPECT_FALSE(load_reference_piece(dir, asked).has_value());
    const ReferencePiece with = reference_piece(dir, asked, 0, {}, &computed);
    EXPECT_TRUE(computed);
    EXPECT_EQ(with.f[0], without.f[0]);
    ASSERT_EQ(with.stokes[0].size(), s.grid.size());
    ASSERT_EQ(with.stokes[1].size(), s.grid.size());
    const ReferencePiece again = reference_piece(dir, asked, 0, {}, &computed);
    EXPECT_FALSE(computed);
    EXPECT_EQ(again.stokes[1], with.stokes[1]);
    EXPECT_EQ(again.stokes_se[0], with.stokes_se[0]);
    reference_piece(dir, plain, 0, {}, &computed);
    EXPECT_FALSE(computed);

    const double mu_i = std::cos(deg_to_rad(55.0));
    const test::PolarizedFresnel fresnel(mu_i, 1.5);
    const double mu_t = std::sqrt(1 - (1 - mu_i * mu_i) / 2.25);
    const Vec3f wi(incident_direction(deg_to_rad(55.0)));
    const std::size_t mirror = s.grid.bin_of(Vec3f(-wi.x, -wi.y, wi.z));
    const std::size_t straight = s.grid.bin_of(Vec3d(-std::sqrt(1 - mu_t * mu_t), 0, -mu_t));
    const double Rs = fresnel.Rs(), Rp = fresnel.Rp();
    const double expected[2] = {(Rs - Rp) / (Rs + Rp), (Rp - Rs) / (2 - Rs - Rp)};
    for (int side = 0; side < 2; ++side) {
        const std::size_t bin = side == 0 ? mirror : straight;
        for (int c = 0; c < 3; ++c) {
            const double f = with.f[side][bin][c];
            EXPECT_NEAR(with.stokes[side][bin][0][c] / f, expected[side], 1e-5)
                << "side " << side << " channel " << c;
            EXPECT_NEAR(with.stokes[side][bin][1][c], 0.0, 1e-6 * f);
            EXPECT_NEAR(with.stokes[side][bin][2][c], 0.0, 1e-6 * f);
        }
    }
}

}  // namespace
}  // namespace lamina

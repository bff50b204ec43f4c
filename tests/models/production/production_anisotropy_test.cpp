// The production coats that define anisotropic roughness (OpenPBR's parametrization: `openpbr`,
// `openpbr-adobe`; docs/models.md, "Anisotropic coats") on anisotropic stacks: their isotropic α,
// and their energy, bounded as measured. What every model that represents anisotropy must do
// (reduce to the isotropic form, turn with its tangents, sample its density) is in
// tests/models/anisotropy_test.cpp; their values against openpbr-bsdf's own code in
// production_golden_test.cpp.
#include "core/math.h"
#include "core/spherical.h"
#include "models/numerics/binned.h"
#include "models/production/production_coat.h"
#include "models/registry.h"
#include "models/test_stacks.h"

#include "models/model_checks.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cmath>
#include <string>
#include <vector>

namespace lamina {
namespace {

using test::brushed;
using test::coated;
using test::dir;

const char* const kAnisotropicCoats[] = {"openpbr", "openpbr-adobe"};

// OpenPBR's isotropic α of α_x, α_y is their root mean square; α itself for an isotropic one.
TEST(ProductionAnisotropy, IsotropicAlphaIsTheRootMeanSquare) {
    const InterfaceSpec iso = test::gold(0.3);
    EXPECT_EQ(openpbr_isotropic_alpha(iso), 0.3);
    // OpenPBR 1.1: a = 0.5 of α = 0.2 gives α_t = 0.2 √(2/1.25), α_b = α_t / 2.
    const double a_t = 0.2 * std::sqrt(2 / 1.25);
    EXPECT_NEAR(openpbr_isotropic_alpha(anisotropic(iso, a_t, 0.5 * a_t, 10)), 0.2, 1e-15);
}

// Energy: the albedo ∫ f μo dωo over the whole hemisphere (no mirror symmetry: full azimuth), per
// incidence and, of the transposed BRDF, per view, at θ ∈ {0°, 45°, 80°} and azimuths across the
// tangents, over brushed metals and a brushed coat over a Lambertian. Per view it stays within
// energy conservation (the quadrature's 1e-3 and the FGD table's 6.3e-3 as in production_test);
// per incidence the albedo scaling exceeds 1 at grazing light, as the isotropic coats do
// (production_test, EnergyAsMeasured): bounded by the measured excess.
TEST(ProductionAnisotropy, EnergyIsBounded) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    o.full_azimuth = true;
    const std::vector<Stack> stacks = {
        brushed(0.3, 0.05, 30, 0.4, 0.02, -45), brushed(0.05, 0.05, 0, 0.6, 0.1, 90), [] {
            Stack s = coated(1.5, 0.4, test::lambertian(Rgbd(0.9)), Rgbd(0.0));
            s.layers[0].interface = anisotropic(s.layers[0].interface, 0.4, 0.05, 60);
            return s;
        }()};
    for (const char* name : kAnisotropicCoats) {
        double forward = 0, per_view = 0;
        for (const Stack& s : stacks) {
            const auto m = make_model(name, s);
            const test::TransposedModel transposed(*m);
            for (double t : {0.0, 45.0, 80.0})
                for (double p : {0.0, 75.0, 150.0}) {
                    const Vec3d w = dir(t, p);
                    forward = std::max(forward, model_albedo(*m, w, Side::Reflection, o).max());
                    per_view =
                        std::max(per_view, model_albedo(transposed, w, Side::Reflection, o).max());
                }
        }
        std::cout << fmt::format("{}: largest albedo per incidence {:.4f}, per view {:.4f}\n", name,
                                 forward, per_view);
        // Measured: per view 0.9934 (openpbr), 0.9991 (openpbr-adobe); per incidence 1.0511,
        // 1.0525 (the albedo scaling's excess at grazing wi, as for isotropic coats).
        EXPECT_LE(per_view, 1 + 1e-3 + 6.3e-3) << name;
        EXPECT_LE(forward, 1.06) << name;
    }
}

}  // namespace
}  // namespace lamina

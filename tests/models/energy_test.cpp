// Energy: a model's albedo (reflection + transmission) stays ≤ 1 over a sweep of the study's
// configurations and incidences — except where the model is known not to conserve energy, which
// is shown explicitly instead of hidden.
#include "core/math.h"
#include "core/spherical.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "test_stacks.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

namespace lamina {
namespace {

using test::coated;

TEST(ModelsEnergy, AlbedoAtMostOne) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    for (const auto& entry : model_registry()) {
        // WW09 and Ele10 do not conserve energy: see the two tests below.
        if (entry.name == "ww09" || entry.name == "ele10") continue;
        if (entry.stochastic) continue;  // unbiased, noisy: tests/randomwalk checks its albedo
        // The production coats' albedo scaling is energy-conserving for the adjoint (per wo), not
        // per wi: production_test.cpp tests each one's own bound.
        if (entry.group == "production") continue;
        // Bel18/Bel'/WB20 energies come from the FGD table: its interpolation budget for conductors
        // (max 6.3e-3, docs/models.md) adds to the quadrature tolerance (1e-3).
        // Bel18 symmetric is not conservative by construction (Bel18SymmetricCanExceedOne below):
        // its budget is the measured excess over a wider sweep, 5.3e-3 (1.24e-2 with lamina's
        // former TIR step, tir=top-interface tir-table=microfacet), rounded up.
        // The transfer-matrix models (tm*) read the same table; lamina-1's hemispherical albedos
        // and its return of the first order come from the same FGD table (and its coat
        // transmittance table, whose budget is smaller): the same budget.
        const bool table_energies = entry.name.rfind("bel", 0) == 0 ||
                                    entry.name.rfind("tm", 0) == 0 || entry.name == "lamina-1" ||
                                    entry.name == "wb20";
        const double tol = entry.name == "bel18-symmetric" ? 2e-2
                           : table_energies                ? 1e-3 + 6.3e-3
                                                           : 1e-3;
        // lamina-1 with single scattering here: its orders ≥ 2 (the default) have a known excess
        // beyond the tables' budget, bounded in Lamina1MultipleScatteringExcess below.
        const std::vector<std::string> flags = entry.name == "lamina-1"
                                                   ? std::vector<std::string>{"microsurface=single"}
                                                   : std::vector<std::string>{};
        for (const auto& [what, stack] : test::energy_sweep(true)) {
            const auto model = entry.make(stack, resolve_options(entry, flags));
            if (!model->support().brdf) continue;
            for (double ti : {0.0, 45.0, 80.0}) {
                const Vec3d wi = incident_direction(deg_to_rad(ti));
                Rgbd a = model_albedo(*model, wi, Side::Reflection, o);
                if (model->support().btdf) a += model_albedo(*model, wi, Side::Transmission, o);
                EXPECT_LE(a.max(), 1.0 + tol) << entry.name << " " << what << " ti=" << ti;
            }
        }
    }
}

// lamina-1's default restores the microsurfaces' orders ≥ 2 as separable lobes whose energies
// come from a Monte-Carlo table (≤ 0.0056 per node, which the inter-reflection series carries
// through 1/(1 − r̄) ≤ 3: 0.017), on top of the tables' budget of AlbedoAtMostOne (the quadrature's
// 1e-3 and the FGD table's 6.3e-3; docs/models.md, lamina-1, "Known errors").
TEST(ModelsEnergy, Lamina1MultipleScatteringExcess) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    double worst = 0;
    std::string where;
    for (const auto& [what, stack] : test::energy_sweep(true)) {
        const auto model = make_model("lamina-1", stack);
        if (!model->support().brdf) continue;
        for (double ti : {0.0, 45.0, 80.0}) {
            const Vec3d wi = incident_direction(deg_to_rad(ti));
            Rgbd a = model_albedo(*model, wi, Side::Reflection, o);
            if (model->support().btdf) a += model_albedo(*model, wi, Side::Transmission, o);
            if (a.max() > worst) {
                worst = a.max();
                where = what + " ti=" + std::to_string(ti);
            }
        }
    }
    std::printf("lamina-1 (orders >= 2 restored): largest albedo %.4f (%s)\n", worst,
                where.c_str());
    EXPECT_LE(worst, 1.0 + 1e-3 + 6.3e-3 + 0.017) << where;
}

// Ele10 evaluates the base at the refracted directions without the 1/η0² compression: a narrow
// base lobe is spread over η0² times too large a solid angle outside (Snell's law of solid
// angles), so a smooth coat over a near-perfect mirror reflects F + (1 − F)² R η0² > 1. That is
// the known defect WW' corrects; this test documents it (and fails if it disappeared).
TEST(ModelsEnergy, Ele10ExceedsOneUnderSmoothCoats) {
    const auto model =
        make_model("ele10", coated(1.5, 0.0, test::conductor(Rgbd(0.05), Rgbd(8.0), 0.0)));
    const Rgbd a = model_albedo(*model, incident_direction(0.0), Side::Reflection);
    EXPECT_GT(a.max(), 1.5);
    const auto prime =
        make_model("ww-prime", coated(1.5, 0.0, test::conductor(Rgbd(0.05), Rgbd(8.0), 0.0)));
    EXPECT_LT(model_albedo(*prime, incident_direction(0.0), Side::Reflection).max(), 1.0);
}

// WW09 takes the coat's transmittance at the half vector, T01 = 1 − F(wi·h): at grazing
// incidence most outgoing directions have a far less grazing h, so the base receives almost all
// the light although the top lobe already reflects a large part: a rough coat over a white
// Lambertian reflects more than it receives at θi = 80°. Documented, not hidden.
TEST(ModelsEnergy, WW09ExceedsOneAtGrazingIncidence) {
    const auto model = make_model("ww09", coated(1.5, 0.1, test::lambertian(Rgbd(1.0))));
    EXPECT_GT(model_albedo(*model, incident_direction(deg_to_rad(80.0)), Side::Reflection).max(),
              1.1);
}

// Bel18 symmetric runs the adding scheme at c0 = |wi·h|, a different cosine for every outgoing
// direction: the lobe energies E_k(c0(wo)) are then not one partition of the incident energy, and
// nothing bounds ∫ Σ E_k(c0(wo)) lobe_k(wo) μo dωo by 1. Over coats η0 ∈ {1.1, 1.2, 1.5, 2},
// α0 ∈ {0, 0.05, 0.1, 0.2, 0.3, 0.5} over a near-perfect mirror, θi ∈ {0°, 30°, 60°, 80°}, the
// excess reaches 0.53% (η0 = 1.2, α0 = 0.1, θi = 60°; 1.24% with lamina's former TIR step), mostly
// through TIR at the grazing c0 of far-off-specular pairs. Shown, not hidden.
TEST(ModelsEnergy, Bel18SymmetricCanExceedOne) {
    const auto model = make_model("bel18-symmetric",
                                  coated(1.2, 0.1, test::conductor(Rgbd(0.05), Rgbd(8.0), 0.0)));
    const Rgbd a = model_albedo(*model, incident_direction(deg_to_rad(60.0)), Side::Reflection);
    EXPECT_GT(a.max(), 1.003);
    EXPECT_LT(a.max(), 1.02);
}

}  // namespace
}  // namespace lamina

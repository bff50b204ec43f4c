// Every deterministic model that represents anisotropy (ModelEntry::represents_anisotropy:
// OpenPBR's coats, Unity's StackLit (its base), the Weidlich–Wilkie family, WB20, lamina-1;
// docs/models.md)
// on anisotropic stacks: it reduces to its isotropic form as α_y → α_x, it turns with its
// interfaces' tangents, and its sampler (where it has one) draws the density it claims. Energy,
// which differs by model, is tested with each.
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "models/model_sampling.h"
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
using test::dir;
using test::relative_difference;

/// The registry's deterministic models that represent anisotropy.
std::vector<std::string> anisotropic_models() {
    std::vector<std::string> out;
    for (const ModelEntry& e : model_registry())
        if (e.represents_anisotropy && !e.stochastic) out.push_back(e.name);
    return out;
}

/// Directions in and off the plane φ = 0.
std::vector<Vec3d> directions() {
    std::vector<Vec3d> out;
    for (double t : {5.0, 30.0, 55.0, 80.0})
        for (double p : {0.0, 40.0, 130.0, 200.0, 310.0})
            out.push_back(dir(t, p));
    return out;
}

/// Whether `name` represents an anisotropic coat (Unity's StackLit has an anisotropic base only:
/// its checks run with the coat isotropic).
bool represents_anisotropic_coat(const std::string& name) {
    return make_model(name, brushed(0.3, 0.08, 20, 0.1, 0.1, 0))->support().brdf;
}

TEST(ModelAnisotropy, TheFamiliesThatRepresentIt) {
    const std::vector<std::string> names = anisotropic_models();
    for (const char* name : {"openpbr", "openpbr-adobe", "unity-stacklit", "ww09", "ele10",
                             "ww-prime", "wb20", "lamina-1"})
        EXPECT_NE(std::find(names.begin(), names.end(), name), names.end()) << name;
    EXPECT_FALSE(represents_anisotropic_coat("unity-stacklit"));
    EXPECT_TRUE(represents_anisotropic_coat("openpbr"));
}

// As α_y → α_x the anisotropic form is the isotropic one: α_y = α_x (1 + 1e-8) on coat and base
// moves no value by more than 1e-6 relative (the lobes' D and Λ are smooth in α_y; terms that read
// one α read the root mean square, which moves by 5e-9 relative).
TEST(ModelAnisotropy, ReducesToTheIsotropicForm) {
    for (const std::string& name : anisotropic_models())
        for (const auto& [c, b] :
             {std::pair{0.2, 0.3}, std::pair{0.05, 0.5}, std::pair{0.4, 0.1}}) {
            const double c_y = represents_anisotropic_coat(name) ? c * (1 + 1e-8) : c;
            // lamina-1's default restores the orders ≥ 2 of isotropic interfaces only (a step at
            // α_y = α_x, docs/models.md): compared with single scattering on both sides.
            const std::vector<std::string> flags =
                name == "lamina-1" ? std::vector<std::string>{"microsurface=single"}
                                   : std::vector<std::string>{};
            const auto iso = make_model(name, brushed(c, c, 0, b, b, 0), flags);
            const auto aniso = make_model(name, brushed(c, c_y, 35, b, b * (1 + 1e-8), -60), flags);
            ASSERT_TRUE(aniso->support().brdf) << name << ": " << aniso->support().reason;
            double worst = 0;
            for (const Vec3d& wi : directions())
                for (const Vec3d& wo : directions())
                    worst = std::max(worst,
                                     relative_difference(aniso->eval(wi, wo), iso->eval(wi, wo)));
            EXPECT_LT(worst, 1e-6) << name << " coat " << c << " base " << b;
        }
}

// Swapping α_x and α_y is turning the tangent by 90°, and turning both tangents and both
// directions by ψ leaves every value: the lobes are the anisotropic GGX of physics/microfacet.h in
// the interface's frame, and every other term depends on cosines to the normal alone.
TEST(ModelAnisotropy, TurnsWithItsTangents) {
    const double psi = 37;
    const auto turn = [](const Vec3d& w, double deg) {
        const double c = std::cos(deg_to_rad(deg)), s = std::sin(deg_to_rad(deg));
        return Vec3d(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
    };
    for (const std::string& name : anisotropic_models()) {
        const double c_y = represents_anisotropic_coat(name) ? 0.08 : 0.3;
        const auto m = make_model(name, brushed(0.3, c_y, 20, 0.1, 0.4, -50));
        const auto swapped = make_model(name, brushed(c_y, 0.3, 110, 0.4, 0.1, 40));
        const auto turned = make_model(name, brushed(0.3, c_y, 20 + psi, 0.1, 0.4, -50 + psi));
        for (const auto* model : {m.get(), swapped.get(), turned.get()})
            ASSERT_TRUE(model->support().brdf) << name << ": " << model->support().reason;
        double worst_swap = 0, worst_turn = 0;
        for (const Vec3d& wi : directions())
            for (const Vec3d& wo : directions()) {
                const Rgbd f = m->eval(wi, wo);
                worst_swap = std::max(worst_swap, relative_difference(swapped->eval(wi, wo), f));
                worst_turn = std::max(
                    worst_turn, relative_difference(turned->eval(turn(wi, psi), turn(wo, psi)), f));
            }
        EXPECT_LT(worst_swap, 1e-10) << name;
        EXPECT_LT(worst_turn, 1e-10) << name;
    }
}

// The samplers draw the density pdf() claims (chi-square), and each sample's weight is
// eval·cos/pdf, on anisotropic coats and metals lit in and off the plane φ = 0.
TEST(ModelAnisotropy, SamplingMatchesItsDensity) {
    int samplers = 0;  // the chi-square tests' count: two stacks × two incidences per sampler
    for (const std::string& name : anisotropic_models())
        samplers += int(make_model(name, brushed(0.1, 0.1, 0, 0.5, 0.08, 100))->has_sampling());
    for (const std::string& name : anisotropic_models()) {
        const double c_y = represents_anisotropic_coat(name) ? 0.05 : 0.3;
        const std::vector<std::pair<std::string, Stack>> stacks = {
            {"brushed-both", brushed(0.3, c_y, 30, 0.4, 0.02, -45)},
            {"brushed-metal", brushed(0.1, 0.1, 0, 0.5, 0.08, 100)}};
        if (!make_model(name, stacks[0].second)->has_sampling()) continue;
        const int count = 2 * int(stacks.size()) * samplers;
        for (const auto& [what, stack] : stacks) {
            const auto m = make_model(name, stack);
            ASSERT_TRUE(m->support().brdf) << name << ": " << m->support().reason;
            for (const Vec3d& wi : {dir(25, 0), dir(60, 130)}) {
                const auto r = test::model_sampling_chi2(
                    *m, wi, fmt::format("{}-{}-{:.0f}", name, what, wi.z * 100), count);
                EXPECT_TRUE(r.passed) << name << " " << what << ": " << r.message;
                ParticleRng rng(3, 0, 0);
                EXPECT_GT(test::expect_sample_weights(*m, wi, rng, 2000, name), 1000);
            }
        }
    }
}

}  // namespace
}  // namespace lamina

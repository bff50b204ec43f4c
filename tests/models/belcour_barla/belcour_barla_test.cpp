// bb17, Belcour & Barla 2017 as their shader ships it (models/belcour_barla/belcour_barla.h,
// docs/models.md "Belcour & Barla 2017"): against the shader itself (a transliteration run outside
// the repository, data/belcour-barla-shader.json with its provenance), and what the shader's form
// implies: its lobe is GGX with uncorrelated Smith masking (reciprocal), a smooth interface is a
// delta lobe of the Fresnel term's energy, the stacks it represents and the ones it refuses.
#include "models/belcour_barla/belcour_barla.h"
#include "core/vec.h"
#include "layers/stack.h"
#include "models/production/film_fresnel.h"
#include "models/registry.h"
#include "models/test_stacks.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <string>

namespace lamina {
namespace {

using nlohmann::json;

json load_shader_values() {
    const std::string path = std::string(LAMINA_SOURCE_DIR) +
                             "/tests/models/belcour_barla/data/belcour-barla-shader.json";
    std::ifstream in(path);
    if (!in) throw std::runtime_error("cannot read " + path);
    return json::parse(in);
}

/// A conductor of indices (η, k) per channel, roughness α, under the ambient.
Stack bare_metal(const Rgbd& eta, const Rgbd& k, double alpha, double film_eta = 0,
                 double film_min_nm = 0, double film_max_nm = 0) {
    InterfaceSpec metal = test::conductor(eta, k, alpha);
    if (film_eta > 0) {
        metal.has_film = true;
        metal.film.eta = film_eta;
        metal.film.thickness_nm = film_min_nm;
        metal.film.thickness_max_nm = film_max_nm;
    }
    return test::single(metal);
}

// The shader's values (single precision) at 85 pairs on nine stacks: films on titanium, gold,
// aluminium and copper from 5 nm (Dinc 0.02 µm, where the shader blends the film's index) to
// 3 µm, no film, κ3 passed as the extinction, and an ambient of 1.33. The allowance per value is
// the shader's single precision: its Fresnel term I (terms of order 1, some twenty operations)
// to 1e-6 absolute, carried by the pair's lobe D G1 G1/(4 μi μo), plus 1e-4 relative for the
// lobe's own float rounding where D is steep.
TEST(BelcourBarlaGolden, MatchesItsShader) {
    const json data = load_shader_values();
    const json& pairs = data.at("pairs");
    double worst = 0;
    std::string where;
    for (const json& record : data.at("stacks")) {
        const Stack stack = stack_from_json(record.at("stack"), "belcour-barla-shader.json");
        const std::string kappa3 = record.value("kappa3", std::string("attenuation-index"));
        const auto model = make_model("bb17", stack, {"kappa3=" + kappa3});
        ASSERT_TRUE(model->support().brdf) << record.at("id") << ": " << model->support().reason;
        const GGX<double> ggx{stack.base().alpha};
        for (std::size_t i = 0; i < pairs.size(); ++i) {
            const json& p = pairs.at(i);
            const Vec3d wi = test::dir(p.at(0), p.at(1)), wo = test::dir(p.at(2), p.at(3));
            const Vec3d h = normalize(wi + wo);
            const double lobe = ggx.D(h) * ggx.G1(wi) * ggx.G1(wo) / (4 * wi.z * wo.z);
            const Rgbd got = model->eval(wi, wo);
            for (int c = 0; c < 3; ++c) {
                const double want = record.at("values").at(i).at(c).get<double>();
                const double err = std::abs(got[c] - want) / (1e-4 * std::abs(want) + 1e-6 * lobe);
                EXPECT_LE(err, 1.0) << record.at("id") << " pair " << p.dump() << " channel " << c
                                    << ": " << got[c] << " against the shader's " << want;
                if (err > worst) {
                    worst = err;
                    where = fmt::format("{} pair {} channel {}", record.at("id").get<std::string>(),
                                        p.dump(), c);
                }
            }
        }
    }
    std::cout << fmt::format("bb17 against its shader: worst {:.2f} of the allowance ({})\n", worst,
                             where);
}

// The lobe is Walter et al.'s GGX reflection with uncorrelated Smith masking, F at wi·h:
// reciprocal, and its value is D G1 G1 F / (4 μi μo) with F the film's Fresnel term (the model's
// wiring: F is the function the golden test holds to the shader).
TEST(BelcourBarla, LobeIsGgxWithUncorrelatedSmith) {
    const Stack s = bare_metal(Rgbd(2.74, 2.54, 2.26), Rgbd(3.79, 3.43, 3.07), 0.25, 2.5, 60, 60);
    const auto m = make_model("bb17", s);
    const GGX<double> ggx{0.25};
    for (double ti : {0.0, 30.0, 70.0})
        for (double to : {10.0, 45.0, 85.0})
            for (double po : {0.0, 90.0, 180.0}) {
                const Vec3d wi = test::dir(ti, 0), wo = test::dir(to, po);
                const Rgbd f = m->eval(wi, wo), back = m->eval(wo, wi);
                const Vec3d h = normalize(wi + wo);
                const Rgbd F =
                    belcour_barla_fresnel(2.5, 2 * 2.5 * 60 / 1000.0, Rgbd(2.74, 2.54, 2.26),
                                          Rgbd(3.79 / 2.74, 3.43 / 2.54, 3.07 / 2.26), dot(wi, h));
                for (int c = 0; c < 3; ++c) {
                    EXPECT_NEAR(f[c], back[c], 1e-12 * f[c]) << ti << " " << to << " " << po;
                    const double want =
                        ggx.D(h) * ggx.G1(wi) * ggx.G1(wo) * F[c] / (4 * wi.z * wo.z);
                    EXPECT_NEAR(f[c], want, 1e-12 * want) << ti << " " << to << " " << po;
                }
            }
}

// A smooth interface: no lobe, one delta lobe along the mirror carrying the Fresnel term at μi.
TEST(BelcourBarla, SmoothInterfaceIsADeltaLobe) {
    const Stack s =
        bare_metal(Rgbd(0.143, 0.374, 1.442), Rgbd(3.983, 2.385, 1.603), 0, 1.8, 300, 300);
    const auto m = make_model("bb17", s);
    const Vec3d wi = test::dir(40, 0);
    EXPECT_EQ(m->eval(wi, test::dir(40, 180))[0], 0.0);
    const std::vector<DeltaLobe> lobes = m->delta_lobes(wi);
    ASSERT_EQ(lobes.size(), 1u);
    const Rgbd F = belcour_barla_fresnel(1.8, 2 * 1.8 * 300 / 1000.0, Rgbd(0.143, 0.374, 1.442),
                                         Rgbd(3.983 / 0.143, 2.385 / 0.374, 1.603 / 1.442), wi.z);
    for (int c = 0; c < 3; ++c)
        EXPECT_DOUBLE_EQ(lobes[0].energy[c], F[c]);
    EXPECT_NEAR(lobes[0].direction.x, -wi.x, 1e-15);
    EXPECT_NEAR(lobes[0].direction.z, wi.z, 1e-15);
}

// The stacks it represents: a conductor under the ambient, with or without a transparent film of
// at least the ambient's index. Not a coat, not a dielectric base, not an absorbing film, not a
// film of lower index than the ambient (where the shader's total reflection is unset).
TEST(BelcourBarla, RepresentsOneFilmedConductor) {
    const Rgbd eta(2.74, 2.54, 2.26), k(3.79, 3.43, 3.07);
    EXPECT_TRUE(make_model("bb17", bare_metal(eta, k, 0.1))->support().brdf);
    EXPECT_TRUE(make_model("bb17", bare_metal(eta, k, 0.1, 2.5, 60, 120))->support().brdf);
    EXPECT_FALSE(make_model("bb17", bare_metal(eta, k, 0.1))->support().btdf);
    Stack absorbing = bare_metal(eta, k, 0.1, 2.3, 80, 80);
    absorbing.layers[0].interface.film.k = 0.1;
    EXPECT_FALSE(make_model("bb17", absorbing)->support().brdf);
    Stack under_water = bare_metal(eta, k, 0.1, 1.3, 80, 80);
    under_water.ambient_eta = 1.33;
    const Support low = make_model("bb17", under_water)->support();
    EXPECT_FALSE(low.brdf);
    EXPECT_NE(low.reason.find("total reflection"), std::string::npos) << low.reason;
    // A base without extinction below the film's index: the shader's dielectric branch would
    // reflect totally and leave the reflectance unset.
    EXPECT_FALSE(
        make_model("bb17", bare_metal(Rgbd(1.2, 2.0, 2.0), Rgbd(0.0, 1.0, 1.0), 0.1, 1.5, 80, 80))
            ->support()
            .brdf);
    EXPECT_TRUE(
        make_model("bb17", bare_metal(Rgbd(1.6, 2.0, 2.0), Rgbd(0.0, 1.0, 1.0), 0.1, 1.5, 80, 80))
            ->support()
            .brdf);
    EXPECT_FALSE(
        make_model("bb17", test::coated(1.5, 0.1, test::conductor(eta, k, 0.1)))->support().brdf);
    EXPECT_FALSE(make_model("bb17", test::single(test::dielectric(1.5, 0.1)))->support().brdf);
}

// A smooth clear interface of the ambient's own index is no interface: the conductor under it is
// the bare one (the shape the coats take for a bare metal), value for value. Any other top refuses.
TEST(BelcourBarla, IndexMatchedTopIsTheBareMetal) {
    const Rgbd eta(2.74, 2.54, 2.26), k(3.79, 3.43, 3.07);
    for (double ambient : {1.0, 1.33}) {
        Stack bare = bare_metal(eta, k, 0.2, 2.5, 60, 90);
        bare.ambient_eta = ambient;
        Stack matched = test::coated(ambient, 0, bare.layers[0].interface);
        matched.ambient_eta = ambient;
        const auto a = make_model("bb17", bare), b = make_model("bb17", matched);
        ASSERT_TRUE(b->support().brdf) << b->support().reason;
        for (double ti : {0.0, 50.0})
            for (double to : {20.0, 75.0}) {
                const Vec3d wi = test::dir(ti, 0), wo = test::dir(to, 150);
                const Rgbd fa = a->eval(wi, wo), fb = b->eval(wi, wo);
                for (int c = 0; c < 3; ++c)
                    EXPECT_EQ(fa[c], fb[c]) << ambient << " " << ti << " " << to;
            }
        for (auto [eta0, alpha0] : {std::pair{ambient + 0.01, 0.0}, std::pair{ambient, 0.1}}) {
            Stack other = test::coated(eta0, alpha0, bare.layers[0].interface);
            other.ambient_eta = ambient;
            EXPECT_FALSE(make_model("bb17", other)->support().brdf) << eta0 << " " << alpha0;
        }
    }
}

// kappa3=extinction hands the shader κ3 = k: its base is then η(1 + ik), another metal. Without a
// film the Fresnel term's ratio between two angles is that metal's conductor Fresnel ratio.
TEST(BelcourBarla, ExtinctionAsKappa3IsAnotherMetal) {
    const Rgbd eta(1.2, 0.96, 0.65), k(7.3, 6.4, 5.4);
    const Stack s = bare_metal(eta, k, 0);
    const auto exact = make_model("bb17", s), as_k = make_model("bb17:kappa3=extinction", s);
    const Rgbd a1 = exact->delta_lobes(test::dir(0, 0))[0].energy,
               a2 = exact->delta_lobes(test::dir(80, 0))[0].energy,
               b1 = as_k->delta_lobes(test::dir(0, 0))[0].energy,
               b2 = as_k->delta_lobes(test::dir(80, 0))[0].energy;
    const double mu = std::cos(80 * std::numbers::pi / 180);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(a2[c] / a1[c],
                    fresnel_conductor(mu, eta[c], k[c]) / fresnel_conductor(1.0, eta[c], k[c]),
                    1e-12);
        EXPECT_NEAR(b2[c] / b1[c],
                    fresnel_conductor(mu, eta[c], eta[c] * k[c]) /
                        fresnel_conductor(1.0, eta[c], eta[c] * k[c]),
                    1e-12);
    }
}

}  // namespace
}  // namespace lamina

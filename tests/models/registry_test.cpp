// The registry: one table of models, explicit errors for unknown names and options.
#include "models/registry.h"
#include "core/error.h"
#include "test_stacks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace lamina {
namespace {

TEST(ModelRegistry, ListsTheSixModelsOfTheStudyAndTheRandomWalk) {
    std::map<std::string, std::vector<std::string>> by_group;
    for (const auto& e : model_registry()) {
        by_group[e.group].push_back(e.name);
        EXPECT_FALSE(e.description.empty());
        EXPECT_FALSE(e.supports.empty());
        const auto& groups = model_groups();
        EXPECT_NE(std::find(groups.begin(), groups.end(), e.group), groups.end()) << e.name;
        for (const auto& o : e.options()) {
            EXPECT_NE(std::find(o.values.begin(), o.values.end(), o.default_value), o.values.end())
                << e.name << " " << o.key;
        }
    }
    EXPECT_EQ(by_group["2019"],
              (std::vector<std::string>{"ww09", "ele10", "ww-prime", "bel18-forward",
                                        "bel18-symmetric", "bel-prime"}));
    EXPECT_EQ(by_group["successors"], (std::vector<std::string>{"wb20", "tm2", "tm6", "ddb22"}));
    EXPECT_EQ(by_group["lamina"], (std::vector<std::string>{"lamina-1", "lamina-coat"}));
    EXPECT_EQ(by_group["reference"], (std::vector<std::string>{"random-walk"}));
}

// An anisotropic stack (docs/physics.md §3) is built only by the models that represent anisotropy;
// every other one reports it as not supported, saying why, rather than returning an isotropic
// stack's values.
TEST(ModelRegistry, OnlyModelsThatRepresentAnisotropyAreBuiltForIt) {
    Stack brushed = test::coated(1.5, 0.1, anisotropic(test::gold(0.3), 0.3, 0.05, 20.0));
    ASSERT_TRUE(brushed.is_anisotropic());
    int represented = 0;
    for (const auto& e : model_registry()) {
        const auto model = make_model(e.name, brushed);
        if (e.represents_anisotropy) {
            ++represented;
            EXPECT_TRUE(model->support().brdf) << e.name << ": " << model->support().reason;
        } else {
            EXPECT_FALSE(model->support().brdf || model->support().btdf) << e.name;
            EXPECT_NE(model->support().reason.find("anisotropic"), std::string::npos) << e.name;
        }
    }
    EXPECT_GE(represented, 1);  // the random walk
    EXPECT_TRUE(find_model("random-walk").represents_anisotropy);
}

// A model built for an anisotropic or a filmed stack must read what it claims to represent: its
// values change when the base's brushing turns by 90° (out of the plane of incidence, where an
// anisotropic lobe is not symmetric), or when the film's thickness changes. A model that built
// the stack and ignored the anisotropy or the film would return the same values and fail here,
// whatever its registry entry says.
TEST(ModelRegistry, ModelsBuiltForAnisotropyOrFilmsDependOnThem) {
    const auto brushed = [](double tangent_deg) {
        return test::coated(1.5, 0.1, anisotropic(test::gold(0.3), 0.3, 0.05, tangent_deg));
    };
    // A film's own model (group "films") has no coat: its filmed stack is the bare metal.
    const auto filmed = [](double thickness_nm, bool coated) {
        InterfaceSpec base = test::gold(0.2);
        base.has_film = true;
        base.film.thickness_nm = base.film.thickness_max_nm = thickness_nm;
        base.film.eta = 1.8;
        return coated ? test::coated(1.5, 0.1, base) : test::single(base);
    };
    const Vec3d wi = normalize(Vec3d(0.4, 0.3, 0.8)), wo = normalize(Vec3d(-0.2, -0.5, 0.7));
    // Whether `name` is built for both stacks as its flag says, and then tells them apart.
    const auto built_and_depends = [&](const std::string& name, bool flag, const Stack& a,
                                       const Stack& b, const char* what) {
        const auto ma = make_model(name, a), mb = make_model(name, b);
        EXPECT_EQ(ma->support().brdf, flag) << name << " " << what;
        if (!ma->support().brdf) return 0;
        const double fa = ma->eval(wi, wo)[1], fb = mb->eval(wi, wo)[1];
        EXPECT_GT(std::abs(fa - fb), 1e-3 * std::abs(fa))
            << name << " is built for the " << what << " stack but ignores it";
        return 1;
    };
    int anisotropic_built = 0, filmed_built = 0;
    for (const auto& e : model_registry()) {
        if (e.stochastic) continue;  // the random walk: tested against the goniophotometer
        anisotropic_built += built_and_depends(e.name, e.represents_anisotropy, brushed(20),
                                               brushed(110), "anisotropic");
        const bool coated = e.group != "films";
        filmed_built +=
            built_and_depends(e.name, e.films, filmed(150, coated), filmed(400, coated), "filmed");
    }
    EXPECT_GE(anisotropic_built, 2);  // the OpenPBR coats
    EXPECT_GE(filmed_built, 5);  // three.js's, openpbr-bsdf's, Cycles', OpenPBR's and bb17's films
}

TEST(ModelRegistry, ListsTheProductionCoats) {
    std::vector<std::string> names;
    for (const auto& e : model_registry())
        if (e.group == "production") {
            names.push_back(e.name);
            EXPECT_FALSE(e.stochastic);
        }
    EXPECT_EQ(names,
              (std::vector<std::string>{
                  "openpbr", "openpbr-adobe", "standard-surface", "enterprise-pbr", "filament",
                  "gltf-clearcoat", "blender-principled", "kulla-conty", "threejs-clearcoat",
                  "openpbr-materialx", "unity-stacklit", "standard-surface-materialx"}));
}

TEST(ModelRegistry, UnknownNameListsTheKnownOnes) {
    try {
        find_model("ww10");
        FAIL();
    } catch (const InputError& e) {
        EXPECT_EQ(e.field(), "--model");
        EXPECT_NE(std::string(e.what()).find("ww-prime"), std::string::npos);
    }
}

TEST(ModelRegistry, OptionsAreValidated) {
    const ModelEntry& ww = find_model("ww09");
    EXPECT_EQ(resolve_options(ww, {}).at("refraction-normal"), "h");
    EXPECT_EQ(resolve_options(ww, {"refraction-normal=n"}).at("refraction-normal"), "n");
    EXPECT_THROW(resolve_options(ww, {"refraction-normal"}), InputError);
    EXPECT_THROW(resolve_options(ww, {"refraction-normal=x"}), InputError);
    EXPECT_THROW(resolve_options(ww, {"tir=on"}), InputError);
    EXPECT_EQ(resolve_options(find_model("bel18-symmetric"), {}).at("cosine"), "symmetric");
    EXPECT_EQ(resolve_options(find_model("bel-prime"), {}).at("cosine"), "forward");
    // A key given twice (a spec's flag and an --option, or two of either) has no one meaning.
    try {
        resolve_options(ww, {"refraction-normal=n", "refraction-normal=h"});
        ADD_FAILURE() << "a key given twice was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("'refraction-normal' of model 'ww09' given twice (n, "
                                             "then h)"),
                  std::string::npos)
            << e.what();
    }
    EXPECT_THROW(make_model("ww09:refraction-normal=n", test::single(test::gold(0.3)),
                            {"refraction-normal=n"}),
                 InputError);
}

}  // namespace
}  // namespace lamina

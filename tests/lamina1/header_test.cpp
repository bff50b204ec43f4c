// lamina-1's header library reading its data file (include/lamina1/tables.h, the bytes
// `lamina export --lamina1-tables` writes) against lamina's own lamina-1 model, which reads
// lamina's cached tables (the FGD table in full; the data file holds its bins, from which the
// header rebuilds the nodes a material reads): eval, pdf and sample agree to 1e-6 relative on
// every study configuration and example stack, with the default choices (the multiple-scattering
// orders restored on isotropic interfaces), the Walter masking and single scattering.
#include "layers/stack.h"
#include "models/lamina1/lamina1.h"
#include "study/configurations.h"

#include "lamina1/lamina1.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

namespace lamina {
namespace {

lamina1::Vec3 direction(double u1, double u2, bool upper) {
    const double z = std::sqrt(1 - u1), r = std::sqrt(u1), phi = 2 * lamina1::kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), upper ? z : -z};
}

void expect_close(double a, double b, const std::string& what) {
    EXPECT_LE(std::abs(a - b), 1e-6 * std::max(std::abs(a), std::abs(b)) + 1e-300)
        << what << ": " << a << " vs " << b;
}

TEST(Lamina1Header, DataFileEqualsLaminasTables) {
    lamina1::Tables file;
    std::string error;
    ASSERT_TRUE(file.deserialize(lamina1_tables_file(), &error)) << error;
    ASSERT_FALSE(file.has_full_fgd());

    std::vector<Stack> stacks;
    for (const StudyConfiguration& c : builtin_configurations())
        stacks.push_back(c.stack);
    // The brushed metals and lacquers (anisotropic coat and base).
    for (const StudyConfiguration& c : brushed_configurations())
        stacks.push_back(c.stack);
    const std::size_t n_configurations = stacks.size();
    for (const auto& entry :
         std::filesystem::directory_iterator(std::filesystem::path(LAMINA_SOURCE_DIR) / "examples"))
        if (entry.path().extension() == ".json") stacks.push_back(load_stack(entry.path()));

    struct Variant {
        const char* name;
        lamina1::Options options;
    };
    std::vector<Variant> variants(3);
    variants[0].name = "default";
    variants[1].name = "walter";
    variants[1].options.masking = lamina1::Masking::Walter;
    variants[2].name = "single";
    variants[2].options.microsurface = lamina1::Options::Microsurface::Single;

    int compared = 0;
    std::mt19937_64 rng(11);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    for (std::size_t s = 0; s < stacks.size(); ++s) {
        lamina1::Layers layers;
        std::string why;
        if (!lamina1_layers(stacks[s], layers, why)) continue;
        for (std::size_t v = 0; v < variants.size(); ++v) {
            // The study's configurations with the default choices; the examples with all three.
            if (v > 0 && s < n_configurations) continue;
            const lamina1::Options& o = variants[v].options;
            const lamina1::Bsdf own(layers, lamina1_tables(o.masking, true), o);
            const lamina1::Bsdf read(layers, file, o);
            const std::string where = stacks[s].name + " " + variants[v].name;
            ASSERT_EQ(own.support().brdf, read.support().brdf) << where;
            for (int i = 0; i < 40; ++i) {
                const lamina1::Vec3 wi = direction(U(rng), U(rng), true);
                const lamina1::Vec3 wo = direction(U(rng), U(rng), !own.support().btdf || i % 2);
                const lamina1::Rgb a = own.eval(wi, wo), b = read.eval(wi, wo);
                for (int c = 0; c < 3; ++c)
                    expect_close(a[c], b[c], where + " eval");
                expect_close(own.pdf(wi, wo), read.pdf(wi, wo), where + " pdf");
                const lamina1::Vec3 u(U(rng), U(rng), U(rng));
                const auto sa = own.sample(wi, u), sb = read.sample(wi, u);
                ASSERT_EQ(bool(sa), bool(sb)) << where;
                if (sa) {
                    expect_close(sa->wo.z, sb->wo.z, where + " sample");
                    expect_close(sa->pdf, sb->pdf, where + " sample pdf");
                    expect_close(sa->weight[1], sb->weight[1], where + " sample weight");
                }
                ++compared;
            }
        }
    }
    EXPECT_GT(compared, 68 * 40);
}

TEST(Lamina1Header, DamagedDataFileIsRefused) {
    const std::string bytes = lamina1_tables_file();
    lamina1::Tables t;
    std::string error;
    EXPECT_FALSE(t.deserialize(bytes.substr(0, bytes.size() / 2), &error));
    EXPECT_NE(error.find("truncated"), std::string::npos) << error;
    EXPECT_FALSE(t.deserialize("{\"a\": 1}", &error));
    EXPECT_EQ(error, "not a lamina-1 tables file");
    std::string other_version = bytes;
    other_version[16] = 9;
    EXPECT_FALSE(t.deserialize(other_version, &error));
    EXPECT_NE(error.find("version"), std::string::npos) << error;
    // A section whose element type is not its own (here the axes' text declared as doubles,
    // which would read eight bytes an element): refused before anything is read.
    std::string other_type = bytes;
    other_type[24 + 24] = 1;  // the first section (axes): its type field after the 24-byte name
    EXPECT_FALSE(t.deserialize(other_type, &error));
    EXPECT_EQ(error, "element type of axes") << error;
}

}  // namespace
}  // namespace lamina

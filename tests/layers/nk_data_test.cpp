// The measured optical constants shipped in data/nk/ (data/nk/README.md): every file reads as
// wavelength_nm,n,k rows with increasing wavelengths that cover 360–830 nm, and every value in
// that range lies inside the stack format's conductor ranges (docs/stack-format.md).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lamina {
namespace {

TEST(MeasuredMetals, CoverTheVisibleWithinTheConductorRanges) {
    const std::filesystem::path dir = std::filesystem::path(LAMINA_SOURCE_DIR) / "data" / "nk";
    int files = 0;
    for (const char* metal : {"Au", "Ag", "Cu", "Al", "Cr", "Ti", "Ni", "Fe", "Pt"}) {
        SCOPED_TRACE(metal);
        std::ifstream in(dir / (std::string(metal) + ".csv"));
        ASSERT_TRUE(in) << metal;
        std::string line;
        std::getline(in, line);
        EXPECT_EQ(line, "wavelength_nm,n,k");
        double previous = 0, first = 0, last = 0;
        int rows = 0;
        while (std::getline(in, line)) {
            std::istringstream row(line);
            double wavelength = 0, n = 0, k = 0;
            char c1 = 0, c2 = 0;
            row >> wavelength >> c1 >> n >> c2 >> k;
            ASSERT_TRUE(row && c1 == ',' && c2 == ',') << line;
            EXPECT_GT(wavelength, previous);
            if (wavelength >= 360 && wavelength <= 830) {  // not the samples beyond either end
                EXPECT_GE(n, 0.01);
                EXPECT_LE(n, 10.0);
                EXPECT_GE(k, 0.0);
                EXPECT_LE(k, 10.0);
            }
            if (rows++ == 0) first = wavelength;
            previous = last = wavelength;
        }
        EXPECT_LE(first, 360.0);
        EXPECT_GE(last, 830.0);
        EXPECT_GE(rows, 8);
        ++files;
    }
    EXPECT_EQ(files, 9);
}

}  // namespace
}  // namespace lamina

// Spectral stack values (docs/stack-format.md, "Spectra"): the dispersion formulas, the named
// materials against their published indices, the reader's checks and the canonical form's round
// trip, and the colour tables against the CIE's white point of D65.
#include "layers/spectrum.h"
#include "core/error.h"
#include "layers/colorimetry.h"
#include "layers/stack.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>

namespace lamina {
namespace {

// The Abbe number's definition, V = (n_d − 1)/(n_F − n_C) (ISO 7944).
double abbe_number(const Spectrum& s) {
    return (s.at(587.56) - 1) / (s.at(486.13) - s.at(656.27));
}

TEST(Spectrum, GlassesHaveTheirPublishedIndices) {
    // N-BK7: n_d = 1.5168, V_d = 64.17 (SCHOTT data sheet); fused silica n_d = 1.4585 (Malitson);
    // water at 20 °C n = 1.3334 at 587.56 nm (Daimon & Masumura's fit).
    const Spectrum bk7 = glass_material_eta("BK7");
    EXPECT_NEAR(bk7.at(587.56), 1.5168, 1e-4);
    EXPECT_NEAR(abbe_number(bk7), 64.17, 0.02);
    EXPECT_NEAR(glass_material_eta("fused_silica").at(587.56), 1.4585, 1e-4);
    EXPECT_NEAR(glass_material_eta("water").at(587.56), 1.3334, 1e-4);
    // Normal dispersion: the index falls with the wavelength.
    for (const char* glass : {"BK7", "fused_silica", "water"}) {
        const Spectrum s = glass_material_eta(glass);
        for (double l = 360; l < 830; l += 10)
            EXPECT_GT(s.at(l), s.at(l + 10)) << glass << " at " << l;
    }
}

TEST(Spectrum, AbbeReproducesItsNumbers) {
    const Spectrum s = abbe_spectrum(1.62, 36.4);
    EXPECT_NEAR(s.at(587.56), 1.62, 1e-12);
    EXPECT_NEAR(abbe_number(s), 36.4, 1e-9);
}

TEST(Spectrum, TableInterpolatesLinearlyAndHoldsItsEnds) {
    const Spectrum s = table_spectrum({400, 500, 700}, {0.2, 0.4, 0.0});
    EXPECT_DOUBLE_EQ(s.at(450), 0.3);
    EXPECT_DOUBLE_EQ(s.at(600), 0.2);
    EXPECT_DOUBLE_EQ(s.at(360), 0.2);
    EXPECT_DOUBLE_EQ(s.at(830), 0.0);
    // Cauchy: n = A + B/λ² (λ in µm).
    EXPECT_DOUBLE_EQ(cauchy_spectrum({1.5, 0.01}).at(500), 1.5 + 0.01 / 0.25);
}

TEST(Spectrum, MetalsAreTheirMeasuredSamples) {
    // Gold at 616.8 nm in Johnson & Christy: n = 0.21, k = 3.272 (data/nk/Au.csv).
    for (const char* metal : {"Au", "Ag", "Cu", "Al", "Cr", "Ti", "Ni", "Fe", "Pt"}) {
        EXPECT_TRUE(is_conductor_material(metal));
        const Spectrum k = conductor_material_k(metal);
        EXPECT_GT(k.at(550), 0.5) << metal;
    }
    EXPECT_FALSE(is_conductor_material("Unobtainium"));
}

TEST(SpectralStack, ReadsEveryFormAndWritesItBack) {
    const char* text = R"({"name": "s", "layers": [
        {"interface": {"type": "dielectric", "eta": {"material": "BK7"}, "alpha": 0.1},
         "medium": {"tau_a": {"spectrum": [[400, 1.0], [700, 0.0]]}, "tau_s": 0.5}},
        {"interface": {"type": "dielectric", "eta": {"sellmeier": [1.0, 0.01]}, "alpha": 0},
         "medium": {"tau_a": 0.1}},
        {"interface": {"type": "dielectric", "eta": {"cauchy": [1.4, 0.004]}, "alpha": 0},
         "medium": {"tau_a": 0.1}},
        {"interface": {"type": "dielectric", "eta": {"abbe": [1.6, 40]}, "alpha": 0.2}},
        {"interface": {"type": "conductor", "material": "Au", "alpha": 0.1}}]})";
    const Stack s = parse_stack(text, "s.json");
    EXPECT_TRUE(s.is_spectral());
    // The RGB values are the spectra at the channels' wavelengths; a dielectric's eta at green's.
    EXPECT_DOUBLE_EQ(s.layers[0].interface.eta, glass_material_eta("BK7").at(532));
    EXPECT_NEAR(s.layers[0].medium.tau_a[0], (700 - 630.0) / 300, 1e-12);
    EXPECT_NEAR(s.layers[0].medium.tau_a[2], (700 - 465.0) / 300, 1e-12);
    EXPECT_DOUBLE_EQ(s.layers[4].interface.k[0], conductor_material_k("Au").at(630));
    EXPECT_EQ(stack_from_json(stack_to_json(s), "again"), s);
    EXPECT_NE(describe(s).find("conductor Au"), std::string::npos);
    // The stack at other wavelengths, its path at channel 2's.
    const Stack at = s.at_wavelengths(Rgbd(400, 500, 600), 2);
    EXPECT_DOUBLE_EQ(at.layers[0].interface.eta, glass_material_eta("BK7").at(600));
    EXPECT_DOUBLE_EQ(at.layers[4].interface.eta_rgb[0], conductor_material_eta("Au").at(400));
}

// An RGB value given as numbers is, at other wavelengths, the number of the channel whose
// wavelength is nearest (630, 532 and 465 nm by default): a reddish albedo stays reddish when a
// spectral run reads it at 400, 550 and 700 nm (blue's, green's and red's numbers, in that
// order), and at the stack's own wavelengths every number is itself; a conductor's RGB index, a
// medium's optical depths and its g likewise, and a spectrum beside them is read as before.
TEST(SpectralStack, RgbNumbersAreTheNearestChannelsSpectrum) {
    const char* text = R"({"name": "s", "layers": [
        {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.1},
         "medium": {"tau_a": [0.1, 0.2, 0.3], "tau_s": {"spectrum": [[400, 1.0], [700, 0.0]]},
                    "g": [0.5, 0.0, -0.5]}},
        {"interface": {"type": "dielectric", "eta": 1.3, "alpha": 0.1}},
        {"interface": {"type": "lambertian", "albedo": [0.8, 0.5, 0.2]}}]})";
    const Stack s = parse_stack(text, "s.json");
    const Stack same = s.at_wavelengths(s.wavelengths_nm, 1);
    EXPECT_EQ(same, s);
    const Stack at = s.at_wavelengths(Rgbd(400, 550, 700), 1);
    EXPECT_EQ(at.layers[2].interface.albedo, Rgbd(0.2, 0.5, 0.8));
    EXPECT_EQ(at.layers[0].medium.tau_a, Rgbd(0.3, 0.2, 0.1));
    EXPECT_EQ(at.layers[0].medium.g, Rgbd(-0.5, 0.0, 0.5));
    EXPECT_NEAR(at.layers[0].medium.tau_s[0], 1.0, 1e-12);
    EXPECT_NEAR(at.layers[0].medium.tau_s[2], 0.0, 1e-12);
    // The edges between channels: the midpoints of 465, 532 and 630 nm.
    const Stack edges = s.at_wavelengths(Rgbd(498, 499, 582), 1);
    EXPECT_EQ(edges.layers[2].interface.albedo, Rgbd(0.2, 0.5, 0.8));
    // One wavelength in every channel (a dispersive projection's node): one number.
    EXPECT_EQ(s.at_wavelengths(Rgbd(520), 1).layers[2].interface.albedo, Rgbd(0.5));
    // Channel wavelengths that repeat one: each channel keeps its own number at its own
    // wavelength.
    Stack repeated = s;
    repeated.wavelengths_nm = Rgbd(532, 532, 465);
    EXPECT_EQ(repeated.at_wavelengths(repeated.wavelengths_nm, 1).layers[2].interface.albedo,
              Rgbd(0.8, 0.5, 0.2));
    // A conductor given as RGB numbers.
    Stack metal = parse_stack(R"({"name": "m", "layers": [{"interface": {"type": "conductor",
        "eta": [0.2, 0.4, 1.4], "k": [3.9, 2.4, 1.6], "alpha": 0.1}}]})",
                              "m.json");
    const Stack metal_at = metal.at_wavelengths(Rgbd(450, 540, 650), 0);
    EXPECT_EQ(metal_at.layers[0].interface.eta_rgb, Rgbd(1.4, 0.4, 0.2));
    EXPECT_EQ(metal_at.layers[0].interface.k, Rgbd(1.6, 2.4, 3.9));
}

TEST(SpectralStack, RefusesBadSpectraByName) {
    auto error = [](const std::string& interface) {
        try {
            parse_stack(R"({"layers": [{"interface": )" + interface + "}]}", "bad.json");
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error(R"({"type": "conductor", "material": "Gold", "alpha": 0})").find("\"Au\""),
              std::string::npos);
    EXPECT_NE(
        error(R"({"type": "conductor", "material": "Au", "eta": 1, "alpha": 0})").find("either"),
        std::string::npos);
    EXPECT_NE(
        error(R"({"type": "dielectric", "eta": {"material": "glass"}, "alpha": 0})").find("BK7"),
        std::string::npos);
    // An index below 1 somewhere in 360–830 nm names the wavelength.
    EXPECT_NE(
        error(R"({"type": "dielectric", "eta": {"cauchy": [0.9, 0.01]}, "alpha": 0})").find(" nm"),
        std::string::npos);
    EXPECT_NE(error(R"({"type": "lambertian", "albedo": {"spectrum": [[500, 0.5], [400, 0.2]]}})")
                  .find("increasing"),
              std::string::npos);
    EXPECT_NE(error(R"({"type": "lambertian", "albedo": {"abbe": [1.5, 50]}})").find("spectrum"),
              std::string::npos);
}

// The CIE tables (data/cie) give D65's white point: x = 0.31271, y = 0.32902 (CIE 015:2018,
// Table 5, 5 nm sums), and the sRGB of that XYZ is (1, 1, 1) to the rounding of the matrix.
TEST(Colorimetry, D65WhitePoint) {
    Rgbd sum(0.0);
    for (int l = 360; l <= 830; l += 5)
        sum += d65_xyz_weights(l);
    const double total = sum[0] + sum[1] + sum[2];
    EXPECT_NEAR(sum[0] / total, 0.31271, 2e-5);
    EXPECT_NEAR(sum[1] / total, 0.32902, 2e-5);
    const Rgbd srgb = xyz_to_linear_srgb(sum / sum[1]);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(srgb[c], 1.0, 2e-4);
    EXPECT_EQ(d65_xyz_weights(359.9), Rgbd(0.0));
}

}  // namespace
}  // namespace lamina

// A study (or `lamina compare`) of a spectral stack: its reference is traced spectrally and
// tabulated in linear sRGB, and its models are compared in the same colour — the projection of
// their spectra (models/spectral_projection.h), not their values at the channels' wavelengths.
#include "study/study.h"

#include "layers/stack.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/spectral_projection.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace lamina {
namespace {

TEST(StudySpectral, ModelsAreComparedInTheReferencesColour) {
    const std::filesystem::path dir =
        std::filesystem::path(LAMINA_BINARY_DIR) / "test-output" / "spectral-study";
    std::filesystem::remove_all(dir);
    StudyConfiguration config;
    config.id = "gold-spectral";
    config.category = "spectral";
    config.stack = parse_stack(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.2}},
            {"interface": {"type": "conductor", "material": "Au", "alpha": 0.3}}]})",
        "test");
    StudySettings s;
    s.models = {"openpbr"};
    s.reference.theta_i_deg = {30};
    s.reference.particles = 20'000;
    s.reference.grid = HemisphereGrid(9, 6);
    s.quiet = true;
    const StudyResult r = run_study({config}, s, dir);

    const auto projected = make_spectral_projection(
        [](const Stack& at) { return make_model("openpbr", at); }, config.stack);
    const Rgbd want = bin_model(*projected, s.reference.grid, {30}).albedo(0, Side::Reflection);
    const Rgbd at_channels = bin_model(*make_model("openpbr", config.stack), s.reference.grid, {30})
                                 .albedo(0, Side::Reflection);
    int rows = 0;
    for (const MetricRow& row : r.rows) {
        if (row.model != "openpbr") continue;
        ++rows;
        ASSERT_TRUE(row.supported);
        const int c = row.channel;
        EXPECT_NEAR(row.metrics.albedo_model, want[c], 1e-9 * want[c]) << "channel " << c;
        // The colour is not the three point samples: gold's blue differs by several per cent.
        if (c == 2) {
            EXPECT_GT(std::abs(want[c] / at_channels[c] - 1), 0.01);
        }
    }
    EXPECT_EQ(rows, 3);

    // config.json says the channels are colour, and over which range.
    std::ifstream in(dir / "configs" / "gold-spectral" / "config.json");
    const nlohmann::json cj = nlohmann::json::parse(in);
    ASSERT_TRUE(cj.contains("spectral"));
    EXPECT_EQ(cj["spectral"]["min_nm"].get<double>(), s.reference.spectral_min_nm);
    EXPECT_EQ(cj["spectral"]["max_nm"].get<double>(), s.reference.spectral_max_nm);
}

}  // namespace
}  // namespace lamina

// The report library without a browser: the .npy reader and write_explorer on a tiny study
// directory written here (docs/formats.md). The page itself is tested in Chromium by the ctest
// `browser` (tests/report/browser_test.js).
#include "report/explorer.h"
#include "core/error.h"
#include "core/npy.h"
#include "core/packed_array.h"

#include <gtest/gtest.h>
#include <omp.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace lamina {
namespace {

fs::path fresh_dir(const std::string& name) {
    const fs::path d = fs::temp_directory_path() / ("lamina-report-test-" + name);
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
}

void write_text(const fs::path& p, const std::string& text) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << text;
}

// A version 1.0 .npy file, header padded to a multiple of 64 bytes as NumPy writes it.
void write_npy(const fs::path& p, const std::vector<std::size_t>& shape,
               const std::vector<float>& data, const std::string& descr = "<f4") {
    std::string dims;
    for (std::size_t n : shape)
        dims += std::to_string(n) + ", ";
    std::string header =
        "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
    header += std::string((64 - (10 + header.size() + 1) % 64) % 64, ' ') + "\n";
    std::ofstream out(p, std::ios::binary);
    out.write("\x93NUMPY\x01\x00", 8);
    const std::uint16_t len = std::uint16_t(header.size());
    out.put(char(len & 0xff));
    out.put(char(len >> 8));
    out << header;
    out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size() * 4));
}

std::string read_text(const fs::path& p) {
    std::ifstream in(p);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(Npy, ReadsShapeAndData) {
    const fs::path d = fresh_dir("npy");
    write_npy(d / "a.npy", {2, 3}, {0, 1, 2, 3, 4, 5.5f});
    const NpyFloat32 a = read_npy_float32(d / "a.npy");
    EXPECT_EQ(a.shape, (std::vector<std::size_t>{2, 3}));
    ASSERT_EQ(a.data.size(), 6u);
    EXPECT_EQ(a.data[5], 5.5f);
}

TEST(Npy, RejectsOtherTypesAndTruncation) {
    const fs::path d = fresh_dir("npy-bad");
    write_npy(d / "f8.npy", {1}, {0, 0}, "<f8");
    EXPECT_THROW(read_npy_float32(d / "f8.npy"), InputError);
    write_npy(d / "short.npy", {4}, {1, 2});
    try {
        read_npy_float32(d / "short.npy");
        FAIL() << "a truncated file was read";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("short.npy"), std::string::npos) << e.what();
    }
    EXPECT_THROW(read_npy_float32(d / "missing.npy"), InputError);
}

TEST(Explorer, MissingStudyNamesStudyJson) {
    const fs::path d = fresh_dir("missing");
    try {
        write_explorer(d);
        FAIL() << "no study.json, yet a page was written";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("study.json"), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(d / "index.html"));
}

// A study's float32 table as a packed array (what lamina writes) or as .npy (older studies).
void write_table(const fs::path& stem, const std::vector<std::size_t>& shape,
                 const std::vector<float>& values, bool packed) {
    if (packed) {
        fs::create_directories(stem.parent_path());
        std::ofstream(fs::path(stem.string() + ".lza"), std::ios::binary)
            << packed_array_file(values, shape, /*half=*/false);
    } else {
        write_npy(fs::path(stem.string() + ".npy"), shape, values);
    }
}

// One configuration, reference + one model, one incidence, a 2 × 2 grid, f = 1/π everywhere for
// the reference (albedo exactly 1: Σ Ω⊥ over the hemisphere is π) and 2/π for the model; the
// tables packed (.lza) and, as older studies hold them, .npy.
class ExplorerTables : public ::testing::TestWithParam<bool> {};

TEST_P(ExplorerTables, WritesPageDataAndAlbedos) {
    const fs::path d = fresh_dir(GetParam() ? "tiny-lza" : "tiny-npy");
    write_text(d / "study.json", R"({"theta_i": [30], "grid": {"n_theta": 2, "n_phi": 2},
        "models": ["ww09"], "preset": "test",
        "configurations": [{"id": "c1", "category": "plastic",
                            "parameters": {"alpha0": "0.1"}, "sides": ["R"]}]})");
    write_text(d / "configs/c1/config.json", R"({"id": "c1", "sources": ["reference", "ww09"],
        "sides": ["R"], "supported": {"ww09": {"R": true, "T": false, "reason": ""}}})");
    std::vector<float> tables(2 * 2 * 2 * 3);
    for (std::size_t k = 0; k < tables.size(); ++k)
        tables[k] = float((k < 12 ? 1 : 2) / M_PI);
    write_table(d / "configs/c1/tables", {2, 1, 1, 2, 2, 3}, tables, GetParam());
    write_table(d / "configs/c1/reference_se", {1, 1, 2, 2, 3}, std::vector<float>(12, 0.01f),
                GetParam());
    write_text(d / "metrics.csv",
               "config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,"
               "albedo_ref,albedo_model,albedo_error,rmse,log_rmse,noise_floor,"
               "misplaced_floor_noise,supported\n"
               "c1,plastic,ww09,30,R,g,1,0.9,1,2,1,0.3,0.2,0.01,0.02,true\n");

    const ExplorerSummary s = write_explorer(d);
    EXPECT_EQ(s.configurations, 1u);
    for (const char* f :
         {"index.html", "explorer/plotly.min.js", "explorer/explorer.js", "explorer/colour.js",
          "explorer/explorer.css", "explorer/data/index.js", "explorer/data/c1.js"})
        EXPECT_TRUE(fs::exists(d / f)) << f;
    EXPECT_GT(fs::file_size(d / "explorer/plotly.min.js"), 1000000u);
    EXPECT_NE(read_text(d / "index.html").find("explorer/data/index.js"), std::string::npos);

    std::string index = read_text(d / "explorer/data/index.js");
    const std::string prefix = "window.LAMINA_INDEX = ";
    ASSERT_EQ(index.rfind(prefix, 0), 0u);
    index = index.substr(prefix.size());
    index.erase(index.find_last_of(';'));
    const nlohmann::json j = nlohmann::json::parse(index);
    const auto& c = j["configs"][0];
    EXPECT_EQ(c["id"], "c1");
    EXPECT_NEAR(c["albedo"]["reference"]["R"][0][1].get<double>(), 1.0, 1e-6);
    EXPECT_NEAR(c["albedo"]["ww09"]["R"][0][1].get<double>(), 2.0, 1e-6);
    EXPECT_NEAR(j["metrics"]["c1"]["ww09"]["R"]["me"][0][1].get<double>(), 1.0, 1e-12);
    EXPECT_TRUE(j["metrics"]["c1"]["ww09"]["R"]["me"][0][0].is_null());  // a row not given
    // The one colour table (web/model-colors.json) travels with the page.
    EXPECT_EQ(j["palette"]["models"]["ww09"], "#E69F00");
    EXPECT_TRUE(j["palette"]["extra"].is_array());
    EXPECT_NEAR(j["metrics"]["c1"]["ww09"]["R"]["mf"][0][1].get<double>(), 0.9, 1e-12);
    EXPECT_NEAR(j["metrics"]["c1"]["ww09"]["R"]["nf_mf"][0][1].get<double>(), 0.02, 1e-12);
    EXPECT_NE(read_text(d / "explorer/data/c1.js").find("LAMINA_DATA"), std::string::npos);
    // No staging folder is left behind.
    for (const auto& e : fs::recursive_directory_iterator(d))
        EXPECT_EQ(e.path().filename().string().rfind(".staging", 0), std::string::npos) << e.path();
}

// The configurations are encoded side by side over the threads: the page's data are the same for
// one thread as for three, and the index keeps the study's order.
TEST(Explorer, PageDataDoNotDependOnTheThreadCount) {
    std::map<int, std::map<std::string, std::string>> pages;
    for (int threads : {1, 3}) {
        const fs::path d = fresh_dir("threads");  // the same folder: its name is the page's title
        std::string configs;
        for (int k = 5; k >= 1; --k) {  // listed in reverse: the index must keep this order
            const std::string id = fmt::format("c{}", k);
            configs += fmt::format(R"({}{{"id": "{}", "category": "plastic", "sides": ["R"]}})",
                                   configs.empty() ? "" : ",", id);
            write_text(d / "configs" / id / "config.json",
                       R"({"sources": ["reference", "ww09"], "sides": ["R"],
                           "supported": {"ww09": {"R": true, "T": false, "reason": ""}}})");
            std::vector<float> tables(2 * 2 * 2 * 3);
            for (std::size_t j = 0; j < tables.size(); ++j)
                tables[j] = float((1 + k * (j % 5)) / M_PI);
            write_table(d / "configs" / id / "tables", {2, 1, 1, 2, 2, 3}, tables, true);
            write_table(d / "configs" / id / "reference_se", {1, 1, 2, 2, 3},
                        std::vector<float>(12, 0.01f * float(k)), true);
        }
        write_text(d / "study.json", R"({"theta_i": [30], "grid": {"n_theta": 2, "n_phi": 2},
            "models": ["ww09"], "preset": "test", "configurations": [)" +
                                         configs + "]}");
        write_text(d / "metrics.csv",
                   "config,category,model,theta_i,side,channel,misplaced_energy,misplaced_floor,"
                   "albedo_ref,albedo_model,albedo_error,rmse,log_rmse,noise_floor,"
                   "misplaced_floor_noise,supported\n");
        omp_set_num_threads(threads);
        write_explorer(d);
        omp_set_num_threads(omp_get_num_procs());
        for (const auto& e : fs::directory_iterator(d / "explorer" / "data"))
            pages[threads][e.path().filename().string()] = read_text(e.path());
    }
    EXPECT_EQ(pages[1].size(), 7u);  // five configurations, the index, the stamps
    for (const auto& [name, text] : pages[1]) {
        EXPECT_EQ(pages[3][name], text) << name;
    }
    const std::string& index = pages[3]["index.js"];
    EXPECT_LT(index.find(R"("id":"c5")"), index.find(R"("id":"c1")"));
}

TEST_P(ExplorerTables, TableShapeMismatchNamesTheFile) {
    const fs::path d = fresh_dir(GetParam() ? "shape-lza" : "shape-npy");
    write_text(d / "study.json", R"({"theta_i": [0, 30], "grid": {"n_theta": 2, "n_phi": 2},
        "configurations": [{"id": "c1", "category": "x", "sides": ["R"]}]})");
    write_text(d / "configs/c1/config.json", R"({"sources": ["reference"], "sides": ["R"]})");
    write_table(d / "configs/c1/tables", {1, 1, 1, 2, 2, 3}, std::vector<float>(12, 1.0f),
                GetParam());
    try {
        write_explorer(d);
        FAIL() << "a table of the wrong shape was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(GetParam() ? "tables.lza" : "tables.npy"),
                  std::string::npos)
            << e.what();
    }
}

// The polarization view's data come from configs/<id>/reference_stokes.lza when the study stored
// it (its values are checked against the files in Chromium, browser_polarization.js): absent
// without the file, present with it, and a file of the wrong shape is named.
TEST(Explorer, PolarizationDataFromReferenceStokes) {
    const fs::path d = fresh_dir("stokes");
    write_text(d / "study.json", R"({"theta_i": [30], "grid": {"n_theta": 2, "n_phi": 2},
        "configurations": [{"id": "c1", "category": "x", "sides": ["R"]}]})");
    write_text(d / "configs/c1/config.json", R"({"sources": ["reference"], "sides": ["R"]})");
    write_table(d / "configs/c1/tables", {1, 1, 1, 2, 2, 3}, std::vector<float>(12, 0.3f), true);
    write_explorer(d);
    EXPECT_EQ(read_text(d / "explorer/data/c1.js").find("\"polarization\""), std::string::npos);
    std::vector<float> stokes(2 * 1 * 1 * 3 * 2 * 2 * 3, 0.01f);
    write_table(d / "configs/c1/reference_stokes", {2, 1, 1, 3, 2, 2, 3}, stokes, true);
    write_explorer(d);
    const std::string data = read_text(d / "explorer/data/c1.js");
    for (const char* key : {"\"polarization\"", "\"dop\"", "\"dop_se\"", "\"aolp\""})
        EXPECT_NE(data.find(key), std::string::npos) << key;
    write_table(d / "configs/c1/reference_stokes", {2, 1, 1, 3, 2, 1, 3},
                std::vector<float>(36, 0.01f), true);
    try {
        write_explorer(d);
        FAIL() << "a reference_stokes.lza of the wrong shape was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("reference_stokes.lza"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("shape"), std::string::npos) << e.what();
    }
}

// lamina-1's states for the live spheres (config.json → lamina1_gpu, lamina1_gpu.f32) go into the
// page data as base64 of the file's bytes with their layout; a file of the wrong size or a missing
// one is refused, naming it. The page's shaders are written beside it (explorer/glsl.js).
TEST(Explorer, Lamina1StatesForTheLiveSpheres) {
    const fs::path d = fresh_dir("lamina1-gpu");
    write_text(d / "study.json", R"({"theta_i": [30], "grid": {"n_theta": 2, "n_phi": 2},
        "configurations": [{"id": "c1", "category": "x", "sides": ["R"]}]})");
    const std::string gpu = R"({"file": "lamina1_gpu.f32", "state": 2, "head": 1,
        "variants": [["alpha0", 0.3]]})";
    write_text(d / "configs/c1/config.json",
               R"({"sources": ["reference"], "sides": ["R"], "lamina1_gpu": )" + gpu + "}");
    write_table(d / "configs/c1/tables", {1, 1, 1, 2, 2, 3}, std::vector<float>(12, 0.3f), true);
    const float floats[3] = {1.0f, 2.0f, 3.0f};  // state (2 floats), one head (1 float)
    std::ofstream(d / "configs/c1/lamina1_gpu.f32", std::ios::binary)
        .write(reinterpret_cast<const char*>(floats), sizeof floats);
    write_explorer(d);
    const std::string data = read_text(d / "explorer/data/c1.js");
    // base64 of the 12 bytes 00 00 80 3f 00 00 00 40 00 00 40 40 (1.0f, 2.0f, 3.0f little-endian)
    EXPECT_NE(data.find(R"("floats":"AACAPwAAAEAAAEBA")"), std::string::npos)
        << data.substr(0, 300);
    EXPECT_NE(data.find(R"("variants":[["alpha0",0.3]])"), std::string::npos);
    const std::string glsl = read_text(d / "explorer/glsl.js");
    for (const char* key : {"lamina1_eval", "lamina_coat_eval", "\"laminaCoatTable\":[65535,"})
        EXPECT_NE(glsl.find(key), std::string::npos) << key;
    EXPECT_TRUE(fs::exists(d / "explorer/spheres.js"));
    std::ofstream(d / "configs/c1/lamina1_gpu.f32", std::ios::binary)
        .write(reinterpret_cast<const char*>(floats), 8);
    try {
        write_explorer(d);
        FAIL() << "a lamina1_gpu.f32 of the wrong size was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("lamina1_gpu.f32"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("8 bytes"), std::string::npos) << e.what();
    }
    fs::remove(d / "configs/c1/lamina1_gpu.f32");
    try {
        write_explorer(d);
        FAIL() << "a missing lamina1_gpu.f32 was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos) << e.what();
    }
}

// A slab's states end with its bins (`tail`): each variant's part is its head then its tail, and
// the file's size is checked against that layout.
TEST(Explorer, Lamina1StatesWithASlabsBins) {
    const fs::path d = fresh_dir("lamina1-gpu-tail");
    write_text(d / "study.json", R"({"theta_i": [30], "grid": {"n_theta": 2, "n_phi": 2},
        "configurations": [{"id": "c1", "category": "x", "sides": ["R"]}]})");
    write_text(d / "configs/c1/config.json",
               R"({"sources": ["reference"], "sides": ["R"], "lamina1_gpu": {"file":
        "lamina1_gpu.f32", "state": 3, "head": 1, "tail": 1, "variants": [["alpha0", 0.3]]}})");
    write_table(d / "configs/c1/tables", {1, 1, 1, 2, 2, 3}, std::vector<float>(12, 0.3f), true);
    const float floats[5] = {1.0f, 2.0f, 3.0f, 4.0f, 5.0f};  // state (3), head (1) and tail (1)
    std::ofstream(d / "configs/c1/lamina1_gpu.f32", std::ios::binary)
        .write(reinterpret_cast<const char*>(floats), sizeof floats);
    write_explorer(d);
    const std::string data = read_text(d / "explorer/data/c1.js");
    EXPECT_NE(data.find(R"("tail":1)"), std::string::npos) << data.substr(0, 300);
    // Without the tail's float per variant the file is one float short.
    std::ofstream(d / "configs/c1/lamina1_gpu.f32", std::ios::binary)
        .write(reinterpret_cast<const char*>(floats), 16);
    try {
        write_explorer(d);
        FAIL() << "a lamina1_gpu.f32 without the variant's tail was accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("16 bytes"), std::string::npos) << e.what();
    }
}

INSTANTIATE_TEST_SUITE_P(Formats, ExplorerTables, ::testing::Values(true, false),
                         [](const auto& info) { return info.param ? "packed" : "npy"; });

}  // namespace
}  // namespace lamina

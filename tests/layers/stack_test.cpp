// Stack files (docs/stack-format.md): valid parses, broadcasting, defaults, the canonical JSON
// round trip, and one test per kind of bad input, each checking that the single error names the
// file, the JSON pointer of the field, the offending value and what is allowed.
#include "layers/stack.h"
#include "core/error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <string>

namespace lamina {
namespace {

using json = nlohmann::json;
namespace fs = std::filesystem;

const fs::path kExamples = fs::path(LAMINA_SOURCE_DIR) / "examples";

/// A valid two-layer stack (the benchmark plastic) to break one field at a time.
json plastic() {
    return json::parse(R"({
        "name": "red plastic", "ambient_eta": 1.0,
        "layers": [
          {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.05},
           "medium": {"tau_a": [0.1, 0.0, 0.9], "tau_s": 0, "g": 0}},
          {"interface": {"type": "lambertian", "albedo": [0.8, 0.2, 0.1]}}]})");
}

/// A valid coat over a conductor.
json paint() {
    return json::parse(R"({
        "layers": [
          {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0.05},
           "medium": {"tau_a": 0.1}},
          {"interface": {"type": "conductor", "eta": [0.143, 0.374, 1.442],
                         "k": [3.983, 2.385, 1.603], "alpha": 0.3}}]})");
}

json with(json j, const std::string& pointer, json value) {
    j[json::json_pointer(pointer)] = std::move(value);
    return j;
}

json without(json j, const std::string& pointer) {
    const json::json_pointer p(pointer);
    j[p.parent_pointer()].erase(p.back());
    return j;
}

/// The message of the InputError that parsing `j` as "bad.json" throws ("" and a failure if none).
std::string error_of(const json& j) {
    try {
        stack_from_json(j, "bad.json");
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), "bad.json");
        return e.what();
    }
    ADD_FAILURE() << "accepted: " << j.dump();
    return "";
}

/// Writes `text` to a fresh file and returns the message of the InputError load_stack throws.
std::string load_error_of(const std::string& text, const std::string& file = "bad.json") {
    const fs::path dir = fs::path(testing::TempDir()) / "lamina_stack_test";
    fs::create_directories(dir);
    const fs::path path = dir / file;
    std::ofstream(path) << text;
    try {
        load_stack(path);
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), path.string());
        return e.what();
    }
    ADD_FAILURE() << "accepted: " << text;
    return "";
}

void expect_mentions(const std::string& message, std::initializer_list<std::string> fragments) {
    for (const auto& f : fragments)
        EXPECT_NE(message.find(f), std::string::npos) << "'" << f << "' not in: " << message;
}

// ---- Valid input ----------------------------------------------------------------------------

TEST(StackParse, ReadsTheFormatOfPhysicsNotes) {
    const Stack s = stack_from_json(plastic(), "plastic.json");
    EXPECT_EQ(s.name, "red plastic");
    EXPECT_EQ(s.ambient_eta, 1.0);
    ASSERT_EQ(s.layers.size(), 2u);
    const Layer& coat = s.layers[0];
    EXPECT_EQ(coat.interface.type, InterfaceType::Dielectric);
    EXPECT_EQ(coat.interface.eta, 1.5);
    EXPECT_EQ(coat.interface.alpha, 0.05);
    EXPECT_TRUE(coat.has_medium);
    EXPECT_EQ(coat.medium.tau_a, Rgbd(0.1, 0.0, 0.9));
    EXPECT_FALSE(coat.medium.scatters());
    EXPECT_EQ(s.base().type, InterfaceType::Lambertian);
    EXPECT_EQ(s.base().albedo, Rgbd(0.8, 0.2, 0.1));
    EXPECT_FALSE(s.layers[1].has_medium);
    EXPECT_FALSE(s.transmits());
    EXPECT_EQ(s.eta_above(1), 1.5);
}

TEST(StackParse, ScalarsBroadcastToRgb) {
    json j = with(plastic(), "/layers/0/medium/tau_a", 0.25);
    j = with(j, "/layers/0/medium/tau_s", 0.5);
    j = with(j, "/layers/0/medium/g", -0.3);
    j = with(j, "/layers/1/interface/albedo", 0.8);
    const Stack s = stack_from_json(j, "x");
    EXPECT_EQ(s.layers[0].medium.tau_a, Rgbd(0.25));
    EXPECT_EQ(s.layers[0].medium.tau_s, Rgbd(0.5));
    EXPECT_EQ(s.layers[0].medium.g, Rgbd(-0.3));
    EXPECT_EQ(s.base().albedo, Rgbd(0.8));

    json c = with(paint(), "/layers/1/interface/eta", 0.2);
    c = with(c, "/layers/1/interface/k", 3);  // integers are numbers too
    const Stack p = stack_from_json(c, "x");
    EXPECT_EQ(p.base().eta_rgb, Rgbd(0.2));
    EXPECT_EQ(p.base().k, Rgbd(3.0));
}

TEST(StackParse, Defaults) {
    // name: the file stem; ambient_eta: 1; medium keys: 0; no medium: none.
    json j = without(without(plastic(), "/name"), "/ambient_eta");
    j["layers"][0]["medium"] = json::object();
    const Stack s = stack_from_json(j, "dir/some-stack.json");
    EXPECT_EQ(s.name, "some-stack");
    EXPECT_EQ(s.ambient_eta, 1.0);
    EXPECT_TRUE(s.layers[0].has_medium);
    EXPECT_EQ(s.layers[0].medium, MediumSpec{});
    EXPECT_TRUE(s.layers[0].medium.is_empty());

    const Stack bare = stack_from_json(without(plastic(), "/layers/0/medium"), "x.json");
    EXPECT_FALSE(bare.layers[0].has_medium);
    const Stack scattering =
        stack_from_json(with(plastic(), "/layers/0/medium", {{"tau_s", 0.5}}), "x");
    EXPECT_EQ(scattering.layers[0].medium.tau_a, Rgbd(0.0));
    EXPECT_EQ(scattering.layers[0].medium.g, Rgbd(0.0));
    EXPECT_TRUE(scattering.layers[0].medium.scatters());
}

TEST(StackParse, AmbientAndSingleInterfaces) {
    const Stack water = stack_from_json(json::parse(R"({"ambient_eta": 1.33, "layers": [
            {"interface": {"type": "dielectric", "eta": 1.0, "alpha": 0.1}}]})"),
                                        "x");
    EXPECT_EQ(water.ambient_eta, 1.33);
    EXPECT_EQ(water.eta_above(0), 1.33);
    EXPECT_TRUE(water.transmits());
    const Stack metal =
        stack_from_json(with(paint(), "/layers", json::array({paint()["layers"][1]})), "x");
    EXPECT_EQ(metal.layers.size(), 1u);
    EXPECT_TRUE(metal.base().is_opaque());
}

TEST(StackParse, LoadsEveryExample) {
    const Stack plastic = load_stack(kExamples / "plastic.json");
    EXPECT_EQ(plastic.layers[0].interface.alpha, 0.2);
    EXPECT_EQ(plastic.layers[0].interface.eta, 1.5);
    EXPECT_EQ(plastic.layers[0].medium.tau_a, Rgbd(0.1, 0.0, 0.9));
    EXPECT_EQ(plastic.base().albedo, Rgbd(0.8));

    const Stack paint = load_stack(kExamples / "metallic-paint.json");
    EXPECT_EQ(paint.layers[0].interface.alpha, 0.05);
    EXPECT_EQ(paint.layers[0].medium.tau_a, Rgbd(0.1));
    EXPECT_EQ(paint.base().type, InterfaceType::Conductor);
    EXPECT_EQ(paint.base().eta_rgb, Rgbd(0.2));
    EXPECT_EQ(paint.base().k, Rgbd(3.0));
    EXPECT_EQ(paint.base().alpha, 0.3);

    const Stack gold = load_stack(kExamples / "frosted-gold.json");
    EXPECT_EQ(gold.layers[0].interface.alpha, 0.3);
    EXPECT_TRUE(gold.layers[0].medium.is_empty());
    EXPECT_EQ(gold.base().eta_rgb, Rgbd(0.143, 0.374, 1.442));
    EXPECT_EQ(gold.base().k, Rgbd(3.983, 2.385, 1.603));
    EXPECT_EQ(gold.base().alpha, 0.05);

    const Stack slab = load_stack(kExamples / "slab.json");
    EXPECT_TRUE(slab.transmits());
    EXPECT_EQ(slab.layers[0].interface.alpha, 0.1);
    EXPECT_EQ(slab.base().eta, 1.0);
    EXPECT_EQ(slab.base().alpha, 0.3);

    const Stack milky = load_stack(kExamples / "milky-coat.json");
    EXPECT_TRUE(milky.layers[0].medium.scatters());
    EXPECT_EQ(milky.layers[0].medium.tau_s, Rgbd(0.5));
    EXPECT_EQ(milky.layers[0].medium.g, Rgbd(0.3));
    EXPECT_EQ(milky.base().type, InterfaceType::Lambertian);

    for (const auto& entry : fs::directory_iterator(kExamples)) {
        if (entry.path().extension() != ".json") continue;
        const Stack s = load_stack(entry.path());
        EXPECT_FALSE(s.name.empty()) << entry.path() << " should carry a name";
        EXPECT_EQ(stack_from_json(stack_to_json(s), "x"), s) << entry.path();
    }
}

// ---- Canonical form and round trip ----------------------------------------------------------

TEST(StackRoundTrip, CanonicalFormHasRgbArraysAndOnlyTheKeysOfEachType) {
    const json j = stack_to_json(stack_from_json(paint(), "paint.json"));
    EXPECT_EQ(j["name"], "paint");
    EXPECT_EQ(j["ambient_eta"], 1.0);
    EXPECT_EQ(j["layers"][0]["interface"],
              json::parse(R"({"type": "dielectric", "eta": 1.5, "alpha": 0.05})"));
    EXPECT_EQ(j["layers"][0]["medium"],
              json::parse(R"({"tau_a": [0.1, 0.1, 0.1], "tau_s": [0, 0, 0], "g": [0, 0, 0]})"));
    EXPECT_EQ(j["layers"][1]["interface"],
              json::parse(R"({"type": "conductor", "eta": [0.143, 0.374, 1.442],
                              "k": [3.983, 2.385, 1.603], "alpha": 0.3})"));
    EXPECT_FALSE(j["layers"][1].contains("medium"));
}

TEST(StackRoundTrip, ThroughJsonValueAndText) {
    Stack scattering;
    scattering.name = "three layers";
    scattering.ambient_eta = 1.33;
    Layer top;
    top.interface.eta = 1.5;
    top.interface.alpha = 0.3;
    top.has_medium = true;
    top.medium.tau_a = Rgbd(0.1, 0.2, 0.3);
    top.medium.tau_s = Rgbd(0.5, 1.0, 2.0);
    top.medium.g = Rgbd(0.3, -0.2, 0.9);
    Layer middle;
    middle.interface.eta = 1.2;
    middle.interface.alpha = 0.0;
    middle.has_medium = true;
    middle.medium.tau_a = Rgbd(1.0 / 3.0);  // not exactly representable in decimal
    Layer base;
    base.interface.type = InterfaceType::Conductor;
    base.interface.eta_rgb = Rgbd(0.143, 0.374, 1.442);
    base.interface.k = Rgbd(3.983, 2.385, 1.603);
    base.interface.alpha = 0.05;
    scattering.layers = {top, middle, base};

    Stack slab;
    slab.name = "slab";
    Layer face;
    face.interface.eta = 1.5;
    face.interface.alpha = 0.001;
    face.has_medium = true;
    face.medium.tau_a = Rgbd(0.1, 0.0, 0.9);
    Layer back;
    back.interface.eta = 1.0;
    back.interface.alpha = 0.3;
    slab.layers = {face, back};

    Stack lambert;
    lambert.name = "matte";
    Layer matte;
    matte.interface.type = InterfaceType::Lambertian;
    matte.interface.albedo = Rgbd(0.8, 0.2, 0.1);
    lambert.layers = {matte};

    for (const Stack& s : {scattering, slab, lambert, stack_from_json(plastic(), "x"),
                           stack_from_json(paint(), "x")}) {
        EXPECT_EQ(stack_from_json(stack_to_json(s), "x"), s) << s.name;
        EXPECT_EQ(stack_from_json(json::parse(stack_to_json(s).dump()), "x"), s) << s.name;
    }
}

// ---- describe -------------------------------------------------------------------------------

TEST(StackDescribe, OneReadableLine) {
    const std::string plastic_line = describe(stack_from_json(plastic(), "x"));
    EXPECT_EQ(plastic_line,
              "red plastic: air | dielectric η=1.5 α=0.05 | medium τa=(0.1, 0, 0.9) | lambertian "
              "ρ=(0.8, 0.2, 0.1)");
    const std::string paint_line = describe(stack_from_json(paint(), "paint.json"));
    expect_mentions(paint_line,
                    {"paint: air", "medium τa=0.1 |",
                     "conductor η=(0.143, 0.374, 1.442) k=(3.983, 2.385, 1.603) α=0.3"});
    EXPECT_EQ(paint_line.find('\n'), std::string::npos);

    const std::string milky = describe(load_stack(kExamples / "milky-coat.json"));
    expect_mentions(milky, {"τs=0.5", "g=0.3"});
    const std::string slab = describe(load_stack(kExamples / "slab.json"));
    expect_mentions(slab, {"slab", "transmits"});
    const std::string water = describe(stack_from_json(with(plastic(), "/ambient_eta", 1.33), "x"));
    expect_mentions(water, {"ambient η=1.33"});
}

// ---- Bad input: one test per kind ------------------------------------------------------------

TEST(StackReject, MalformedJsonWithLineAndColumn) {
    const std::string m =
        load_error_of("{\n  \"layers\": [\n    {\"interface\": {\"type\" \"dielectric\"}}\n  ]\n}");
    expect_mentions(m, {"bad.json", "malformed JSON", "line 3, column"});
    expect_mentions(load_error_of("", "empty.json"), {"empty.json", "malformed JSON"});
}

TEST(StackReject, NotAnObject) {
    expect_mentions(error_of(json::array({1, 2})),
                    {"bad.json", "JSON object", "an array", "[1,2]", "\"layers\""});
    expect_mentions(error_of("plastic"), {"JSON object", "a string", "\"plastic\""});
}

TEST(StackReject, UnknownKeysAtEveryLevelWithSuggestion) {
    json typo = plastic();
    typo["layers"][0]["interface"]["alpah"] = 0.05;
    typo["layers"][0]["interface"].erase("alpha");
    expect_mentions(error_of(typo),
                    {"bad.json", "/layers/0/interface/alpah", "unknown key \"alpah\"",
                     "did you mean \"alpha\"?", "\"type\", \"eta\", \"alpha\""});

    expect_mentions(error_of(with(plastic(), "/layer", json::array())),
                    {"/layer:", "did you mean \"layers\"?",
                     "\"name\", \"ambient_eta\", \"wavelengths_nm\", \"layers\""});
    expect_mentions(error_of(with(plastic(), "/layers/0/meduim", json::object())),
                    {"/layers/0/meduim", "did you mean \"medium\"?", "\"interface\", \"medium\""});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_b", 0.1)),
                    {"/layers/0/medium/tau_b", "\"tau_a\", \"tau_s\", \"g\""});
    // A key of another interface type is unknown here.
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/alpha", 0.1)),
                    {"/layers/1/interface/alpha", "lambertian", "\"type\", \"albedo\""});
    // Names from other renderers point to lamina's.
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/roughness", 0.1)),
                    {"did you mean \"alpha\"?"});
    // Keys holding '/' or '~' are escaped in the pointer (RFC 6901).
    expect_mentions(error_of(with(plastic(), "/a~1b", 1)), {"/a~1b:", "unknown key \"a/b\""});
}

TEST(StackReject, DuplicateKeys) {
    const std::string m = load_error_of(
        R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0, "alpha": 0.1}}]})");
    expect_mentions(m, {"bad.json", "/layers/0/interface/alpha", "duplicate key \"alpha\""});
}

TEST(StackReject, WrongTypes) {
    expect_mentions(
        error_of(with(plastic(), "/layers/0/interface/eta", "1.5")),
        {"bad.json", "/layers/0/interface/eta", "expected a number", "a string", "\"1.5\""});
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/albedo", true)),
                    {"/layers/1/interface/albedo", "a boolean", "true"});
    expect_mentions(error_of(with(plastic(), "/layers", json::object())),
                    {"/layers:", "expected an array", "an object"});
    expect_mentions(error_of(with(plastic(), "/layers/0", 3)),
                    {"/layers/0:", "expected a layer", "\"interface\", \"medium\"", "a number"});
    expect_mentions(error_of(with(plastic(), "/layers/0/interface", "dielectric")),
                    {"/layers/0/interface:", "expected an interface", "\"dielectric\""});
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/type", 1)),
                    {"/layers/0/interface/type:", "expected a string", "\"lambertian\""});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium", json::array())),
                    {"/layers/0/medium:", "expected a medium", "an array"});
    expect_mentions(error_of(with(plastic(), "/name", 7)),
                    {"/name:", "expected a non-empty string", "a number", "7"});
    expect_mentions(error_of(with(plastic(), "/ambient_eta", nullptr)),
                    {"/ambient_eta:", "expected a number", "null"});
}

TEST(StackReject, RgbArraysOfTheWrongLength) {
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/albedo", {0.8, 0.2})),
                    {"bad.json", "/layers/1/interface/albedo", "an array of 3 numbers",
                     "an array of 2", "[0.8,0.2]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_a", {0.1, 0, 0.9, 1})),
                    {"/layers/0/medium/tau_a", "an array of 4"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_a", {0.1, "0", 0.9})),
                    {"/layers/0/medium/tau_a/1", "expected a number", "\"0\""});
}

TEST(StackReject, NonFiniteNumbers) {
    // JSON text cannot hold NaN or inf, but 1e999 overflows a double.
    expect_mentions(load_error_of(R"({"layers": [
        {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0},
         "medium": {"tau_a": [0.1, 1e999, 0]}},
        {"interface": {"type": "lambertian", "albedo": 1}}]})"),
                    {"bad.json", "/layers/0/medium/tau_a/1", "1e999", "finite"});
    expect_mentions(load_error_of(R"({"ambient_eta": -1e999, "layers": []})"),
                    {"/ambient_eta", "-1e999", "finite"});
    // A document built in code can hold them.
    const double inf = std::numeric_limits<double>::infinity();
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/eta", inf)),
                    {"/layers/0/interface/eta", "inf", "finite"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/g", {0.0, 0.0, std::nan("")})),
                    {"/layers/0/medium/g/2", "nan", "finite"});
}

TEST(StackReject, EtaOutsideItsRange) {
    // Dielectric and ambient: [1, 5]; conductor: [0.01, 10] (docs/stack-format.md, "Ranges").
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/eta", 0)),
                    {"bad.json", "/layers/0/interface/eta", "got 0", "[1, 5]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/eta", 1e308)),
                    {"/layers/0/interface/eta", "got 1e+308", "[1, 5]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/eta", 0.99)),
                    {"/layers/0/interface/eta", "got 0.99", "[1, 5]"});
    expect_mentions(error_of(with(paint(), "/layers/1/interface/eta/2", -1.4)),
                    {"/layers/1/interface/eta/2", "got -1.4", "[0.01, 10]"});
    expect_mentions(error_of(with(paint(), "/layers/1/interface/eta/0", 1e-320)),
                    {"/layers/1/interface/eta/0", "got 1e-320", "[0.01, 10]"});
    expect_mentions(error_of(with(plastic(), "/ambient_eta", -1)),
                    {"/ambient_eta", "got -1", "[1, 5]"});
    expect_mentions(error_of(with(plastic(), "/ambient_eta", 1e-320)),
                    {"/ambient_eta", "got 1e-320", "[1, 5]"});
    expect_mentions(error_of(with(plastic(), "/ambient_eta", 5.000000000000001)),
                    {"/ambient_eta", "got 5.000000000000001", "[1, 5]"});
}

TEST(StackParse, AcceptsTheBoundsOfEveryRange) {
    auto accepted = [](const json& j) {
        EXPECT_NO_THROW(stack_from_json(j, "ok.json")) << j.dump();
    };
    for (double eta : {1.0, 5.0}) {
        accepted(with(plastic(), "/layers/0/interface/eta", eta));
        accepted(with(plastic(), "/ambient_eta", eta));
    }
    for (double eta : {0.01, 10.0})
        accepted(with(paint(), "/layers/1/interface/eta", eta));
    for (double k : {0.0, 10.0})
        accepted(with(paint(), "/layers/1/interface/k", k));
    for (double alpha : {0.0, 1e-4, 1.0})
        accepted(with(plastic(), "/layers/0/interface/alpha", alpha));
    for (double tau : {0.0, 5e-324, 100.0}) {
        accepted(with(plastic(), "/layers/0/medium/tau_a", tau));
        accepted(with(plastic(), "/layers/0/medium/tau_s", tau));
    }
    accepted(with(plastic(), "/layers/0/medium/tau_s", 1e4));  // a white paint
    for (double g : {-0.99, 0.0, 5e-324, 0.99})
        accepted(with(plastic(), "/layers/0/medium/g", g));
    // A hundred layers: 99 coats over a base.
    json many = plastic();
    json coat = many["layers"][0];
    while (many["layers"].size() < 100)
        many["layers"].insert(many["layers"].begin(), coat);
    accepted(many);
    many["layers"].insert(many["layers"].begin(), coat);
    expect_mentions(error_of(many), {"/layers", "101 layers", "at most 100"});
}

TEST(StackParse, NegativeZeroIsReadAsZero) {
    const Stack s = stack_from_json(with(plastic(), "/layers/0/interface/alpha", -0.0), "z.json");
    EXPECT_EQ(s.layers[0].interface.alpha, 0.0);
    EXPECT_FALSE(std::signbit(s.layers[0].interface.alpha));
}

TEST(StackReject, DielectricEtaMustBeScalar) {
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/eta", {1.5, 1.5, 1.5})),
                    {"bad.json", "/layers/0/interface/eta", "single number", "[1.5,1.5,1.5]",
                     "one refraction path serves all channels"});
}

TEST(StackReject, AlphaOutsideItsRange) {
    expect_mentions(
        error_of(with(plastic(), "/layers/0/interface/alpha", 1.5)),
        {"bad.json", "/layers/0/interface/alpha", "got 1.5", "0 (smooth) or [0.0001, 1]"});
    expect_mentions(error_of(with(paint(), "/layers/1/interface/alpha", -0.1)),
                    {"/layers/1/interface/alpha", "got -0.1", "[0.0001, 1]"});
    // Rougher than a mirror but smoother than any surface geometric optics describes.
    expect_mentions(error_of(with(plastic(), "/layers/0/interface/alpha", 1e-300)),
                    {"/layers/0/interface/alpha", "got 1e-300", "0 (smooth) or [0.0001, 1]"});
}

TEST(StackReject, OpticalDepthsOutsideTheirRange) {
    expect_mentions(
        error_of(with(plastic(), "/layers/0/medium/tau_a/2", -0.9)),
        {"bad.json", "/layers/0/medium/tau_a/2", "got -0.9", "[0, 100]", "optical depth"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_s", -1)),
                    {"/layers/0/medium/tau_s", "got -1", "[0, 10000]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_s", 1e308)),
                    {"/layers/0/medium/tau_s", "got 1e+308", "[0, 10000]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_a", 101)),
                    {"/layers/0/medium/tau_a", "got 101", "[0, 100]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/tau_s", 10001)),
                    {"/layers/0/medium/tau_s", "got 10001", "[0, 10000]"});
}

TEST(StackReject, AnisotropyOutsideItsRange) {
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/g", 1)),
                    {"bad.json", "/layers/0/medium/g", "got 1", "[-0.99, 0.99]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/g", {0, -1, 0})),
                    {"/layers/0/medium/g/1", "got -1", "[-0.99, 0.99]"});
    expect_mentions(error_of(with(plastic(), "/layers/0/medium/g", 0.995)),
                    {"/layers/0/medium/g", "got 0.995", "[-0.99, 0.99]"});
}

TEST(StackReject, AlbedoOutsideUnitInterval) {
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/albedo", 1.2)),
                    {"bad.json", "/layers/1/interface/albedo", "got 1.2", "[0, 1]"});
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/albedo/0", -0.1)),
                    {"/layers/1/interface/albedo/0", "got -0.1"});
}

TEST(StackReject, ExtinctionOutsideItsRange) {
    expect_mentions(error_of(with(paint(), "/layers/1/interface/k", {1, -2, 0})),
                    {"bad.json", "/layers/1/interface/k/1", "got -2", "[0, 10]"});
    expect_mentions(error_of(with(paint(), "/layers/1/interface/k", 1e308)),
                    {"/layers/1/interface/k", "got 1e+308", "[0, 10]"});
}

TEST(StackReject, DeeplyNestedJsonIsRefusedWithoutCrashing) {
    // 10^5 nested arrays where a number belongs: refused while parsing (depth) ...
    const std::string deep(100000, '[');
    expect_mentions(
        load_error_of("{\"ambient_eta\": " + deep + std::string(100000, ']') + ", \"layers\": []}"),
        {"/ambient_eta/0/0", "nested more than 32 levels"});
    // ... and, for JSON parsed elsewhere (study configurations), shown without recursion.
    json nested = 1;
    for (int i = 0; i < 100000; ++i)
        nested = json::array({std::move(nested)});
    expect_mentions(error_of(with(plastic(), "/ambient_eta", std::move(nested))),
                    {"/ambient_eta", "expected a number", "[[[[...]]]]"});
}

TEST(StackReject, UnknownInterfaceType) {
    expect_mentions(
        error_of(with(plastic(), "/layers/1/interface/type", "lambert")),
        {"bad.json", "/layers/1/interface/type", "\"lambert\"", "did you mean \"lambertian\"?",
         "\"dielectric\", \"conductor\", \"lambertian\""});
}

TEST(StackReject, MissingRequiredKeys) {
    expect_mentions(error_of(without(plastic(), "/layers/0/interface/alpha")),
                    {"bad.json", "/layers/0/interface/alpha", "missing required key \"alpha\"",
                     "write 0 for a smooth interface"});
    expect_mentions(error_of(without(paint(), "/layers/1/interface/k")),
                    {"/layers/1/interface/k", "missing required key \"k\""});
    expect_mentions(error_of(without(plastic(), "/layers/0/interface/eta")),
                    {"/layers/0/interface/eta", "missing required key \"eta\""});
    expect_mentions(error_of(without(plastic(), "/layers/1/interface/albedo")),
                    {"/layers/1/interface/albedo", "missing required key \"albedo\""});
    expect_mentions(error_of(without(plastic(), "/layers/1/interface/type")),
                    {"/layers/1/interface/type", "missing required key \"type\""});
    expect_mentions(error_of(without(plastic(), "/layers/1/interface")),
                    {"/layers/1/interface", "missing required key \"interface\""});
}

TEST(StackReject, OpaqueInterfaceNotLast) {
    json j = plastic();
    j["layers"].push_back(j["layers"][0]);
    expect_mentions(error_of(j), {"bad.json", "/layers/1/interface/type", "lambertian", "opaque",
                                  "must be the last", "1 more layer follows"});
    json c = paint();
    c["layers"] = json::array({c["layers"][1], c["layers"][0], c["layers"][0]});
    expect_mentions(error_of(c), {"/layers/0/interface/type", "conductor", "2 more layers follow"});
}

TEST(StackReject, MediumUnderTheLastInterface) {
    expect_mentions(error_of(with(plastic(), "/layers/1/medium", {{"tau_a", 0.1}})),
                    {"bad.json", "/layers/1/medium", "semi-infinite", "not supported"});
    json slab = json::parse(R"({"layers": [
        {"interface": {"type": "dielectric", "eta": 1.5, "alpha": 0}, "medium": {}}]})");
    expect_mentions(error_of(slab), {"/layers/0/medium", "semi-infinite"});
}

TEST(StackReject, EmptyLayers) {
    expect_mentions(error_of(with(plastic(), "/layers", json::array())),
                    {"bad.json", "/layers", "no layers"});
}

TEST(StackReject, MissingLayers) {
    expect_mentions(error_of(without(plastic(), "/layers")),
                    {"bad.json", "/layers", "missing required key \"layers\""});
}

TEST(StackReject, NameEmptyOrWithControlCharacters) {
    expect_mentions(error_of(with(plastic(), "/name", "")), {"/name", "non-empty string"});
    expect_mentions(error_of(with(plastic(), "/name", "two\nlines")),
                    {"/name", "\"two\\nlines\"", "without control characters"});
}

TEST(StackLoad, MissingOrUnreadableFile) {
    const fs::path missing = fs::path(testing::TempDir()) / "lamina_no_such_stack.json";
    try {
        load_stack(missing);
        ADD_FAILURE() << "loaded a missing file";
    } catch (const InputError& e) {
        expect_mentions(e.what(), {missing.string(), "cannot read", "no such file"});
    }
    try {
        load_stack(testing::TempDir());
        ADD_FAILURE() << "loaded a directory";
    } catch (const InputError& e) {
        expect_mentions(e.what(), {"cannot read", "directory"});
    }
}

TEST(StackLoad, NameDefaultsToTheFileStem) {
    const fs::path dir = fs::path(testing::TempDir()) / "lamina_stack_test";
    fs::create_directories(dir);
    const fs::path path = dir / "blue-glass.json";
    std::ofstream(path) << without(plastic(), "/name").dump(2);
    EXPECT_EQ(load_stack(path).name, "blue-glass");
}

// ---- Thin films (docs/physics.md §9) --------------------------------------------------------

TEST(StackFilm, ParsesOneThicknessOrARangeAndRoundTrips) {
    const Stack a = stack_from_json(
        with(paint(), "/layers/1/interface/film", {{"thickness_nm", 120}, {"eta", 2.2}}), "x");
    ASSERT_TRUE(a.layers[1].interface.has_film);
    EXPECT_EQ(a.layers[1].interface.film.thickness_nm, 120);
    EXPECT_EQ(a.layers[1].interface.film.thickness_max_nm, 120);
    EXPECT_FALSE(a.layers[1].interface.film.varies());
    EXPECT_EQ(a.layers[1].interface.film.k, 0.0);  // the default
    EXPECT_TRUE(a.has_film());
    EXPECT_EQ(a.wavelengths_nm, kDefaultChannelWavelengthsNm);
    const Stack b =
        stack_from_json(with(with(plastic(), "/layers/0/interface/film",
                                  {{"thickness_nm", {100, 300}}, {"eta", 1.33}, {"k", 0.01}}),
                             "/wavelengths_nm", {650, 550, 450}),
                        "x");
    EXPECT_TRUE(b.layers[0].interface.film.varies());
    EXPECT_EQ(b.layers[0].interface.film.thickness_max_nm, 300);
    EXPECT_EQ(b.wavelengths_nm, Rgbd(650, 550, 450));
    for (const Stack& s : {a, b}) {
        EXPECT_EQ(stack_from_json(stack_to_json(s), "x"), s);
        EXPECT_TRUE(stack_to_json(s).contains("wavelengths_nm"));
    }
    EXPECT_NE(describe(b).find("film d=[100, 300] nm η=1.33 k=0.01"), std::string::npos)
        << describe(b);
    // A stack without a film keeps the canonical form it always had.
    EXPECT_FALSE(stack_to_json(stack_from_json(plastic(), "x")).contains("wavelengths_nm"));
}

TEST(StackFilm, RejectsBadFilmsNamingTheField) {
    auto film = [](json f) { return with(plastic(), "/layers/0/interface/film", std::move(f)); };
    expect_mentions(error_of(film({{"eta", 1.4}})),
                    {"bad.json", "/layers/0/interface/film/thickness_nm", "missing"});
    expect_mentions(error_of(film({{"thickness_nm", -1}, {"eta", 1.4}})),
                    {"/layers/0/interface/film/thickness_nm", "got -1", "[0, 10000]"});
    expect_mentions(error_of(film({{"thickness_nm", {300, 100}}, {"eta", 1.4}})),
                    {"/layers/0/interface/film/thickness_nm", "min <= max"});
    expect_mentions(error_of(film({{"thickness_nm", {1, 2, 3}}, {"eta", 1.4}})),
                    {"/layers/0/interface/film/thickness_nm", "[min, max]"});
    expect_mentions(error_of(film({{"thickness_nm", 100}})),
                    {"/layers/0/interface/film/eta", "missing"});
    expect_mentions(error_of(film({{"thickness_nm", 100}, {"eta", 7}})),
                    {"/layers/0/interface/film/eta", "got 7", "[0.01, 5]"});
    expect_mentions(error_of(film({{"thickness_nm", 100}, {"eta", 1.4}, {"k", -1}})),
                    {"/layers/0/interface/film/k", "got -1", "[0, 10]"});
    expect_mentions(error_of(film({{"thickness_nm", 100}, {"eta", 1.4}, {"thickness", 1}})),
                    {"/layers/0/interface/film/thickness", "unknown key", "thickness_nm"});
    expect_mentions(error_of(film(3)), {"/layers/0/interface/film", "a thin film"});
    // Films on dielectrics and conductors only.
    expect_mentions(error_of(with(plastic(), "/layers/1/interface/film",
                                  {{"thickness_nm", 100}, {"eta", 1.4}})),
                    {"/layers/1/interface/film", "unknown key"});
    expect_mentions(error_of(with(plastic(), "/wavelengths_nm", {650, 550, 100})),
                    {"/wavelengths_nm/2", "got 100", "[360, 830]"});
    expect_mentions(error_of(with(plastic(), "/wavelengths_nm", 550)),
                    {"/wavelengths_nm", "array of 3"});
}

TEST(StackFilm, FlippedStackKeepsTheFilmOnItsInterface) {
    const Stack s = stack_from_json(
        with(json::parse(R"({"layers": [{"interface": {"type": "dielectric", "eta": 1.5,
                                                        "alpha": 0}}]})"),
             "/layers/0/interface/film", {{"thickness_nm", 90}, {"eta", 1.38}}),
        "x");
    const Stack f = flipped_stack(s);
    EXPECT_TRUE(f.layers[0].interface.has_film);
    EXPECT_EQ(f.layers[0].interface.film, s.layers[0].interface.film);
    EXPECT_EQ(f.wavelengths_nm, s.wavelengths_nm);
}

}  // namespace
}  // namespace lamina

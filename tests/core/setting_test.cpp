// Settings declared once (core/setting.h): the codecs of each type, and everything a struct's
// `fields` gives without another line: JSON both ways, the cache key's text, the command line.
#include "core/setting.h"

#include "cli/settings_options.h"
#include "layers/transport_settings.h"
#include "simulator/goniophotometer.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace lamina {
namespace {

const SettingInfo kCount{.name = "count", .help = "", .min = 1, .max = 1000};
const SettingInfo kAny{.name = "any", .help = ""};

TEST(SettingCodec, WholeNumbersInAnyNotationWithinTheirRange) {
    using C = SettingCodec<std::uint64_t>;
    EXPECT_EQ(C::from_text("1e2", kCount, "w", "f"), 100u);
    EXPECT_EQ(C::from_text("250", kCount, "w", "f"), 250u);
    EXPECT_THROW(C::from_text("2.5", kCount, "w", "f"), InputError);
    EXPECT_THROW(C::from_text("0", kCount, "w", "f"), InputError);
    EXPECT_THROW(C::from_text("1001", kCount, "w", "f"), InputError);
    EXPECT_THROW(C::from_text("-5", kCount, "w", "f"), InputError);
    EXPECT_THROW(C::from_text("ten", kCount, "w", "f"), InputError);
    // A seed uses the whole 64-bit range (the study's second half is seed + 0x9e3779b97f4a7c15).
    const std::uint64_t big = std::numeric_limits<std::uint64_t>::max();
    EXPECT_EQ(C::from_text(std::to_string(big), kAny, "w", "f"), big);
    EXPECT_EQ(C::from_json(nlohmann::json(big), kAny, "w", "f"), big);
    EXPECT_EQ(C::from_json(nlohmann::json(1e6), kAny, "w", "f"), 1000000u);
    EXPECT_THROW(C::from_json(nlohmann::json("x"), kAny, "w", "f"), InputError);
    EXPECT_THROW(C::from_json(nlohmann::json(true), kAny, "w", "f"), InputError);
}

TEST(SettingCodec, ErrorsNameWhereAndTheField) {
    try {
        SettingCodec<int>::from_text("0", kCount, "command line", "--count");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), "command line");
        EXPECT_EQ(e.field(), "--count");
        EXPECT_NE(e.problem().find("'0' is not allowed"), std::string::npos) << e.problem();
        EXPECT_NE(e.problem().find("[1, 1000]"), std::string::npos) << e.problem();
    }
}

TEST(SettingCodec, SwitchesIncidencesGridsAndEnums) {
    EXPECT_TRUE(SettingCodec<bool>::from_text("on", kAny, "w", "f"));
    EXPECT_FALSE(SettingCodec<bool>::from_json(nlohmann::json(false), kAny, "w", "f"));
    EXPECT_THROW(SettingCodec<bool>::from_text("yes", kAny, "w", "f"), InputError);

    using Angles = SettingCodec<std::vector<double>>;
    EXPECT_EQ(Angles::from_text("0, 30,60", kAny, "w", "f"), (std::vector<double>{0, 30, 60}));
    EXPECT_EQ(Angles::from_json(nlohmann::json(45), kAny, "w", "f"), std::vector<double>{45});
    EXPECT_THROW(Angles::from_text("0,90", kAny, "w", "f"), InputError);  // [0, 90)
    EXPECT_THROW(Angles::from_json(nlohmann::json::array(), kAny, "w", "f"), InputError);
    EXPECT_EQ(Angles::to_text({0, 15.5}), "0,15.5");

    using Grid = SettingCodec<HemisphereGrid>;
    for (const nlohmann::json& j : {nlohmann::json("18x12"), nlohmann::json::array({18, 12}),
                                    nlohmann::json{{"n_theta", 18}, {"n_phi", 12}}})
        EXPECT_EQ(Grid::from_json(j, kAny, "w", "f").to_string(), "18x12") << j.dump();
    EXPECT_THROW(Grid::from_text("18by12", kAny, "w", "f"), InputError);
    EXPECT_EQ(Grid::to_json(HemisphereGrid(18, 12)),
              (nlohmann::json{{"n_theta", 18}, {"n_phi", 12}}));

    using Masking = SettingCodec<TransmissionMasking>;
    EXPECT_EQ(Masking::from_text("pbrt", kAny, "w", "f"), TransmissionMasking::Pbrt);
    try {
        Masking::from_text("walter", kAny, "w", "f");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(e.problem().find("'walter' is not a transmission masking: use smith"),
                  std::string::npos)
            << e.problem();
    }
}

// A settings struct of the test's own: what a new setting gets from its one line in `fields`.
struct Demo {
    int count = 3;
    bool dummy = false;
    Microsurface microsurface = Microsurface::Single;
    int threads = 0;

    template <typename Self, typename Visit>
    static void fields(Self& s, Visit&& visit) {
        visit({.name = "count", .help = "a count", .min = 1, .max = 1000}, s.count);
        visit({.name = "dummy", .help = "a switch", .key_unsaid = "off"}, s.dummy);
        visit({.name = "microsurface", .help = "a named value", .key_unsaid = "single"},
              s.microsurface);
        visit({.name = "threads", .help = "not in the key", .key = SettingInfo::Key::No},
              s.threads);
    }
};

TEST(Settings, JsonBothWaysByName) {
    Demo d;
    d.count = 7;
    d.dummy = true;
    const nlohmann::json j = settings_to_json(d);
    EXPECT_EQ(j, (nlohmann::json{
                     {"count", 7}, {"dummy", true}, {"microsurface", "single"}, {"threads", 0}}));
    Demo back;
    settings_from_json(back, j, "file.json");
    EXPECT_EQ(back.count, 7);
    EXPECT_TRUE(back.dummy);
    Demo partial;
    settings_from_json(partial, nlohmann::json{{"microsurface", "multiple"}}, "file.json");
    EXPECT_EQ(partial.microsurface, Microsurface::Multiple);
    EXPECT_EQ(partial.count, 3);  // the others keep their values
    try {
        settings_from_json(partial, nlohmann::json{{"cuont", 2}}, "file.json");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.where(), "file.json");
        EXPECT_EQ(e.field(), "cuont");
        EXPECT_NE(e.problem().find("count, dummy, microsurface, threads"), std::string::npos);
    }
    EXPECT_THROW(settings_from_json(partial, nlohmann::json{{"count", 0}}, "f"), InputError);
}

TEST(Settings, KeyTextSaysOnlyWhatDiffersFromItsEarlierValue) {
    Demo d;
    EXPECT_EQ(settings_key_text(d), " | count 3");  // no key_unsaid: always said
    d.dummy = true;
    d.threads = 8;
    d.microsurface = Microsurface::Multiple;
    EXPECT_EQ(settings_key_text(d), " | count 3 | dummy on | microsurface multiple");
}

TEST(Settings, CommandLineOptionsFromTheFields) {
    Demo d;
    CLI::App app;
    cli::add_settings_options(&app, d);
    const CLI::Option* dummy = app.get_option("--dummy");
    EXPECT_EQ(dummy->get_default_str(), "off");
    EXPECT_EQ(dummy->get_description(), "a switch");
    std::vector<std::string> args = {"--microsurface", "multiple", "--dummy", "on",
                                     "--count",        "1e2"};
    std::reverse(args.begin(), args.end());  // CLI11 reads a reversed vector
    app.parse(args);
    EXPECT_EQ(d.count, 100);
    EXPECT_TRUE(d.dummy);
    EXPECT_EQ(d.microsurface, Microsurface::Multiple);

    Demo e;
    CLI::App bad;
    cli::add_settings_options(&bad, e);
    std::vector<std::string> zero = {"0", "--count"};
    try {
        bad.parse(zero);
        FAIL() << "no error";
    } catch (const InputError& err) {
        EXPECT_EQ(err.where(), "command line");
        EXPECT_EQ(err.field(), "--count");
    }
}

TEST(Settings, EverySimulationSettingRoundTripsAndValidates) {
    SimulationSettings s;
    s.theta_i_deg = {10, 20};
    s.particles = 12345;
    s.seed = 0x9e3779b97f4a7c16ull;
    s.grid = HemisphereGrid(30, 20);
    s.kernel = Kernel::Scalar;
    s.transport.microsurface = Microsurface::Multiple;
    s.transport.max_events = 77;
    SimulationSettings back;
    settings_from_json(back, settings_to_json(s), "test");
    EXPECT_EQ(settings_to_json(back), settings_to_json(s));
    EXPECT_NO_THROW(validate_settings(s));
    s.particles = 0;
    EXPECT_THROW(validate_settings(s), InputError);
}

}  // namespace
}  // namespace lamina

// Fuzzing lamina's inputs (docs/robustness.md). Random stack files, valid and broken, go through
// the parser: each is either accepted, and then lies in the documented ranges, or refused with an
// InputError naming the file and the field. Every accepted stack then goes through every model of
// the registry (models added later are fuzzed too), with random ablation flags, at awkward
// directions (normal, grazing, exactly 90°, the mirror direction, below the surface), through
// eval, prepare, delta_lobes, peak_directions, sampling, bin averages and albedos; some through
// small goniophotometer runs with both kernels, and through the sphere renderer. Every number
// that comes out must be finite and ≥ 0.
//
// In `make test` a fixed seed and a fixed number of cases (a few seconds). For longer runs:
//   LAMINA_FUZZ_SECONDS=3600 build/lamina_tests --gtest_filter='StackFuzz.*'
// with LAMINA_FUZZ_SEED to change the seed and LAMINA_FUZZ_CASE=N to rerun the one case N that
// failed (each case is drawn from its own generator, keyed by seed and case number; its file is
// then written to the working directory as fuzz-SEED-N.json).
#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "layers/stack.h"
#include "models/numerics/binned.h"
#include "models/random_walk/random_walk_model.h"
#include "models/registry.h"
#include "render/renderer.h"
#include "simulator/goniophotometer.h"
#include "study/configurations.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace lamina {
namespace {

// ---- Configuration ------------------------------------------------------------------------

struct FuzzConfig {
    std::uint64_t seed = 20261201;
    long cases = 160;    ///< stacks in a run of `make test`
    double seconds = 0;  ///< > 0: run for this long instead (cases then unlimited)
    long only = -1;      ///< ≥ 0: this case alone
};

FuzzConfig config_from_environment() {
    FuzzConfig c;
    if (const char* s = std::getenv("LAMINA_FUZZ_SEED")) c.seed = std::strtoull(s, nullptr, 10);
    if (const char* s = std::getenv("LAMINA_FUZZ_CASES")) c.cases = std::strtol(s, nullptr, 10);
    if (const char* s = std::getenv("LAMINA_FUZZ_SECONDS")) c.seconds = std::strtod(s, nullptr);
    if (const char* s = std::getenv("LAMINA_FUZZ_CASE")) c.only = std::strtol(s, nullptr, 10);
    return c;
}

// Which case is running, for the message of a crash (written with write(2) from the handler).
char g_crash_note[256] = "";

extern "C" void on_fatal_signal(int sig) {
    const ssize_t ignored = write(STDERR_FILENO, g_crash_note, std::strlen(g_crash_note));
    (void)ignored;
    std::signal(sig, SIG_DFL);
    std::raise(sig);
}

// ---- Drawing ------------------------------------------------------------------------------

class Draw {
  public:
    Draw(std::uint64_t seed, std::uint64_t index) : rng_(seed, 0xf022, index) {}
    double u() { return rng_.uniform_double(); }
    int below(int n) { return std::min(n - 1, int(u() * n)); }
    bool chance(double p) { return u() < p; }
    template <typename T>
    const T& pick(const std::vector<T>& v) {
        return v[std::size_t(below(int(v.size())))];
    }

  private:
    ParticleRng rng_;
};

std::string num(double x) {
    return fmt::format("{}", x);
}

/// A number inside [lo, hi] (both finite, lo ≤ hi): the bounds, their neighbours inside, tiny and
/// subnormal values when 0 is allowed, round and random values.
double inside(Draw& d, double lo, double hi) {
    switch (d.below(10)) {
        case 0:
            return lo;
        case 1:
            return hi;
        case 2:
            return std::nextafter(lo, hi);
        case 3:
            return std::nextafter(hi, lo);
        case 4:
            if (lo <= 0 && hi > 0) {  // tiny and subnormal numbers, both signs where allowed
                const double tiny = d.pick<double>(
                    {5e-324, 1e-320, 2.2250738585072014e-308, 1e-300, 1e-160, 1e-20});
                return lo < 0 && d.chance(0.5) ? -tiny : tiny;
            }
            return lo + (hi - lo) * 1e-12;
        case 5:
            if (lo <= 0 && hi > 0) return hi * std::pow(10.0, -300 * d.u());  // log-uniform
            return lo * std::pow(hi / lo, d.u());
        default:
            return lo + (hi - lo) * d.u();
    }
}

/// Text of a value that is not a number in [lo, hi]: beyond a bound, huge, NaN-like tokens that
/// JSON does not have, literals that overflow, numbers in strings, wrong types.
std::string outside(Draw& d, double lo, double hi) {
    switch (d.below(8)) {
        case 0:
            return num(std::nextafter(lo, -1e300));
        case 1:
            return num(std::nextafter(hi, 1e300));
        case 2:
            return num(d.pick<double>({-1.7976931348623157e308, 1.7976931348623157e308, 1e308,
                                       -5e-324, -1e-320, -1.0, 1e10, 1e300}));
        case 3:
            return d.pick<std::string>({"1e999", "-1e999", "1e400", "NaN", "nan", "Infinity",
                                        "-Infinity", "inf", "0x10", "+1", ".5", "1.", "01", "1e",
                                        "--1", "1e+", "1,5"});
        case 4:
            return d.pick<std::string>({"\"1.5\"", "null", "true", "false", "[]", "{}", "[1, 2]",
                                        "[1, 2, 3, 4]", "[[1, 2, 3]]", "{\"value\": 1}"});
        case 5:
            // A number far out on either side, log-uniform over the whole double range.
            return num((d.chance(0.5) ? -1 : 1) * std::pow(10.0, -320 + 628 * d.u()));
        case 6:
            return fmt::format("[{}, {}, {}]", num(inside(d, lo, hi)),
                               num(std::nextafter(hi, 1e300)), num(inside(d, lo, hi)));
        default:
            return fmt::format("\"{}\"", std::string(std::size_t(d.below(200)), 'x'));
    }
}

/// How a case is drawn: a valid stack (every value inside its range, the file well formed) or a
/// mutant (some values outside, keys missing or unknown, wrong structure, broken text).
struct Mode {
    bool valid = true;
    double p_bad = 0;  ///< mutant: probability that one value or key is broken
};

std::string value(Draw& d, const Mode& m, double lo, double hi, bool rgb) {
    if (!m.valid && d.chance(m.p_bad)) return outside(d, lo, hi);
    if (rgb && d.chance(0.5))
        return fmt::format("[{}, {}, {}]", num(inside(d, lo, hi)), num(inside(d, lo, hi)),
                           num(inside(d, lo, hi)));
    if (d.chance(0.1) && lo <= 0 && hi >= 0) return d.pick<std::string>({"0", "-0", "0.0", "-0.0"});
    if (d.chance(0.05) && lo <= 1 && hi >= 1) return "1";
    return num(inside(d, lo, hi));
}

/// Roughness: 0 (smooth) or in [1e-4, 1].
std::string alpha_value(Draw& d, const Mode& m) {
    if (!m.valid && d.chance(m.p_bad))
        return d.chance(0.5) ? outside(d, 1e-4, 1)
                             : num(d.pick<double>(
                                   {5e-324, 1e-300, 1e-10, 9.99e-5, std::nextafter(1e-4, 0.0)}));
    if (d.chance(0.3)) return d.chance(0.8) ? "0" : "-0";
    return num(inside(d, 1e-4, 1));
}

using Fields = std::vector<std::pair<std::string, std::string>>;

/// The object text of `fields`; a mutant may lose a field, gain an unknown or a duplicate one.
std::string object(Draw& d, const Mode& m, Fields fields, std::size_t required) {
    if (!m.valid) {
        if (!fields.empty() && d.chance(m.p_bad * 0.3) && required > 0)
            fields.erase(fields.begin() + d.below(int(std::min(required, fields.size()))));
        if (d.chance(m.p_bad * 0.3))
            fields.insert(fields.begin() + d.below(int(fields.size()) + 1),
                          {d.pick<std::string>({"alpah", "roughness", "ior", "", "eta ", "Eta",
                                                "tau", "x/y~z", "\u00e9ta"}),
                           "1"});
        if (!fields.empty() && d.chance(m.p_bad * 0.2))
            fields.push_back(fields[std::size_t(d.below(int(fields.size())))]);
        if (!fields.empty() && d.chance(m.p_bad * 0.1)) std::swap(fields.front(), fields.back());
    }
    std::string out = "{";
    for (std::size_t i = 0; i < fields.size(); ++i)
        out += fmt::format("{}\"{}\": {}", i ? ", " : "", fields[i].first, fields[i].second);
    return out + "}";
}

/// Which of the newer stack features a case may draw: a valid stack never holds a film beside an
/// anisotropic interface (the stack format refuses that pair; a mutant may hold it).
struct Features {
    bool film = false, anisotropy = false, spectra = false;
};

/// Roughness of a rough interface that may be anisotropic: α or [α_x, α_y], the pair's ratio
/// anywhere from 1 to 10⁴.
std::string roughness_value(Draw& d, const Mode& m, const Features& features) {
    if (!features.anisotropy || !d.chance(0.5)) return alpha_value(d, m);
    if (!m.valid && d.chance(m.p_bad))
        return d.pick<std::string>({"[0, 0.5]", "[0.5, 0]", "[0.1]", "[0.1, 0.2, 0.3]", "[]",
                                    "[\"0.1\", 0.2]", "[0.1, null]", "[[0.1], 0.2]",
                                    fmt::format("[{}, {}]", outside(d, 1e-4, 1), num(0.3))});
    const double a = inside(d, 1e-4, 1), b = d.chance(0.3) ? inside(d, 1e-4, 1) : a * 1e-3;
    return d.chance(0.5) ? fmt::format("[{}, {}]", num(a), num(std::max(b, 1e-4)))
                         : fmt::format("[{}, {}]", num(std::max(b, 1e-4)), num(a));
}

/// A spectral value in [lo, hi] (docs/stack-format.md, "Spectra"): a measured table, or for a
/// dielectric's index (`index`) a dispersion formula or a named glass.
std::string spectrum_value(Draw& d, const Mode& m, double lo, double hi, bool index) {
    if (!m.valid && d.chance(m.p_bad))
        return d.pick<std::string>(
            {"{}", "{\"spectrum\": []}", "{\"spectrum\": [[500, 1]]}",
             "{\"spectrum\": [[500, 1], [400, 1]]}", "{\"spectrum\": [[500, 1], [500, 1]]}",
             "{\"spectrum\": [[50, 1], [900, 1]]}", "{\"spectrum\": [[400, 1, 2], [900, 1]]}",
             fmt::format("{{\"spectrum\": [[400, {}], [700, {}]]}}", outside(d, lo, hi),
                         num(inside(d, lo, hi))),
             "{\"sellmeier\": [1.0]}", "{\"sellmeier\": [1, 0.01, 1]}", "{\"cauchy\": []}",
             "{\"cauchy\": [1.5, 0, 0, 0, 0]}", "{\"cauchy\": [0.5]}", "{\"abbe\": [1.5]}",
             "{\"abbe\": [1.5, 5]}", "{\"abbe\": [0.5, 50]}", "{\"material\": \"bk7\"}",
             "{\"material\": 7}", "{\"material\": \"Au\"}", "{\"spectrum\": \"BK7\"}",
             "{\"cauchy\": [1.5], \"abbe\": [1.5, 50]}", "{\"sellmeier\": [1e300, 1]}",
             "{\"cauchy\": [1.5, -1e300]}",
             // A Sellmeier pole between two whole nm inside the visible range.
             "{\"sellmeier\": [1.25, 0, 1e-6, 0.25050025]}",
             "{\"sellmeier\": [1.25, 0, -1e-6, 0.25050025]}"});
    const int forms = index ? 5 : 1;
    switch (d.below(forms)) {
        case 1:
            return d.pick<std::string>({"{\"material\": \"BK7\"}",
                                        "{\"material\": \"fused_silica\"}",
                                        "{\"material\": \"water\"}"});
        case 2:  // n_d in [1, 2.5], any Abbe number: the index stays in [1, 2.9] over 360–830 nm
            return fmt::format("{{\"abbe\": [{}, {}]}}", num(inside(d, 1, 2.5)),
                               num(inside(d, 10, 120)));
        case 3:  // normal dispersion, up to 4 terms: n in [1, 4.1] over 360–830 nm
            return fmt::format("{{\"cauchy\": [{}, {}, {}, {}]}}", num(inside(d, 1, 4)),
                               num(inside(d, 0, 0.01)), num(inside(d, 0, 1e-4)),
                               num(inside(d, 0, 1e-6)));
        case 4:  // one or two resonances in the ultraviolet (C < 0.1 µm²) and the infrared
            return fmt::format("{{\"sellmeier\": [{}, {}, {}, {}]}}", num(inside(d, 0.1, 1.5)),
                               num(inside(d, 0, 0.05)), num(inside(d, 0, 1)),
                               num(inside(d, 50, 150)));
        default: {
            const int n = d.chance(0.1) ? 2 + d.below(2000) : 2 + d.below(6);
            std::string out = "{\"spectrum\": [";
            double wl = inside(d, 100, 400);
            for (int i = 0; i < n; ++i) {
                out += fmt::format("{}[{}, {}]", i ? ", " : "", num(wl), num(inside(d, lo, hi)));
                wl = std::nextafter(wl, 1e9) + (d.chance(0.2) ? 0 : 1000 * d.u() / n);
            }
            return out + "]}";
        }
    }
}

/// A number, RGB or (with spectra) a spectral value.
std::string spectral_or_value(Draw& d, const Mode& m, const Features& features, double lo,
                              double hi, bool rgb, bool index = false) {
    if (features.spectra && d.chance(0.4)) return spectrum_value(d, m, lo, hi, index);
    return value(d, m, lo, hi, rgb);
}

/// The optional film of a dielectric or conductor interface.
void add_film(Draw& d, const Mode& m, const Features& features, Fields& fields) {
    if (!features.film || !d.chance(0.5)) return;
    std::string thickness;
    if (!m.valid && d.chance(m.p_bad)) {
        thickness =
            d.pick<std::string>({"[100, 50]", "[100]", "[1, 2, 3]", "[-1, 10]", "[0, 10001]",
                                 "-0.001", "10000.000001", "\"100\"", "null", outside(d, 0, 1e4)});
    } else if (d.chance(0.4)) {
        const double a = inside(d, 0, 1e4), b = inside(d, 0, 1e4);
        thickness = fmt::format("[{}, {}]", num(std::min(a, b)),
                                num(d.chance(0.2) ? std::min(a, b) : std::max(a, b)));
    } else {
        thickness = num(d.pick<double>({0.0, 1e-3, 1e4, inside(d, 0, 1e4), inside(d, 50, 1000)}));
    }
    Fields film = {{"thickness_nm", thickness}, {"eta", value(d, m, 0.01, 5, false)}};
    if (d.chance(0.5)) film.push_back({"k", value(d, m, 0, 10, false)});
    fields.push_back({"film", object(d, m, film, 2)});
}

std::string interface_text(Draw& d, const Mode& m, int type, const Features& features) {
    const std::vector<std::string> types = {"dielectric", "conductor", "lambertian"};
    std::string type_text = "\"" + types[std::size_t(type)] + "\"";
    if (!m.valid && d.chance(m.p_bad * 0.2))
        type_text = d.pick<std::string>(
            {"\"metal\"", "\"Dielectric\"", "1", "null", "\"\"", "[\"dielectric\"]"});
    Fields fields;
    switch (type) {
        case 0:
            fields = {{"type", type_text},
                      {"eta", spectral_or_value(d, m, features, 1, 5, false, true)},
                      {"alpha", roughness_value(d, m, features)}};
            break;
        case 1:
            fields = {{"type", type_text}};
            if (features.spectra && d.chance(0.3)) {
                fields.push_back(
                    {"material",
                     !m.valid && d.chance(m.p_bad)
                         ? d.pick<std::string>({"\"gold\"", "\"BK7\"", "\"\"", "3"})
                         : d.pick<std::string>({"\"Ag\"", "\"Al\"", "\"Au\"", "\"Cr\"", "\"Cu\"",
                                                "\"Fe\"", "\"Ni\"", "\"Pt\"", "\"Ti\""})});
                if (!m.valid && d.chance(m.p_bad)) fields.push_back({"k", "1"});
            } else {
                fields.push_back({"eta", spectral_or_value(d, m, features, 0.01, 10, true)});
                fields.push_back({"k", spectral_or_value(d, m, features, 0, 10, true)});
            }
            fields.push_back({"alpha", roughness_value(d, m, features)});
            break;
        default:
            return object(
                d, m,
                {{"type", type_text}, {"albedo", spectral_or_value(d, m, features, 0, 1, true)}},
                2);
    }
    const std::size_t required = fields.size();
    if (features.anisotropy && d.chance(0.5))
        fields.push_back({"tangent_deg", value(d, m, -360, 360, false)});
    add_film(d, m, features, fields);
    return object(d, m, fields, required);
}

std::string medium_text(Draw& d, const Mode& m, const Features& features) {
    Fields f;
    if (d.chance(0.7)) f.push_back({"tau_a", spectral_or_value(d, m, features, 0, 100, true)});
    if (d.chance(0.5))
        f.push_back(
            {"tau_s", spectral_or_value(d, m, features, 0, d.chance(0.1) ? 1e4 : 100, true)});
    if (d.chance(0.5)) f.push_back({"g", value(d, m, -0.99, 0.99, true)});
    return object(d, m, f, 0);
}

/// The text of one stack file.
std::string stack_text(Draw& d, const Mode& m) {
    // The newer features: films or anisotropy (both only in a mutant), and spectra with either.
    Features features;
    switch (d.below(4)) {
        case 1:
            features.film = true;
            break;
        case 2:
            features.anisotropy = true;
            break;
        default:
            break;
    }
    if (!m.valid && d.chance(m.p_bad * 0.2)) features.film = features.anisotropy = true;
    features.spectra = d.chance(0.3);
    int n_layers = 1 + d.below(3);
    if (d.chance(0.15)) n_layers = 4 + d.below(9);
    if (d.chance(0.01)) n_layers = 100;
    if (!m.valid && d.chance(m.p_bad * 0.05)) n_layers = d.chance(0.5) ? 0 : 101;
    std::string layers;
    for (int i = 0; i < n_layers; ++i) {
        const bool last = i + 1 == n_layers;
        int type = last ? d.below(3) : 0;
        if (!m.valid && !last && d.chance(m.p_bad * 0.1)) type = 1 + d.below(2);  // opaque above
        Fields f = {{"interface", interface_text(d, m, type, features)}};
        if ((!last && d.chance(0.7)) || (!m.valid && last && d.chance(m.p_bad * 0.1)))
            f.push_back({"medium", medium_text(d, m, features)});
        std::string layer = object(d, m, f, 1);
        if (!m.valid && d.chance(m.p_bad * 0.05))
            layer = d.pick<std::string>({"[" + layer + "]", "null", "\"layer\"", "{}",
                                         "{\"interface\": [" + f[0].second + "]}"});
        layers += (i ? ", " : "") + layer;
    }
    Fields top;
    if (d.chance(0.5)) {
        std::string name = "\"fuzzed\"";
        if (!m.valid && d.chance(m.p_bad))
            name = d.pick<std::string>(
                {"\"\"", "\"a\\nb\"", "\"tab\\there\"", "42", "null", "\"\\u0000\"", "[\"x\"]"});
        else if (d.chance(0.2))
            name = d.pick<std::string>(
                {"\"caf\u00e9 \u03b7=1.5\"", "\"a/b\\\\c\"", "\"" + std::string(300, 'n') + "\""});
        top.push_back({"name", name});
    }
    if (d.chance(0.6)) top.push_back({"ambient_eta", value(d, m, 1, 5, false)});
    if ((features.film || features.spectra) && d.chance(0.4)) {
        std::string wl = fmt::format("[{}, {}, {}]", num(inside(d, 360, 830)),
                                     num(inside(d, 360, 830)), num(inside(d, 360, 830)));
        if (!m.valid && d.chance(m.p_bad))
            wl = d.pick<std::string>({"[630, 532]", "530", "[630, 532, 359.99]", "[0, 0, 0]",
                                      "[630, 532, 1e999]", "null", outside(d, 360, 830)});
        top.push_back({"wavelengths_nm", wl});
    }
    std::string layers_text = "[" + layers + "]";
    if (!m.valid && d.chance(m.p_bad * 0.05))
        layers_text = d.pick<std::string>({"{" + layers + "}", "null", "3", "[[" + layers + "]]"});
    top.push_back({"layers", layers_text});
    std::string text = object(d, m, top, top.size());
    if (!m.valid) {
        // Broken text: truncated, a byte changed or dropped, wrapped, deeply nested, or empty.
        switch (d.chance(m.p_bad) ? d.below(7) : -1) {
            case 0:
                text = text.substr(0, std::size_t(d.below(int(text.size()))));
                break;
            case 1:
                text[std::size_t(d.below(int(text.size())))] =
                    d.pick<char>({'{', '}', '[', ']', ',', ':', '"', '\\', '\0', 'e', '-', '\xff'});
                break;
            case 2:
                text.erase(std::size_t(d.below(int(text.size()))), 1);
                break;
            case 3:
                text = "[" + text + "]";
                break;
            case 4: {
                const int depth = d.chance(0.5) ? 31 + d.below(3) : 100000;
                text = fmt::format("{{\"ambient_eta\": {}1{}, \"layers\": [{}]}}",
                                   std::string(std::size_t(depth), '['),
                                   std::string(std::size_t(depth), ']'), layers);
                break;
            }
            case 5:
                text = d.pick<std::string>({"", " ", "null", "[]", "{}", "\"stack\"", "1e999",
                                            "\xef\xbb\xbf{}", "{\"layers\": []}"});
                break;
            case 6:
                text += d.pick<std::string>({"}", " x", ",", "\n{}"});
                break;
            default:
                break;
        }
    }
    return text;
}

// ---- Checks -------------------------------------------------------------------------------

std::string shorten(const std::string& text, std::size_t n = 1500) {
    return text.size() <= n ? text : text.substr(0, n) + fmt::format("... ({} bytes)", text.size());
}

bool good(double x) {
    return std::isfinite(x) && x >= 0;
}
bool good(const Rgbd& v) {
    return good(v[0]) && good(v[1]) && good(v[2]);
}
bool good(const Rgbf& v) {
    return good(double(v[0])) && good(double(v[1])) && good(double(v[2]));
}
bool finite(const Vec3d& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
bool finite(const Rgbd& v) {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
}
std::string show(const Vec3d& v) {
    return fmt::format("({}, {}, {})", v.x, v.y, v.z);
}
std::string show(const Rgbd& v) {
    return fmt::format("({}, {}, {})", v[0], v[1], v[2]);
}

bool in(double x, double lo, double hi) {
    return x >= lo && x <= hi;
}
bool in(const Rgbd& v, double lo, double hi) {
    return in(v[0], lo, hi) && in(v[1], lo, hi) && in(v[2], lo, hi);
}

/// The ranges of docs/stack-format.md, restated independently of the parser.
std::string outside_ranges(const Stack& s) {
    if (!in(s.ambient_eta, 1, 5)) return "ambient_eta";
    if (!in(s.wavelengths_nm, 360, 830)) return "wavelengths_nm";
    if (s.layers.empty() || s.layers.size() > 100) return "layer count";
    bool film = false, anisotropic = false;
    for (const Layer& l : s.layers) {
        film = film || l.interface.has_film;
        anisotropic =
            anisotropic || (l.interface.type != InterfaceType::Lambertian &&
                            l.interface.alpha_y >= 0 && l.interface.alpha_y != l.interface.alpha);
    }
    if (film && anisotropic) return "film beside an anisotropic interface";
    for (std::size_t i = 0; i < s.layers.size(); ++i) {
        const InterfaceSpec& f = s.layers[i].interface;
        if (f.is_opaque() && i + 1 != s.layers.size()) return "opaque interface above the base";
        if (f.type != InterfaceType::Lambertian && !(f.alpha == 0 || in(f.alpha, 1e-4, 1)))
            return "alpha";
        if (f.alpha_y >= 0 && !(in(f.alpha, 1e-4, 1) && in(f.alpha_y, 1e-4, 1))) return "alpha_y";
        if (!in(f.tangent_deg, -360, 360)) return "tangent_deg";
        if (f.has_film &&
            (f.type == InterfaceType::Lambertian || !in(f.film.thickness_nm, 0, 1e4) ||
             !in(f.film.thickness_max_nm, f.film.thickness_nm, 1e4) || !in(f.film.eta, 0.01, 5) ||
             !in(f.film.k, 0, 10)))
            return "film";
        if (f.type == InterfaceType::Dielectric && !in(f.eta, 1, 5)) return "dielectric eta";
        if (f.type == InterfaceType::Conductor && (!in(f.eta_rgb, 0.01, 10) || !in(f.k, 0, 10)))
            return "conductor eta or k";
        if (f.type == InterfaceType::Lambertian && !in(f.albedo, 0, 1)) return "albedo";
        const MediumSpec& m = s.layers[i].medium;
        if (s.layers[i].has_medium &&
            (!in(m.tau_a, 0, 100) || !in(m.tau_s, 0, 1e4) || !in(m.g, -0.99, 0.99)))
            return "medium";
    }
    return "";
}

/// Counts failures and stops the run after a few (one bug tends to fail every case after it).
struct Failures {
    int count = 0;
    int limit = 12;
    bool enough() const { return count >= limit; }
};

#define FUZZ_EXPECT(cond, failures, message)                                \
    do {                                                                    \
        if (!(cond)) {                                                      \
            ++(failures).count;                                             \
            ADD_FAILURE() << "fuzz: " << #cond << " failed: " << (message); \
        }                                                                   \
    } while (0)

/// The directions each model is evaluated at for incidence wi: the awkward ones first.
std::vector<Vec3d> outgoing_directions(Draw& d, const Vec3d& wi) {
    const double phi = 2 * kPi<double> * d.u();
    std::vector<Vec3d> out = {
        mirror_direction(wi),
        normalize(mirror_direction(wi) + Vec3d(1e-9, 0, 0)),
        {0, 0, 1},
        {0, 0, -1},
        {1, 0, 0},                               // exactly horizontal
        {std::cos(phi), std::sin(phi), 1e-300},  // grazing: cos² underflows to 0...
        {std::cos(phi), std::sin(phi), -1e-300},
        {std::cos(phi), std::sin(phi), 1e-160},  // ...or to a subnormal number
        {std::cos(phi), std::sin(phi), 1e-20},
        {std::cos(phi), std::sin(phi), 6.123233995736766e-17},  // θo = 90° in degrees
        -wi,                                                    // straight through
        {-wi.x, -wi.y, -wi.z},
        wi,  // back towards the light
        direction_from_angles(deg_to_rad(90 * d.u()), phi, Side::Reflection),
        direction_from_angles(deg_to_rad(90 * d.u()), phi, Side::Transmission),
        direction_from_angles(deg_to_rad(89.999999), phi, Side::Reflection),
    };
    return out;
}

std::vector<Vec3d> incident_directions(Draw& d) {
    std::vector<Vec3d> out = {incident_direction(0.0), incident_direction(deg_to_rad(90.0)),
                              incident_direction(deg_to_rad(89.9999999)),
                              incident_direction(deg_to_rad(1e-7)), Vec3d(1, 0, 0)};
    for (int i = 0; i < 2; ++i)
        out.push_back(incident_direction(deg_to_rad(90 * d.u())));
    // An incidence off the xz plane (the models are isotropic; callers use φi = 0, but any wi).
    const double phi = 2 * kPi<double> * d.u(), theta = deg_to_rad(90 * d.u());
    out.push_back(
        {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)});
    return out;
}

struct CaseContext {
    std::string where, text;
    Failures* failures;
};

void check_model(Draw& d, const CaseContext& c, const ModelEntry& entry, const Stack& stack,
                 bool binned) {
    Failures& failures = *c.failures;
    // Random ablation flags (the default half of the time).
    std::vector<std::string> assignments;
    for (const OptionSpec& o : entry.options()) {
        if (entry.stochastic && o.key == "samples") {
            assignments.push_back("samples=16");
            continue;
        }
        if (d.chance(0.5)) assignments.push_back(o.key + "=" + d.pick(o.values));
    }
    const std::string what =
        fmt::format("model {} {} on {} = {}", entry.name,
                    fmt::format("[{}]", fmt::join(assignments, " ")), c.where, shorten(c.text));
    std::unique_ptr<Model> model;
    try {
        model = entry.make(stack, resolve_options(entry, assignments));
    } catch (const std::exception& e) {
        FUZZ_EXPECT(false, failures, what + ": construction threw " + e.what());
        return;
    }
    const Support support = model->support();
    FUZZ_EXPECT(support.brdf || !support.reason.empty(), failures, what);
    std::vector<Vec3d> wis = incident_directions(d);
    std::size_t n_wi = wis.size(), n_wo = 100;
    if (entry.stochastic) n_wi = 3, n_wo = 4;  // a random walk per query: fewer queries
    for (std::size_t a = 0; a < n_wi && !failures.enough(); ++a) {
        const Vec3d wi = wis[a];
        const std::string at = fmt::format("{} at wi = {}", what, show(wi));
        std::vector<Vec3d> wos = outgoing_directions(d, wi);
        for (const Vec3d& p : model->peak_directions(wi)) {
            FUZZ_EXPECT(finite(p), failures, at + ": peak direction " + show(p));
            wos.push_back(p);
        }
        const auto prepared = model->prepare(wi);
        for (std::size_t b = 0; b < wos.size() && b < n_wo; ++b) {
            const Vec3d& wo = wos[b];
            const Rgbd f = model->eval(wi, wo);
            FUZZ_EXPECT(good(f), failures,
                        fmt::format("{}, wo = {}: eval {}", at, show(wo), show(f)));
            const Rgbd fp = prepared->eval(wo);
            FUZZ_EXPECT(good(fp), failures,
                        fmt::format("{}, wo = {}: prepared eval {}", at, show(wo), show(fp)));
            if (model->has_sampling()) {
                const double pdf = model->pdf(wi, wo);
                FUZZ_EXPECT(good(pdf), failures,
                            fmt::format("{}, wo = {}: pdf {}", at, show(wo), pdf));
            }
        }
        for (const DeltaLobe& lobe : model->delta_lobes(wi)) {
            FUZZ_EXPECT(finite(lobe.direction) && good(lobe.energy), failures,
                        fmt::format("{}: delta lobe {} energy {}", at, show(lobe.direction),
                                    show(lobe.energy)));
        }
        if (model->has_sampling()) {
            for (int s = 0; s < 8; ++s) {
                const Vec3d u = s == 0   ? Vec3d(0, 0, 0)
                                : s == 1 ? Vec3d(std::nextafter(1.0, 0.0), std::nextafter(1.0, 0.0),
                                                 std::nextafter(1.0, 0.0))
                                         : Vec3d(d.u(), d.u(), d.u());
                if (const auto smp = model->sample(wi, u)) {
                    FUZZ_EXPECT(finite(smp->wo) && good(smp->weight) && good(smp->pdf), failures,
                                fmt::format("{}: sample {} → wo {} weight {} pdf {}", at, show(u),
                                            show(smp->wo), show(smp->weight), smp->pdf));
                }
            }
        }
    }
    if (binned && !entry.stochastic && (support.brdf || support.btdf) && !failures.enough()) {
        // The bin averages of `lamina eval --binned` and the study, on a coarse grid with a
        // small evaluation budget (the same code paths, a fraction of the cost).
        BinnedOptions options;
        options.eval_budget = 3000;
        options.max_depth = 4;
        const std::vector<double> thetas = {d.pick<double>({0.0, 89.999, 60.0}),
                                            90 * d.u() * 0.999};
        const BinnedTable t = bin_model(*model, HemisphereGrid(3, 4), thetas, options);
        for (std::size_t i = 0; i < t.lobes.size(); ++i)
            for (const BinnedLobe& lobe : t.lobes[i])
                for (std::size_t j = 0; j < lobe.f.size(); ++j)
                    FUZZ_EXPECT(good(lobe.f[j]) && good(lobe.se[j]), failures,
                                fmt::format("{}: bin {} of θi = {}: {}", what, j, t.theta_i_deg[i],
                                            show(lobe.f[j])));
        for (Side side : {Side::Reflection, Side::Transmission}) {
            if (side == Side::Transmission && !support.btdf) continue;
            const Rgbd albedo =
                model_albedo(*model, incident_direction(deg_to_rad(thetas[1])), side, options);
            FUZZ_EXPECT(good(albedo), failures, fmt::format("{}: albedo {}", what, show(albedo)));
        }
    }
}

void check_simulation(Draw& d, const CaseContext& c, const Stack& stack) {
    Failures& failures = *c.failures;
    SimulationSettings s;
    s.theta_i_deg = {d.pick<double>({0.0, 89.999999, 45.0}), 90 * d.u() * 0.9999};
    s.particles = kParticlesPerBlock;
    s.seed = 1 + std::uint64_t(d.below(1000));
    s.threads = 1;
    s.grid = HemisphereGrid(3, 4);
    s.kernel = d.chance(0.5) ? Kernel::Scalar : Kernel::Simd;
    s.transport.microsurface = d.chance(0.3) ? Microsurface::Multiple : Microsurface::Single;
    s.transport.polarization = d.chance(0.5);
    if (d.chance(0.3)) s.phi_i_deg = d.pick<double>({360.0, 1e-300, 90.0, 360 * d.u()});
    s.spectral = d.pick<SpectralMode>({SpectralMode::Auto, SpectralMode::On, SpectralMode::Off});
    if (d.chance(0.2)) s.transport.max_events = d.pick<int>({1, 2, 100});
    try {
        validate_settings(s);
    } catch (const InputError&) {
        s.transport.microsurface = Microsurface::Single;  // a combination the kernel does not offer
    }
    // Films on dielectrics and spectral runs are the scalar kernel's: the SIMD kernel must refuse
    // them by name (anisotropy, φi ≠ 0 and films on conductors both kernels trace; a film beside
    // an anisotropic interface never gets here, the stack format refuses it).
    try {
        validate_kernel_for(stack, s);
    } catch (const InputError& e) {
        const bool expected = s.kernel == Kernel::Simd && needs_scalar_kernel(stack, s);
        FUZZ_EXPECT(expected && !e.problem().empty(), failures,
                    fmt::format("simulation refused: {}\n{}", e.what(), shorten(c.text)));
        s.kernel = Kernel::Scalar;
    }
    const std::string what =
        fmt::format("simulation ({} kernel, {} microsurface, polarization {}) of {} = {}",
                    enum_text(s.kernel), enum_text(s.transport.microsurface),
                    s.transport.polarization ? "on" : "off", c.where, shorten(c.text));
    const SimulationResult r = simulate(stack, s);
    const bool spectral = !r.spectral.bin_edges_nm.empty();
    // A spectral run: its tables per wavelength bin and their XYZ projection are non-negative;
    // their linear sRGB projection (`table`, brdf.csv) is an unbiased estimate that may be
    // negative (the sRGB colour-matching weights are negative over part of the spectrum:
    // docs/formats.md), and must be finite.
    for (std::size_t i = 0; i < r.spectral.f.size(); ++i)
        FUZZ_EXPECT(good(r.spectral.f[i]) && good(r.spectral.se[i]), failures,
                    fmt::format("{}: spectral table entry {}: f {} se {}", what, i, r.spectral.f[i],
                                r.spectral.se[i]));
    for (std::size_t i = 0; i < r.spectral.xyz.lobes.size(); ++i)
        for (const BinnedLobe& lobe : r.spectral.xyz.lobes[i])
            for (std::size_t j = 0; j < lobe.f.size(); ++j)
                FUZZ_EXPECT(good(lobe.f[j]) && good(lobe.se[j]), failures,
                            fmt::format("{}: XYZ bin {}: f {} se {}", what, j, show(lobe.f[j]),
                                        show(lobe.se[j])));
    for (std::size_t g = 0; g < r.spectral.budget.size(); ++g) {
        double sum = 0;
        for (int t = 0; t < kBudgetTerms + 2; ++t) {
            const double term = r.spectral.budget[g][std::size_t(t)];
            const bool may_be_negative =
                t == int(BudgetTerm::AbsorbedMedium) || t == int(BudgetTerm::AbsorbedBase);
            FUZZ_EXPECT(may_be_negative ? std::isfinite(term) : good(term), failures,
                        fmt::format("{}: spectral budget {} term {} = {}", what, g, t, term));
            if (t < kBudgetTerms) sum += term;
        }
        // Each wavelength bin's budget sums to 1 to rounding, but within its standard error
        // where an interface disperses (docs/formats.md).
        bool dispersive = false;
        for (const Layer& l : stack.layers)
            dispersive = dispersive || (l.interface.type == InterfaceType::Dielectric &&
                                        l.interface.eta_spectrum.has_value());
        FUZZ_EXPECT(dispersive || std::abs(sum - 1) < 1e-6, failures,
                    fmt::format("{}: spectral budget {} sums to {}", what, g, sum));
    }
    for (std::size_t i = 0; i < r.table.lobes.size(); ++i)
        for (const BinnedLobe& lobe : r.table.lobes[i])
            for (std::size_t j = 0; j < lobe.f.size(); ++j)
                FUZZ_EXPECT((spectral ? finite(lobe.f[j]) : good(lobe.f[j])) && good(lobe.se[j]),
                            failures,
                            fmt::format("{}: bin {} of θi = {}: f {} se {}", what, j,
                                        r.table.theta_i_deg[i], show(lobe.f[j]), show(lobe.se[j])));
    if (spectral) return;  // its sRGB budget sums to 1 within its noise only
    for (std::size_t i = 0; i < r.incidences.size(); ++i) {
        const EnergyBudget& b = r.incidences[i].budget;
        for (int t = 0; t < kBudgetTerms; ++t) {
            // absorbed_medium may be negative: with spectral MIS a particle's weight can grow in
            // one channel, and the column is an unbiased estimate of a non-negative quantity, not
            // a sum of non-negative parts (docs/formats.md). So may absorbed_base with polarized
            // light or a thin film, which books there the reweighting of channels whose states or
            // film reflectances differ.
            const Rgbd& term = b.term[std::size_t(t)];
            const bool ok =
                t == int(BudgetTerm::AbsorbedMedium) ||
                        (t == int(BudgetTerm::AbsorbedBase) &&
                         (s.transport.polarization || stack.has_film()))
                    ? std::isfinite(term[0]) && std::isfinite(term[1]) && std::isfinite(term[2])
                    : good(term);
            FUZZ_EXPECT(ok, failures,
                        fmt::format("{}: budget term {} = {}", what,
                                    kBudgetTermNames[std::size_t(t)], show(term)));
        }
        // The terms sum to 1 up to the rounding of the kernels' float weights.
        const Rgbd sum = b.sum();
        FUZZ_EXPECT(std::abs(sum[0] - 1) < 1e-6 && std::abs(sum[1] - 1) < 1e-6 &&
                        std::abs(sum[2] - 1) < 1e-6,
                    failures, fmt::format("{}: the budget sums to {}", what, show(sum)));
        FUZZ_EXPECT(good(b.reflected_se) && good(b.transmitted_se), failures, what);
    }
}

void check_render(Draw& d, const CaseContext& c, const Stack& stack) {
    Failures& failures = *c.failures;
    std::vector<const ModelEntry*> analytic;
    for (const ModelEntry& e : model_registry())
        if (!e.stochastic) analytic.push_back(&e);
    const ModelEntry& entry = *d.pick(analytic);
    const auto model = entry.make(stack, resolve_options(entry, {}));
    if (!model->support().brdf) return;
    RenderSettings rs;
    rs.size = 6;
    rs.spp = 2;
    rs.threads = 1;
    rs.progress = false;
    rs.lobe_alpha = lobe_alpha_for(stack);
    const Rendering r = render_sphere(
        *model, Environment::named(d.pick<std::string>({"studio", "uniform", "sky"})), rs);
    for (const Rgbf& p : r.image.pixels)
        FUZZ_EXPECT(good(p), failures,
                    fmt::format("render of {} with {}: pixel ({}, {}, {})", shorten(c.text),
                                entry.name, p[0], p[1], p[2]));
}

/// One case: draw a file, parse it, check the refusal or run the accepted stack.
void run_case(const FuzzConfig& config, long index, Failures& failures, long& accepted) {
    Draw d(config.seed, std::uint64_t(index));
    Mode mode;
    mode.valid = d.chance(0.6);
    mode.p_bad = d.pick<double>({0.05, 0.15, 0.4});
    const CaseContext c{fmt::format("fuzz-{}-{}.json", config.seed, index), stack_text(d, mode),
                        &failures};
    std::snprintf(
        g_crash_note, sizeof g_crash_note,
        "\nfuzz: crashed in case %ld (rerun: LAMINA_FUZZ_SEED=%llu LAMINA_FUZZ_CASE=%ld)\n", index,
        static_cast<unsigned long long>(config.seed), index);
    if (config.only >= 0) std::ofstream(c.where, std::ios::binary) << c.text;  // to reproduce
    Stack stack;
    try {
        stack = parse_stack(c.text, c.where);
    } catch (const InputError& e) {
        const std::string problem = e.problem();
        FUZZ_EXPECT(!mode.valid, failures,
                    fmt::format("a valid stack was refused: {}\n{}", e.what(), shorten(c.text)));
        FUZZ_EXPECT(e.where() == c.where && !problem.empty(), failures, e.what());
        // A refusal names the field (a JSON pointer), unless the text is not JSON at all or
        // not an object.
        const bool whole_file = problem.starts_with("malformed JSON") ||
                                problem.starts_with("a stack file must hold") ||
                                problem.find("the whole file is") != std::string::npos;
        FUZZ_EXPECT(whole_file || e.field().starts_with("/"), failures,
                    fmt::format("refusal without a field: {}\n{}", e.what(), shorten(c.text)));
        FUZZ_EXPECT(std::string(e.what()).size() < 2000, failures, shorten(e.what()));
        return;
    } catch (const std::exception& e) {
        FUZZ_EXPECT(false, failures,
                    fmt::format("not an InputError: {}\n{}", e.what(), shorten(c.text)));
        return;
    }
    ++accepted;
    const std::string out_of_range = outside_ranges(stack);
    FUZZ_EXPECT(out_of_range.empty(), failures,
                fmt::format("accepted outside the ranges ({}): {}", out_of_range, shorten(c.text)));
    FUZZ_EXPECT(stack_from_json(stack_to_json(stack), c.where) == stack, failures, shorten(c.text));
    const std::string described = describe(stack);
    FUZZ_EXPECT(
        described.find("nan") == std::string::npos && described.find("inf") == std::string::npos,
        failures, described);

    const bool binned = d.chance(0.25);
    for (const ModelEntry& entry : model_registry()) {
        if (failures.enough()) return;
        check_model(d, c, entry, stack, binned);
    }
    if (d.chance(0.25) && !failures.enough()) check_simulation(d, c, stack);
    if (d.chance(0.1) && !failures.enough()) check_render(d, c, stack);
}

TEST(StackFuzz, EveryFileIsAcceptedInRangeOrRefusedByNameAndEveryResultIsFiniteAndNonNegative) {
    const FuzzConfig config = config_from_environment();
    for (int sig : {SIGSEGV, SIGFPE, SIGBUS, SIGABRT, SIGILL})
        std::signal(sig, on_fatal_signal);
    Failures failures;
    if (config.seconds > 0) failures.limit = 200;  // a long run collects more before it stops
    long accepted = 0, cases = 0;
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    };
    if (config.only >= 0) {
        run_case(config, config.only, failures, accepted);
        cases = 1;
    } else {
        for (long i = 0; !failures.enough(); ++i) {
            if (config.seconds > 0 ? elapsed() >= config.seconds : i >= config.cases) break;
            const double t0 = elapsed();
            run_case(config, i, failures, accepted);
            ++cases;
            if (elapsed() - t0 > 30)
                std::fprintf(stderr, "fuzz: case %ld took %.0f s\n", i, elapsed() - t0);
            if (config.seconds > 0 && int(elapsed() / 300) != int(t0 / 300))
                std::printf("fuzz: %.0f s, %ld cases (%ld accepted), %d failures\n", elapsed(),
                            cases, accepted, failures.count);
            std::fflush(stdout);
        }
    }
    for (int sig : {SIGSEGV, SIGFPE, SIGBUS, SIGABRT, SIGILL})
        std::signal(sig, SIG_DFL);
    std::printf(
        "fuzz: seed %llu, %ld cases (%ld stacks accepted, %ld refused) in %.1f s, %d failures\n",
        static_cast<unsigned long long>(config.seed), cases, accepted, cases - accepted, elapsed(),
        failures.count);
    // The fixed run must exercise both outcomes, or it tests nothing.
    if (config.only < 0) {
        EXPECT_GT(accepted, cases / 5);
        EXPECT_GT(cases - accepted, cases / 5);
    }
}

// The ranges keep every stack lamina ships valid: the examples and the study's configurations.
TEST(StackFuzz, TheExamplesAndTheStudyConfigurationsLieInTheRanges) {
    int examples = 0;
    for (const auto& entry :
         std::filesystem::directory_iterator(std::filesystem::path(LAMINA_SOURCE_DIR) / "examples"))
        if (entry.path().extension() == ".json") {
            EXPECT_NO_THROW(load_stack(entry.path())) << entry.path();
            ++examples;
        }
    EXPECT_GE(examples, 5);
    const auto configurations = builtin_configurations();
    EXPECT_GE(configurations.size(), 60u);
    for (const StudyConfiguration& c : configurations) {
        EXPECT_EQ(outside_ranges(c.stack), "") << c.id;
        EXPECT_NO_THROW(stack_from_json(stack_to_json(c.stack), c.id)) << c.id;
    }
}

// A spectrum is checked at every whole nm of 360–830 nm, but used anywhere in between: at the
// channels' wavelengths_nm and at the spectral kernel's lattice points. Found by a sweep of the
// spectral stacks: a Sellmeier term with a tiny B resonating between two whole nm passed the
// check and made a coat of index 67 176 at wavelengths_nm 500.5 (0 just below the resonance). A
// resonance inside the visible range is refused, and a Cauchy formula is also checked where its
// polynomial in 1/λ² turns.
TEST(StackFuzz, SpectraStayInTheirRangesBetweenWholeNanometres) {
    auto refusal = [](const std::string& eta, const std::string& wavelengths) -> std::string {
        const std::string text =
            R"({"wavelengths_nm": )" + wavelengths + R"(, "layers": [{"interface": {"type": )" +
            R"("dielectric", "eta": )" + eta +
            R"(, "alpha": 0.1}}, {"interface": {"type": "lambertian", "albedo": 0.5}}]})";
        try {
            const Stack s = parse_stack(text, "s.json");
            return fmt::format("accepted, eta {}", s.layers[0].interface.eta);
        } catch (const InputError& e) {
            return e.field() + ": " + e.problem();
        }
    };
    // n² = 2.25 + 1e-6 λ²/(λ² − 0.25050025): within 2e-4 of 1.5 at 500 and 501 nm, ±∞ at 500.5.
    const std::string pole =
        refusal(R"({"sellmeier": [1.25, 0, 1e-6, 0.25050025]})", "[630, 500.5, 465]");
    EXPECT_TRUE(pole.starts_with("/layers/0/interface/eta/sellmeier/3: got C = 0.25050025"))
        << pole;
    EXPECT_NE(pole.find("500.5 nm"), std::string::npos) << pole;
    // The same resonance with B = 0 is no resonance; and one in the infrared (glasses') is fine.
    EXPECT_TRUE(refusal(R"({"sellmeier": [1.25, 0, 0, 0.25050025]})", "[630, 500.5, 465]")
                    .starts_with("accepted"));
    EXPECT_TRUE(refusal(R"({"sellmeier": [1.25, 0, 1, 100]})", "[630, 500.5, 465]")
                    .starts_with("accepted"));
    // A Cauchy parabola in x = 1/λ² (µm⁻²), n = 1 − 2e-6 + 0.05 (x − x0)², its minimum x0 halfway
    // between 500 and 501 nm: n ≥ 1 + 1e-6 at every whole nm, 1 − 2e-6 at x0 (λ ≈ 500.5 nm).
    const double x0 = (1 / (0.5 * 0.5) + 1 / (0.501 * 0.501)) / 2, k = 0.05;
    const std::string dip = refusal(
        fmt::format(R"({{"cauchy": [{}, {}, {}]}})", 1 - 2e-6 + k * x0 * x0, -2 * k * x0, k),
        "[630, 532, 465]");
    EXPECT_TRUE(dip.starts_with("/layers/0/interface/eta/cauchy: the spectrum is 0.999998")) << dip;
    EXPECT_NE(dip.find("at 500.4"), std::string::npos) << dip;
}

// The cases of a robustness report on the stack files, which the file ranges now refuse:
// built in code, past the parser, each model must still return finite, non-negative values (the
// models clamp relative indices to the domain they compute in; the tables' coordinates are safe).
TEST(StackFuzz, ModelsStayFiniteForIndicesFarOutsideTheFileRanges) {
    auto coated = [](double ambient, double coat_eta, Layer base) {
        Stack s;
        s.name = "extreme";
        s.ambient_eta = ambient;
        Layer coat;
        coat.interface.type = InterfaceType::Dielectric;
        coat.interface.eta = coat_eta;
        coat.interface.alpha = 0.2;
        coat.has_medium = true;
        coat.medium.tau_a = Rgbd(0.1);
        s.layers = {coat, base};
        return s;
    };
    Layer conductor, lambertian, slab_base;
    conductor.interface.type = InterfaceType::Conductor;
    conductor.interface.eta_rgb = Rgbd(0.2);
    conductor.interface.k = Rgbd(3.0);
    conductor.interface.alpha = 0.3;
    lambertian.interface.type = InterfaceType::Lambertian;
    lambertian.interface.albedo = Rgbd(0.8);
    slab_base.interface.type = InterfaceType::Dielectric;
    slab_base.interface.eta = 1e308;
    slab_base.interface.alpha = 0.3;
    Layer huge_conductor = conductor;
    huge_conductor.interface.eta_rgb = Rgbd(1e308, 1e-320, 1.0);
    huge_conductor.interface.k = Rgbd(1e308, 0.0, 1e-320);
    const std::vector<Stack> stacks = {
        coated(1, 1e308, conductor),      // bel-prime, bel18-forward: segmentation fault
        coated(1e-320, 1.5, lambertian),  // ww09, ele10, ww-prime: NaN
        coated(1e308, 1.5, lambertian),    coated(1e-320, 1.5, conductor),
        coated(1, 1.5, slab_base),  // bel18-forward: NaN
        coated(1, 1e-320, huge_conductor), coated(1e308, 1e-320, slab_base),
    };
    for (const Stack& stack : stacks) {
        for (const ModelEntry& entry : model_registry()) {
            if (entry.stochastic) continue;  // the random walk's float-free domain is the files'
            const auto model = entry.make(stack, resolve_options(entry, {}));
            for (double theta_i : {0.0, 30.0, 89.0}) {
                const Vec3d wi = incident_direction(deg_to_rad(theta_i));
                for (const Vec3d& wo : {mirror_direction(wi), Vec3d(0, 0, 1),
                                        normalize(Vec3d(0.3, 0.2, -1)), Vec3d(0.6, 0, 0.8)}) {
                    const Rgbd f = model->eval(wi, wo);
                    EXPECT_TRUE(good(f)) << entry.name << " on " << describe(stack) << " at "
                                         << show(wi) << " → " << show(wo) << ": " << show(f);
                }
                for (const DeltaLobe& lobe : model->delta_lobes(wi))
                    EXPECT_TRUE(good(lobe.energy) && finite(lobe.direction))
                        << entry.name << " on " << describe(stack) << ": delta lobe "
                        << show(lobe.energy);
            }
        }
    }
}

}  // namespace
}  // namespace lamina

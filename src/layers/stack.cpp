// Stack files: parsing with validation, the canonical JSON form, and a one-line description.
// The format is documented for users in docs/stack-format.md; physics in docs/physics.md §2.
//
// Every rejection is one InputError naming the file, the JSON pointer (RFC 6901) of the field, the
// offending value and what is allowed. Keys are never ignored: an unknown key is an error that
// lists the allowed keys and suggests the closest one, so a typo cannot silently fall back to a
// default.
#include "layers/stack.h"

#include "core/atomic_file.h"
#include "core/check.h"
#include "core/error.h"
#include "core/json_text.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <span>
#include <sstream>
#include <string_view>
#include <vector>

namespace lamina {

namespace {

using json = nlohmann::json;
using Keys = std::span<const std::string_view>;

// ---- JSON pointers and how values are shown -------------------------------------------------

/// RFC 6901 escaping of one reference token: '~' → "~0", '/' → "~1".
std::string escape_token(std::string_view key) {
    std::string out;
    for (char c : key) {
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else
            out += c;
    }
    return out;
}

std::string child(const std::string& pointer, std::string_view key) {
    return pointer + "/" + escape_token(key);
}
std::string child(const std::string& pointer, std::size_t index) {
    return pointer + "/" + std::to_string(index);
}

/// The value as the user wrote it (numbers in shortest round-trip form; NaN and inf by name,
/// which json::dump would print as null), shortened to one readable line. Written here rather
/// than with json::dump, which recurses once per nesting level (a file of 10^5 nested brackets
/// would overflow the stack) and prints the whole value before it could be shortened: this one
/// stops after kShowMax characters and shows containers nested deeper than three levels as "...".
constexpr std::size_t kShowMax = 60;
void append_shown(std::string& out, const json& value, int depth) {
    if (out.size() > kShowMax) return;
    if (value.is_array() || value.is_object()) {
        out += value.is_array() ? '[' : '{';
        if (depth >= 3 && !value.empty())
            out += "...";
        else {
            bool first = true;
            for (auto it = value.begin(); it != value.end() && out.size() <= kShowMax; ++it) {
                if (!first) out += ',';
                first = false;
                if (value.is_object()) out += json(it.key()).dump() + ':';
                append_shown(out, *it, depth + 1);
            }
        }
        out += value.is_array() ? ']' : '}';
    } else if (value.is_number_float()) {
        out += fmt::format("{}", value.get<double>());
    } else if (value.is_string() && value.get_ref<const std::string&>().size() > kShowMax) {
        out += json(value.get_ref<const std::string&>().substr(0, kShowMax)).dump();
    } else {
        out += value.dump();
    }
}
std::string show(const json& value) {
    std::string text;
    append_shown(text, value, 0);
    if (text.size() > kShowMax) text = text.substr(0, kShowMax - 3) + "...";
    return text;
}

std::string type_phrase(const json& value) {
    switch (value.type()) {
        case json::value_t::null:
            return "null";
        case json::value_t::boolean:
            return "a boolean";
        case json::value_t::string:
            return "a string";
        case json::value_t::array:
            return fmt::format("an array of {}", value.size());
        case json::value_t::object:
            return "an object";
        default:
            return "a number";
    }
}

std::string quoted_list(Keys keys) {
    std::string out;
    for (auto k : keys)
        out += (out.empty() ? "\"" : ", \"") + std::string(k) + "\"";
    return out;
}

// ---- Suggestions for unknown keys and types -------------------------------------------------

/// Optimal-string-alignment distance (Levenshtein plus adjacent transpositions), case-insensitive,
/// so that "alpah" is one edit from "alpha".
std::size_t edit_distance(std::string_view a, std::string_view b) {
    auto lower = [](char c) {
        return static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    };
    const std::size_t n = a.size(), m = b.size();
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1));
    for (std::size_t i = 0; i <= n; ++i)
        d[i][0] = i;
    for (std::size_t j = 0; j <= m; ++j)
        d[0][j] = j;
    for (std::size_t i = 1; i <= n; ++i) {
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = lower(a[i - 1]) == lower(b[j - 1]) ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) &&
                lower(a[i - 2]) == lower(b[j - 1]))
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
        }
    }
    return d[n][m];
}

/// Names users reach for from other renderers, mapped to lamina's key.
std::string_view synonym(std::string_view key) {
    static constexpr std::pair<std::string_view, std::string_view> kSynonyms[] = {
        {"roughness", "alpha"},    {"ior", "eta"},      {"kappa", "k"},
        {"reflectance", "albedo"}, {"color", "albedo"}, {"absorption", "tau_a"},
        {"scattering", "tau_s"},   {"anisotropy", "g"}, {"kind", "type"}};
    for (auto [from, to] : kSynonyms)
        if (edit_distance(key, from) == 0) return to;
    return {};
}

/// " did you mean \"alpha\"?" when one allowed name is close to `key`, else "".
std::string suggestion(std::string_view key, Keys allowed) {
    std::string_view best;
    std::size_t best_distance = 3;  // suggest only within two edits...
    for (auto candidate : allowed) {
        std::size_t distance = edit_distance(key, candidate);
        // A truncated name ("lambert", "diel") counts as one edit.
        if (key.size() >= 3 && key.size() < candidate.size() &&
            edit_distance(key, candidate.substr(0, key.size())) == 0)
            distance = std::min<std::size_t>(distance, 1);
        // ...and never by rewriting the whole word ("g" is not a typo of "k").
        if (distance < best_distance && distance < candidate.size()) {
            best = candidate;
            best_distance = distance;
        }
    }
    if (best.empty()) {
        const std::string_view to = synonym(key);
        if (!to.empty() && std::find(allowed.begin(), allowed.end(), to) != allowed.end())
            best = to;
    }
    return best.empty() ? "" : fmt::format(" did you mean \"{}\"?", best);
}

// ---- The validating reader ------------------------------------------------------------------

constexpr std::string_view kStackKeys[] = {"name", "ambient_eta", "wavelengths_nm", "layers"};
constexpr std::string_view kLayerKeys[] = {"interface", "medium"};
constexpr std::string_view kInterfaceTypes[] = {"dielectric", "conductor", "lambertian"};
constexpr std::string_view kDielectricKeys[] = {"type", "eta", "alpha", "tangent_deg", "film"};
constexpr std::string_view kConductorKeys[] = {"type",  "eta",         "k",   "material",
                                               "alpha", "tangent_deg", "film"};
constexpr std::string_view kSpectrumForms[] = {"spectrum", "sellmeier", "cauchy", "abbe",
                                               "material"};
constexpr std::string_view kFilmKeys[] = {"thickness_nm", "eta", "k"};
constexpr std::string_view kLambertianKeys[] = {"type", "albedo"};
constexpr std::string_view kMediumKeys[] = {"tau_a", "tau_s", "g"};

constexpr std::string_view kAlphaHint =
    "GGX roughness, 0 or in [0.0001, 1], or [alpha_x, alpha_y] for an anisotropic interface; "
    "write 0 for a smooth interface";

/// A constraint on one number: the test and how it reads in a message.
struct Allowed {
    bool (*ok)(double);
    std::string_view text;
};
// The physical ranges (docs/stack-format.md, "Ranges", says why each bound is where it is). They
// keep every number inside the domain the estimators are written for: relative dielectric indices
// within [1/5, 5] (the TIR and FGD tables of models/ cover it), roughnesses whose α² and GGX peak
// 1/(πα²) are normal floats, optical depths whose attenuation is still above float's smallest
// normal number (absorption) or whose mean free path is still many float ulps of a layer
// (scattering), and HG phase functions whose 1 − g² survives float rounding.
constexpr double kEtaDielectricMin = 1, kEtaDielectricMax = 5;
constexpr double kEtaConductorMin = 0.01, kEtaConductorMax = 10, kKConductorMax = 10;
constexpr double kAlphaRoughMin = 1e-4;
constexpr double kTangentDegMax = 360;
constexpr double kTauMax = 100, kTauScatteringMax = 1e4;
constexpr double kGMax = 0.99;
constexpr std::size_t kMaxLayers = 100;
// Films up to 10 µm (beyond a few µm the coherence of broadband light is gone and the period of
// the fringes in angle falls below any grid; the range still lets the period average be tested);
// film indices from metals' (η down to 0.01) to high-index oxides; channel wavelengths within the
// visible range of the CIE 1931 observer.
constexpr double kFilmThicknessMax = 1e4;
constexpr double kWavelengthMin = 360, kWavelengthMax = 830;

constexpr Allowed kDielectricEta{
    [](double v) { return v >= kEtaDielectricMin && v <= kEtaDielectricMax; }, "[1, 5]"};
constexpr Allowed kConductorEta{
    [](double v) { return v >= kEtaConductorMin && v <= kEtaConductorMax; }, "[0.01, 10]"};
constexpr Allowed kConductorK{[](double v) { return v >= 0 && v <= kKConductorMax; }, "[0, 10]"};
constexpr Allowed kAlpha{[](double v) { return v == 0 || (v >= kAlphaRoughMin && v <= 1); },
                         "0 (smooth) or [0.0001, 1]"};
constexpr Allowed kAlphaRough{[](double v) { return v >= kAlphaRoughMin && v <= 1; },
                              "[0.0001, 1] (each of an anisotropic [alpha_x, alpha_y])"};
constexpr Allowed kTangentDeg{[](double v) { return v >= -kTangentDegMax && v <= kTangentDegMax; },
                              "[-360, 360] degrees"};
constexpr Allowed kOpticalDepth{[](double v) { return v >= 0 && v <= kTauMax; }, "[0, 100]"};
constexpr Allowed kScatteringDepth{[](double v) { return v >= 0 && v <= kTauScatteringMax; },
                                   "[0, 10000]"};
constexpr Allowed kUnit{[](double v) { return v >= 0 && v <= 1; }, "[0, 1]"};
constexpr Allowed kFilmThickness{[](double v) { return v >= 0 && v <= kFilmThicknessMax; },
                                 "[0, 10000]"};
constexpr Allowed kFilmEta{[](double v) { return v >= kEtaConductorMin && v <= kEtaDielectricMax; },
                           "[0.01, 5]"};
constexpr Allowed kWavelength{[](double v) { return v >= kWavelengthMin && v <= kWavelengthMax; },
                              "[360, 830]"};
constexpr Allowed kSampleWavelength{[](double v) { return v >= 100 && v <= 10000; },
                                    "[100, 10000]"};
constexpr Allowed kAbbe{[](double v) { return v >= 10 && v <= 120; }, "[10, 120]"};
constexpr std::size_t kMaxSpectrumSamples = 10000;
constexpr Allowed kHgG{[](double v) { return v >= -kGMax && v <= kGMax; }, "[-0.99, 0.99]"};

class Reader {
  public:
    explicit Reader(std::string where) : where_(std::move(where)) {}

    Stack stack(const json& j) {
        if (!j.is_object())
            fail("", fmt::format("a stack file must hold a JSON object with keys {}, got {}: {}",
                                 quoted_list(kStackKeys), type_phrase(j), show(j)));
        check_keys(j, "", kStackKeys, "the stack");

        Stack s;
        if (const json* name = j.contains("name") ? &j["name"] : nullptr) {
            if (!name->is_string() || name->get<std::string>().empty())
                fail("/name", fmt::format("expected a non-empty string, got {}: {}",
                                          type_phrase(*name), show(*name)));
            s.name = name->get<std::string>();
            // The name is printed on one line (describe, reports): no line breaks or tabs.
            if (std::any_of(s.name.begin(), s.name.end(),
                            [](unsigned char c) { return c < 0x20 || c == 0x7f; }))
                fail("/name", fmt::format("got {}; allowed: a name without control characters "
                                          "(line breaks, tabs)",
                                          show(*name)));
        } else {
            // The file's name, printed on one line as a given name is: a control character in
            // it (a line break in a file name) becomes '_'.
            s.name = std::filesystem::path(where_).stem().string();
            std::replace_if(
                s.name.begin(), s.name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; },
                '_');
            if (s.name.empty()) s.name = "stack";
        }
        if (j.contains("ambient_eta"))
            s.ambient_eta = number(j["ambient_eta"], "/ambient_eta", kDielectricEta,
                                   "absolute refractive index of the ambient medium");

        if (j.contains("wavelengths_nm")) {
            const json& wl = j["wavelengths_nm"];
            if (!wl.is_array() || wl.size() != 3)
                fail("/wavelengths_nm",
                     fmt::format("expected an array of 3 numbers [R, G, B] (the vacuum "
                                 "wavelengths of the channels in nm), got {}: {}",
                                 type_phrase(wl), show(wl)));
            s.wavelengths_nm =
                rgb(wl, "/wavelengths_nm", kWavelength, "vacuum wavelength of the channel in nm");
        }

        const json& layers = required(j, "", "layers", "an array of layers, top to bottom");
        if (!layers.is_array())
            fail("/layers", fmt::format("expected an array of layers (top to bottom), got {}: {}",
                                        type_phrase(layers), show(layers)));
        if (layers.empty())
            fail("/layers",
                 "the stack has no layers; give at least one, the last being the base, e.g. "
                 "{\"interface\": {\"type\": \"lambertian\", \"albedo\": 0.8}}");
        if (layers.size() > kMaxLayers)
            fail("/layers", fmt::format("the stack has {} layers; allowed: at most {}",
                                        layers.size(), kMaxLayers));
        for (std::size_t i = 0; i < layers.size(); ++i)
            s.layers.push_back(layer(layers[i], child("/layers", i), i, layers.size()));
        check_no_film_with_anisotropy(s, where_);
        // The RGB values of the spectra: at the channels' wavelengths, a dielectric's eta at the
        // green channel's.
        return s.is_spectral() ? s.at_wavelengths(s.wavelengths_nm, 1) : s;
    }

  private:
    [[noreturn]] void fail(const std::string& pointer, std::string problem) const {
        throw InputError(where_, pointer, std::move(problem));
    }

    /// `what` names the object and its keys, e.g. `a medium (an object with keys ...)`.
    void expect_object(const json& j, const std::string& pointer, const std::string& what) const {
        if (!j.is_object())
            fail(pointer, fmt::format("expected {}, got {}: {}", what, type_phrase(j), show(j)));
    }

    /// Every key of `object` must be one of `allowed`.
    void check_keys(const json& object, const std::string& pointer, Keys allowed,
                    std::string_view what) const {
        for (const auto& item : object.items()) {
            const std::string& key = item.key();
            if (std::find(allowed.begin(), allowed.end(), key) != allowed.end()) continue;
            fail(child(pointer, key),
                 fmt::format("unknown key \"{}\" in {};{} allowed keys: {}", key, what,
                             suggestion(key, allowed), quoted_list(allowed)));
        }
    }

    const json& required(const json& object, const std::string& pointer, std::string_view key,
                         std::string_view hint) const {
        if (!object.contains(key))
            fail(child(pointer, key), fmt::format("missing required key \"{}\" ({})", key, hint));
        return *object.find(key);
    }

    double number(const json& v, const std::string& pointer, Allowed allowed,
                  std::string_view meaning) const {
        if (!v.is_number())
            fail(pointer, fmt::format("expected a number ({}), got {}: {}", meaning, type_phrase(v),
                                      show(v)));
        const double x = v.get<double>();
        if (!std::isfinite(x))
            fail(pointer,
                 fmt::format("got {}; allowed: a finite number {} ({})", x, allowed.text, meaning));
        if (!allowed.ok(x))
            fail(pointer, fmt::format("got {}; allowed: {} ({})", show(v), allowed.text, meaning));
        return x + 0.0;  // −0 becomes +0 (the same number, printed without a sign)
    }

    /// A number (broadcast to the three channels) or an array of exactly three numbers.
    Rgbd rgb(const json& v, const std::string& pointer, Allowed allowed,
             std::string_view meaning) const {
        if (v.is_number()) return Rgbd(number(v, pointer, allowed, meaning));
        if (!v.is_array() || v.size() != 3)
            fail(pointer, fmt::format("expected a number or an array of 3 numbers [R, G, B] "
                                      "({}), got {}: {}",
                                      meaning, type_phrase(v), show(v)));
        Rgbd out;
        for (std::size_t c = 0; c < 3; ++c)
            out[c] = number(v[c], child(pointer, c), allowed, meaning);
        return out;
    }

    /// A spectral value (docs/stack-format.md, "Spectra"): an object with one key, "spectrum"
    /// ([[λ, value], …]), "sellmeier" ([B1, C1, …]), "cauchy" ([A, B, …]), "abbe" ([n_d, V_d]) or
    /// "material" (a glass); the last three only where `index` is true (a dielectric's eta). Its
    /// value at every whole nm of 360–830 must lie in `allowed`.
    Spectrum spectrum(const json& v, const std::string& pointer, Allowed allowed,
                      std::string_view meaning, bool index) const {
        const std::span<const std::string_view> forms(kSpectrumForms, index ? 5 : 1);
        if (v.size() != 1)
            fail(pointer, fmt::format("a spectral value is an object with one key, one of {}; "
                                      "got {}",
                                      quoted_list(forms), show(v)));
        const std::string key = v.begin().key();
        const std::string kp = child(pointer, key);
        if (std::find(forms.begin(), forms.end(), key) == forms.end())
            fail(kp, fmt::format("unknown spectral form \"{}\";{} allowed: {}", key,
                                 suggestion(key, forms), quoted_list(forms)));
        const json& body = v.begin().value();
        auto numbers = [&](std::size_t min_count, std::size_t max_count, std::string_view what) {
            if (!body.is_array() || body.size() < min_count || body.size() > max_count)
                fail(kp,
                     fmt::format("expected {}, got {}: {}", what, type_phrase(body), show(body)));
            std::vector<double> out;
            for (std::size_t i = 0; i < body.size(); ++i) {
                if (!body[i].is_number() || !std::isfinite(body[i].get<double>()))
                    fail(child(kp, i),
                         fmt::format("expected a finite number, got {}", show(body[i])));
                out.push_back(body[i].get<double>() + 0.0);
            }
            return out;
        };
        Spectrum out;
        if (key == "spectrum") {
            if (!body.is_array() || body.size() < 2 || body.size() > kMaxSpectrumSamples)
                fail(kp, fmt::format("expected an array of 2 to {} samples [wavelength_nm, value], "
                                     "got {}: {}",
                                     kMaxSpectrumSamples, type_phrase(body), show(body)));
            std::vector<double> wl, values;
            for (std::size_t i = 0; i < body.size(); ++i) {
                const json& sample = body[i];
                const std::string sp = child(kp, i);
                if (!sample.is_array() || sample.size() != 2)
                    fail(sp, fmt::format("expected a sample [wavelength_nm, value], got {}: {}",
                                         type_phrase(sample), show(sample)));
                wl.push_back(
                    number(sample[0], child(sp, 0), kSampleWavelength, "vacuum wavelength in nm"));
                if (i > 0 && wl[i] <= wl[i - 1])
                    fail(child(sp, 0), fmt::format("got {} after {}; allowed: wavelengths in "
                                                   "increasing order",
                                                   wl[i], wl[i - 1]));
                values.push_back(number(sample[1], child(sp, 1), allowed, meaning));
            }
            out = table_spectrum(std::move(wl), std::move(values));
        } else if (key == "sellmeier") {
            std::vector<double> b_c = numbers(2, 8, "[B1, C1, B2, C2, …], 1 to 4 pairs (C in µm²)");
            if (b_c.size() % 2 != 0)
                fail(kp,
                     fmt::format("expected pairs [B1, C1, B2, C2, …], got {} numbers", b_c.size()));
            // A resonance inside the visible range (λ² = C) sends n² to ±∞ there, between any
            // two wavelengths a check could sample; real glasses resonate in the ultraviolet and
            // the infrared.
            constexpr double kC_min = kSpectrumMinNm * 1e-3 * kSpectrumMinNm * 1e-3;
            constexpr double kC_max = kSpectrumMaxNm * 1e-3 * kSpectrumMaxNm * 1e-3;
            for (std::size_t i = 0; i < b_c.size(); i += 2)
                if (b_c[i] != 0 && b_c[i + 1] >= kC_min && b_c[i + 1] <= kC_max)
                    fail(
                        child(kp, i + 1),
                        fmt::format("got C = {} µm², a resonance at {:.6g} nm; allowed: C < {:.6g} "
                                    "or > {:.6g} µm² (resonances outside 360-830 nm), or B = 0",
                                    b_c[i + 1], std::sqrt(b_c[i + 1]) * 1e3, kC_min, kC_max));
            out = sellmeier_spectrum(std::move(b_c));
        } else if (key == "cauchy") {
            out = cauchy_spectrum(
                numbers(1, 4, "[A, B, C, D] (B in µm², C in µm⁴, …), 1 to 4 terms"));
        } else if (key == "abbe") {
            const std::vector<double> nv = numbers(2, 2, "[n_d, V_d]");
            number(body[0], child(kp, 0), kDielectricEta, "refractive index at 587.56 nm");
            number(body[1], child(kp, 1), kAbbe, "Abbe number");
            out = abbe_spectrum(nv[0], nv[1]);
        } else {  // a named glass
            if (!body.is_string() || !is_glass_material(body.get<std::string>()))
                fail(kp, fmt::format("got {}; allowed: one of {} (data/glass)", show(body),
                                     glass_material_names()));
            out = glass_material_eta(body.get<std::string>());
        }
        check_spectrum(out, kp, allowed, meaning);
        out.given = v.dump();
        return out;
    }

    /// The spectrum at every whole nm of 360–830 lies in `allowed`.
    void check_spectrum(const Spectrum& s, const std::string& pointer, Allowed allowed,
                        std::string_view meaning) const {
        std::vector<double> wavelengths = s.turning_points_nm(kSpectrumMinNm, kSpectrumMaxNm);
        for (double l = kSpectrumMinNm; l <= kSpectrumMaxNm; l += 1)
            wavelengths.push_back(l);
        std::sort(wavelengths.begin(), wavelengths.end());
        for (double l : wavelengths) {
            const double value = s.at(l);
            if (!std::isfinite(value) || !allowed.ok(value))
                fail(pointer, fmt::format("the spectrum is {} at {} nm; allowed: {} ({}) over "
                                          "360-830 nm",
                                          value, l, allowed.text, meaning));
        }
    }

    /// A number, [R, G, B], or a spectral value (an object: `spectrum`).
    Rgbd rgb_or_spectrum(const json& v, const std::string& pointer, Allowed allowed,
                         std::string_view meaning, std::optional<Spectrum>& spectral) const {
        if (v.is_object()) {
            spectral = spectrum(v, pointer, allowed, meaning, false);
            return Rgbd(0.0);  // set from the spectrum (Stack::at_wavelengths)
        }
        return rgb(v, pointer, allowed, meaning);
    }

    Layer layer(const json& j, const std::string& pointer, std::size_t index, std::size_t count) {
        expect_object(j, pointer,
                      fmt::format("a layer (an object with keys {})", quoted_list(kLayerKeys)));
        check_keys(j, pointer, kLayerKeys, "a layer");
        const bool last = index + 1 == count;

        Layer out;
        const std::string ip = child(pointer, "interface");
        out.interface = interface(required(j, pointer, "interface",
                                           "the interface at the top of this layer, an object "
                                           "with a \"type\""),
                                  ip);
        if (out.interface.is_opaque() && !last)
            fail(child(ip, "type"),
                 fmt::format("a {} interface is opaque and must be the last one (the base), but "
                             "{} more layer{} follow{} it; move it to the bottom or remove the "
                             "layers below",
                             j["interface"]["type"].get<std::string>(), count - index - 1,
                             count - index - 1 == 1 ? "" : "s", count - index - 1 == 1 ? "s" : ""));
        if (j.contains("medium")) {
            const std::string mp = child(pointer, "medium");
            if (last)
                fail(mp,
                     "the last interface (the base) cannot have a medium below it: it would be a "
                     "semi-infinite medium, which is not supported; remove \"medium\" here, or "
                     "close the medium with another interface below (a dielectric makes a slab)");
            out.has_medium = true;
            out.medium = medium(j["medium"], mp);
        }
        return out;
    }

    InterfaceSpec interface(const json& j, const std::string& pointer) const {
        expect_object(j, pointer,
                      fmt::format("an interface (an object with a \"type\", one of {})",
                                  quoted_list(kInterfaceTypes)));
        const std::string tp = child(pointer, "type");
        const json& type = required(j, pointer, "type",
                                    "one of \"dielectric\", \"conductor\", "
                                    "\"lambertian\"");
        if (!type.is_string())
            fail(tp, fmt::format("expected a string, one of {}; got {}: {}",
                                 quoted_list(kInterfaceTypes), type_phrase(type), show(type)));
        const std::string name = type.get<std::string>();

        InterfaceSpec out;
        if (name == "dielectric") {
            out.type = InterfaceType::Dielectric;
            check_keys(j, pointer, kDielectricKeys, "a dielectric interface");
            const json& eta = required(j, pointer, "eta",
                                       "absolute refractive index of what lies below, in [1, 5]");
            if (eta.is_array())
                fail(child(pointer, "eta"),
                     fmt::format("a dielectric's eta must be a single number or a spectral value "
                                 "(an object), got {}: {}; one refraction path serves all "
                                 "channels, so RGB indices are not supported (a dispersive index "
                                 "is a spectrum, e.g. {{\"material\": \"BK7\"}})",
                                 type_phrase(eta), show(eta)));
            if (eta.is_object())
                out.eta_spectrum = spectrum(eta, child(pointer, "eta"), kDielectricEta,
                                            "absolute refractive index of what lies below", true);
            else
                out.eta = number(eta, child(pointer, "eta"), kDielectricEta,
                                 "absolute refractive index of what lies below");
            roughness(j, pointer, "dielectric", out);
            film(j, pointer, out);
        } else if (name == "conductor") {
            out.type = InterfaceType::Conductor;
            check_keys(j, pointer, kConductorKeys, "a conductor interface");
            if (j.contains("material")) {
                const json& m = j["material"];
                const std::string mp = child(pointer, "material");
                if (!m.is_string() || !is_conductor_material(m.get<std::string>()))
                    fail(mp, fmt::format("got {}; allowed: one of {} (measured n, k: data/nk)",
                                         show(m), conductor_material_names()));
                for (const char* key : {"eta", "k"})
                    if (j.contains(key))
                        fail(child(pointer, key),
                             fmt::format("a conductor gives either \"material\" or \"eta\" and "
                                         "\"k\", not both (\"{}\" sets them)",
                                         m.get<std::string>()));
                out.material = m.get<std::string>();
                out.eta_spectrum = conductor_material_eta(out.material);
                out.k_spectrum = conductor_material_k(out.material);
            } else {
                out.eta_rgb = rgb_or_spectrum(
                    required(j, pointer, "eta",
                             "real part of the absolute complex index, in [0.01, 10], number, "
                             "[R, G, B] or a spectrum; or give a \"material\""),
                    child(pointer, "eta"), kConductorEta, "real part of the absolute complex index",
                    out.eta_spectrum);
                out.k = rgb_or_spectrum(
                    required(j, pointer, "k",
                             "extinction coefficient, in [0, 10], number, [R, G, B] or a "
                             "spectrum"),
                    child(pointer, "k"), kConductorK,
                    "extinction coefficient, imaginary part of the absolute index", out.k_spectrum);
            }
            roughness(j, pointer, "conductor", out);
            film(j, pointer, out);
        } else if (name == "lambertian") {
            out.type = InterfaceType::Lambertian;
            check_keys(j, pointer, kLambertianKeys, "a lambertian interface");
            out.albedo = rgb_or_spectrum(
                required(j, pointer, "albedo", "in [0, 1], number, [R, G, B] or a spectrum"),
                child(pointer, "albedo"), kUnit, "Lambertian albedo", out.albedo_spectrum);
        } else {
            fail(tp, fmt::format("unknown interface type \"{}\";{} allowed: {}", name,
                                 suggestion(name, kInterfaceTypes), quoted_list(kInterfaceTypes)));
        }
        return out;
    }

    /// `alpha`: a number, or [alpha_x, alpha_y] (both rough: an anisotropic interface), and the
    /// optional `tangent_deg`.
    void roughness(const json& j, const std::string& pointer, std::string_view type,
                   InterfaceSpec& out) const {
        const json& v = required(j, pointer, "alpha",
                                 fmt::format("a {} needs an explicit {}", type, kAlphaHint));
        const std::string ap = child(pointer, "alpha");
        if (v.is_array()) {
            if (v.size() != 2)
                fail(ap, fmt::format("expected a number or [alpha_x, alpha_y] (2 numbers), got "
                                     "an array of {}: {}",
                                     v.size(), show(v)));
            out.alpha = number(v[0], child(ap, std::size_t{0}), kAlphaRough,
                               "GGX roughness along the tangent (alpha_x)");
            out.alpha_y = number(v[1], child(ap, std::size_t{1}), kAlphaRough,
                                 "GGX roughness along the bitangent (alpha_y)");
        } else {
            out.alpha = number(v, ap, kAlpha, "GGX roughness, 0 = smooth");
        }
        if (j.contains("tangent_deg"))
            out.tangent_deg =
                number(j["tangent_deg"], child(pointer, "tangent_deg"), kTangentDeg,
                       "angle of the tangent (the direction of alpha_x) from +x, in degrees");
    }

    /// The optional "film" of a dielectric or conductor interface.
    void film(const json& j, const std::string& pointer, InterfaceSpec& out) const {
        if (!j.contains("film")) return;
        const std::string fp = child(pointer, "film");
        const json& f = j["film"];
        expect_object(f, fp,
                      fmt::format("a thin film (an object with keys {})", quoted_list(kFilmKeys)));
        check_keys(f, fp, kFilmKeys, "a thin film");
        out.has_film = true;
        const std::string tp = child(fp, "thickness_nm");
        const json& t = required(f, fp, "thickness_nm",
                                 "the film's thickness in nm, in [0, 10000], or a range [min, max] "
                                 "over which it is uniformly distributed");
        constexpr std::string_view kMeaning = "film thickness in nm";
        if (t.is_array()) {
            if (t.size() != 2)
                fail(tp, fmt::format("expected a number or a range [min, max] of 2 numbers "
                                     "({}), got {}: {}",
                                     kMeaning, type_phrase(t), show(t)));
            out.film.thickness_nm = number(t[0], child(tp, 0), kFilmThickness, kMeaning);
            out.film.thickness_max_nm = number(t[1], child(tp, 1), kFilmThickness, kMeaning);
            if (out.film.thickness_max_nm < out.film.thickness_nm)
                fail(tp, fmt::format("got the range {}; allowed: [min, max] with min <= max "
                                     "(a uniform distribution of thickness over it)",
                                     show(t)));
        } else {
            out.film.thickness_nm = number(t, tp, kFilmThickness, kMeaning);
            out.film.thickness_max_nm = out.film.thickness_nm;
        }
        out.film.eta = number(required(f, fp, "eta", "the film's refractive index, in [0.01, 5]"),
                              child(fp, "eta"), kFilmEta, "real part of the film's absolute index");
        if (f.contains("k"))
            out.film.k = number(f["k"], child(fp, "k"), kConductorK,
                                "extinction coefficient of the film, imaginary part of its index");
    }

    MediumSpec medium(const json& j, const std::string& pointer) const {
        expect_object(j, pointer,
                      fmt::format("a medium (an object with keys {})", quoted_list(kMediumKeys)));
        check_keys(j, pointer, kMediumKeys, "a medium");
        MediumSpec out;
        if (j.contains("tau_a"))
            out.tau_a = rgb_or_spectrum(j["tau_a"], child(pointer, "tau_a"), kOpticalDepth,
                                        "absorption normal optical depth, dimensionless",
                                        out.tau_a_spectrum);
        if (j.contains("tau_s"))
            out.tau_s = rgb_or_spectrum(j["tau_s"], child(pointer, "tau_s"), kScatteringDepth,
                                        "scattering normal optical depth, dimensionless",
                                        out.tau_s_spectrum);
        if (j.contains("g"))
            out.g = rgb(j["g"], child(pointer, "g"), kHgG, "Henyey-Greenstein mean cosine");
        return out;
    }

    std::string where_;
};

// ---- Parsing the text: duplicate keys and number overflow -----------------------------------

/// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string parser_message(const json::exception& e) {
    return json_exception_text(e);
}

/// Follows the document event by event (nlohmann's SAX interface) to know the JSON pointer of
/// what it is reading. It rejects duplicate keys, which JSON parsers silently resolve to the last
/// one, and names the field when a number overflows (1e999 is refused by the parser). A pass of
/// its own before the document is built: nlohmann's parser with a callback (3.11) searches the
/// enclosing array again at the end of each object, quadratic in the array's length (400 000
/// objects: 27 s); this pass and the plain parse are linear.
class PathTracker {
  public:
    explicit PathTracker(const std::string& where) : where_(where) {}

    bool null() { return value(); }
    bool boolean(bool) { return value(); }
    bool number_integer(json::number_integer_t) { return value(); }
    bool number_unsigned(json::number_unsigned_t) { return value(); }
    bool number_float(json::number_float_t, const json::string_t&) { return value(); }
    bool string(json::string_t&) { return value(); }
    bool binary(json::binary_t&) { return value(); }
    bool start_object(std::size_t) { return starts(true); }
    bool start_array(std::size_t) { return starts(false); }
    bool end_object() { return ends(); }
    bool end_array() { return ends(); }
    bool key(json::string_t& key) {
        Frame& f = frames_.back();
        f.key = key;
        if (!f.keys.insert(f.key).second)
            throw InputError(where_, pending_pointer(),
                             fmt::format("duplicate key \"{}\"; each key may appear once in an "
                                         "object (a parser would silently keep the last one)",
                                         f.key));
        return true;
    }
    /// The parser's error (malformed text, or 406: a number beyond a double's range): kept for
    /// parse_json_strict, which names the field.
    bool parse_error(std::size_t, const std::string&, const json::exception& e) {
        error_id_ = e.id;
        error_ = parser_message(e);
        return false;
    }

    int error_id() const { return error_id_; }
    const std::string& error() const { return error_; }

    /// The pointer of the value being read now (the one after the last key or array element).
    std::string pending_pointer() const {
        std::string out;
        for (std::size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            if (f.is_object)
                out = child(out, f.key);
            else  // elements before the innermost are in progress; the innermost's is next
                out = child(out, i + 1 == frames_.size() ? f.count : f.count - 1);
        }
        return out;
    }

  private:
    static constexpr int kMaxDepth = 32;
    struct Frame {
        bool is_object;
        std::set<std::string> keys;
        std::string key;
        std::size_t count;
    };
    bool value() {
        element_starts();
        return true;
    }
    bool starts(bool is_object) {
        // lamina's files nest at most ten levels deep (a stack's tabulated spectrum, its deepest
        // value, sits seven deep: stack, layers, layer, interface or medium, value, samples,
        // sample; a study's configurations file adds three); far deeper is no lamina file, and
        // would only make messages unreadable.
        if (frames_.size() >= std::size_t(kMaxDepth))
            throw InputError(
                where_, pending_pointer(),
                fmt::format("JSON nested more than {} levels deep; lamina's files need at most "
                            "ten",
                            kMaxDepth));
        element_starts();
        frames_.push_back({is_object, {}, {}, 0});
        return true;
    }
    bool ends() {
        frames_.pop_back();
        return true;
    }
    void element_starts() {
        if (!frames_.empty() && !frames_.back().is_object) ++frames_.back().count;
    }

    const std::string& where_;
    std::vector<Frame> frames_;
    int error_id_ = 0;
    std::string error_;
};

}  // namespace

json parse_json_strict(const std::string& text, const std::string& where) {
    // The parser takes a NUL byte for the end of the text: whatever followed would be ignored.
    if (const std::size_t nul = text.find('\0'); nul != std::string::npos)
        throw InputError(where, "",
                         fmt::format("malformed JSON: a NUL byte at offset {} (JSON text has "
                                     "none)",
                                     nul));
    PathTracker tracker(where);
    if (!json::sax_parse(text, &tracker)) {
        const std::string at = tracker.pending_pointer();
        if (tracker.error_id() == 406)  // a number literal beyond a double's range, e.g. 1e999
            throw InputError(
                where, at,
                fmt::format("{}: not a finite number; allowed: finite numbers{}", tracker.error(),
                            at.empty() ? " (the whole file is this number)" : ""));
        throw InputError(where, "",
                         fmt::format("malformed JSON: {}{}", tracker.error(),
                                     at.empty() ? "" : fmt::format(" (near {})", at)));
    }
    try {
        return json::parse(text);
    } catch (const json::exception& e) {  // not expected: the same text passed the first pass
        throw InputError(where, "", fmt::format("malformed JSON: {}", parser_message(e)));
    }
}

namespace {

// ---- Describing -----------------------------------------------------------------------------

/// What a spectral value is, for describe: the named material, or the spectrum's form.
std::string spectrum_label(const Spectrum& spectrum) {
    const json given = json::parse(spectrum.given);
    const auto first = given.begin();
    return first.key() == "material" ? first.value().get<std::string>() : first.key();
}

/// "0.1" when the three channels agree, else "(0.1, 0, 0.9)".
std::string show_rgb(const Rgbd& v) {
    if (v[0] == v[1] && v[1] == v[2]) return fmt::format("{}", v[0]);
    return fmt::format("({}, {}, {})", v[0], v[1], v[2]);
}

json rgb_json(const Rgbd& v) {
    return json::array({v[0], v[1], v[2]});
}

/// An interface's `alpha`: the number, or [alpha_x, alpha_y] where α_y was given.
json alpha_json(const InterfaceSpec& i) {
    return i.alpha_y < 0 ? json(i.alpha) : json::array({i.alpha, i.alpha_y});
}

/// "α=0.1", or "α=(0.1, 0.4) ψ=30°" for an interface with its own α_y or tangent.
std::string show_alpha(const InterfaceSpec& i) {
    std::string out = i.alpha_y < 0 ? fmt::format("α={}", i.alpha)
                                    : fmt::format("α=({}, {})", i.alpha, i.alpha_y);
    if (i.tangent_deg != 0) out += fmt::format(" ψ={}°", i.tangent_deg);
    return out;
}

}  // namespace

void check_no_film_with_anisotropy(const Stack& stack, const std::string& where) {
    if (!stack.has_film() || !stack.is_anisotropic()) return;
    // The file's pointers of the first film and the first anisotropic interface.
    std::size_t film = 0, anisotropic = 0;
    while (!stack.layers[film].interface.has_film)
        ++film;
    while (!stack.layers[anisotropic].interface.is_anisotropic())
        ++anisotropic;
    throw InputError(where.empty() ? stack.name : where,
                     fmt::format("/layers/{}/interface/film", film),
                     fmt::format("a thin film on a stack with an anisotropic interface "
                                 "(/layers/{}/interface/alpha) is not traced yet (films and "
                                 "anisotropy each work alone); remove the film or make the "
                                 "roughness one number",
                                 anisotropic));
}

Stack stack_from_json(const nlohmann::json& j, const std::string& where) {
    return Reader(where).stack(j);
}

Stack load_stack(const std::filesystem::path& path) {
    // A stack file is a few kilobytes (tabulated spectra included); a stream without end
    // (/dev/zero, a pipe) must not be read forever.
    return parse_stack(read_file_bounded(path, kMaxStackFileBytes, "the stack file"),
                       path.string());
}

Stack parse_stack(const std::string& text, const std::string& where) {
    return stack_from_json(parse_json_strict(text, where), where);
}

nlohmann::json stack_to_json(const Stack& stack) {
    // A value given as a spectrum is written as it was given (its RGB values follow from it).
    auto value = [](const std::optional<Spectrum>& spectrum, const json& plain) {
        return spectrum ? json::parse(spectrum->given) : plain;
    };
    json layers = json::array();
    for (const Layer& layer : stack.layers) {
        const InterfaceSpec& i = layer.interface;
        json interface;
        switch (i.type) {
            case InterfaceType::Dielectric:
                interface = {{"type", "dielectric"},
                             {"eta", value(i.eta_spectrum, i.eta)},
                             {"alpha", alpha_json(i)}};
                if (i.tangent_deg != 0) interface["tangent_deg"] = i.tangent_deg;
                break;
            case InterfaceType::Conductor:
                interface = {{"type", "conductor"}};
                if (!i.material.empty()) {
                    interface["material"] = i.material;
                } else {
                    interface["eta"] = value(i.eta_spectrum, rgb_json(i.eta_rgb));
                    interface["k"] = value(i.k_spectrum, rgb_json(i.k));
                }
                interface["alpha"] = alpha_json(i);
                if (i.tangent_deg != 0) interface["tangent_deg"] = i.tangent_deg;
                break;
            case InterfaceType::Lambertian:
                interface = {{"type", "lambertian"},
                             {"albedo", value(i.albedo_spectrum, rgb_json(i.albedo))}};
                break;
        }
        if (i.has_film)
            interface["film"] = {
                {"thickness_nm", i.film.varies()
                                     ? json::array({i.film.thickness_nm, i.film.thickness_max_nm})
                                     : json(i.film.thickness_nm)},
                {"eta", i.film.eta},
                {"k", i.film.k}};
        json l = {{"interface", interface}};
        if (layer.has_medium)
            l["medium"] = {
                {"tau_a", value(layer.medium.tau_a_spectrum, rgb_json(layer.medium.tau_a))},
                {"tau_s", value(layer.medium.tau_s_spectrum, rgb_json(layer.medium.tau_s))},
                {"g", rgb_json(layer.medium.g)}};
        layers.push_back(std::move(l));
    }
    json out = {{"name", stack.name}, {"ambient_eta", stack.ambient_eta}, {"layers", layers}};
    // Written where it matters or was changed: the canonical form of a stack without a film or a
    // spectrum is what it has always been.
    if (stack.has_film() || stack.is_spectral() ||
        !(stack.wavelengths_nm == kDefaultChannelWavelengthsNm))
        out["wavelengths_nm"] = rgb_json(stack.wavelengths_nm);
    return out;
}

Stack Stack::at_wavelengths(const Rgbd& wavelengths, int path_channel) const {
    Stack out = *this;
    out.wavelengths_nm = wavelengths;
    // A value given as RGB numbers stands for the spectrum that takes, at each wavelength, the
    // number of the channel whose wavelength (this stack's wavelengths_nm) is nearest: at its own
    // channels' wavelengths it is itself, and channel c at another wavelength reads the number of
    // its part of the spectrum, not the c-th number.
    // Channel c keeps its own number where another channel's wavelength is as near (a stack
    // whose wavelengths_nm repeat one is itself at its own wavelengths).
    auto nearest_channel = [&](std::size_t c) {
        const double lambda = wavelengths[c];
        std::size_t best = c;
        for (std::size_t k = 0; k < 3; ++k)
            if (std::abs(wavelengths_nm[k] - lambda) < std::abs(wavelengths_nm[best] - lambda))
                best = k;
        return best;
    };
    auto at = [&](const std::optional<Spectrum>& spectrum, Rgbd& rgb) {
        const Rgbd given = rgb;
        for (std::size_t c = 0; c < 3; ++c)
            rgb[c] = spectrum ? spectrum->at(wavelengths[c]) : given[nearest_channel(c)];
    };
    for (Layer& layer : out.layers) {
        InterfaceSpec& i = layer.interface;
        switch (i.type) {
            case InterfaceType::Dielectric:
                if (i.eta_spectrum)
                    i.eta = i.eta_spectrum->at(wavelengths[std::size_t(path_channel)]);
                break;
            case InterfaceType::Conductor:
                at(i.eta_spectrum, i.eta_rgb);
                at(i.k_spectrum, i.k);
                break;
            case InterfaceType::Lambertian:
                at(i.albedo_spectrum, i.albedo);
                break;
        }
        at(layer.medium.tau_a_spectrum, layer.medium.tau_a);
        at(layer.medium.tau_s_spectrum, layer.medium.tau_s);
        at(std::nullopt, layer.medium.g);  // the phase function's g: RGB numbers only
    }
    return out;
}

namespace {
/// " film d=… nm η=…" (and k) of a filmed interface, "" otherwise.
std::string describe_film(const InterfaceSpec& i) {
    if (!i.has_film) return "";
    const FilmSpec& f = i.film;
    std::string out = f.varies()
                          ? fmt::format(" film d=[{}, {}] nm", f.thickness_nm, f.thickness_max_nm)
                          : fmt::format(" film d={} nm", f.thickness_nm);
    out += fmt::format(" η={}", f.eta);
    if (f.k > 0) out += fmt::format(" k={}", f.k);
    return out;
}
}  // namespace

std::string describe(const Stack& stack) {
    std::string out = fmt::format("{}: ", stack.name);
    out += stack.ambient_eta == 1.0 ? "air" : fmt::format("ambient η={}", stack.ambient_eta);
    for (std::size_t n = 0; n < stack.layers.size(); ++n) {
        const Layer& layer = stack.layers[n];
        const InterfaceSpec& i = layer.interface;
        switch (i.type) {
            case InterfaceType::Dielectric:
                out += fmt::format(" | dielectric η={} {}",
                                   i.eta_spectrum ? spectrum_label(*i.eta_spectrum)
                                                  : fmt::format("{}", i.eta),
                                   show_alpha(i)) +
                       describe_film(i);
                if (n + 1 == stack.layers.size())
                    out += fmt::format(" (slab: transmits into η={})", i.eta);
                break;
            case InterfaceType::Conductor:
                if (!i.material.empty())
                    out += fmt::format(" | conductor {} {}", i.material, show_alpha(i));
                else
                    out += fmt::format(
                        " | conductor η={} k={} {}",
                        i.eta_spectrum ? spectrum_label(*i.eta_spectrum) : show_rgb(i.eta_rgb),
                        i.k_spectrum ? spectrum_label(*i.k_spectrum) : show_rgb(i.k),
                        show_alpha(i));
                out += describe_film(i);
                break;
            case InterfaceType::Lambertian:
                out += fmt::format(" | lambertian ρ={}", i.albedo_spectrum
                                                             ? spectrum_label(*i.albedo_spectrum)
                                                             : show_rgb(i.albedo));
                break;
        }
        if (layer.has_medium) {
            const MediumSpec& m = layer.medium;
            out +=
                fmt::format(" | medium τa={}", m.tau_a_spectrum ? spectrum_label(*m.tau_a_spectrum)
                                                                : show_rgb(m.tau_a));
            // A τs spectrum scatters at some wavelength even where the channels' values are 0.
            if (m.scatters() || m.tau_s_spectrum)
                out += fmt::format(
                    " τs={} g={}",
                    m.tau_s_spectrum ? spectrum_label(*m.tau_s_spectrum) : show_rgb(m.tau_s),
                    show_rgb(m.g));
        }
    }
    return out;
}

Stack flipped_stack(const Stack& stack) {
    LAMINA_CHECK(!stack.layers.empty() && stack.transmits());
    const std::size_t L = stack.layers.size();
    Stack out;
    out.name = stack.name + " (from below)";
    out.ambient_eta = stack.base().eta;
    out.wavelengths_nm = stack.wavelengths_nm;
    for (std::size_t j = 0; j < L; ++j) {
        const std::size_t k = L - 1 - j;  // the old interface
        Layer layer;
        layer.interface = stack.layers[k].interface;
        layer.interface.eta = stack.eta_above(k);
        // A dielectric's spectral index moves with its region as the number does.
        layer.interface.eta_spectrum =
            k >= 1 ? stack.layers[k - 1].interface.eta_spectrum : std::nullopt;
        if (k >= 1) {  // the old region above interface k is the medium of layer k − 1
            layer.has_medium = stack.layers[k - 1].has_medium;
            layer.medium = stack.layers[k - 1].medium;
        }
        out.layers.push_back(layer);
    }
    return out;
}

}  // namespace lamina

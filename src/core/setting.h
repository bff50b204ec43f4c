#pragma once
// Settings, each declared once (docs/architecture.md, "How a setting travels").
//
// A settings struct (SimulationSettings, MicrosurfaceSettings, …) lists each of its settings once,
// in a static function `fields(self, visit)` that calls visit(SettingInfo, member) per setting:
// the name, one line of help, the allowed range of a number and, for the reference's cache key,
// the value the key leaves unsaid. The default is the member's initializer. Everything that reads
// or writes settings goes through that list and the codec of the member's type (SettingCodec):
//
//   - JSON (settings_to_json, settings_from_json): result.json, the study's files, the MPI work
//   list
//     and Python's keyword arguments and defaults;
//   - the command line (cli/settings_options.h): the option --NAME ('-' for '_'), its help, its
//     default and the error that names it;
//   - the text of the reference's cache key (settings_key_text).
//
// Adding a setting is its member with its default and one line in `fields`; the code that uses it
// reads the member.
//
// Errors: a value outside what the codec accepts is an InputError naming `where` (the file, or
// "command line") and the field (the setting's name, or the option the caller names).

#include "core/enum_names.h"
#include "core/error.h"
#include "core/grid.h"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <array>
#include <charconv>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace lamina {

struct SettingInfo {
    const char* name;  ///< snake_case: the JSON key and Python keyword; --name-with-dashes
    const char* help;  ///< one line
    /// Numbers: the closed range allowed.
    double min = -std::numeric_limits<double>::infinity();
    double max = std::numeric_limits<double>::infinity();
    /// How the reference's cache key (study/reference.h) holds the setting.
    enum class Key {
        Tail,   ///< settings_key_text writes " | name value", unless the value is key_unsaid
        Fixed,  ///< the key's fixed part writes it itself, in its own form
        No,     ///< not at all: it does not change the reference's numbers (threads)
    } key = Key::Tail;
    /// Key::Tail: the value the key leaves unsaid, the one the reference had before the setting
    /// existed, so that caches made then stay valid; null: always said.
    const char* key_unsaid = nullptr;
};

/// The command-line spelling of a setting's name: "--max-events" for "max_events".
std::string option_name(const std::string& setting_name);

/// Reading and writing one type of setting: text (the command line, the cache key) and JSON.
/// Specialized below for whole numbers, reals, on/off, incidence lists, grids and named enums.
template <typename T, typename Enable = void>
struct SettingCodec;

namespace setting_detail {
/// A finite number written in any decimal notation ("2.5", "1e6"); false otherwise.
bool parse_real(const std::string& text, double& out);
/// An integer written as one (optional sign, digits) within the range of T; false otherwise.
template <typename T>
bool parse_integer(const std::string& text, T& out) {
    const std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t");
    if (a == std::string::npos) return false;
    const char* first = text.data() + a;
    const char* last = text.data() + b + 1;
    if (*first == '+') ++first;
    const auto [ptr, ec] = std::from_chars(first, last, out);
    return ec == std::errc() && ptr == last;
}
[[noreturn]] void fail(const std::string& where, const std::string& field, std::string problem);
std::string range_text(const SettingInfo& info);
/// Whether `text` is an integer literal (an optional sign, then digits; blanks around).
bool is_integer_text(const std::string& text);
double checked_whole(double v, const std::string& shown, const SettingInfo& info,
                     const std::string& where, const std::string& field);
}  // namespace setting_detail

/// Whole numbers: text written as an integer ("18446744073709551615") or in any decimal notation
/// whose value is whole and at most 1e15 in magnitude ("1e6"); JSON integers (or such text); within
/// [info.min, info.max] and the type's range.
template <typename T>
struct SettingCodec<T, std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>>> {
    static std::string to_text(T v) { return std::to_string(v); }
    static nlohmann::json to_json(T v) { return v; }
    static T from_text(const std::string& text, const SettingInfo& info, const std::string& where,
                       const std::string& field) {
        T exact{};
        if (setting_detail::parse_integer(text, exact))
            return checked(exact, text, info, where, field);
        // Integer text beyond the type: its own range, not the decimal notation's 1e15.
        if (setting_detail::is_integer_text(text)) {
            constexpr T kMin = std::numeric_limits<T>::min(), kMax = std::numeric_limits<T>::max();
            const std::string lo =
                info.min > double(kMin) ? fmt::format("{}", info.min) : std::to_string(kMin);
            const std::string hi =
                info.max < double(kMax) ? fmt::format("{}", info.max) : std::to_string(kMax);
            setting_detail::fail(where, field,
                                 fmt::format("'{}' is not allowed: expected a whole number in "
                                             "[{}, {}]",
                                             text, lo, hi));
        }
        double v = 0;
        if (!setting_detail::parse_real(text, v))
            setting_detail::fail(where, field, "'" + text + "' is not a number");
        return T(setting_detail::checked_whole(v, "'" + text + "'", info, where, field));
    }
    static T from_json(const nlohmann::json& j, const SettingInfo& info, const std::string& where,
                       const std::string& field) {
        if (j.is_string()) return from_text(j.get<std::string>(), info, where, field);
        if (j.is_number_integer()) return from_text(j.dump(), info, where, field);
        if (!j.is_number()) setting_detail::fail(where, field, "expected a whole number");
        return T(setting_detail::checked_whole(j.get<double>(), j.dump(), info, where, field));
    }

  private:
    static T checked(T v, const std::string& text, const SettingInfo& info,
                     const std::string& where, const std::string& field) {
        if (double(v) < info.min || double(v) > info.max)
            setting_detail::fail(where, field,
                                 "'" + text + "' is not allowed: expected a whole number " +
                                     setting_detail::range_text(info));
        return v;
    }
};

/// Reals within [info.min, info.max].
template <>
struct SettingCodec<double> {
    static std::string to_text(double v);
    static nlohmann::json to_json(double v) { return v; }
    static double from_text(const std::string& text, const SettingInfo& info,
                            const std::string& where, const std::string& field);
    static double from_json(const nlohmann::json& j, const SettingInfo& info,
                            const std::string& where, const std::string& field);
};

/// On/off switches: text "on" | "off", JSON true | false (or the text).
template <>
struct SettingCodec<bool> {
    static std::string to_text(bool v) { return v ? "on" : "off"; }
    static nlohmann::json to_json(bool v) { return v; }
    static bool from_text(const std::string& text, const SettingInfo& info,
                          const std::string& where, const std::string& field);
    static bool from_json(const nlohmann::json& j, const SettingInfo& info,
                          const std::string& where, const std::string& field);
};

/// Incidences θi in degrees, each in [0, 90): text "0,30,60", JSON [0, 30, 60]; at least one.
template <>
struct SettingCodec<std::vector<double>> {
    static std::string to_text(const std::vector<double>& v);
    static nlohmann::json to_json(const std::vector<double>& v) { return v; }
    static std::vector<double> from_text(const std::string& text, const SettingInfo& info,
                                         const std::string& where, const std::string& field);
    static std::vector<double> from_json(const nlohmann::json& j, const SettingInfo& info,
                                         const std::string& where, const std::string& field);
};

/// The goniophotometer's grid: text "90x90", JSON {"n_theta": 90, "n_phi": 90} (or the text).
template <>
struct SettingCodec<HemisphereGrid> {
    static std::string to_text(const HemisphereGrid& g) { return g.to_string(); }
    static nlohmann::json to_json(const HemisphereGrid& g);
    static HemisphereGrid from_text(const std::string& text, const SettingInfo& info,
                                    const std::string& where, const std::string& field);
    static HemisphereGrid from_json(const nlohmann::json& j, const SettingInfo& info,
                                    const std::string& where, const std::string& field);
};

/// Named enums (core/enum_names.h): text and JSON are the value's name.
template <typename E>
struct SettingCodec<E, std::enable_if_t<std::is_enum_v<E>>> {
    static std::string to_text(E v) { return enum_text(v); }
    static nlohmann::json to_json(E v) { return to_text(v); }
    static E from_text(const std::string& text, const SettingInfo&, const std::string& where,
                       const std::string& field) {
        std::string allowed;
        for (const auto& n : enum_names(E{})) {
            if (n.text == text) return n.value;
            allowed += (allowed.empty() ? "" : ", ") + std::string(n.text) + " (" + n.meaning + ")";
        }
        setting_detail::fail(where, field,
                             "'" + text + "' is not " + enum_noun(E{}) + ": use " + allowed);
    }
    static E from_json(const nlohmann::json& j, const SettingInfo& info, const std::string& where,
                       const std::string& field) {
        if (!j.is_string()) setting_detail::fail(where, field, "expected a name (a string)");
        return from_text(j.get<std::string>(), info, where, field);
    }
};

/// The settings of `s` as a JSON object, one key per setting.
template <typename S>
nlohmann::json settings_to_json(const S& s) {
    nlohmann::json j = nlohmann::json::object();
    S::fields(s, [&](const SettingInfo& info, const auto& member) {
        using T = std::decay_t<decltype(member)>;
        j[info.name] = SettingCodec<T>::to_json(member);
    });
    return j;
}

/// Reads the settings a JSON object names into `s` (the others keep their values). InputError
/// naming `where` and the setting for a bad value, and for a key that is no setting of S (listing
/// them).
template <typename S>
void settings_from_json(S& s, const nlohmann::json& j, const std::string& where) {
    if (!j.is_object()) throw InputError(where, "", "expected an object of settings");
    std::vector<std::string> names;
    S::fields(s, [&](const SettingInfo& info, auto& member) {
        using T = std::decay_t<decltype(member)>;
        names.push_back(info.name);
        if (const auto it = j.find(info.name); it != j.end())
            member = SettingCodec<T>::from_json(*it, info, where, info.name);
    });
    for (const auto& [key, value] : j.items()) {
        bool known = false;
        for (const std::string& n : names)
            known = known || n == key;
        if (!known) {
            std::string list;
            for (const std::string& n : names)
                list += (list.empty() ? "" : ", ") + n;
            throw InputError(where, key, "is not a setting; the settings are " + list);
        }
    }
}

/// The text the reference's cache key holds for the Key::Tail settings of `s`: " | NAME VALUE" for
/// each one not at its key_unsaid value, in declaration order.
template <typename S>
std::string settings_key_text(const S& s) {
    std::string out;
    S::fields(s, [&](const SettingInfo& info, const auto& member) {
        using T = std::decay_t<decltype(member)>;
        if (info.key != SettingInfo::Key::Tail) return;
        const std::string text = SettingCodec<T>::to_text(member);
        if (info.key_unsaid && text == info.key_unsaid) return;
        out += " | " + std::string(info.name) + " " + text;
    });
    return out;
}

}  // namespace lamina

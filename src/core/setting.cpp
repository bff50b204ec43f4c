#include "core/setting.h"

#include "core/incidences.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <sstream>

namespace lamina {

std::string option_name(const std::string& setting_name) {
    std::string out = "--" + setting_name;
    for (char& c : out)
        if (c == '_') c = '-';
    return out;
}

namespace setting_detail {

bool parse_real(const std::string& text, double& out) {
    const std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t");
    if (a == std::string::npos) return false;
    const char* first = text.data() + a;
    const char* last = text.data() + b + 1;
    const auto [ptr, ec] = std::from_chars(first, last, out);
    return ec == std::errc() && ptr == last && std::isfinite(out);
}

bool is_integer_text(const std::string& text) {
    const std::size_t a = text.find_first_not_of(" \t"), b = text.find_last_not_of(" \t");
    if (a == std::string::npos) return false;
    std::size_t i = a + ((text[a] == '-' || text[a] == '+') ? 1 : 0);
    if (i > b) return false;
    for (; i <= b; ++i)
        if (text[i] < '0' || text[i] > '9') return false;
    return true;
}

void fail(const std::string& where, const std::string& field, std::string problem) {
    throw InputError(where, field, std::move(problem));
}

std::string range_text(const SettingInfo& info) {
    if (std::isinf(info.max)) return fmt::format("≥ {}", info.min);
    return fmt::format("in [{}, {}]", info.min, info.max);
}

double checked_whole(double v, const std::string& shown, const SettingInfo& info,
                     const std::string& where, const std::string& field) {
    // Whole numbers of at most 1e15: exact in a double, and far beyond any run's budget.
    constexpr double kLargest = 1e15;
    const double lo = std::max(info.min, -kLargest), hi = std::min(info.max, kLargest);
    if (!(v == std::floor(v)) || v < lo || v > hi)
        fail(where, field,
             fmt::format("{} is not allowed: expected a whole number {} (1e7-style accepted)",
                         shown, range_text({info.name, info.help, lo, hi})));
    return v;
}

}  // namespace setting_detail

std::string SettingCodec<double>::to_text(double v) {
    return fmt::format("{}", v);
}

double SettingCodec<double>::from_text(const std::string& text, const SettingInfo& info,
                                       const std::string& where, const std::string& field) {
    double v = 0;
    if (!setting_detail::parse_real(text, v))
        setting_detail::fail(where, field, fmt::format("'{}' is not a number", text));
    if (v < info.min || v > info.max)
        setting_detail::fail(
            where, field,
            fmt::format("{} is outside the allowed range {}", v, setting_detail::range_text(info)));
    return v;
}

double SettingCodec<double>::from_json(const nlohmann::json& j, const SettingInfo& info,
                                       const std::string& where, const std::string& field) {
    if (j.is_string()) return from_text(j.get<std::string>(), info, where, field);
    if (!j.is_number()) setting_detail::fail(where, field, "expected a number");
    return from_text(fmt::format("{}", j.get<double>()), info, where, field);
}

bool SettingCodec<bool>::from_text(const std::string& text, const SettingInfo&,
                                   const std::string& where, const std::string& field) {
    if (text == "on") return true;
    if (text == "off") return false;
    setting_detail::fail(where, field, fmt::format("'{}' is not allowed: use on or off", text));
}

bool SettingCodec<bool>::from_json(const nlohmann::json& j, const SettingInfo& info,
                                   const std::string& where, const std::string& field) {
    if (j.is_boolean()) return j.get<bool>();
    if (j.is_string()) return from_text(j.get<std::string>(), info, where, field);
    setting_detail::fail(where, field, "expected true or false (or \"on\", \"off\")");
}

std::string SettingCodec<std::vector<double>>::to_text(const std::vector<double>& v) {
    return fmt::format("{}", fmt::join(v, ","));
}

std::vector<double> SettingCodec<std::vector<double>>::from_text(const std::string& text,
                                                                 const SettingInfo&,
                                                                 const std::string& where,
                                                                 const std::string& field) {
    std::vector<double> out;
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ',');) {
        double v = 0;
        if (!setting_detail::parse_real(item, v))
            setting_detail::fail(
                where, field,
                fmt::format("'{}' is not a number (expected degrees, e.g. 0,30,60)", item));
        out.push_back(v);
    }
    if (!text.empty() && text.back() == ',')
        setting_detail::fail(where, field, "the list ends with a comma (expected e.g. 0,30,60)");
    if (out.empty())
        setting_detail::fail(where, field, "expected at least one angle, e.g. 0,30,60");
    check_incidence_list(out, where, field);
    return out;
}

std::vector<double> SettingCodec<std::vector<double>>::from_json(const nlohmann::json& j,
                                                                 const SettingInfo& info,
                                                                 const std::string& where,
                                                                 const std::string& field) {
    if (j.is_string()) return from_text(j.get<std::string>(), info, where, field);
    if (j.is_number()) return from_json(nlohmann::json::array({j}), info, where, field);
    if (!j.is_array() || j.empty())
        setting_detail::fail(where, field, "expected a list of incidences in degrees");
    std::vector<double> out;
    for (const nlohmann::json& v : j) {
        if (!v.is_number()) setting_detail::fail(where, field, "expected numbers (degrees)");
        out.push_back(v.get<double>());
    }
    check_incidence_list(out, where, field);
    return out;
}

nlohmann::json SettingCodec<HemisphereGrid>::to_json(const HemisphereGrid& g) {
    return {{"n_theta", g.n_theta()}, {"n_phi", g.n_phi()}};
}

HemisphereGrid SettingCodec<HemisphereGrid>::from_text(const std::string& text, const SettingInfo&,
                                                       const std::string& where,
                                                       const std::string& field) {
    try {
        return HemisphereGrid::parse(text, field);
    } catch (const InputError& e) {
        throw InputError(where, field, e.problem());
    }
}

HemisphereGrid SettingCodec<HemisphereGrid>::from_json(const nlohmann::json& j,
                                                       const SettingInfo& info,
                                                       const std::string& where,
                                                       const std::string& field) {
    if (j.is_string()) return from_text(j.get<std::string>(), info, where, field);
    // [n_theta, n_phi] (a Python tuple) or {"n_theta": n_theta, "n_phi": n_phi}.
    const bool pair = j.is_array() && j.size() == 2;
    const bool object = j.is_object() && j.contains("n_theta") && j.contains("n_phi");
    const nlohmann::json n_theta = pair ? j[0] : object ? j["n_theta"] : nlohmann::json();
    const nlohmann::json n_phi = pair ? j[1] : object ? j["n_phi"] : nlohmann::json();
    if (!n_theta.is_number_integer() || !n_phi.is_number_integer())
        setting_detail::fail(where, field,
                             "expected \"NTHETAxNPHI\", [n_theta, n_phi] or {\"n_theta\": "
                             "n_theta, \"n_phi\": n_phi}");
    // Each count as JSON wrote it: one past a 64-bit integer's range is shown as given.
    return from_text(fmt::format("{}x{}", n_theta.dump(), n_phi.dump()), info, where, field);
}

}  // namespace lamina

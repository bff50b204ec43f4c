#include "cli/options.h"

#include "core/error.h"
#include "core/setting.h"

#include <fmt/format.h>

#include <cmath>

namespace lamina::cli {

std::vector<double> parse_incidences(const std::string& text, const std::string& option) {
    // The settings' own reader of incidence lists (core/setting.h), under the option's name.
    return SettingCodec<std::vector<double>>::from_text(
        text, SettingInfo{.name = "theta_i", .help = ""}, "command line", option);
}

std::uint64_t parse_count(const std::string& text, const std::string& option) {
    double v;
    if (!setting_detail::parse_real(text, v) || v < 1 || v > 1e15 || v != std::floor(v))
        throw InputError("command line", option,
                         fmt::format("'{}' is not allowed: expected a whole number in [1, 1e15] "
                                     "(1e7-style accepted)",
                                     text));
    return std::uint64_t(v);
}

CLI::Validator some_patterns() {
    return CLI::Validator(
        [](std::string& text) {
            return text.find_first_not_of(", ") == std::string::npos
                       ? std::string("'" + text +
                                     "' names no configuration: give id globs (plastic-*, "
                                     "slab-*-clear), or leave --only out for every configuration")
                       : std::string();
        },
        "GLOBS");
}

std::string format_rgb(const Rgbd& v) {
    return fmt::format("({:.4f}, {:.4f}, {:.4f})", v[0], v[1], v[2]);
}

}  // namespace lamina::cli

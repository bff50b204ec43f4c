#include "cli/options.h"

#include "core/error.h"
#include "core/incidences.h"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <sstream>

namespace lamina::cli {

namespace {
bool parse_double(const std::string& s, double& out) {
    std::size_t a = s.find_first_not_of(" \t"), b = s.find_last_not_of(" \t");
    if (a == std::string::npos) return false;
    const char* first = s.data() + a;
    const char* last = s.data() + b + 1;
    auto [ptr, ec] = std::from_chars(first, last, out);
    return ec == std::errc() && ptr == last && std::isfinite(out);
}
}  // namespace

std::vector<double> parse_angle_list(const std::string& text, const std::string& option) {
    std::vector<double> out;
    std::stringstream ss(text);
    for (std::string item; std::getline(ss, item, ',');) {
        double v;
        if (!parse_double(item, v))
            throw InputError(
                "command line", option,
                fmt::format("'{}' is not a number (expected degrees, e.g. 0,30,60)", item));
        out.push_back(v);
    }
    if (!text.empty() && text.back() == ',')
        throw InputError("command line", option,
                         "the list ends with a comma (expected e.g. 0,30,60)");
    if (out.empty())
        throw InputError("command line", option, "expected at least one angle, e.g. 0,30,60");
    return out;
}

std::vector<double> parse_incidences(const std::string& text, const std::string& option) {
    std::vector<double> out = parse_angle_list(text, option);
    check_incidence_list(out, "command line", option);
    return out;
}

std::uint64_t parse_count(const std::string& text, const std::string& option) {
    double v;
    if (!parse_double(text, v) || v < 1 || v > 1e15 || v != std::floor(v))
        throw InputError("command line", option,
                         fmt::format("'{}' is not allowed: expected a whole number in [1, 1e15] "
                                     "(1e7-style accepted)",
                                     text));
    return std::uint64_t(v);
}

std::string format_rgb(const Rgbd& v) {
    return fmt::format("({:.4f}, {:.4f}, {:.4f})", v[0], v[1], v[2]);
}

}  // namespace lamina::cli

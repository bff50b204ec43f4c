#include "cli/parse_errors.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cctype>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

namespace lamina::cli {

namespace {

/// "The value ..." → "the value ...": CLI11's sentences continue lamina's "field: " prefix.
std::string lower_first(std::string text) {
    if (!text.empty()) text[0] = char(std::tolower(static_cast<unsigned char>(text[0])));
    return text;
}

/// What an option's value must look like, from CLI11's type name ("INT", or "INT:INT in [8 -
/// 8192]" with a validator's description after the colon).
std::string type_phrase(std::string type) {
    type = type.substr(0, type.find(':'));
    if (type == "FLOAT") return "a number";
    if (type == "INT") return "a whole number";
    if (type == "UINT") return "a whole number";
    if (type == "TEXT") return "text";
    return "a value of type " + type;
}

/// A bound as written by std::to_string ("8", "0.000000", "1797693...000.000000"), shortened.
std::string show_bound(const std::string& text) {
    return fmt::format("{}", std::strtod(text.c_str(), nullptr));
}

const CLI::App* parsed_subcommand(const CLI::App& app) {
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        if (sub->parsed()) return sub;
    return nullptr;
}

/// "NAME: rest" → {NAME, rest} when NAME is an option or positional name, else {"", text}.
std::pair<std::string, std::string> split_name(const std::string& text) {
    const auto colon = text.find(": ");
    if (colon == std::string::npos || colon == 0 || text.find(' ') < colon) return {"", text};
    return {text.substr(0, colon), text.substr(colon + 2)};
}

}  // namespace

InputError input_error_from(const CLI::ParseError& error, const CLI::App& app) {
    const CLI::App* sub = parsed_subcommand(app);
    const std::string help =
        sub ? fmt::format("see `lamina {} --help`", sub->get_name()) : "see `lamina --help`";
    const std::string what = error.what();
    std::vector<std::string> names;
    for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; }))
        names.push_back(s->get_name());

    // Arguments nobody took: an unknown option or subcommand, or one positional too many. CLI11
    // checks required options before it complains about these, but they are the actual mistake.
    const std::vector<std::string> extra = app.remaining(true);
    if (!extra.empty() && (dynamic_cast<const CLI::RequiredError*>(&error) ||
                           dynamic_cast<const CLI::ExtrasError*>(&error))) {
        const std::string& x = extra.front();
        if (x.starts_with("-"))
            return InputError("command line", x, fmt::format("unknown option; {}", help));
        if (!sub)
            return InputError(
                "command line", "",
                fmt::format("unknown subcommand '{}'; known: {}", x, fmt::join(names, ", ")));
        return InputError("command line", x,
                          fmt::format("unexpected argument (one too many?); {}", help));
    }

    if (dynamic_cast<const CLI::RequiredError*>(&error)) {
        constexpr std::string_view kSuffix = " is required";
        if (what == "A subcommand is required")
            return InputError("command line", "",
                              fmt::format("a subcommand is required, one of: {}; {}",
                                          fmt::join(names, ", "), help));
        if (what.ends_with(kSuffix))
            return InputError("command line", what.substr(0, what.size() - kSuffix.size()),
                              fmt::format("required; {}", help));
        return InputError("command line", "", fmt::format("{}; {}", lower_first(what), help));
    }

    if (dynamic_cast<const CLI::ConversionError*>(&error)) {
        // "Could not convert: --theta-o = abc"
        constexpr std::string_view kPrefix = "Could not convert: ";
        const auto eq = what.find(" = ");
        if (what.starts_with(kPrefix) && eq != std::string::npos) {
            const std::string name = what.substr(kPrefix.size(), eq - kPrefix.size());
            const std::string value = what.substr(eq + 3);
            const CLI::Option* option = sub ? sub->get_option_no_throw(name) : nullptr;
            const std::string expected =
                option ? type_phrase(option->get_type_name()) : std::string("another value");
            return InputError("command line", name,
                              fmt::format("'{}' is not {}; {}", value, expected, help));
        }
    }

    auto [name, problem] = split_name(what);
    if (dynamic_cast<const CLI::ValidationError*>(&error)) {
        // A CLI::Range: "Value V not in range A to B" (std::to_string bounds).
        constexpr std::string_view kValue = "Value ";
        const auto in_range = problem.find(" not in range ");
        const auto to = problem.rfind(" to ");
        if (problem.starts_with(kValue) && in_range != std::string::npos && to > in_range) {
            const std::string value = problem.substr(kValue.size(), in_range - kValue.size());
            const std::string lo = problem.substr(in_range + 14, to - in_range - 14);
            const std::string hi = problem.substr(to + 4);
            const CLI::Option* option = sub ? sub->get_option_no_throw(name) : nullptr;
            const std::string what_number =
                option ? type_phrase(option->get_type_name()) : std::string("a number");
            std::string allowed;
            if (std::strtod(hi.c_str(), nullptr) >= 1e15) {  // no upper bound
                // (CLI::PositiveNumber's bound, the smallest normal double, reads 0.000000:
                // lamina's options use a Range from 1 for counts and seeds instead.)
                allowed = fmt::format("{} >= {}", what_number, show_bound(lo));
            } else {
                allowed =
                    fmt::format("{} in [{}, {}]", what_number, show_bound(lo), show_bound(hi));
            }
            return InputError("command line", name,
                              fmt::format("'{}' is not allowed: expected {}", value, allowed));
        }
    }
    if (dynamic_cast<const CLI::ArgumentMismatch*>(&error)) {
        // "--model: 1 required TEXT missing": the option came last, without its value.
        if (problem.find(" required ") != std::string::npos && problem.ends_with(" missing")) {
            const CLI::Option* option = sub ? sub->get_option_no_throw(name) : nullptr;
            const std::string expected =
                option ? type_phrase(option->get_type_name()) : std::string("a value");
            return InputError("command line", name,
                              fmt::format("expects a value ({}) after it; {}", expected, help));
        }
        // "--particles: At Most 1 required but received 2": the option was given twice.
        constexpr std::string_view kTwice = "At Most 1 required but received ";
        if (problem.starts_with(kTwice))
            return InputError("command line", name,
                              fmt::format("given {} times; it takes one value, given once; {}",
                                          problem.substr(kTwice.size()), help));
    }
    return InputError("command line", name, fmt::format("{}; {}", lower_first(problem), help));
}

}  // namespace lamina::cli

#pragma once
// Parsing of option values shared by the subcommands. Each throws InputError naming the option.

#include "core/rgb.h"

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace lamina::cli {

/// "0,30,60" → {0, 30, 60}: incidences in [0, 90) degrees, each once, as the settings read them.
std::vector<double> parse_incidences(const std::string& text, const std::string& option);

/// "1e7", "250000", "1.6e8" → an integer count ≥ 1 (must be a whole number ≤ 1e15).
std::uint64_t parse_count(const std::string& text, const std::string& option);

/// "(0.1234, 0.5, 1)" for messages.
std::string format_rgb(const Rgbd& v);

/// The check of an --only option (configuration id globs, commas): given, it names some pattern
/// (an empty value would silently mean every configuration).
CLI::Validator some_patterns();

}  // namespace lamina::cli

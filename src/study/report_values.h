#pragma once
// How the study's writers (study.json, summary.json and summary.md, the engine findings) put
// numbers into their outputs: each convention defined once.

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <string>

namespace lamina {

/// A number for JSON, null where it is not finite (JSON has no NaN or infinity).
inline nlohmann::json json_number(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

/// A fraction as a percentage with one decimal ("12.3%"), "–" where it is not finite.
inline std::string percent_text(double v) {
    return std::isfinite(v) ? fmt::format("{:.1f}%", 100 * v) : "–";
}

/// The names of the RGB channels in tables.
inline constexpr const char* kChannelNames[3] = {"r", "g", "b"};

}  // namespace lamina

#pragma once
// nlohmann::json's exception texts without their "[json.exception.parse_error.101] " prefix: the
// readers of lamina's JSON files (stacks, study folders, exports) put the file and the field in
// front of what is wrong, and the prefix says nothing a user can act on.

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>

namespace lamina {

inline std::string json_exception_text(const nlohmann::json::exception& e) {
    std::string_view text = e.what();
    if (const auto end = text.find("] "); text.starts_with("[json.exception.") && end != text.npos)
        text.remove_prefix(end + 2);
    return std::string(text);
}

}  // namespace lamina

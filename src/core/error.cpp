#include "core/error.h"

#include <fmt/format.h>

namespace lamina {

namespace {
// The message is one line of text: control characters that reach it from the input (a NUL or a
// line break inside a JSON key or string, a byte of a binary file) are written as escapes, so that
// neither a C string's end nor a line break cuts it short.
std::string printable(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char ch : text) {
        const auto byte = static_cast<unsigned char>(ch);
        if (byte >= 0x20 && byte != 0x7f) {
            out += ch;
        } else if (ch == '\n') {
            out += "\\n";
        } else if (ch == '\t') {
            out += "\\t";
        } else if (ch == '\r') {
            out += "\\r";
        } else {
            out += fmt::format("\\u{:04x}", unsigned(byte));
        }
    }
    return out;
}

std::string compose(const std::string& where, const std::string& field,
                    const std::string& problem) {
    return printable(field.empty() ? fmt::format("{}: {}", where, problem)
                                   : fmt::format("{}: {}: {}", where, field, problem));
}
}  // namespace

InputError::InputError(std::string where, std::string field, std::string problem)
    : std::runtime_error(compose(where, field, problem)),
      where_(std::move(where)),
      field_(std::move(field)),
      problem_(std::move(problem)) {}

}  // namespace lamina

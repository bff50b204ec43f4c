#include "layers/stack.h"

#include "core/error.h"

#include <nlohmann/json.hpp>

namespace lamina {

// Placeholder: the parser and validator are being written (issue 2).
Stack stack_from_json(const nlohmann::json&, const std::string& where) {
    throw InputError(where, "", "stack parsing not implemented yet");
}
Stack load_stack(const std::filesystem::path& path) {
    throw InputError(path.string(), "", "stack parsing not implemented yet");
}
nlohmann::json stack_to_json(const Stack&) {
    return nlohmann::json::object();
}
std::string describe(const Stack& stack) {
    return stack.name;
}

}  // namespace lamina

#include "core/error.h"

#include <fmt/format.h>

namespace lamina {

namespace {
std::string compose(const std::string& where, const std::string& field,
                    const std::string& problem) {
    return field.empty() ? fmt::format("{}: {}", where, problem)
                         : fmt::format("{}: {}: {}", where, field, problem);
}
}  // namespace

InputError::InputError(std::string where, std::string field, std::string problem)
    : std::runtime_error(compose(where, field, problem)),
      where_(std::move(where)),
      field_(std::move(field)),
      problem_(std::move(problem)) {}

}  // namespace lamina

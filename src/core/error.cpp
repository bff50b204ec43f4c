#include "core/error.h"

namespace lamina {

namespace {
std::string compose(const std::string& where, const std::string& field,
                    const std::string& problem) {
    std::string msg = where;
    if (!field.empty()) msg += ": " + field;
    return msg + ": " + problem;
}
}  // namespace

InputError::InputError(std::string where, std::string field, std::string problem)
    : std::runtime_error(compose(where, field, problem)),
      where_(std::move(where)),
      field_(std::move(field)),
      problem_(std::move(problem)) {}

}  // namespace lamina

#pragma once
// Errors a user can act on (docs/style.md §8, tier 1): bad input rejected once, at parse time, with
// a message that names the file, the field (a JSON pointer or an option name), the value and what
// is allowed. The CLI prints what() and exits non-zero.

#include <stdexcept>
#include <string>

namespace lamina {

class InputError : public std::runtime_error {
  public:
    /// `where` is the file (or "command line"); `field` the JSON pointer or option (may be empty);
    /// `problem` says what is wrong with the value and what is allowed.
    InputError(std::string where, std::string field, std::string problem);

    const std::string& where() const { return where_; }
    const std::string& field() const { return field_; }
    const std::string& problem() const { return problem_; }

  private:
    std::string where_, field_, problem_;
};

}  // namespace lamina

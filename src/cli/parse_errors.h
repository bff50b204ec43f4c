#pragma once
// CLI11's own parse errors in lamina's form. CLI11 reports an unknown option, a missing value, a
// value of the wrong type ("--theta-o abc") or outside a validator's range, a missing required
// option or subcommand with its own wording and exit codes (105, 106, ...); lamina reports every
// bad input as an InputError, "lamina: command line: OPTION: what is wrong and what is allowed",
// with exit code 1. This translates the first into the second.

#include "core/error.h"

#include <CLI/CLI.hpp>

namespace lamina::cli {

/// The InputError ("command line", the option or argument, the problem and what is allowed, and
/// where to read more) for a parse error of `app`, whose parsed subcommand and unexpected
/// arguments (App::remaining) are looked up to name things. Never called for CLI::Success
/// (--help, --version), which CLI11 prints itself.
InputError input_error_from(const CLI::ParseError& error, const CLI::App& app);

}  // namespace lamina::cli

#pragma once
// The measured cost per evaluation of the production coats and lamina-coat, which the summary's
// section for engine developers quotes beside their errors. Measured numbers, not computed ones:
// data/coat_costs.json, written by scripts/coat_costs.py (`make coat-costs`) from one run of the
// BM_CoatEval benchmarks, with the machine, the date and the command; embedded at build time so
// that a study's summary does not depend on where lamina runs.

#include <map>
#include <string>

namespace lamina {

struct CoatCosts {
    std::string machine, date, command;
    /// ns per evaluation by model spec ("openpbr", "openpbr:leaves=exact", "lamina-coat") and
    /// bench stack ("plastic", "coated-gold").
    std::map<std::string, std::map<std::string, double>> ns;

    /// The cost of `spec` on `stack`, or NaN where it was not measured.
    double of(const std::string& spec, const std::string& stack) const;
};

/// data/coat_costs.json as this build embedded it (parsed once).
const CoatCosts& coat_costs();

}  // namespace lamina

#include "models/registry.h"

#include "core/error.h"
#include "models/factories.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>

namespace lamina {

const std::vector<ModelEntry>& model_registry() {
    static const std::vector<ModelEntry> entries = {
        {"ww09",
         "Weidlich & Wilkie, SIGGRAPH Asia 2009 course code: T01 and refraction at h, base at "
         "outside directions",
         "bases: lambertian, conductor, dielectric (slab reflection); sides: R", ww09_options,
         make_ww09},
        {"ele10",
         "Elek 2010 (CESCG, Alg. 1): T01 at h, refraction about n, alpha1 <- max(alpha0, alpha1)",
         "bases: lambertian, conductor, dielectric (slab reflection); sides: R", ele10_options,
         make_ele10},
        {"ww-prime",
         "WW': T01, T10 and refraction at n, 1/eta0^2 compression, alpha1 <- max(alpha0, alpha1)",
         "bases: lambertian, conductor, dielectric (slab reflection); sides: R", ww_prime_options,
         make_ww_prime},
        {"bel18-forward", "Belcour 2018 adding of lobe statistics, cosine mu_i (not reciprocal)",
         "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R",
         bel18_forward_options, make_bel18_forward},
        {"bel18-symmetric", "Belcour 2018 adding of lobe statistics, cosine |wi.h| (reciprocal)",
         "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R",
         bel18_symmetric_options, make_bel18_symmetric},
        {"bel-prime", "Bel': Bel18 forward with the exact top reflection and a slab BTDF lobe",
         "bases: conductor, dielectric; media: absorbing, forward-scattering; sides: R, T (slab)",
         bel_prime_options, make_bel_prime},
        {"lamina-1",
         "lamina-1: exact top reflection, first order through the coat's directional "
         "transmittance, inter-reflection series, lobe widened by the coat's refraction spread",
         "bases: lambertian, conductor, dielectric; media: absorbing; sides: R, T (slab)",
         lamina1_options, make_lamina1},
        {"random-walk",
         "Position-free random walks with next-event estimation (Guo et al. 2018): the stochastic "
         "per-query reference, unbiased",
         "every stack; sides: R, T (slab)", random_walk_options, make_random_walk, true},
    };
    return entries;
}

const ModelEntry& find_model(const std::string& name, const std::string& field) {
    const auto& entries = model_registry();
    const auto it = std::find_if(entries.begin(), entries.end(),
                                 [&](const ModelEntry& e) { return e.name == name; });
    if (it != entries.end()) return *it;
    std::vector<std::string> names;
    for (const auto& e : entries)
        names.push_back(e.name);
    throw InputError(
        "command line", field,
        fmt::format("unknown model '{}'; known models: {}", name, fmt::join(names, ", ")));
}

ModelOptions resolve_options(const ModelEntry& entry, const std::vector<std::string>& assignments,
                             const std::string& field) {
    const std::vector<OptionSpec> specs = entry.options();
    ModelOptions out;
    for (const auto& s : specs)
        out[s.key] = s.default_value;
    for (const auto& a : assignments) {
        const auto eq = a.find('=');
        if (eq == std::string::npos || eq == 0)
            throw InputError("command line", field,
                             fmt::format("'{}' is not an assignment: expected KEY=VALUE", a));
        const std::string key = a.substr(0, eq), value = a.substr(eq + 1);
        const auto spec = std::find_if(specs.begin(), specs.end(),
                                       [&](const OptionSpec& s) { return s.key == key; });
        if (spec == specs.end()) {
            std::vector<std::string> keys;
            for (const auto& s : specs)
                keys.push_back(s.key);
            throw InputError("command line", field,
                             fmt::format("model '{}' has no option '{}'; its options: {}",
                                         entry.name, key, fmt::join(keys, ", ")));
        }
        if (std::find(spec->values.begin(), spec->values.end(), value) == spec->values.end())
            throw InputError("command line", field,
                             fmt::format("option '{}' of model '{}' cannot be '{}'; allowed: {}",
                                         key, entry.name, value, fmt::join(spec->values, ", ")));
        out[key] = value;
    }
    return out;
}

std::unique_ptr<Model> make_model(const std::string& name, const Stack& stack,
                                  const std::vector<std::string>& assignments) {
    const ModelEntry& entry = find_model(name);
    return entry.make(stack, resolve_options(entry, assignments));
}

}  // namespace lamina

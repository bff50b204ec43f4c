#include "study/coat_costs.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace lamina {

// data/coat_costs.json's text (generated: coat_costs_data.cpp).
extern const char* const kCoatCostsJson;

double CoatCosts::of(const std::string& spec, const std::string& stack) const {
    const auto m = ns.find(spec);
    if (m == ns.end()) return NAN;
    const auto s = m->second.find(stack);
    return s == m->second.end() ? NAN : s->second;
}

const CoatCosts& coat_costs() {
    static const CoatCosts costs = [] {
        const nlohmann::json j = nlohmann::json::parse(kCoatCostsJson);
        CoatCosts c;
        c.machine = j.at("machine").get<std::string>();
        c.date = j.at("date").get<std::string>();
        c.command = j.at("command").get<std::string>();
        for (const auto& [spec, stacks] : j.at("ns_per_evaluation").items())
            for (const auto& [stack, ns] : stacks.items())
                c.ns[spec][stack] = ns.get<double>();
        return c;
    }();
    return costs;
}

}  // namespace lamina

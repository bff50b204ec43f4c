// The measured costs the summary quotes (study/coat_costs.h, data/coat_costs.json): every coat the
// engine developers' section can list has a measurement on both bench stacks, so a production coat
// added to the registry without re-running scripts/coat_costs.py fails here.
#include "study/coat_costs.h"

#include "models/model_options.h"
#include "models/registry.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace lamina {
namespace {

TEST(CoatCosts, EveryProductionCoatAndLaminaCoatIsMeasured) {
    const CoatCosts& costs = coat_costs();
    EXPECT_FALSE(costs.machine.empty());
    EXPECT_EQ(costs.date.size(), 10u) << costs.date;  // YYYY-MM-DD
    EXPECT_NE(costs.command.find("BM_CoatEval"), std::string::npos) << costs.command;
    int measured = 0;
    for (const ModelEntry& e : model_registry()) {
        if (e.group != "production" && e.name != "lamina-coat") continue;
        std::vector<std::string> specs = {e.name};
        const auto options = e.options();
        if (std::any_of(options.begin(), options.end(),
                        [](const OptionSpec& o) { return o.key == "leaves"; }))
            specs.push_back(e.name + ":leaves=exact");
        for (const std::string& spec : specs)
            for (const char* stack : {"plastic", "coated-gold"}) {
                const double ns = costs.of(spec, stack);
                EXPECT_TRUE(std::isfinite(ns) && ns > 1 && ns < 1e5) << spec << " " << stack;
                ++measured;
            }
    }
    EXPECT_GE(measured, 2 * 10);
    EXPECT_TRUE(std::isnan(costs.of("not-a-coat", "plastic")));
    EXPECT_TRUE(std::isnan(costs.of("openpbr", "not-a-stack")));
}

}  // namespace
}  // namespace lamina

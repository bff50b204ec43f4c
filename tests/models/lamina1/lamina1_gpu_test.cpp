// lamina1_gpu_states (the explorer's live spheres, docs/explorer.md): the stack's own state is
// lamina1_gpu_state's, and each variant's per-material part is the state of the stack built with
// that one parameter changed, through the stack (test_stacks.h) rather than through lamina-1's
// layers; the slope-sum table after it is the same for every material.

#include "lamina1/lamina1.h"
#include "models/lamina1/lamina1.h"
#include "models/test_stacks.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace lamina {
namespace {

using test::coated;
using test::gold;
using test::lambertian;

// Every variant against `changed(parameter, value)`, the stack with that parameter changed.
void expect_variants(const Stack& stack,
                     const std::function<Stack(const std::string&, double)>& changed,
                     const std::map<std::string, int>& counts) {
    std::string why;
    const Lamina1GpuStates states = lamina1_gpu_states(stack, {}, why);
    ASSERT_FALSE(states.state.empty()) << why;
    EXPECT_EQ(states.state, lamina1_gpu_state(stack, {}, why));
    ASSERT_EQ(states.head, std::size_t(lamina1::kGpuSlopeSum));
    ASSERT_EQ(states.tail, states.state.size() - std::size_t(lamina1::kGpuSize));
    const std::size_t part = states.head + states.tail;
    ASSERT_EQ(states.heads.size(), states.variants.size() * part);
    std::map<std::string, int> seen;
    for (std::size_t k = 0; k < states.variants.size(); ++k) {
        const Lamina1GpuVariant& v = states.variants[k];
        ++seen[v.parameter];
        const std::vector<float> want = lamina1_gpu_state(changed(v.parameter, v.value), {}, why);
        ASSERT_EQ(want.size(), states.state.size()) << v.parameter << " " << v.value << ": " << why;
        const auto at = states.heads.begin() + std::ptrdiff_t(k * part);
        const std::vector<float> head(at, at + std::ptrdiff_t(states.head));
        const std::vector<float> tail(at + std::ptrdiff_t(states.head), at + std::ptrdiff_t(part));
        EXPECT_EQ(head, std::vector<float>(want.begin(), want.begin() + states.head))
            << v.parameter << " = " << v.value;
        EXPECT_EQ(tail, std::vector<float>(want.end() - std::ptrdiff_t(states.tail), want.end()))
            << v.parameter << " = " << v.value;
        EXPECT_TRUE(std::equal(want.begin() + states.head, want.begin() + lamina1::kGpuSize,
                               states.state.begin() + states.head))
            << "the slope-sum table depends on " << v.parameter;
    }
    EXPECT_EQ(seen, counts);
}

TEST(Lamina1Gpu, VariantsOfAPlasticAreItsStatesWithOneParameterChanged) {
    const Rgbd tau(0.1, 0.0, 0.9);
    auto changed = [&](const std::string& p, double v) {
        if (p == "alpha0") return coated(1.5, v, lambertian(Rgbd(0.8)), tau);
        if (p == "eta0") return coated(v, 0.2, lambertian(Rgbd(0.8)), tau);
        if (p == "tau_a") return coated(1.5, 0.2, lambertian(Rgbd(0.8)), Rgbd(v));
        EXPECT_EQ(p, "albedo");
        return coated(1.5, 0.2, lambertian(Rgbd(v)), tau);
    };
    expect_variants(coated(1.5, 0.2, lambertian(Rgbd(0.8)), tau), changed,
                    {{"alpha0", 7}, {"eta0", 5}, {"tau_a", 5}, {"albedo", 5}});
}

TEST(Lamina1Gpu, VariantsOfCoatedGoldKeepTheGoldsAbsoluteIndex) {
    auto changed = [](const std::string& p, double v) {
        if (p == "alpha0") return coated(1.5, v, gold(0.05));
        if (p == "eta0") return coated(v, 0.3, gold(0.05));  // the stack's gold is absolute
        if (p == "tau_a") return coated(1.5, 0.3, gold(0.05), Rgbd(v));
        EXPECT_EQ(p, "alpha1");
        return coated(1.5, 0.3, gold(v));
    };
    expect_variants(coated(1.5, 0.3, gold(0.05)), changed,
                    {{"alpha0", 7}, {"eta0", 5}, {"tau_a", 5}, {"alpha1", 5}});
}

// A slab's state carries its bins after the slope-sum table (a tail of the per-material part).
TEST(Lamina1Gpu, VariantsOfASlabCarryTheirBins) {
    const Rgbd tau(0.1, 0.0, 0.3);
    auto changed = [&](const std::string& p, double v) {
        if (p == "alpha0") return coated(1.5, v, test::dielectric(1.0, 0.2), tau);
        if (p == "eta0") return coated(v, 0.3, test::dielectric(1.0, 0.2), tau);
        if (p == "tau_a") return coated(1.5, 0.3, test::dielectric(1.0, 0.2), Rgbd(v));
        EXPECT_EQ(p, "alpha1");
        return coated(1.5, 0.3, test::dielectric(1.0, v), tau);
    };
    const Stack slab = coated(1.5, 0.3, test::dielectric(1.0, 0.2), tau);
    std::string why;
    EXPECT_EQ(lamina1_gpu_state(slab, {}, why).size(), std::size_t(lamina1::kGpuBinsEnd)) << why;
    EXPECT_EQ(lamina1_gpu_state(slab, {{"slab-orders", "series"}}, why).size(),
              std::size_t(lamina1::kGpuSize));
    expect_variants(slab, changed, {{"alpha0", 7}, {"eta0", 5}, {"tau_a", 5}, {"alpha1", 5}});
}

TEST(Lamina1Gpu, NoStatesWhereTheGlslFormDoesNotApply) {
    std::string why;
    EXPECT_TRUE(
        lamina1_gpu_states(test::brushed(0.3, 0.05, 30, 0.4, 0.02, -45), {}, why).state.empty());
    EXPECT_FALSE(why.empty());
}

}  // namespace
}  // namespace lamina

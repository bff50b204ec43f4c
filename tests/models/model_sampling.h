#pragma once
// The two checks every sampled model's importance sampling gets (docs/style.md §9): the sampler's
// directions against the density pdf() claims (the chi-square harness of support/chi2.h), and
// each sample's own weight and density against eval() and pdf() at the drawn direction.

#include "core/rng.h"
#include "core/vec.h"
#include "models/model.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace lamina::test {

/// Chi-square of `model`'s sample(wi, ·) against its pdf(wi, ·) (`test_count` tests in the suite:
/// the Šidák correction).
inline Chi2Result model_sampling_chi2(const Model& model, const Vec3d& wi, const std::string& name,
                                      int test_count, std::size_t sample_count = 200'000) {
    Chi2Options o;
    o.name = name;
    o.sample_count = sample_count;
    o.test_count = test_count;
    return run_chi2(
        o,
        [&](const std::array<double, 3>& u) {
            const auto s = model.sample(wi, Vec3d(u[0], u[1], u[2]));
            if (!s) return Chi2Draw::none();
            return Chi2Draw::direction(s->wo);
        },
        [&](const Vec3d& wo) { return model.pdf(wi, wo); });
}

/// Draws `n` samples at wi: each sample's pdf is pdf(wi, wo) and its weight eval(wi, wo)·|cos θo|
/// / pdf, to 1e-12 relative. Returns how many draws gave a direction.
inline int expect_sample_weights(const Model& model, const Vec3d& wi, ParticleRng& rng, int n,
                                 const std::string& what) {
    int drawn = 0;
    for (int k = 0; k < n; ++k) {
        const Vec3d u(rng.uniform_double(), rng.uniform_double(), rng.uniform_double());
        const auto s = model.sample(wi, u);
        if (!s) continue;
        ++drawn;
        EXPECT_NEAR(s->pdf, model.pdf(wi, s->wo), 1e-12 * s->pdf) << what;
        const Rgbd want = model.eval(wi, s->wo) * (std::abs(s->wo.z) / s->pdf);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(s->weight[c], want[c], 1e-12 * want[c] + 1e-300) << what;
    }
    return drawn;
}

}  // namespace lamina::test

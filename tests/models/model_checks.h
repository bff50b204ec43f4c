#pragma once
// Checks every analytic model with a prepared evaluator or a sampler must pass, shared by the
// families' tests.

#include "core/rng.h"
#include "core/spherical.h"
#include "models/model.h"
#include "models/numerics/binned.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

namespace lamina::test {

/// |a − b| / max(|a|, |b|) in the channel where it is largest (0 where they are equal).
inline double relative_difference(const Rgbd& a, const Rgbd& b) {
    double worst = 0;
    for (int c = 0; c < 3; ++c)
        if (a[c] != b[c])
            worst =
                std::max(worst, std::abs(a[c] - b[c]) / std::max(std::abs(a[c]), std::abs(b[c])));
    return worst;
}

/// prepare(wi)->for_one_thread() (where there is one) evaluates exactly as eval(wi, ·) on a run
/// like a θ row's (each cosine met again at other azimuths, and again after more cosines than a
/// row's rectangle has: what the evaluator keeps is reused and replaced), on both sides.
inline void expect_one_thread_evaluator_equals_eval(const Model& model, const Vec3d& wi) {
    const auto local = model.prepare(wi)->for_one_thread();
    if (!local) return;
    for (int pass = 0; pass < 2; ++pass)
        for (double theta_o = 2.5; theta_o < 90; theta_o += 7.5)
            for (double phi_o : {0.0, 45.0, 90.0, 135.0, 180.0})
                for (Side side : {Side::Reflection, Side::Transmission}) {
                    const Vec3d wo =
                        direction_from_angles(deg_to_rad(theta_o), deg_to_rad(phi_o), side);
                    EXPECT_EQ(local->eval(wo), model.eval(wi, wo))
                        << model.name() << " at θo = " << theta_o << ", φo = " << phi_o;
                }
}

/// prepare(wi) evaluates exactly as eval(wi, ·), on both sides, in and out of the incidence plane,
/// and so does its evaluator for one thread.
inline void expect_prepared_equals_eval(const Model& model, const Vec3d& wi) {
    const auto prepared = model.prepare(wi);
    for (double theta_o : {10.0, 40.0, 60.0})
        for (double phi_o : {0.0, 90.0, 170.0})
            for (Side side : {Side::Reflection, Side::Transmission}) {
                const Vec3d wo =
                    direction_from_angles(deg_to_rad(theta_o), deg_to_rad(phi_o), side);
                EXPECT_EQ(prepared->eval(wo), model.eval(wi, wo));
            }
    expect_one_thread_evaluator_equals_eval(model, wi);
}

/// The sampler: E[weight] over n samples (seed `seed`) is the albedo of the non-delta lobes on
/// the sides the model supports, within five standard errors of the mean (plus the quadrature's
/// 1e-4), and pdf() is the density sample() draws from (checked on every 97th sample).
inline void expect_sampler_matches_albedo(const Model& model, const Vec3d& wi, std::uint64_t seed,
                                          int n, const std::string& label) {
    ASSERT_TRUE(model.has_sampling()) << label;
    ParticleRng rng(seed, 0, 0);
    double sum = 0, sum2 = 0;
    for (int i = 0; i < n; ++i) {
        const Vec3d u(rng.uniform_double(), rng.uniform_double(), rng.uniform_double());
        const auto s = model.sample(wi, u);
        const double w = s ? s->weight.mean() : 0.0;
        if (s && i % 97 == 0) {
            EXPECT_NEAR(model.pdf(wi, s->wo), s->pdf, 1e-12 * s->pdf) << label;
        }
        sum += w;
        sum2 += w * w;
    }
    const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
    BinnedOptions o;
    o.rel_tol = 1e-4;
    Rgbd albedo = model_albedo(model, wi, Side::Reflection, o);
    if (model.support().btdf) albedo += model_albedo(model, wi, Side::Transmission, o);
    EXPECT_NEAR(mean, albedo.mean(), 5 * se + 1e-4) << label;
}

/// The model with its directions swapped, f_T(a, b) = f(b, a): its albedo at wo is the light
/// arriving at wo from every wi, ∫ f(wi, wo) μi dωi (the energy per view direction).
struct TransposedModel final : Model {
    const Model& m;
    explicit TransposedModel(const Model& model) : m(model) {}
    std::string name() const override { return m.name(); }
    Support support() const override { return m.support(); }
    Rgbd eval(const Vec3d& a, const Vec3d& b) const override { return m.eval(b, a); }
    std::vector<DeltaLobe> delta_lobes(const Vec3d& w) const override { return m.delta_lobes(w); }
};

}  // namespace lamina::test

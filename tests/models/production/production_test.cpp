// The production coats (models/production/production_coat.h, docs/models.md "Production coats"):
// their limits, values at points against the sources' equations written out here with independent
// arithmetic (Fresnel, GGX and Smith restated, never the model's helpers), their energy and
// reciprocity as measured, and what they do not support.
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "models/model_checks.h"
#include "models/numerics/binned.h"
#include "models/numerics/quadrature.h"
#include "models/production/production_coat.h"
#include "models/registry.h"
#include "models/test_stacks.h"
#include "support/closed_forms.h"

#include <gtest/gtest.h>

#include <fmt/format.h>

#include <complex>
#include <iostream>

namespace lamina {
namespace {

using test::coated;
using test::conductor_ref;
using test::dir;
using test::fresnel_ref;

// --- The sources' equations, restated ------------------------------------------------------

double schlick_ref(double c, double f0) {
    return f0 + (1 - f0) * std::pow(1 - c, 5);
}
/// GGX D in the form α² / (π (cos²θ (α² − 1) + 1)²) (Walter et al. 2007, Eq. 33).
double ggx_D(const Vec3d& h, double alpha) {
    const double a2 = alpha * alpha;
    return a2 / (kPi<double> * sqr(h.z * h.z * (a2 - 1) + 1));
}
/// Smith Λ for GGX, (−1 + √(1 + α² tan²θ))/2 (Heitz 2014, Eq. 72).
double ggx_lambda(const Vec3d& w, double alpha) {
    const double tan2 = (1 - w.z * w.z) / (w.z * w.z);
    return (-1 + std::sqrt(1 + alpha * alpha * tan2)) / 2;
}
double ggx_G2(const Vec3d& wi, const Vec3d& wo, double alpha) {
    return 1 / (1 + ggx_lambda(wi, alpha) + ggx_lambda(wo, alpha));
}
double refracted_cos(double mu, double eta) {
    return std::sqrt(1 - (1 - mu * mu) / (eta * eta));
}
/// F82-tint (OpenPBR 1.1, "Metal"): F_S(μ) − μ(1 − μ)⁶/(μ̄(1 − μ̄)⁶) (F_S(μ̄) − tint F_S(μ̄)).
double f82_ref(double mu, double f0, double tint) {
    const double mb = 1.0 / 7;
    return schlick_ref(mu, f0) - mu * std::pow(1 - mu, 6) / (mb * std::pow(1 - mb, 6)) *
                                     (schlick_ref(mb, f0) - tint * schlick_ref(mb, f0));
}

const Rgbd kRho(0.8, 0.5, 0.2);
const Rgbd kTau(0.1, 0.2, 0.3);
const Rgbd kGoldEta(0.18, 0.42, 1.37), kGoldK(3.4, 2.35, 1.85);  // test::gold

void expect_rgb_near(const Rgbd& got, const Rgbd& want, double rel, const std::string& what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c], want[c], rel * std::abs(want[c]) + 1e-14) << what << " channel " << c;
}

std::vector<const ModelEntry*> production() {
    std::vector<const ModelEntry*> out;
    for (const auto& e : model_registry())
        if (e.group == "production") out.push_back(&e);
    return out;
}

// --- Limits ---------------------------------------------------------------------------------

// A smooth clear coat over a black base: all that is left is the top interface's mirror
// reflection, in the model's own Fresnel (Schlick 0.04 for the coats with a fixed IOR). Filament
// and three.js clamp their coat roughness (r ≥ 0.045), Unity's StackLit every lobe (α ≥ 1/1024):
// they have no smooth limit as shipped (Filament and three.js only with the exact leaves);
// MaterialX's smooth coat (a lobe at α = 1e-8) is compensated by its fitted albedo, F × (1 + F_ss
// (1 − E)/E).
TEST(ProductionCoats, SmoothCoatOverBlackBaseIsTheTopReflection) {
    const Stack s = coated(1.5, 0.0, test::lambertian(Rgbd(0.0)));
    for (const ModelEntry* e : production()) {
        for (const char* leaves : {"shipped", "exact"}) {
            std::vector<std::string> opts;
            bool has_leaves = false;
            for (const auto& o : e->options())
                has_leaves |= o.key == "leaves";
            if (std::string(leaves) == "exact") {
                if (!has_leaves) continue;
                opts.push_back("leaves=exact");
            }
            if ((e->name == "filament" || e->name == "threejs-clearcoat" ||
                 e->name == "unity-stacklit") &&
                opts.empty())
                continue;  // clamped
            const auto m = make_model(e->name, s, opts);
            ASSERT_TRUE(m->support().brdf) << e->name;
            const bool schlick =
                opts.empty() && (e->name == "enterprise-pbr" || e->name == "gltf-clearcoat");
            const bool materialx = opts.empty() && (e->name == "openpbr-materialx" ||
                                                    e->name == "standard-surface-materialx");
            for (double ti : {0.0, 35.0, 75.0}) {
                const Vec3d wi = dir(ti, 0);
                const auto lobes = m->delta_lobes(wi);
                ASSERT_EQ(lobes.size(), 1u) << e->name << " " << leaves;
                const double c = wi.z;
                double want = schlick ? 0.04 + 0.96 * std::pow(1 - c, 5) : fresnel_ref(c, 1.5);
                if (materialx) {
                    const SchlickSplit fit = materialx_ggx_albedo_fit(c, 1e-8);
                    const double E = fit.scale + fit.bias;
                    want *= 1 + (0.04 + 0.96 / 21) * (1 - E) / E;
                }
                expect_rgb_near(lobes[0].energy, Rgbd(want), 1e-12, e->name + " " + leaves);
                EXPECT_NEAR(lobes[0].direction.x, -wi.x, 1e-15);
                EXPECT_NEAR(lobes[0].direction.z, wi.z, 1e-15);
                for (const Vec3d& wo : {dir(20, 40), dir(60, 170), dir(85, 300)})
                    EXPECT_EQ(m->eval(wi, wo).max(), 0.0) << e->name;
            }
        }
    }
}

// An index-matched coat (η0 = 1) reflects nothing and attenuates nothing: the albedo-scaling
// models leave the bare base, ρ/π, even when the coat is rough (E_coat = 0, F = 0 everywhere).
// With darkening on, OpenPBR and Adobe keep the residual of their average-Fresnel fits at η = 1:
// d'Eon's E_F(1) = ln(9454.8/9438.6), Kulla & Conty's 0.997118 + 0.1014 − 0.965241 − 0.130607
// (K = K_r = K_s = E_F(1)); Adobe also counts that residual as the diffuse base's specularity,
// E_b = lerp(ρ, 1, E_F(1)).
TEST(ProductionCoats, IndexMatchedCoatLeavesTheBase) {
    const Stack s = coated(1.0, 0.3, test::lambertian(kRho));
    const Vec3d wi = dir(40, 0), wo = dir(65, 110);
    for (const auto& [name, opts] : std::vector<std::pair<std::string, std::vector<std::string>>>{
             {"openpbr", {"darkening=off"}},
             {"openpbr-adobe", {"darkening=off"}},
             {"openpbr-adobe", {"darkening=off", "reciprocal=on"}},
             {"standard-surface", {}},
             {"blender-principled", {}},
             {"kulla-conty", {}},
             {"kulla-conty", {"form=view"}}}) {
        const auto m = make_model(name, s, opts);
        expect_rgb_near(m->eval(wi, wo), kRho * kInvPi<double>, 1e-6, name);
    }
    const double ef_deon = std::log((10893.0 - 1438.2) / (-774.4 + 10212.0 + 1.0));
    const double ef_kc = 0.997118 + 0.1014 - 0.965241 - 0.130607;
    for (const auto& [name, ef] :
         {std::pair{"openpbr", ef_deon}, std::pair{"openpbr-adobe", ef_kc}}) {
        const double K = 1 - (1 - ef);  // K_r at η = 1 (a diffuse base: K = K_r)
        const bool adobe = std::string(name) == "openpbr-adobe";
        Rgbd want;
        for (int c = 0; c < 3; ++c) {
            const double E_b = adobe ? kRho[c] * (1 - ef) + ef : kRho[c];
            want[c] = kRho[c] / kPi<double> * (1 - K) / (1 - E_b * K);
        }
        expect_rgb_near(make_model(name, s)->eval(wi, wo), want, 1e-6, name);
    }
}

// --- Values against the sources' equations ---------------------------------------------------

// OpenPBR 1.1 over a diffuse base, smooth coat (E_coat = F exactly): f = (1 − F(μo)) ·
// T^(1/μt_i + 1/μt_o) · Δ · ρ/π with T = e^(−τ) (coat_color = T² = e^(−2τ)), Δ = (1 − K)/(1 − ρK),
// K = K_r = 1 − (1 − E_F(η))/η² and d'Eon's E_F.
TEST(ProductionCoats, OpenPbrDiffuseAgainstTheSpecification) {
    const double eta = 1.5;
    const Stack s = coated(eta, 0.0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    const double ef = std::log((10893 * eta - 1438.2) / (-774.4 * eta * eta + 10212 * eta + 1));
    const double K = 1 - (1 - ef) / (eta * eta);
    const double path = 1 / refracted_cos(wi.z, eta) + 1 / refracted_cos(wo.z, eta);
    Rgbd want;
    for (int c = 0; c < 3; ++c)
        want[c] = (1 - fresnel_ref(wo.z, eta)) * std::exp(-kTau[c] * path) * (1 - K) /
                  (1 - kRho[c] * K) * kRho[c] / kPi<double>;
    expect_rgb_near(make_model("openpbr", s)->eval(wi, wo), want, 1e-9, "openpbr");
    // view-tint=off: the constant coat_color e^(−2τ).
    Rgbd flat;
    for (int c = 0; c < 3; ++c)
        flat[c] = want[c] / std::exp(-kTau[c] * path) * std::exp(-2 * kTau[c]);
    expect_rgb_near(make_model("openpbr", s, {"view-tint=off"})->eval(wi, wo), flat, 1e-9,
                    "openpbr view-tint=off");
}

// OpenPBR's fit of the hemispherical Fresnel albedo E_F(η) = 2 ∫ F(μ; η) μ dμ against that
// integral (Gauss–Legendre, split at the critical cosine below 1): within the 0.2 % of
// reflectance the specification states over η ∈ [1, 3] (measured 1.5e-3), and below 1 through
// reciprocity, E_F(η) = 1 − η² (1 − E_F(1/η)), within η² of that.
TEST(ProductionCoats, OpenPbrAverageFresnelFitWithinItsStatedAccuracy) {
    const QuadratureRule q = gauss_legendre(64);
    auto average = [&](double eta) {
        const double mu_c = eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;  // total reflection below
        double sum = 0;
        for (const auto& [lo, hi] : {std::pair{0.0, mu_c}, std::pair{mu_c, 1.0}})
            for (std::size_t i = 0; i < q.x.size(); ++i) {
                const double mu = lo + (hi - lo) * q.x[i];
                sum += 2 * mu * fresnel_ref(mu, eta) * q.w[i] * (hi - lo);
            }
        return sum;
    };
    double worst = 0;
    for (double eta = 1.02; eta <= 3.0; eta += 0.02) {
        worst = std::max(worst, std::abs(openpbr_average_fresnel_fit(eta) - average(eta)));
        EXPECT_NEAR(openpbr_average_fresnel_fit(eta), average(eta), 2e-3) << eta;
    }
    for (const double eta : {0.4, 0.67, 0.9})
        EXPECT_NEAR(openpbr_average_fresnel_fit(eta), average(eta), 2e-3 * eta * eta) << eta;
    std::cout << fmt::format("OpenPBR's E_F fit: worst {:.1e} over [1.02, 3]\n", worst);
}

// OpenPBR over gold (darkening off, smooth coat so roughening leaves r): the F82-tint metal with
// F0 and the tint from the exact conductor Fresnel under the coat (η1/η0, κ1/η0).
TEST(ProductionCoats, OpenPbrMetalIsF82Tint) {
    const double eta = 1.5, alpha1 = 0.3;
    const Stack s = coated(eta, 0.0, test::gold(alpha1), kTau);
    const Vec3d wi = dir(25, 0), wo = dir(50, 160);
    const Vec3d h = normalize(wi + wo);
    const double path = 1 / refracted_cos(wi.z, eta) + 1 / refracted_cos(wo.z, eta);
    const double lobe = ggx_D(h, alpha1) * ggx_G2(wi, wo, alpha1) / (4 * wi.z * wo.z);
    Rgbd want, exact;
    for (int c = 0; c < 3; ++c) {
        const double e = kGoldEta[c] / eta, k = kGoldK[c] / eta;
        const double f0 = conductor_ref(1, e, k);
        const double tint = std::min(1.0, conductor_ref(1.0 / 7, e, k) / schlick_ref(1.0 / 7, f0));
        const double scale = (1 - fresnel_ref(wo.z, eta)) * std::exp(-kTau[c] * path);
        want[c] = scale * f82_ref(dot(wi, h), f0, tint) * lobe;
        exact[c] = scale * conductor_ref(dot(wi, h), e, k) * lobe;
    }
    expect_rgb_near(make_model("openpbr", s, {"darkening=off"})->eval(wi, wo), want, 1e-9,
                    "openpbr F82");
    expect_rgb_near(make_model("openpbr", s, {"darkening=off", "leaves=exact"})->eval(wi, wo),
                    exact, 1e-9, "openpbr exact leaves");
}

// Adobe (impl/openpbr_bsdf.h): Kulla & Conty's average-Fresnel fit E_F in K_s = E_F(η) and
// K_r = 1 − (1 − E_F(η))/η², K = lerp(K_s, K_r, lerp(1, r', s)) and E_b = lerp(ρ, 1, s), with
// s = E_F(1) = 2.67e-3 the specularity of the diffuse base's specular at relative index 1 and
// r' the default specular roughness 0.3 (a smooth coat leaves it unroughened); the light side's
// 1 − E(μi) only with reciprocal=on.
TEST(ProductionCoats, AdobeDiffuseAgainstItsCode) {
    const double eta = 1.5;
    const Stack s = coated(eta, 0.0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    const double ef = (eta - 1) / (4.08567 + 1.00071 * eta);
    const double spec = 0.997118 + 0.1014 - 0.965241 - 0.130607;  // E_F(1), the η ≤ 1 branch
    const double K_r = 1 - (1 - ef) / (eta * eta);
    const double K = ef + (K_r - ef) * (1 + spec * (0.3 - 1));
    const double path = 1 / refracted_cos(wi.z, eta) + 1 / refracted_cos(wo.z, eta);
    Rgbd want;
    for (int c = 0; c < 3; ++c)
        want[c] = (1 - fresnel_ref(wo.z, eta)) * std::exp(-kTau[c] * path) * (1 - K) /
                  (1 - (kRho[c] * (1 - spec) + spec) * K) * kRho[c] / kPi<double>;
    expect_rgb_near(make_model("openpbr-adobe", s)->eval(wi, wo), want, 1e-9, "adobe");
    expect_rgb_near(make_model("openpbr-adobe", s, {"reciprocal=on"})->eval(wi, wo),
                    want * (1 - fresnel_ref(wi.z, eta)), 1e-9, "adobe reciprocal");
}

// Standard Surface: coat_color (1 − E_coat(wo)) base, coat_color = e^(−2τ); coat_affect_color
// squares the diffuse colour.
TEST(ProductionCoats, StandardSurfaceAgainstTheSpecification) {
    const Stack s = coated(1.5, 0.0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    Rgbd want, squared;
    for (int c = 0; c < 3; ++c) {
        want[c] = std::exp(-2 * kTau[c]) * (1 - fresnel_ref(wo.z, 1.5)) * kRho[c] / kPi<double>;
        squared[c] = want[c] * kRho[c];
    }
    expect_rgb_near(make_model("standard-surface", s)->eval(wi, wo), want, 1e-9, "ss");
    expect_rgb_near(make_model("standard-surface", s, {"affect-color=1"})->eval(wi, wo), squared,
                    1e-9, "ss affect-color");
}

// Enterprise PBR 2025x: core (1 − max(F_c(v·n), F_c(l·n))) + M_c F_c(h·v), F_c = Schlick 0.04.
TEST(ProductionCoats, EnterprisePbrAgainstTheSpecification) {
    const double alpha0 = 0.25;
    const Stack s = coated(1.5, alpha0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    const Vec3d h = normalize(wi + wo);
    auto Fc = [](double c) { return 0.04 + 0.96 * std::pow(1 - c, 5); };
    const double coat =
        Fc(dot(wo, h)) * ggx_D(h, alpha0) * ggx_G2(wi, wo, alpha0) / (4 * wi.z * wo.z);
    Rgbd want;
    for (int c = 0; c < 3; ++c)
        want[c] = coat + kRho[c] / kPi<double> * std::exp(-2 * kTau[c]) *
                             (1 - std::max(Fc(wo.z), Fc(wi.z)));
    expect_rgb_near(make_model("enterprise-pbr", s)->eval(wi, wo), want, 1e-9, "epbr");
}

// Filament: Fc = Schlick(0.04, l·h), the coat lobe Fc D / (4 (l·h)²) (Kelemen), base (1 − Fc);
// its coat roughness clamped to r ≥ 0.045 (the desktop target); base roughness max(r, r_c); the
// metal's F0 in air through f0ClearCoatToSurface, its Schlick f90 = min(1, 16.5 ΣF0); D capped at
// 453.5²/π. The energy compensation (from its DFG texture) is off here: ProductionCoatsGolden
// checks it against Filament's own.
TEST(ProductionCoats, FilamentAgainstItsDocumentation) {
    auto Fc = [](double c) { return 0.04 + 0.96 * std::pow(1 - c, 5); };
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    const Vec3d h = normalize(wi + wo);
    const double lh = dot(wi, h);
    {
        const double alpha0 = 0.04;  // r = 0.2
        const Stack s = coated(1.5, alpha0, test::lambertian(kRho), kTau);
        Rgbd want;
        for (int c = 0; c < 3; ++c)
            want[c] = Fc(lh) * ggx_D(h, alpha0) / (4 * lh * lh) +
                      (1 - Fc(lh)) * kRho[c] / kPi<double> * std::exp(-2 * kTau[c]);
        expect_rgb_near(make_model("filament", s)->eval(wi, wo), want, 1e-9, "filament");
        Rgbd at_n;
        for (int c = 0; c < 3; ++c)
            at_n[c] = Fc(lh) * ggx_D(h, alpha0) / (4 * lh * lh) +
                      (1 - Fc(wo.z)) * kRho[c] / kPi<double> * std::exp(-2 * kTau[c]);
        expect_rgb_near(make_model("filament", s, {"attenuation=n"})->eval(wi, wo), at_n, 1e-9,
                        "filament attenuation=n");
    }
    {
        // A near-smooth coat: r = √0.001 < 0.045 is clamped; at the mirror pair D is capped.
        const Stack s = coated(1.5, 0.001, test::lambertian(Rgbd(0.0)));
        const double a = 0.045 * 0.045;
        const Vec3d wo2 = dir(32, 178);
        const Vec3d h2 = normalize(wi + wo2);
        const double want = Fc(dot(wi, h2)) * ggx_D(h2, a) / (4 * sqr(dot(wi, h2)));
        EXPECT_NEAR(make_model("filament", s)->eval(wi, wo2)[0], want, 1e-9 * want);
        const Vec3d mirror = dir(30, 180);
        const double d_max = sqr(453.5) / kPi<double>;
        ASSERT_LT(d_max, ggx_D(Vec3d(0, 0, 1), a));
        const double capped = Fc(wi.z) * d_max / (4 * sqr(wi.z));
        EXPECT_NEAR(make_model("filament", s)->eval(wi, mirror)[0], capped, 1e-9 * capped);
    }
    {
        // Gold under the coat (r_c = 0.2 < r1 = √0.3: the max leaves r1; ΣF0 > 1/16.5: f90 = 1).
        const double alpha0 = 0.04, alpha1 = 0.3;
        const Stack s = coated(1.5, alpha0, test::gold(alpha1));
        const double lobe = ggx_D(h, alpha1) * ggx_G2(wi, wo, alpha1) / (4 * wi.z * wo.z);
        Rgbd want;
        for (int c = 0; c < 3; ++c) {
            const double f0_air = conductor_ref(1, kGoldEta[c], kGoldK[c]);
            const double f0 =
                f0_air * (f0_air * (0.941892 - 0.263008 * f0_air) + 0.346479) - 0.0285998;
            want[c] = Fc(lh) * ggx_D(h, alpha0) / (4 * lh * lh) +
                      (1 - Fc(lh)) * schlick_ref(lh, f0) * lobe;
        }
        expect_rgb_near(make_model("filament", s, {"energy-compensation=off"})->eval(wi, wo), want,
                        1e-9, "filament gold");
    }
    {
        // A metal of F0 below 2 % (η = 1.2, κ = 0.01 in air, under the coat 0 after the
        // conversion's clamp in green and blue): f90 = 16.5 ΣF0 < 1.
        const double alpha1 = 0.3;
        const Rgbd eta(1.45, 1.2, 1.2), k(1.0, 0.01, 0.01);
        const Stack s = coated(1.5, 0.04, test::conductor(eta, k, alpha1));
        Rgbd f0;
        for (int c = 0; c < 3; ++c) {
            const double f0_air = conductor_ref(1, eta[c], k[c]);
            f0[c] = std::clamp(
                f0_air * (f0_air * (0.941892 - 0.263008 * f0_air) + 0.346479) - 0.0285998, 0.0,
                1.0);
        }
        const double f90 = 16.5 * (f0[0] + f0[1] + f0[2]);
        ASSERT_LT(f90, 1);
        const double lobe = ggx_D(h, alpha1) * ggx_G2(wi, wo, alpha1) / (4 * wi.z * wo.z);
        Rgbd want;
        for (int c = 0; c < 3; ++c)
            want[c] = Fc(lh) * ggx_D(h, 0.04) / (4 * lh * lh) +
                      (1 - Fc(lh)) * (f0[c] + (f90 - f0[c]) * std::pow(1 - lh, 5)) * lobe;
        expect_rgb_near(make_model("filament", s, {"energy-compensation=off"})->eval(wi, wo), want,
                        1e-9, "filament f90");
    }
}

// glTF: mix(base, clearcoat_brdf, 0.04 Schlick at N·V), clearcoat_brdf = D G / (4 |N·L| |N·V|);
// three.js puts the lobe's Fresnel at V·H (coat-fresnel=h).
TEST(ProductionCoats, GltfAgainstTheExtension) {
    const double alpha0 = 0.04;
    const Stack s = coated(1.5, alpha0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    const Vec3d h = normalize(wi + wo);
    auto Fs = [](double c) { return 0.04 + 0.96 * std::pow(1 - c, 5); };
    const double brdf = ggx_D(h, alpha0) * ggx_G2(wi, wo, alpha0) / (4 * wi.z * wo.z);
    Rgbd want, three;
    for (int c = 0; c < 3; ++c) {
        const double base = kRho[c] / kPi<double> * std::exp(-2 * kTau[c]) * (1 - Fs(wo.z));
        want[c] = base + Fs(wo.z) * brdf;
        three[c] = base + Fs(dot(wo, h)) * brdf;
    }
    expect_rgb_near(make_model("gltf-clearcoat", s)->eval(wi, wo), want, 1e-9, "gltf");
    expect_rgb_near(make_model("gltf-clearcoat", s, {"coat-fresnel=h"})->eval(wi, wo), three, 1e-9,
                    "gltf three.js");
}

// Blender: base × (1 − E_coat(wo)) × tint^(1/μt_o), the tint once along the view, matched at
// normal incidence: tint = e^(−2τ).
TEST(ProductionCoats, BlenderAgainstItsClosure) {
    // A smooth coat over a Lambertian base: the base weighted by 1 − (Cycles' estimate of the
    // coat's albedo at μo) and by coat_tint^(1/μt_o). The estimate F0 + (1 − F0) s reads the table
    // of s at Cycles' nodes: μ = m/15, z = k/15 with F0 = z⁴ (η from F0), at the first roughness
    // node (r = 1e-4, where s is its smooth value ŝ(μ) = (F(μ) − F0)/(1 − F0) to 1e-9), linearly
    // interpolated in μ and z; the white albedo there is 1 (to 1e-9).
    const double eta = 1.5;
    const Stack s = coated(eta, 0.0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    auto s_hat = [](double mu, double e) {
        const double f0 = sqr((e - 1) / (e + 1));
        return (fresnel_ref(mu, e) - f0) / (1 - f0);
    };
    auto eta_of_z = [](double z) {
        const double q = z * z;  // √F0
        return (1 + q) / (1 - q);
    };
    const double z = std::sqrt((eta - 1) / (eta + 1)) * 15, y = wo.z * 15;
    const int k = int(z), m = int(y);
    auto at_z = [&](int kk) {
        const double e = eta_of_z(kk / 15.0);
        return std::lerp(s_hat(m / 15.0, e), s_hat((m + 1) / 15.0, e), y - m);
    };
    const double factor = std::lerp(at_z(k), at_z(k + 1), z - k);
    const double f0 = sqr((eta - 1) / (eta + 1));
    const double albedo = f0 + (1 - f0) * factor;
    Rgbd want;
    for (int c = 0; c < 3; ++c)
        want[c] = (1 - albedo) * std::pow(std::exp(-2 * kTau[c]), 1 / refracted_cos(wo.z, eta)) *
                  kRho[c] / kPi<double>;
    expect_rgb_near(make_model("blender-principled", s)->eval(wi, wo), want, 1e-8, "blender");
}

// Kulla & Conty: (1 − E(μi))(1 − E(μo))/(1 − E_avg) f_base, E_avg = 2∫E μ dμ (here by a
// midpoint rule; the model integrates by Gauss–Legendre).
TEST(ProductionCoats, KullaContyAgainstTheCourseNotes) {
    const double eta = 1.5;
    const Stack s = coated(eta, 0.0, test::lambertian(kRho), kTau);
    const Vec3d wi = dir(30, 0), wo = dir(55, 135);
    double e_avg = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
        const double mu = (i + 0.5) / n;
        e_avg += 2 * fresnel_ref(mu, eta) * mu / n;
    }
    const double path = 1 / refracted_cos(wi.z, eta) + 1 / refracted_cos(wo.z, eta);
    Rgbd want;
    for (int c = 0; c < 3; ++c)
        want[c] = (1 - fresnel_ref(wi.z, eta)) * (1 - fresnel_ref(wo.z, eta)) / (1 - e_avg) *
                  std::exp(-kTau[c] * path) * kRho[c] / kPi<double>;
    expect_rgb_near(make_model("kulla-conty", s)->eval(wi, wo), want, 1e-7, "kulla-conty");
}

// Base roughening, each model's rule: the roughened model equals the unroughened one on a stack
// whose base already has the roughened α (α = r²), darkening off so that only the lobe moves.
TEST(ProductionCoats, BaseRougheningRules) {
    const double alpha0 = 0.2, alpha1 = 0.05, eta = 1.5;
    const double r0 = std::sqrt(alpha0), r1 = std::sqrt(alpha1);
    struct Case {
        std::string name;
        std::vector<std::string> on, off;
        double r_prime;
    };
    const std::vector<Case> cases = {
        {"openpbr",
         {"darkening=off"},
         {"darkening=off", "roughening=off"},
         std::pow(std::pow(r1, 4) + 2 * std::pow(r0, 4), 0.25)},
        {"openpbr-adobe",
         {"darkening=off"},
         {"darkening=off", "roughening=off"},
         std::pow(std::pow(r1, 4) + (1 - 1 / eta) * std::pow(r0, 4), 0.25)},
        {"filament", {}, {"roughening=off"}, std::max(r1, r0)},
        {"standard-surface", {"affect-roughness=1"}, {}, r1 + (1 - r1) * r0},
    };
    const Vec3d wi = dir(35, 0), wo = dir(40, 170);
    for (const Case& c : cases) {
        const auto on = make_model(c.name, coated(eta, alpha0, test::gold(alpha1)), c.on);
        const auto off = make_model(c.name, coated(eta, alpha0, test::gold(sqr(c.r_prime))), c.off);
        expect_rgb_near(on->eval(wi, wo), off->eval(wi, wo), 1e-9, c.name);
    }
}

// --- Energy -----------------------------------------------------------------------------------

/// The model with its arguments swapped: its albedo is the original's ∫ f(wi, wo) μi dωi at wo.
class Transposed final : public Model {
  public:
    explicit Transposed(std::unique_ptr<Model> m) : m_(std::move(m)) {}
    std::string name() const override { return m_->name() + "^T"; }
    Support support() const override { return m_->support(); }
    Rgbd eval(const Vec3d& a, const Vec3d& b) const override { return m_->eval(b, a); }
    // Every delta lobe here sits at the mirror pair, whose energy is symmetric (h = n).
    std::vector<DeltaLobe> delta_lobes(const Vec3d& w) const override { return m_->delta_lobes(w); }

  private:
    std::unique_ptr<Model> m_;
};

double max_albedo(const ModelEntry& e, bool transposed, const std::vector<std::string>& opts = {},
                  bool lambertian_only = false) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    double worst = 0;
    for (const auto& [what, stack] : test::energy_sweep(false)) {
        if (lambertian_only && what.find("lambertian") == std::string::npos) continue;
        std::unique_ptr<Model> m = e.make(stack, resolve_options(e, opts));
        if (!m->support().brdf) continue;
        if (transposed) m = std::make_unique<Transposed>(std::move(m));
        for (double t : {0.0, 45.0, 80.0})
            worst = std::max(
                worst,
                model_albedo(*m, incident_direction(deg_to_rad(t)), Side::Reflection, o).max());
    }
    return worst;
}

// The albedo-scaling coats (1 − E(μo), or a Fresnel at n·wo) conserve energy for the light
// arriving at each wo (∫ f μi dωi = E(μo) + (1 − E(μo)) E_base ≤ 1): tested. Per incidence they
// do not: at grazing wi the coat reflects E(μi) ≈ 1 while the base still receives 1 − E(μo) for
// most wo. The measured excess at θi ≤ 80° over the sweep (docs/models.md) bounds the forward
// albedo, and the test fails if the excess disappeared. Tolerances: the quadrature's 1e-3 and
// the FGD table's interpolation budget (6.3e-3, docs/models.md).
TEST(ProductionCoats, EnergyAsMeasured) {
    const double tol = 1e-3 + 6.3e-3;
    for (const char* name : {"openpbr", "openpbr-adobe", "standard-surface", "gltf-clearcoat",
                             "blender-principled", "threejs-clearcoat"}) {
        const ModelEntry& e = find_model(name);
        EXPECT_LE(max_albedo(e, true), 1 + tol) << name << " (per wo)";
        const double forward = max_albedo(e, false);
        EXPECT_GT(forward, 1.2) << name;
        EXPECT_LE(forward, 1.33) << name;
    }
    // MaterialX's throughput is 1 minus its *fitted* albedo of the compensated coat lobe, not the
    // lobe's own: per wo it gains up to 0.8 % (measured 1.0082), forward 1.331.
    const ModelEntry& materialx = find_model("openpbr-materialx");
    const double materialx_per_wo = max_albedo(materialx, true),
                 materialx_forward = max_albedo(materialx, false);
    EXPECT_GT(materialx_per_wo, 1.005);
    EXPECT_LE(materialx_per_wo, 1.011);
    EXPECT_GT(materialx_forward, 1.3);
    EXPECT_LE(materialx_forward, 1.34);
    // Enterprise PBR's 1 − max(F(μi), F(μo)) conserves energy both ways; dspbr-pt's
    // multiple-scattering lobe for the metal adds light with its fitted albedos (measured 1.067:
    // gold α1 = 0.4 under a smooth coat, θi = 80°).
    const ModelEntry& enterprise = find_model("enterprise-pbr");
    EXPECT_LE(max_albedo(enterprise, false, {"multiple-scattering=off"}), 1 + 1e-3);
    const double enterprise_ms = max_albedo(enterprise, false);
    EXPECT_GT(enterprise_ms, 1.05);
    EXPECT_LE(enterprise_ms, 1.075);
    // Filament's base × (1 − Fc(l·h)) does not: at grazing incidence l·h is far from grazing.
    const double filament = max_albedo(find_model("filament"), false);
    EXPECT_GT(filament, 1.3);
    EXPECT_LE(filament, 1.36);
    // Kulla & Conty's 1/(1 − E_avg) normalizes a diffuse base exactly; under a metal it
    // overshoots (measured 1.050).
    const ModelEntry& kc = find_model("kulla-conty");
    EXPECT_LE(max_albedo(kc, false, {}, true), 1 + tol);
    const double kc_all = max_albedo(kc, false);
    EXPECT_GT(kc_all, 1.03);
    EXPECT_LE(kc_all, 1.06);
}

// --- Reciprocity -----------------------------------------------------------------------------

double reciprocity_error(const Model& m) {
    double worst = 0;
    for (double ti : {10.0, 40.0, 70.0})
        for (double to : {20.0, 55.0, 80.0})
            for (double po : {30.0, 150.0}) {
                const Vec3d a = dir(ti, 0), b = dir(to, po);
                const Rgbd fab = m.eval(a, b), fba = m.eval(b, a);
                for (int c = 0; c < 3; ++c)
                    worst = std::max(worst, std::abs(fab[c] - fba[c]) / std::max(fab[c], fba[c]));
            }
    return worst;
}

// Measured (docs/models.md): Enterprise PBR, Filament without its energy compensation, Kulla &
// Conty (reciprocal form) and Adobe's reciprocal=on are reciprocal; the view-only albedo scaling
// (OpenPBR, Adobe's default, Standard Surface, Blender), glTF's n·wo Fresnel and Filament's
// compensation (1 + F0 (1/E(μo) − 1), of the view only) are not.
TEST(ProductionCoats, ReciprocityAsMeasured) {
    const std::vector<Stack> stacks = {coated(1.5, 0.2, test::lambertian(kRho), kTau),
                                       coated(1.5, 0.1, test::gold(0.25), kTau)};
    for (const auto& [name, opts] : std::vector<std::pair<std::string, std::vector<std::string>>>{
             {"enterprise-pbr", {}},
             {"filament", {"energy-compensation=off"}},
             {"kulla-conty", {}},
             {"openpbr-adobe", {"reciprocal=on"}}})
        for (const Stack& s : stacks)
            EXPECT_LT(reciprocity_error(*make_model(name, s, opts)), 1e-12) << name;
    for (const char* name : {"openpbr", "openpbr-adobe", "standard-surface", "blender-principled",
                             "gltf-clearcoat", "threejs-clearcoat", "openpbr-materialx"})
        EXPECT_GT(reciprocity_error(*make_model(name, stacks[0])), 0.05) << name;
    const double filament_metal = reciprocity_error(*make_model("filament", stacks[1]));
    std::cout << "filament over gold: reciprocity error " << filament_metal << "\n";
    EXPECT_GT(filament_metal, 0.05);
    EXPECT_LT(reciprocity_error(*make_model("filament", stacks[0])), 1e-12);
}

// --- Not supported ---------------------------------------------------------------------------

TEST(ProductionCoats, SupportIsExplicit) {
    for (const ModelEntry* e : production()) {
        const auto slab = make_model(e->name, coated(1.5, 0.1, test::dielectric(1.3, 0.2)));
        EXPECT_FALSE(slab->support().brdf);
        EXPECT_NE(slab->support().reason.find("slab"), std::string::npos) << e->name;
        const auto scattering =
            make_model(e->name, coated(1.5, 0.1, test::lambertian(kRho), Rgbd(0.1), Rgbd(0.5)));
        EXPECT_FALSE(scattering->support().brdf);
        EXPECT_NE(scattering->support().reason.find("scattering"), std::string::npos) << e->name;
        const auto other_ior = make_model(e->name, coated(1.3, 0.1, test::lambertian(kRho)));
        const bool fixed = e->name == "enterprise-pbr" || e->name == "filament" ||
                           e->name == "gltf-clearcoat" || e->name == "threejs-clearcoat";
        EXPECT_EQ(other_ior->support().brdf, !fixed) << e->name;
        if (fixed) {
            EXPECT_NE(other_ior->support().reason.find("fixed IOR"), std::string::npos) << e->name;
        }
        // Below the surface: no BTDF, zero.
        EXPECT_FALSE(other_ior->support().btdf);
        EXPECT_EQ(make_model(e->name, coated(1.5, 0.1, test::lambertian(kRho)))
                      ->eval(dir(30, 0), Vec3d(0, 0.3, -0.95))
                      .max(),
                  0.0);
    }
}

// Importance sampling: each sample's density is pdf(wi, wo) and its weight eval·μo/pdf; the
// mean weight estimates the albedo (rough coats and bases: no delta lobe), within 4 standard
// errors of the estimate plus the quadrature's 1e-4 (fixed seed).
TEST(ProductionCoats, SamplingEstimatesTheAlbedo) {
    const std::vector<Stack> stacks = {coated(1.5, 0.1, test::lambertian(kRho), kTau),
                                       coated(1.5, 0.2, test::gold(0.3), kTau)};
    for (const ModelEntry* e : production()) {
        for (const Stack& s : stacks) {
            const auto m = make_model(e->name, s);
            ASSERT_TRUE(m->has_sampling()) << e->name;
            for (double ti : {20.0, 70.0}) {
                const Vec3d wi = dir(ti, 0);
                const int n = 100000;
                Rgbd sum(0.0), sum2(0.0);
                for (int k = 0; k < n; ++k) {
                    ParticleRng rng(7, std::uint64_t(ti), std::uint64_t(k));
                    const Vec3d u(rng.uniform_double(), rng.uniform_double(), rng.uniform_double());
                    const auto smp = m->sample(wi, u);
                    if (!smp) continue;
                    if (k < 2000) {
                        EXPECT_NEAR(smp->pdf, m->pdf(wi, smp->wo), 1e-12 * smp->pdf);
                        expect_rgb_near(smp->weight, m->eval(wi, smp->wo) * (smp->wo.z / smp->pdf),
                                        1e-12, e->name);
                    }
                    sum += smp->weight;
                    sum2 += smp->weight * smp->weight;
                }
                const Rgbd albedo = model_albedo(*m, wi, Side::Reflection);
                for (int c = 0; c < 3; ++c) {
                    const double mean = sum[c] / n;
                    const double se = std::sqrt(std::max(0.0, sum2[c] / n - mean * mean) / n);
                    EXPECT_NEAR(mean, albedo[c], 4 * se + 1e-4 * albedo[c])
                        << e->name << " ti=" << ti << " channel " << c;
                }
            }
        }
    }
}

// The evaluator for one thread (bin_model's, one per θ row) keeps what depends on wo.z alone: the
// same values as eval, bit for bit, for every production coat on a metal and a Lambertian base,
// a rough and a smooth coat.
TEST(ProductionCoats, EvaluatorForOneThreadIsEvalBitForBit) {
    for (const Stack& s :
         {coated(1.5, 0.2, test::gold(0.3), kTau), coated(1.5, 0.0, test::gold(0.3), kTau),
          coated(1.4, 0.3, test::lambertian(kRho), kTau), coated(1.5, 0.05, test::gold(0.0))})
        for (const ModelEntry* e : production()) {
            const auto m = make_model(e->name, s);
            if (!m->support().brdf) continue;
            for (double theta_i : {0.0, 50.0, 85.0})
                test::expect_one_thread_evaluator_equals_eval(*m, dir(theta_i, 0));
        }
}

// prepare() caches the incident half: the same values as eval.
TEST(ProductionCoats, PreparedEvaluatorMatchesEval) {
    const Stack s = coated(1.5, 0.2, test::gold(0.3), kTau);
    for (const ModelEntry* e : production()) {
        const auto m = make_model(e->name, s);
        const Vec3d wi = dir(50, 0);
        const auto p = m->prepare(wi);
        for (const Vec3d& wo : {dir(10, 10), dir(50, 180), dir(80, 90)})
            expect_rgb_near(p->eval(wo), m->eval(wi, wo), 1e-15, e->name);
    }
}

}  // namespace
}  // namespace lamina

// Weier & Belcour 2020 (wb20): Belcour 2018's adding with 2×2 lobe covariances. Its isotropic
// limit is bel18-forward; a bare brushed conductor is one anisotropic GGX lobe of
// physics/microfacet.h; a smooth coat scales a brushed base's covariance by the refraction
// Jacobian and the inter-reflections, per axis; its albedo stays within the FGD table's budget
// over the whole azimuth. (The registry-driven anisotropy checks run on it too.)
#include "core/math.h"
#include "models/belcour/belcour.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/tables/fgd_table.h"
#include "models/test_stacks.h"
#include "physics/microfacet.h"

#include "models/model_checks.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test::brushed;
using test::dir;
using test::relative_difference;

// Isotropic interfaces: every covariance is σ I and the energies read α(σ), so wb20 is
// bel18-forward up to rounding (coats, media, conductor and dielectric bases).
TEST(Wb20, IsotropicStacksAreBel18Forward) {
    const std::vector<Stack> stacks = {brushed(0.2, 0.2, 0, 0.3, 0.3, 0),
                                       brushed(0.05, 0.05, 0, 0.5, 0.5, 0),
                                       test::coated(1.5, 0.1, test::dielectric(1.3, 0.4),
                                                    Rgbd(0.2, 0.1, 0.0), Rgbd(0.3, 0.3, 0.3), 0.7),
                                       test::single(test::gold(0.25))};
    for (const Stack& s : stacks) {
        const auto wb = make_model("wb20", s);
        const auto bel = make_model("bel18-forward", s);
        ASSERT_TRUE(wb->support().brdf) << wb->support().reason;
        double worst = 0;
        for (double ti : {0.0, 20.0, 50.0, 75.0})
            for (double pi : {0.0, 70.0, 200.0})
                for (double to : {10.0, 40.0, 80.0})
                    for (double po : {0.0, 100.0, 250.0}) {
                        const Vec3d wi = dir(ti, pi), wo = dir(to, po);
                        worst = std::max(worst,
                                         relative_difference(wb->eval(wi, wo), bel->eval(wi, wo)));
                    }
        EXPECT_LT(worst, 1e-9);
    }
}

// A bare brushed conductor: one lobe, E D G2 / (4 μi μo), D and G2 the anisotropic GGX of
// α_x = α(σ(α_x)) = α_x and α_y along the tangent at ψ (physics/microfacet.h), E the FGD of the
// conductor at the roughness of the variance along the incident azimuth φi,
// α(σ(α_x) cos²(φi − ψ) + σ(α_y) sin²(φi − ψ)).
TEST(Wb20, BareBrushedConductorIsTheAnisotropicGgx) {
    const double ax = 0.1, ay = 0.4, psi = 30;
    const InterfaceSpec g = test::gold(ax);
    const Stack s = test::single(anisotropic(g, ax, ay, psi));
    const auto model = make_model("wb20", s);
    ASSERT_TRUE(model->support().brdf) << model->support().reason;
    const GGX<double> ggx = GGX<double>::anisotropic(ax, ay, deg_to_rad(psi));
    const FgdTable& fgd = FgdTable::get();
    double worst = 0;
    for (double ti : {10.0, 40.0, 70.0})
        for (double pi : {0.0, 55.0, 160.0})
            for (double to : {5.0, 35.0, 65.0})
                for (double po : {15.0, 120.0, 300.0}) {
                    const Vec3d wi = dir(ti, pi), wo = dir(to, po);
                    const Vec3d h = normalize(wi + wo);
                    const double shape = ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
                    const double phi = deg_to_rad(pi - psi);
                    const double alpha_e = belcour_alpha_of_variance(
                        belcour_variance_of_alpha(ax, false) * sqr(std::cos(phi)) +
                            belcour_variance_of_alpha(ay, false) * sqr(std::sin(phi)),
                        false);
                    Rgbd expected;
                    for (int c = 0; c < 3; ++c)
                        expected[c] = fgd(wi.z, alpha_e, g.eta_rgb[c], g.k[c]) * shape;
                    worst = std::max(worst, relative_difference(model->eval(wi, wo), expected));
                }
    EXPECT_LT(worst, 1e-9);
}

// energy-roughness=mean: the energy reads the roughness of the covariance's mean over azimuths,
// α((σ(α_x) + σ(α_y))/2), whatever the incident azimuth.
TEST(Wb20, EnergyRoughnessMeanReadsTheAzimuthalMean) {
    const double ax = 0.1, ay = 0.4, psi = 30;
    const InterfaceSpec g = test::gold(ax);
    const Stack s = test::single(anisotropic(g, ax, ay, psi));
    const ModelEntry& entry = find_model("wb20");
    const auto model = entry.make(s, resolve_options(entry, {"energy-roughness=mean"}));
    ASSERT_TRUE(model->support().brdf) << model->support().reason;
    const GGX<double> ggx = GGX<double>::anisotropic(ax, ay, deg_to_rad(psi));
    const double alpha_e = belcour_alpha_of_variance(
        0.5 * (belcour_variance_of_alpha(ax, false) + belcour_variance_of_alpha(ay, false)), false);
    const FgdTable& fgd = FgdTable::get();
    for (double pi : {0.0, 75.0}) {
        const Vec3d wi = dir(40, pi), wo = dir(30, 170);
        const Vec3d h = normalize(wi + wo);
        const double shape = ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
        Rgbd expected;
        for (int c = 0; c < 3; ++c)
            expected[c] = fgd(wi.z, alpha_e, g.eta_rgb[c], g.k[c]) * shape;
        EXPECT_LT(relative_difference(model->eval(wi, wo), expected), 1e-9) << pi;
    }
}

// A smooth coat (η 1.5) over a brushed conductor, no TIR step: the coat adds no variance, so the
// base's lobe has the covariance J (1 + rr) R(ψ) diag(σ(α_x), σ(α_y)) R(ψ)ᵀ, J = η cos θt / cos θi
// the refraction Jacobian (Belcour 2018, §5.2) and rr = Ri0 R / (1 − Ri0 R) the inter-reflections
// between the coat seen from below (Ri0 = its FGD at cos θi, α = 0) and the base (R its FGD at
// cos θt and the roughness along the incident azimuth), averaged over RGB.
TEST(Wb20, SmoothCoatScalesEachAxisByTheRefraction) {
    const double ax = 0.15, ay = 0.45, psi_deg = -25, eta = 1.5;
    const InterfaceSpec g = test::gold(ax);
    std::vector<BelcourOperator> ops(2);
    ops[0].kind = BelcourOperator::Dielectric;
    ops[0].n12 = eta;
    ops[0].eta = Rgbd(eta);
    ops[1].kind = BelcourOperator::Conductor;
    ops[1].eta = g.eta_rgb;
    ops[1].k = g.k;
    ops[1].n12 = g.eta_rgb.mean();
    ops[1].alpha = ax;
    ops[1].alpha_b = ay;
    ops[1].tangent_cos = std::cos(deg_to_rad(psi_deg));
    ops[1].tangent_sin = std::sin(deg_to_rad(psi_deg));
    precompute_variances(ops, false);
    BelcourChoices ch;
    ch.anisotropic = true;
    ch.tir = BelcourTir::Off;
    const FgdTable& fgd = FgdTable::get();
    const double sx = belcour_variance_of_alpha(ax, false);
    const double sy = belcour_variance_of_alpha(ay, false);
    for (double ti : {0.0, 30.0, 60.0})
        for (double phi_deg : {0.0, 80.0}) {
            const double c = std::cos(deg_to_rad(ti));
            const double dx = std::cos(deg_to_rad(phi_deg)), dy = std::sin(deg_to_rad(phi_deg));
            const BelcourStats st = belcour_adding_anisotropic(ops, c, ch, dx, dy);
            ASSERT_EQ(st.n_lobes, 2);
            const double ct = std::sqrt(1 - (1 - c * c) / sqr(eta));
            const double J = eta * ct / c;
            const double ri0 = fgd(c, 0.0, eta, 0.0);
            const double phi = deg_to_rad(phi_deg - psi_deg);
            const double alpha_e =
                belcour_alpha_of_variance(sx * sqr(std::cos(phi)) + sy * sqr(std::sin(phi)), false);
            double rr = 0;
            for (int k = 0; k < 3; ++k) {
                const double r = fgd(ct, alpha_e, g.eta_rgb[k], g.k[k]);
                rr += ri0 * r / (1 - ri0 * r) / 3;
            }
            const BelcourCovariance expected = BelcourCovariance::of_axes(
                J * (1 + rr) * sx, J * (1 + rr) * sy, ops[1].tangent_cos, ops[1].tangent_sin);
            const BelcourCovariance& got = st.lobes[1].covariance;
            EXPECT_NEAR(got.xx, expected.xx, 1e-12 * sy) << ti;
            EXPECT_NEAR(got.yy, expected.yy, 1e-12 * sy) << ti;
            EXPECT_NEAR(got.xy, expected.xy, 1e-12 * sy) << ti;
            // Its lobe: the axes are the base's, at its tangent.
            const BelcourAnisotropicLobe lobe = belcour_lobe_of_covariance(got, false);
            EXPECT_NEAR(lobe.alpha_x, belcour_alpha_of_variance(J * (1 + rr) * sy, false), 1e-12);
            EXPECT_NEAR(lobe.alpha_y, belcour_alpha_of_variance(J * (1 + rr) * sx, false), 1e-12);
            EXPECT_NEAR(std::remainder(lobe.psi - deg_to_rad(psi_deg + 90), kPi<double>), 0, 1e-12);
        }
}

// Brushed stacks lit from every azimuth: the albedo over the whole azimuth stays ≤ 1 within the
// quadrature tolerance (1e-3) and the FGD table's interpolation budget for conductors (6.3e-3,
// docs/models.md), as bel18-forward's in tests/models/energy_test.cpp.
TEST(Wb20, AlbedoAtMostOneOnBrushedStacks) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    o.full_azimuth = true;
    for (const Stack& s :
         {brushed(0.05, 0.05, 0, 0.05, 0.5, 30), brushed(0.3, 0.05, 60, 0.4, 0.1, -20),
          brushed(0.01, 0.01, 0, 0.02, 0.8, 0)}) {
        const auto model = make_model("wb20", s);
        ASSERT_TRUE(model->support().brdf) << model->support().reason;
        for (double ti : {0.0, 45.0, 80.0})
            for (double pi : {0.0, 45.0, 90.0, 150.0}) {
                const Rgbd a = model_albedo(*model, dir(ti, pi), Side::Reflection, o);
                EXPECT_LE(a.max(), 1.0 + 1e-3 + 6.3e-3) << ti << " " << pi;
            }
    }
}

}  // namespace
}  // namespace lamina

// Belcour 2018 (forward, symmetric) and Bel': limits, reciprocity and support.
#include "models/belcour/belcour.h"
#include "core/math.h"
#include "core/rng.h"
#include "core/spherical.h"
#include "models/model_checks.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/tables/fgd_table.h"
#include "models/tables/tir_table.h"
#include "models/test_stacks.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lamina {
namespace {

using test::coated;

using test::dir;

/// ∫ D G2 / (4 μi μo) μo dωo: the albedo of a GGX lobe of unit energy (what the height-correlated
/// shadowing leaves of it), by a dense midpoint rule in (u = sin²θ, φ) (measure ½ du dφ).
double unit_lobe_albedo(double alpha, const Vec3d& wi) {
    const GGX<double> ggx{alpha};
    const int nu = 1500, nphi = 600;
    double sum = 0;
    for (int a = 0; a < nu; ++a)
        for (int b = 0; b < nphi; ++b) {
            const double u = (a + 0.5) / nu, phi = kPi<double> * (b + 0.5) / nphi;
            const double s = std::sqrt(u);
            const Vec3d wo(s * std::cos(phi), s * std::sin(phi), std::sqrt(1 - u));
            const Vec3d h = normalize(wi + wo);
            sum += ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
        }
    return sum * kPi<double> / (nu * nphi) * 1.0;  // 2 halves × ½ du dφ = du dφ over [0,1]×[0,π]
}

// One dielectric interface (ambient over a half-space): the adding scheme starts with T0i = Ti0
// = 1 and Ri0 = 0, so its single lobe has energy E0 = R12 = FGD(μi, α, η) and roughness α
// (α(σ(α)) = α). Checked against direct integration of the FGD integral, and the binned albedo
// of the model against E0 times the albedo of a unit-energy GGX lobe (the model's f is
// E0·D·G2/(4μiμo), whose shadowing applies on top of the FGD's: this is what Bel18 is).
TEST(Bel18Golden, SingleInterfaceGivesOneLobeOfEnergyFgd) {
    const double eta = 1.5, alpha = 0.3;
    const Stack s = test::single(test::dielectric(eta, alpha));
    BelcourOperator op;
    op.n12 = eta;
    op.eta = Rgbd(eta);
    op.alpha = alpha;
    const auto model = make_model("bel18-forward", s);
    ASSERT_TRUE(model->support().brdf);
    EXPECT_FALSE(model->support().btdf);
    for (double ti : {0.0, 30.0, 60.0, 80.0}) {
        const Vec3d wi = dir(ti, 0);
        const BelcourStats st = belcour_adding({op}, wi.z, {});
        ASSERT_EQ(st.n_lobes, 1);
        const double fgd = FgdTable::direct(wi.z, alpha, eta, 0);
        EXPECT_NEAR(st.lobes[0].energy[0], fgd, 4e-3) << ti;  // table budget (docs/models.md)
        EXPECT_NEAR(st.lobes[0].alpha, alpha, 1e-12);
        const double want = st.lobes[0].energy[0] * unit_lobe_albedo(alpha, wi);
        const Rgbd albedo = model_albedo(*model, wi, Side::Reflection);
        EXPECT_NEAR(albedo[0], want, 2e-4 * want + 1e-6) << ti;
    }
}

// Bel' replaces lobe 0 by the exact top reflection, always: with a base that reflects nothing
// (a conductor index-matched to the coat, F = 0) Bel' is exactly the microfacet reflection of
// the coat (Walter et al. 2007, Eq. 20); with a real base, Bel' − Bel18 forward is exactly
// f_top − E0·D·G2/(4μiμo) with E0 = FGD(μi, α0, η0) (lobe 0 is the only difference).
TEST(BelPrimeGolden, LobeZeroIsTheExactTopReflection) {
    const double eta = 1.5, alpha = 0.2;
    const DielectricInterface<double> top{eta, alpha};
    const auto black =
        make_model("bel-prime", coated(eta, alpha, test::conductor(Rgbd(eta), Rgbd(0.0), 0.3)));
    const auto prime = make_model("bel-prime", coated(eta, alpha, test::gold(0.3)));
    const auto fwd = make_model("bel18-forward", coated(eta, alpha, test::gold(0.3)));
    const GGX<double> ggx{alpha};
    for (double ti : {0.0, 35.0, 70.0})
        for (double to : {15.0, 45.0, 80.0})
            for (double po : {0.0, 120.0, 180.0}) {
                const Vec3d wi = dir(ti, 0), wo = dir(to, po);
                const double exact = top.eval(wi, wo);
                EXPECT_NEAR(black->eval(wi, wo)[0], exact, 1e-12);
                const Vec3d h = normalize(wi + wo);
                const double e0 = FgdTable::get()(wi.z, alpha, eta, 0);
                const double lobe0 = e0 * ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
                for (int c = 0; c < 3; ++c)
                    EXPECT_NEAR(prime->eval(wi, wo)[c] - fwd->eval(wi, wo)[c], exact - lobe0,
                                1e-9 * (exact + lobe0) + 1e-12);
            }
}

// Bel' BTDF of a smooth two-interface slab without absorption: a delta along the direction Snell's
// law gives through both interfaces (sin θt = sin θi / η_exit, azimuth opposite the light) with
// energy T0i = T1 T2 / (1 − R1 R2), R1 = F(μi; η1), R2 = F(μ1; η2/η1) at the refracted cosine μ1,
// T = 1 − R: the incoherent sum of all orders of inter-reflection between two smooth interfaces
// (the adding scheme is exact here with a TIR step that holds no Fresnel factor: TIR cannot occur
// for light that entered; the author's table, the default, counts the top's Fresnel a second time:
// Bel18.AuthorsTirTableCountsTheTopFresnelTwice). Independent of the model's code:
// fresnel_dielectric and Snell directly. The two mirror lobes (energies R1 and T1² R2/(1 − R1R2))
// close the energy balance.
TEST(BelPrimeGolden, SmoothSlabTransmitsTheIncoherentTwoInterfaceSum) {
    const double eta1 = 1.5, eta2 = 1.2;
    const auto model =
        make_model("bel-prime", coated(eta1, 0.0, test::dielectric(eta2, 0.0)), {"tir-table=lobe"});
    ASSERT_TRUE(model->support().btdf);
    for (double ti : {0.0, 30.0, 70.0}) {
        const Vec3d wi = dir(ti, 0);
        const double mu1 = std::sqrt(1 - (1 - wi.z * wi.z) / (eta1 * eta1));
        const double R1 = fresnel_dielectric(wi.z, eta1), R2 = fresnel_dielectric(mu1, eta2 / eta1);
        const double T = (1 - R1) * (1 - R2) / (1 - R1 * R2);
        const double R = R1 + (1 - R1) * (1 - R1) * R2 / (1 - R1 * R2);
        double got_t = 0, got_r = 0;
        for (const DeltaLobe& d : model->delta_lobes(wi)) {
            if (d.direction.z < 0) {
                got_t += d.energy[0];
                const double sin_t = std::sin(deg_to_rad(ti)) / eta2;
                EXPECT_NEAR(d.direction.x, -sin_t, 1e-12);
                EXPECT_NEAR(d.direction.z, -std::sqrt(1 - sin_t * sin_t), 1e-12);
            } else {
                got_r += d.energy[0];
            }
        }
        EXPECT_NEAR(got_t, T, 1e-12) << ti;
        EXPECT_NEAR(got_r, R, 1e-12) << ti;
    }
}

// Bel18's top lobe alone (a base that reflects nothing) is not the exact microfacet reflection,
// and the model does not claim it is: lobe 0 is E0·D·G2/(4μiμo) with E0 = FGD(μi) — the Fresnel
// factor averaged over the lobe (and the shadowing counted twice). Shown: it equals that formula
// to rounding and differs from Walter's f_top by more than 10% where F(wi·h) varies (grazing).
TEST(Bel18, TopLobeAloneIsFgdWeightedNotExact) {
    const double eta = 1.5, alpha = 0.3;
    const auto model =
        make_model("bel18-forward", coated(eta, alpha, test::conductor(Rgbd(eta), Rgbd(0.0), 0.3)));
    const DielectricInterface<double> top{eta, alpha};
    const GGX<double> ggx{alpha};
    const Vec3d wi = dir(75, 0), wo = dir(60, 40);
    const Vec3d h = normalize(wi + wo);
    const double lobe0 =
        FgdTable::get()(wi.z, alpha, eta, 0) * ggx.D(h) * ggx.G2(wi, wo) / (4 * wi.z * wo.z);
    EXPECT_NEAR(model->eval(wi, wo)[0], lobe0, 1e-12 * lobe0);
    EXPECT_GT(std::abs(lobe0 - top.eval(wi, wo)) / top.eval(wi, wo), 0.1);
}

// Bel18 symmetric feeds c0 = |wi·h| = |wo·h| to the adding scheme, so the lobe statistics are
// the same for (wi, wo) and (wo, wi), and D(h), G2 and 1/(μiμo) are symmetric: reciprocal to
// rounding.
TEST(Bel18, SymmetricIsReciprocal) {
    const auto model =
        make_model("bel18-symmetric", coated(1.5, 0.15, test::gold(0.3), Rgbd(0.2, 0.4, 0.1)));
    ParticleRng rng(3, 0, 0);
    for (int n = 0; n < 200; ++n) {
        const Vec3d a = dir(89 * rng.uniform_double(), 0);
        const Vec3d b = dir(89 * rng.uniform_double(), 360 * rng.uniform_double());
        const Rgbd fab = model->eval(a, b), fba = model->eval(b, a);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(fab[c], fba[c], 1e-12 * std::max(fab[c], 1.0));
    }
}

// Bel18 forward feeds c0 = μi: the statistics depend on the light's direction only, so swapping
// wi and wo changes the lobe energies. Not reciprocal by construction — shown, not hidden: at
// (10°, 80°) through a rough coat over gold the two orders differ by more than 5%.
TEST(Bel18, ForwardIsNotReciprocal) {
    const auto model = make_model("bel18-forward", coated(1.5, 0.3, test::gold(0.3)));
    const Vec3d a = dir(10, 0), b = dir(80, 150);
    const double fab = model->eval(a, b)[0], fba = model->eval(b, a)[0];
    EXPECT_GT(std::abs(fab - fba) / std::max(fab, fba), 0.05);
}

// The forward variants compute the statistics once per incidence; the prepared evaluator must
// agree with eval exactly.
TEST(Bel18, PreparedEvaluatorEqualsEval) {
    const auto model = make_model(
        "bel-prime", coated(1.5, 0.1, test::dielectric(1.2, 0.2), Rgbd(0.1), Rgbd(0.3), 0.7));
    ASSERT_TRUE(model->support().btdf);
    test::expect_prepared_equals_eval(*model, dir(40, 0));
}

TEST(Bel18, SupportIsExplicit) {
    for (const char* name : {"bel18-forward", "bel18-symmetric", "bel-prime"}) {
        const auto plastic = make_model(name, coated(1.5, 0.1, test::lambertian(Rgbd(0.5))));
        EXPECT_FALSE(plastic->support().brdf);
        EXPECT_NE(plastic->support().reason.find("no Lambertian base"), std::string::npos);
        const auto back =
            make_model(name, coated(1.5, 0.1, test::gold(0.2), Rgbd(0.1), Rgbd(0.5), -0.3));
        EXPECT_FALSE(back->support().brdf);
        EXPECT_NE(back->support().reason.find("forward"), std::string::npos);
    }
    const Stack slab = coated(1.5, 0.1, test::dielectric(1.2, 0.2));
    EXPECT_FALSE(make_model("bel18-forward", slab)->support().btdf);
    EXPECT_TRUE(make_model("bel-prime", slab)->support().btdf);
}

// Energy bookkeeping of the adding scheme without absorption, TIR off and smooth interfaces: a
// smooth coat over a perfect mirror (conductor with F = 1 is approximated by κ = 10 on the
// table's edge; here a smooth dielectric base instead): R0i + T0i = 1 exactly at every order
// (adding conserves energy when R + T = 1 at each interface).
TEST(Bel18, AddingConservesEnergyWithoutLosses) {
    BelcourOperator top, bottom;
    top.n12 = 1.5;
    top.eta = Rgbd(1.5);
    bottom.n12 = 1.3 / 1.5;
    bottom.eta = Rgbd(bottom.n12);
    BelcourChoices ch;
    ch.tir = BelcourTir::Off;
    for (double c : {1.0, 0.7, 0.3}) {
        const BelcourStats st = belcour_adding({top, bottom}, c, ch);
        ASSERT_EQ(st.n_lobes, 2);
        ASSERT_TRUE(st.transmits);
        const double r = st.lobes[0].energy[0] + st.lobes[1].energy[0];
        EXPECT_NEAR(r + st.transmitted[0], 1.0, 1e-12) << c;
    }
}

// ---- The total-internal-reflection step (docs/models.md, "Belcour 2018", TIR) ----

BelcourOperator dielectric_op(double n12, double alpha) {
    BelcourOperator op;
    op.n12 = n12;
    op.eta = Rgbd(n12);
    op.alpha = alpha;
    return op;
}
BelcourOperator conductor_op(const Rgbd& eta, const Rgbd& k, double alpha) {
    BelcourOperator op;
    op.kind = BelcourOperator::Conductor;
    op.eta = eta;
    op.k = k;
    op.n12 = eta.mean();
    op.alpha = alpha;
    return op;
}
double sigma_of(double alpha) {
    return belcour_variance_of_alpha(alpha, false);
}
double alpha_of(double sigma) {
    return belcour_alpha_of_variance(sigma, false);
}
Rgbd fgd_rgb(double c, double alpha, const Rgbd& eta, const Rgbd& k) {
    const FgdTable& fgd = FgdTable::get();
    return {fgd(c, alpha, eta[0], k[0]), fgd(c, alpha, eta[1], k[1]), fgd(c, alpha, eta[2], k[2])};
}
double snell(double c, double n12) {
    return std::sqrt(1 - (1 - c * c) / (n12 * n12));
}

// The step's placement, by hand on three interfaces: ambient | smooth coat η 1.4 | rough layer
// η 1.8 (α 0.3) | gold (α 0.2, relative to 1.8), forward cosine c0 = 0.8, the author's defaults.
//
// Top (smooth, nothing above): R1 = FGD(c0, 0, 1.4) = F(c0; 1.4), T1 = 1 − R1, no step (nothing
// above it); lobe 0 = (R1, α 0). After it R0i = R1, T0i = Ti0 = T1, Ri0 = R1, every variance 0
// (a smooth interface adds none; rr = 0), J0i = J1 = 1.4 c1/c0, Ji0 = 1/J1, c1 = Snell(c0, 1.4).
//
// Middle (n = 1.8/1.4, α1): σR = σ(α1), α_eff = α(0 + σR) = α1. The step first, for the top
// interface seen from below (η 1/1.4), at the cosine c1 in the layer: τ1 = τ_TIR(c1, α_eff, 1/1.4),
// Ri0 ← R1 + (1 − τ1) T1, Ti0 ← τ1 T1. Then R2 = FGD(c1, α_eff, n), T2 = 1 − R2, Dn = 1 − Ri0 R2,
// lobe 1 = T0i R2 Ti0 / Dn with σ = J0i σR (1 + rr), rr = Ri0 R2/Dn; then T0i ← T1 T2/Dn,
// Ri0 ← R2 + T2² Ri0/Dn, Ti0 ← T2 Ti0/Dn, σT0i ← σT12 + J2 σR rr, σRi0 ← [R2 σR + (T2² Ri0/Dn)
// (σT12 + J2 (σT21 + rr σR))]/Ri0, σTi0 ← Ji0 (σT21 + σR rr), σT12 = σ(α1 |n − 1|/(2n)), σT21 =
// σ(α1 |1 − n|/2), J2 = n c2/c1, c2 = Snell(c1, n), J0i ← J1 J2, Ji0 ← 1/(J1 J2).
//
// Base: σR = σ(α2), α_eff = α(σT0i + σR). The step for the middle interface seen from below
// (η 1.4/1.8), at c2: τ2 = τ_TIR(c2, α_eff, 1.4/1.8), Ri0 ← Ri0 + (1 − τ2) Ti0, Ti0 ← τ2 Ti0;
// R3 = FGD(c2, α_eff, η_gold/1.8 + iκ/1.8) per channel; lobe 2 = T0i R3 Ti0/(1 − Ri0 R3), σ =
// σTi0 + J0i (σT0i + σR + rr (σR + σRi0)). (rr, σ's scalar: channel means, as the scheme.)
// Expected to rounding; and the former placement (once after the top, at its own α = 0: a step
// that never fires for light that entered) gives energies more than 1 % apart.
TEST(Bel18Golden, TirStepPlacementOnThreeInterfacesByHand) {
    const double c0 = 0.8, a1 = 0.3, a2 = 0.2, n = 1.8 / 1.4;
    const Rgbd gold_eta = Rgbd(0.18, 0.42, 1.37) * (1 / 1.8),
               gold_k = Rgbd(3.4, 2.35, 1.85) * (1 / 1.8);
    const std::vector<BelcourOperator> ops = {dielectric_op(1.4, 0.0), dielectric_op(n, a1),
                                              conductor_op(gold_eta, gold_k, a2)};
    const TirDefinition def = TirDefinition::LobeFresnel;
    const FgdTable& fgd = FgdTable::get();
    // Top.
    const double R1 = fresnel_dielectric(c0, 1.4), T1 = 1 - R1;
    const double c1 = snell(c0, 1.4), J1 = 1.4 * c1 / c0;
    // Middle.
    const double sR1 = sigma_of(a1), ae1 = alpha_of(sR1);
    const double tau1 = tir_fraction(def, c1, ae1, 1 / 1.4);
    double Ri0 = R1 + (1 - tau1) * T1, Ti0 = tau1 * T1;
    const double R2 = fgd(c1, ae1, n, 0.0), T2 = 1 - R2;
    double Dn = 1 - Ri0 * R2;
    const double E1 = T1 * R2 * Ti0 / Dn;
    double rr = Ri0 * R2 / Dn;
    const double s1 = J1 * sR1 * (1 + rr);
    const double c2 = snell(c1, n), J2 = n * c2 / c1;
    const double sT12 = sigma_of(a1 * std::abs(n - 1) / (2 * n)),
                 sT21 = sigma_of(a1 * std::abs(1 - n) / 2);
    const double T0i = T1 * T2 / Dn;
    const double through = T2 * Ri0 * T2 / Dn;
    Ri0 = R2 + through;
    Ti0 = T2 * Ti0 / Dn;
    const double sT0i = sT12 + J2 * sR1 * rr;
    const double sRi0 = (R2 * sR1 + through * (sT12 + J2 * (sT21 + rr * sR1))) / Ri0;
    const double sTi0 = (1 / J1) * (sT21 + sR1 * rr);
    const double J0i = J1 * J2;
    // Base.
    const double sR2 = sigma_of(a2), ae2 = alpha_of(sT0i + sR2);
    const double tau2 = tir_fraction(def, c2, ae2, 1.4 / 1.8);
    Ri0 = std::min(Ri0 + (1 - tau2) * Ti0, 1.0);
    Ti0 *= tau2;
    const Rgbd R3 = fgd_rgb(c2, ae2, gold_eta, gold_k);
    const Rgbd Dn3 = Rgbd(1.0) - R3 * Ri0;
    const Rgbd E2 = R3 * (T0i * Ti0) / Dn3;
    rr = (R3 * Ri0 / Dn3).mean();
    const double s2 = sTi0 + J0i * (sT0i + sR2 + rr * (sR2 + sRi0));

    const BelcourStats st = belcour_adding(ops, c0, {});
    ASSERT_EQ(st.n_lobes, 3);
    EXPECT_NEAR(st.lobes[0].energy[0], R1, 1e-15);
    EXPECT_EQ(st.lobes[0].alpha, 0.0);
    for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(st.lobes[1].energy[k], E1, 1e-12 * E1);
        EXPECT_NEAR(st.lobes[2].energy[k], E2[k], 1e-12 * E2[k]);
    }
    EXPECT_NEAR(st.lobes[1].alpha, alpha_of(s1), 1e-12);
    EXPECT_NEAR(st.lobes[2].alpha, alpha_of(s2), 1e-12);
    // Both steps act: τ1, τ2 well below 1.
    EXPECT_LT(tau1, 0.95);
    EXPECT_LT(tau2, 0.95);

    BelcourChoices former;
    former.tir = BelcourTir::TopInterface;
    const BelcourStats old = belcour_adding(ops, c0, former);
    EXPECT_GT(std::abs(old.lobes[1].energy[0] / E1 - 1), 0.01);
    EXPECT_GT(std::abs(old.lobes[2].energy[0] / E2[0] - 1), 0.01);
}

// Two interfaces (a rough coat η 1.5, α0 0.2, over gold α 0.3), the two placements by hand at c0 =
// 0.6. Top: R1 = FGD(c0, α0, 1.5), T1 = 1 − R1, c1 = Snell(c0, 1.5), after it Ri0 = R1, Ti0 = T1,
// σT0i = σ(α0 ½ |1.5 − 1|/1.5) (rr = 0). Base: α_eff = α(σT0i + σ(αb)), R3 = FGD(c1, α_eff, gold),
// lobe 1 = T1 R3 Ti0 / (1 − Ri0 R3) after the step:
// - each-interface (the author's): τ = τ_TIR(c1, α_eff, 1/1.5), at the base's α_eff;
// - top-interface (lamina's former): τ = τ_TIR(c1, α0, 1/1.5), at the top's own roughness,
// each with the three tables; tir=off: no step.
TEST(Bel18Golden, TwoInterfaceTirPlacementsByHand) {
    const double c0 = 0.6, a0 = 0.2, ab = 0.3;
    const Rgbd geta(0.18, 0.42, 1.37), gk(3.4, 2.35, 1.85);
    const std::vector<BelcourOperator> ops = {dielectric_op(1.5, a0),
                                              conductor_op(geta / 1.5, gk / 1.5, ab)};
    const double R1 = FgdTable::get()(c0, a0, 1.5, 0.0), T1 = 1 - R1, c1 = snell(c0, 1.5);
    const double sT0i = sigma_of(a0 * 0.5 * 0.5 / 1.5);
    const double ae = alpha_of(sT0i + sigma_of(ab));
    const Rgbd R3 = fgd_rgb(c1, ae, geta / 1.5, gk / 1.5);
    auto lobe1 = [&](double tau) {
        const double Ri0 = R1 + (1 - tau) * T1, Ti0 = tau * T1;
        return Rgbd(T1 * Ti0) * R3 / (Rgbd(1.0) - R3 * Ri0);
    };
    for (TirDefinition def :
         {TirDefinition::LobeFresnel, TirDefinition::Lobe, TirDefinition::Microfacet}) {
        BelcourChoices each, top, off;
        each.tir_table = top.tir_table = def;
        top.tir = BelcourTir::TopInterface;
        off.tir = BelcourTir::Off;
        const Rgbd want_each = lobe1(tir_fraction(def, c1, ae, 1 / 1.5));
        const Rgbd want_top = lobe1(tir_fraction(def, c1, a0, 1 / 1.5));
        const Rgbd want_off = lobe1(1.0);
        const BelcourStats se = belcour_adding(ops, c0, each), sp = belcour_adding(ops, c0, top),
                           so = belcour_adding(ops, c0, off);
        for (int k = 0; k < 3; ++k) {
            EXPECT_NEAR(se.lobes[1].energy[k], want_each[k], 1e-12) << enum_text(def);
            EXPECT_NEAR(sp.lobes[1].energy[k], want_top[k], 1e-12) << enum_text(def);
            EXPECT_NEAR(so.lobes[1].energy[k], want_off[k], 1e-12);
        }
    }
}

// What the author's table holds, on a smooth slab (η 1.5 over η 1.2, no absorption): the step at
// the bottom interface multiplies the upward transmission T1 = 1 − R1 by τ = 1 − F(μ1; 1/1.5) —
// which is 1 − R1 again (Fresnel is the same from both sides of a smooth interface) — so that Ri0 =
// R1 + R1 T1, Ti0 = T1², and the slab transmits T0i = T1 T2 / (1 − Ri0 R2) instead of the exact
// T1 T2 / (1 − R1 R2) (BelPrimeGolden.SmoothSlabTransmitsTheIncoherentTwoInterfaceSum); its second
// reflection lobe is T1 R2 T1² / (1 − Ri0 R2). R1 = F(μi; 1.5), R2 = F(μ1; 1.2/1.5). The step
// conserves energy (it moves Ti0 to Ri0): the light it keeps inside goes down again, so the slab
// transmits more and reflects less than the exact sum.
TEST(Bel18, AuthorsTirTableCountsTheTopFresnelTwice) {
    const double eta1 = 1.5, eta2 = 1.2;
    const auto model = make_model("bel-prime", coated(eta1, 0.0, test::dielectric(eta2, 0.0)));
    for (double ti : {0.0, 30.0, 70.0}) {
        const Vec3d wi = dir(ti, 0);
        const double mu1 = snell(wi.z, eta1);
        const double R1 = fresnel_dielectric(wi.z, eta1), T1 = 1 - R1;
        EXPECT_NEAR(fresnel_dielectric(mu1, 1 / eta1), R1, 1e-14);
        const double R2 = fresnel_dielectric(mu1, eta2 / eta1), T2 = 1 - R2;
        const double Ri0 = R1 + R1 * T1;
        const double T = T1 * T2 / (1 - Ri0 * R2), E1 = T1 * R2 * T1 * T1 / (1 - Ri0 * R2);
        double got_t = 0, got_r = 0;
        for (const DeltaLobe& d : model->delta_lobes(wi))
            (d.direction.z < 0 ? got_t : got_r) += d.energy[0];
        EXPECT_NEAR(got_t, T, 1e-12) << ti;
        EXPECT_NEAR(got_r, R1 + E1, 1e-12) << ti;
        EXPECT_GT(got_t - T1 * T2 / (1 - R1 * R2), 1e-4);  // the exact sum
        EXPECT_NEAR(got_t + got_r, 1.0, 1e-12);
    }
}

// Absorbing coats: in the author's code a medium is a layer entry that carries the coat's index,
// so the interface below it sees the relative index 1 and no step — the default (tir-media=skip)
// is then tir=off exactly; tir-media=cross keeps the step across the medium (lamina's former
// reading, here more than 1 % at θi 75°). Without the medium the step acts: more than 10 % on the
// base lobe off the specular direction (θo 0° and 30°).
TEST(Bel18, AbsorbingCoatHasNoTirStepByDefault) {
    const Stack s = coated(1.5, 0.05, test::gold(0.3), Rgbd(0.2, 0.1, 0.05));
    for (const char* name : {"bel18-forward", "bel18-symmetric", "bel-prime"}) {
        const auto def = make_model(name, s);
        const auto off = make_model(name, s, {"tir=off"});
        const auto cross = make_model(name, s, {"tir-media=cross"});
        const Vec3d wi = dir(75, 0);
        double max_diff = 0;
        for (double to : {10.0, 45.0, 75.0})
            for (double po : {0.0, 90.0, 180.0}) {
                const Vec3d wo = dir(to, po);
                const Rgbd a = def->eval(wi, wo), b = off->eval(wi, wo), c = cross->eval(wi, wo);
                for (int k = 0; k < 3; ++k) {
                    EXPECT_EQ(a[k], b[k]) << name;
                    max_diff = std::max(max_diff, std::abs(c[k] / a[k] - 1));
                }
            }
        EXPECT_GT(max_diff, 0.01) << name;
    }
    // Without the medium the step acts (the same coat, τa = 0: no medium operator).
    const Stack clear = coated(1.5, 0.05, test::gold(0.3));
    const Vec3d wi = dir(75, 0);
    for (double to : {0.0, 30.0}) {
        const Vec3d wo = dir(to, 180);
        EXPECT_GT(std::abs(make_model("bel18-forward", clear)->eval(wi, wo)[0] /
                               make_model("bel18-forward", clear, {"tir=off"})->eval(wi, wo)[0] -
                           1),
                  0.1);
    }
}

// medium-variance=every-medium gives an absorbing medium the variance σ_HG(g) of its stack's g,
// which the default gives only to a medium that scatters: the absorbing coat with every-medium
// equals (to rounding) the same coat scattering a negligible τs = 1e-12 by default, and widens the
// base lobe; at g = 0 the variance is that of the roughest lobe (σ_HG(0) is infinite).
TEST(Bel18, MediumVarianceOption) {
    const Rgbd tau(0.3);
    const Stack absorbing = coated(1.5, 0.1, test::gold(0.2), tau, Rgbd(0.0), 0.6);
    const Stack barely = coated(1.5, 0.1, test::gold(0.2), tau, Rgbd(1e-12), 0.6);
    const auto every = make_model("bel18-forward", absorbing, {"medium-variance=every-medium"});
    const auto scattering = make_model("bel18-forward", barely);
    const auto plain = make_model("bel18-forward", absorbing);
    const Vec3d wi = dir(30, 0);
    for (double to : {0.0, 30.0, 60.0}) {
        const Vec3d wo = dir(to, 180);
        EXPECT_NEAR(every->eval(wi, wo)[0], scattering->eval(wi, wo)[0],
                    1e-9 * scattering->eval(wi, wo)[0]);
    }
    // Wider: the base lobe's peak is lower.
    const Vec3d peak = dir(30, 180);
    EXPECT_LT(every->eval(wi, peak)[1], 0.9 * plain->eval(wi, peak)[1]);
    const Stack g0 = coated(1.5, 0.1, test::gold(0.2), tau);
    const auto capped = make_model("bel18-forward", g0, {"medium-variance=every-medium"});
    const Rgbd f = capped->eval(wi, peak);
    EXPECT_TRUE(std::isfinite(f[0]) && f[0] > 0);
}

}  // namespace
}  // namespace lamina

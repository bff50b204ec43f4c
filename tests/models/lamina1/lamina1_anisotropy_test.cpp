// lamina-1 with anisotropic interfaces (docs/models.md, "lamina-1", "Anisotropic coats and
// bases"): the general code path at α_x = α_y is the isotropic model, the BRDF stays reciprocal
// and its albedo within the isotropic model's budget, and what it does not represent (an
// anisotropic slab, the GLSL form) is refused with the reason. The generic checks every model
// that represents anisotropy passes (tangent turns, α_x ↔ α_y, sampling) are in
// tests/models/anisotropy_test.cpp.
#include "core/math.h"
#include "core/rng.h"
#include "lamina1/lamina1.h"
#include "models/lamina1/lamina1.h"
#include "models/numerics/binned.h"
#include "models/registry.h"
#include "models/test_stacks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace lamina {
namespace {

using test::brushed;
using test::coated;
using test::dir;

double relative(double a, double b) {
    const double scale = std::max(std::abs(a), std::abs(b));
    return scale > 0 ? std::abs(a - b) / scale : 0.0;
}
double relative(const lamina1::Rgb& a, const lamina1::Rgb& b) {
    double worst = 0;
    for (int c = 0; c < 3; ++c)
        worst = std::max(worst, relative(a[c], b[c]));
    return worst;
}

// The anisotropic code path (every α_y given: the slope covariances, the anisotropic GGX of the
// coat and of the widened base lobe, the lobe's density stretched by Σ^{1/2}) at α_y = α_x, with
// tangents turned, is the isotropic model: eval, pdf and the drawn samples within 1e-12 relative
// (rounding: the covariance α²(cos²ψ + sin²ψ) I and its square root are α² I and α I to a few
// ulps), for the lobe shapes and spreads. Single scattering on both sides: the default (auto)
// restores the orders ≥ 2 of isotropic interfaces only, and multiple refuses anisotropic ones.
TEST(Lamina1Anisotropy, EqualRoughnessesAreTheIsotropicModel) {
    using Options = lamina1::Options;
    Options single;
    single.microsurface = Options::Microsurface::Single;
    std::vector<std::pair<std::string, Options>> choices;
    choices.push_back({"defaults", single});
    Options o = single;
    o.first_order_lobe = Options::FirstOrderLobe::Sum;
    choices.push_back({"sum", o});
    o.first_order_lobe = Options::FirstOrderLobe::Ggx;
    choices.push_back({"ggx", o});
    o = single;
    o.spread = Options::Spread::Normal;
    choices.push_back({"spread normal", o});
    o.spread = Options::Spread::Off;
    choices.push_back({"spread off", o});
    o = single;
    o.masking = lamina1::Masking::Walter;
    choices.push_back({"walter", o});
    const std::vector<std::pair<std::string, Stack>> stacks = {
        {"paint", coated(1.5, 0.1, test::gold(0.3), Rgbd(0.1, 0.2, 0.3))},
        {"frosted", coated(1.5, 0.4, test::gold(0.05))},
        {"plastic", coated(1.3, 0.2, test::lambertian(Rgbd(0.8, 0.5, 0.2)))},
        {"smooth metal", coated(2.0, 0.3, test::conductor(Rgbd(0.2), Rgbd(3.0), 0.0))}};
    ParticleRng rng(11, 0, 0);
    for (const auto& [cname, choice] : choices)
        for (const auto& [sname, stack] : stacks) {
            lamina1::Layers iso;
            std::string why;
            ASSERT_TRUE(lamina1_layers(stack, iso, why)) << why;
            lamina1::Layers aniso = iso;
            aniso.alpha0_y = iso.alpha0;
            aniso.tangent0 = 0.7;
            if (iso.alpha1 > 0) {
                aniso.alpha1_y = iso.alpha1;
                aniso.tangent1 = -2.1;
            }
            const lamina1::Tables& tables = lamina1_tables(choice.masking, false);
            const lamina1::Bsdf a(iso, tables, choice), b(aniso, tables, choice);
            ASSERT_TRUE(b.support().brdf) << b.support().reason;
            double worst_f = 0, worst_pdf = 0, worst_sample = 0;
            for (int n = 0; n < 400; ++n) {
                const Vec3d wi = dir(88 * rng.uniform_double(), 360 * rng.uniform_double());
                const Vec3d wo = dir(88 * rng.uniform_double(), 360 * rng.uniform_double());
                const lamina1::Vec3 i{wi.x, wi.y, wi.z}, w{wo.x, wo.y, wo.z};
                worst_f = std::max(worst_f, relative(a.eval(i, w), b.eval(i, w)));
                worst_pdf = std::max(worst_pdf, relative(a.pdf(i, w), b.pdf(i, w)));
                const lamina1::Vec3 u{rng.uniform_double(), rng.uniform_double(),
                                      rng.uniform_double()};
                const auto sa = a.sample(i, u), sb = b.sample(i, u);
                ASSERT_EQ(bool(sa), bool(sb)) << cname << " " << sname;
                if (sa)
                    worst_sample =
                        std::max({worst_sample, std::abs(sa->wo.x - sb->wo.x),
                                  std::abs(sa->wo.y - sb->wo.y), std::abs(sa->wo.z - sb->wo.z),
                                  relative(sa->pdf, sb->pdf), relative(sa->weight, sb->weight)});
            }
            EXPECT_LE(worst_f, 1e-12) << cname << " " << sname;
            EXPECT_LE(worst_pdf, 1e-12) << cname << " " << sname;
            EXPECT_LE(worst_sample, 1e-12) << cname << " " << sname;
        }
}

// Reciprocal with anisotropic interfaces: the coat's anisotropic D and Λ are symmetric in
// (wi, wo), and so is the widened lobe's covariance Σ1 + (k_i² + k_o²)/4 Σ0 and its density;
// the prepared evaluation is eval.
// Energy: nothing absorbs in the near-perfect mirror's stacks, so the albedo over the whole
// azimuth stays within the isotropic model's budget (the quadrature's 1e-3 and the FGD table's
// 6.3e-3; Lamina1.AlbedoAtMostOne), lit along, across and between the tangents.
TEST(Lamina1Anisotropy, ReciprocalAndAlbedoAtMostOne) {
    BinnedOptions o;
    o.rel_tol = 1e-3;
    o.full_azimuth = true;
    auto mirror = [](double eta0, double c_x, double c_y, double psi0, double b_x, double b_y,
                     double psi1) {
        Stack s = coated(eta0, c_x, test::conductor(Rgbd(0.05), Rgbd(8.0), b_x));
        if (c_y != c_x) s.layers[0].interface = anisotropic(s.layers[0].interface, c_x, c_y, psi0);
        if (b_y != b_x) s.layers[1].interface = anisotropic(s.layers[1].interface, b_x, b_y, psi1);
        return s;
    };
    const std::vector<std::pair<std::string, Stack>> stacks = {
        {"brushed coat, brushed metal", brushed(0.3, 0.05, 30, 0.4, 0.02, -45)},
        {"clear coat, brushed metal", brushed(0.05, 0.05, 0, 0.6, 0.1, 90)},
        {"brushed coat, white",
         [] {
             Stack s = coated(1.5, 0.2, test::lambertian(Rgbd(1.0)));
             s.layers[0].interface = anisotropic(s.layers[0].interface, 0.2, 0.02, 60);
             return s;
         }()},
        {"mirror 1.2", mirror(1.2, 0.7, 0.1, 20, 0.3, 0.05, 110)},
        {"mirror 1.5", mirror(1.5, 0.05, 0.4, 0, 0.4, 0.05, 0)},
        {"mirror 2", mirror(2.0, 0.3, 0.05, 45, 0.05, 0.3, 45)},
    };
    double worst = 0;
    for (const auto& [what, stack] : stacks) {
        const auto model = make_model("lamina-1", stack);
        ASSERT_TRUE(model->support().brdf) << what << ": " << model->support().reason;
        for (double ti : {10.0, 45.0, 80.0})
            for (double pi : {0.0, 75.0, 150.0}) {
                const Vec3d wi = dir(ti, pi);
                const auto prepared = model->prepare(wi);
                for (double to : {20.0, 55.0, 80.0})
                    for (double po : {30.0, 150.0, 260.0}) {
                        const Vec3d wo = dir(to, po);
                        const Rgbd fab = model->eval(wi, wo), fba = model->eval(wo, wi);
                        const Rgbd prepared_ab = prepared->eval(wo);
                        for (int c = 0; c < 3; ++c) {
                            EXPECT_NEAR(fab[c], fba[c], 1e-12 * std::max(fab[c], 1.0)) << what;
                            EXPECT_EQ(fab[c], prepared_ab[c]) << what;
                        }
                    }
                const double a = model_albedo(*model, wi, Side::Reflection, o).max();
                worst = std::max(worst, a);
                EXPECT_LE(a, 1.0 + 1e-3 + 6.3e-3) << what << " ti=" << ti << " phi=" << pi;
            }
    }
    std::printf("lamina-1 on brushed stacks: largest albedo %.4f\n", worst);
}

// Extreme anisotropic materials (α 1e-4 against 1, index-matched and dense coats, smooth and
// rough bases, a Lambertian) at extreme directions (normal, 1e-4 from grazing): eval, pdf and
// the drawn samples are finite and non-negative — the covariances' determinants, near 1e-8 of
// their entries' squares here, and the widened lobe's zero covariance under an index-matched
// coat over a smooth base, never give NaN.
TEST(Lamina1Anisotropy, ExtremeMaterialsStayFinite) {
    ParticleRng rng(13, 0, 0);
    int drawn = 0;
    for (double eta0 : {1.0, 1.0001, 1.5, 10.0})
        for (const auto& [c_x, c_y] : {std::pair{1e-4, 1.0}, std::pair{1.0, 1e-3}})
            for (int base = 0; base < 4; ++base) {
                lamina1::Layers l;
                l.eta0 = eta0;
                l.alpha0 = c_x;
                l.alpha0_y = c_y;
                l.tangent0 = 6.3 * rng.uniform_double();
                l.tau_a = lamina1::Rgb(0.1, 0.0, 2.0);
                l.base = base == 0 ? lamina1::Base::Lambertian : lamina1::Base::Conductor;
                l.albedo = lamina1::Rgb(0.9);
                l.base_eta = lamina1::Rgb(0.2, 0.5, 1.4);
                l.base_k = lamina1::Rgb(3.4, 2.4, 1.8);
                l.alpha1 = base == 1 ? 0.0 : base == 2 ? 1.0 : 1e-4;
                if (base >= 2) {
                    l.alpha1_y = base == 2 ? 1e-4 : 1.0;
                    l.tangent1 = 6.3 * rng.uniform_double();
                }
                const lamina1::Bsdf bsdf(l, lamina1_tables(lamina1::Masking::Smith, false));
                ASSERT_TRUE(bsdf.support().brdf) << bsdf.support().reason;
                for (int n = 0; n < 200; ++n) {
                    auto direction = [&](int k) {
                        const double theta = k % 3 == 0   ? 0.0
                                             : k % 3 == 1 ? 89.99
                                                          : 89.9 * rng.uniform_double();
                        const Vec3d w = dir(theta, 360 * rng.uniform_double());
                        return lamina1::Vec3{w.x, w.y, w.z};
                    };
                    const lamina1::Vec3 wi = direction(n), wo = direction(n / 3);
                    const lamina1::Rgb f = bsdf.eval(wi, wo);
                    const double pdf = bsdf.pdf(wi, wo);
                    for (int c = 0; c < 3; ++c)
                        ASSERT_TRUE(std::isfinite(f[c]) && f[c] >= 0) << eta0 << " " << base;
                    ASSERT_TRUE(std::isfinite(pdf) && pdf >= 0) << eta0 << " " << base;
                    const auto s = bsdf.sample(
                        wi, {rng.uniform_double(), rng.uniform_double(), rng.uniform_double()});
                    if (!s) continue;
                    ++drawn;
                    ASSERT_TRUE(std::isfinite(s->pdf) && s->pdf > 0);
                    for (int c = 0; c < 3; ++c)
                        ASSERT_TRUE(std::isfinite(s->weight[c]) && s->weight[c] >= 0);
                    ASSERT_TRUE(std::isfinite(s->wo.x + s->wo.y + s->wo.z));
                }
            }
    EXPECT_GT(drawn, 2000);
}

// What lamina-1 does not represent is refused with the reason: an anisotropic slab (its
// transmission lobes are isotropic), the multiple-scattering orders of an anisotropic interface
// (isotropic energies: at the rms roughness they restore what an isotropic interface loses, far
// more than an anisotropic one loses along its smooth axis), an anisotropic interface without
// both roughnesses, and the GLSL form of an anisotropic material.
TEST(Lamina1Anisotropy, RefusesWhatItDoesNotRepresent) {
    Stack slab = coated(1.5, 0.2, test::dielectric(1.0, 0.3));
    slab.layers[0].interface = anisotropic(slab.layers[0].interface, 0.2, 0.05, 0);
    const auto m = make_model("lamina-1", slab);
    EXPECT_FALSE(m->support().brdf);
    EXPECT_NE(m->support().reason.find("anisotropic"), std::string::npos) << m->support().reason;
    const auto multiple =
        make_model("lamina-1", brushed(0.3, 0.05, 30, 0.4, 0.02, -45), {"microsurface=multiple"});
    EXPECT_FALSE(multiple->support().brdf);
    EXPECT_NE(multiple->support().reason.find("microsurface=multiple"), std::string::npos);

    lamina1::Layers layers;
    layers.alpha0 = 0.0;
    layers.alpha0_y = 0.2;
    const lamina1::Bsdf smooth_x(layers, lamina1_tables(lamina1::Masking::Smith, false));
    EXPECT_FALSE(smooth_x.support().brdf);
    EXPECT_NE(smooth_x.support().reason.find("both roughnesses"), std::string::npos);

    std::string why;
    EXPECT_TRUE(lamina1_gpu_state(brushed(0.3, 0.05, 30, 0.4, 0.02, -45), {}, why).empty());
    EXPECT_NE(why.find("anisotropic"), std::string::npos) << why;
    EXPECT_FALSE(lamina1_gpu_state(brushed(0.3, 0.3, 0, 0.4, 0.4, 0), {}, why).empty()) << why;
}

}  // namespace
}  // namespace lamina

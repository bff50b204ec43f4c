// Sphere renderings (render/renderer.h): the proofs of the renderer — white furnace, black stack,
// WW' equal to the reference where it is exact, identical images across thread counts — and the
// image files.
#include "render/renderer.h"

#include "core/math.h"

#include "models/random_walk/random_walk_model.h"
#include "models/registry.h"
#include "render/contact_sheet.h"
#include "render/image.h"
#include "support/stacks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

namespace lamina {
namespace {

/// The mean of the green channel over the pixels entirely on the sphere, and its standard error
/// (pixels as independent samples).
std::pair<double, double> sphere_mean(const Rendering& r) {
    double sum = 0, sum_sq = 0;
    int n = 0;
    for (std::size_t i = 0; i < r.mask.size(); ++i)
        if (r.mask[i]) {
            const double v = r.image.pixels[i][1];
            sum += v;
            sum_sq += v * v;
            ++n;
        }
    const double mean = sum / n;
    return {mean, std::sqrt((sum_sq / n - mean * mean) / (n - 1))};
}

RenderSettings small(int size, int spp, int threads = 0) {
    RenderSettings s;
    s.size = size;
    s.spp = spp;
    s.threads = threads;
    s.progress = false;
    return s;
}

// A clear coat of index 1.5 and roughness alpha over a grey Lambertian of albedo rho.
Stack clear_coat_over_lambertian(double alpha, double rho) {
    return test::make_stack({test::with_medium(test::dielectric_layer(1.5, alpha), Rgbd(0.0)),
                             test::lambertian_layer(Rgbd(rho))});
}

// A white Lambertian under a uniform white environment: L = ∫ (1/π) · 1 · cos dω = 1. With the
// random walk both strategies are exact here (its connection is ρ/π and its sample weight ρ; the
// MIS weights p/(p + q) and q/(p + q) are ½ each), so every pixel is 1 to rounding.
TEST(Render, WhiteFurnaceLambertianIsOne) {
    const Stack white = test::make_stack({test::lambertian_layer(Rgbd(1.0))});
    const auto rw = make_model("random-walk", white);
    const Rendering r = render_sphere(*rw, Environment::named("uniform"), small(24, 4));
    int n = 0;
    for (std::size_t i = 0; i < r.mask.size(); ++i)
        if (r.mask[i]) {
            ++n;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(r.image.pixels[i][c], 1.0, 1e-5);
        }
    EXPECT_GT(n, 200);
}

// A smooth coat (τ = 0) over a white Lambertian has albedo exactly 1 (docs/physics.md §6.3), so
// under the uniform environment it renders 1 within noise: the sphere's mean over n pixels has
// standard error σ/√n, estimated from the pixels themselves.
TEST(RenderStat, WhiteFurnaceSmoothCoatOverWhiteIsOne) {
    const Stack coated = clear_coat_over_lambertian(0.0, 1.0);
    const auto rw = make_model("random-walk", coated);
    const Rendering r = render_sphere(*rw, Environment::named("uniform"), small(32, 16));
    const auto [mean, se] = sphere_mean(r);
    EXPECT_LT(std::abs(mean - 1), 5 * se) << mean << " ± " << se;
    EXPECT_LT(se, 0.02);
}

TEST(Render, BlackStackRendersBlack) {
    const Stack black = test::make_stack({test::lambertian_layer(Rgbd(0.0))});
    const auto rw = make_model("random-walk", black);
    RenderSettings s = small(16, 2);
    const Rendering r = render_sphere(*rw, Environment::named("studio"), s);
    for (std::size_t i = 0; i < r.mask.size(); ++i)
        if (r.mask[i]) {
            EXPECT_EQ(r.image.pixels[i], Rgbf(0.f));
        }
}

// WW' is exact for a smooth coat over a black base (only the top's mirror reflection F(μ)
// remains): its rendering equals the reference's within noise (here both are exact: the
// reference's delta lobe is the ladder's F, and its walks below the coat die on the black base).
TEST(Render, WWPrimeMatchesTheReferenceWhereItIsExact) {
    const Stack s = clear_coat_over_lambertian(0.0, 0.0);
    const auto ref = make_model("random-walk", s);
    const auto ww = make_model("ww-prime", s);
    ASSERT_TRUE(ww->support().brdf);
    const Environment env = Environment::named("studio");
    const Rendering a = render_sphere(*ref, env, small(32, 8));
    const Rendering b = render_sphere(*ww, env, small(32, 8));
    EXPECT_LT(relative_rmse(b.image, a.image, a.mask), 1e-5);
    double total = 0;
    for (const Rgbf& p : a.image.pixels)
        total += p[0];
    EXPECT_GT(total, 0);
}

// A rough coat (α = 0.3) over a black base: WW' is exactly the Walter et al. 2007 top reflection
// (its base term vanishes with ρ = 0), and so is the stack — light refracted into the coat is
// absorbed by the base. The random walk estimates it by its own connections, with noise; the two
// renderings (independent seeds) must agree within that noise. Over the sphere's pixel-channels,
// with x = rw − ww, a = rw − rw', b = ww − ww' (four independent seeds), an unbiased pair has
// E[Σx²] = σ_rw² + σ_ww² summed = E[Σa² + Σb²]/2; a bias β per pixel adds Σβ². The statistic
// D = Σx² − (Σa² + Σb²)/2 has variance ≈ Σx⁴ + (Σa⁴ + Σb⁴)/4 (Var y² ≤ E y⁴, conservative):
// |D| must stay below 4 of its standard deviations.
TEST(RenderStat, WWPrimeMatchesTheRandomWalkOnARoughCoatOverBlack) {
    const Stack s = clear_coat_over_lambertian(0.3, 0.0);
    const auto rw = make_model("random-walk", s);
    const auto ww = make_model("ww-prime", s);
    const Environment env = Environment::named("studio");
    auto render = [&](const Model& m, std::uint64_t seed) {
        RenderSettings rs = small(32, 128);
        rs.seed = seed;
        rs.lobe_alpha = 0.3;
        return render_sphere(m, env, rs);
    };
    const Rendering rw1 = render(*rw, 1), rw2 = render(*rw, 2);
    const Rendering ww1 = render(*ww, 3), ww2 = render(*ww, 4);
    double x2 = 0, a2 = 0, b2 = 0, x4 = 0, a4 = 0, b4 = 0, signal = 0;
    int n = 0;
    for (std::size_t i = 0; i < rw1.mask.size(); ++i) {
        if (!rw1.mask[i]) continue;
        for (int c = 0; c < 3; ++c) {
            const double x = rw1.image.pixels[i][c] - ww1.image.pixels[i][c];
            const double a = rw1.image.pixels[i][c] - rw2.image.pixels[i][c];
            const double b = ww1.image.pixels[i][c] - ww2.image.pixels[i][c];
            x2 += x * x;
            a2 += a * a;
            b2 += b * b;
            x4 += sqr(x * x);
            a4 += sqr(a * a);
            b4 += sqr(b * b);
            signal += rw1.image.pixels[i][c];
            ++n;
        }
    }
    ASSERT_GT(n, 100);
    ASSERT_GT(signal, 0);
    const double d = x2 - (a2 + b2) / 2;
    const double sd = std::sqrt(x4 + (a4 + b4) / 4);
    EXPECT_LT(std::abs(d), 4 * sd) << "Σx² " << x2 << ", noise " << (a2 + b2) / 2 << ", sd " << sd;
}

// ---- Transparent spheres (docs/rendering.md §2.1) -----------------------------------------------
// A clear slab — smooth index-matched interfaces (η = 1 on both sides) and no medium — bends and
// reflects nothing: every walk goes straight through the near side and the far side with weight
// 1, so each pixel on the sphere is exactly the environment behind it along the view ray, −z.
TEST(Render, ClearSphereShowsTheEnvironmentBehindIt) {
    const Stack clear =
        test::make_stack({test::dielectric_layer(1.0, 0.0), test::dielectric_layer(1.0, 0.0)});
    const auto rw = make_model("random-walk", clear);
    const Environment env = Environment::named("studio");
    const Rgbd behind = env.radiance(Vec3d(0, 0, -1));
    ASSERT_GT(behind.max(), 0);
    const Rendering r = render_sphere(*rw, env, small(24, 4));
    int n = 0;
    for (std::size_t i = 0; i < r.mask.size(); ++i)
        if (r.mask[i]) {
            ++n;
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(r.image.pixels[i][c], behind[c], 1e-5 * behind[c]) << "pixel " << i;
        }
    EXPECT_GT(n, 200);
}

// Non-absorbing slabs under the uniform white environment: nothing is absorbed or lost (smooth
// interfaces, no absorption, scattering with albedo 1), so every ray that reaches the sphere
// leaves it, reflected or transmitted, and the sphere renders 1 within noise — only if the
// transmitted light is followed through the sphere (a BRDF-only rendering shows R < 1). A glass
// shell (η = 1 inside) and a coated scattering ball of index 1.33 inside (the radiance inside is
// η² times the outside's: the reciprocity factors (η_out/η_in)² and back must both be right for
// the sun term, and here cancel). Mean over the sphere's pixels with its standard error.
TEST(RenderStat, WhiteFurnaceNonAbsorbingSlabsAreOne) {
    const std::vector<Stack> stacks = {
        test::make_stack({test::dielectric_layer(1.5, 0.0), test::dielectric_layer(1.0, 0.0)}),
        test::make_stack(
            {test::with_medium(test::dielectric_layer(1.5, 0.0), Rgbd(0.0), Rgbd(1.0), Rgbd(0.5)),
             test::dielectric_layer(1.33, 0.0)})};
    for (const Stack& stack : stacks) {
        const auto rw = make_model("random-walk", stack);
        for (bool transparent : {true, false}) {
            RenderSettings rs = small(32, 16);
            rs.transparent = transparent;
            const Rendering r = render_sphere(*rw, Environment::named("uniform"), rs);
            const auto [mean, se] = sphere_mean(r);
            if (transparent) {
                EXPECT_LT(std::abs(mean - 1), 5 * se) << stack.name << ": " << mean << " ± " << se;
                EXPECT_LT(se, 0.02);
            } else {
                EXPECT_GT(1 - mean, 5 * se) << "BRDF only: " << mean << " ± " << se;
            }
        }
    }
}

// Multiple scattering on the microsurfaces (docs/rendering.md §1.6): a rough coat (τ = 0) over a
// white Lambertian and a transparent non-absorbing rough slab lose nothing, so under the uniform
// environment they render 1 within noise; with single scattering the same spheres are darker by
// far more than their standard error (the energy the microsurfaces lose). Every pixel is finite.
TEST(RenderStat, WhiteFurnaceRoughStacksAreOneWithMultipleScattering) {
    const std::vector<Stack> stacks = {
        clear_coat_over_lambertian(0.5, 1.0),
        test::make_stack({test::with_medium(test::dielectric_layer(1.5, 0.4), Rgbd(0.0)),
                          test::dielectric_layer(1.0, 0.6)})};
    for (const Stack& stack : stacks)
        for (const char* microsurface : {"multiple", "single"}) {
            const auto rw =
                make_model("random-walk", stack, {std::string("microsurface=") + microsurface});
            RenderSettings rs = small(32, 16);
            rs.transparent = stack.transmits();
            const Rendering r = render_sphere(*rw, Environment::named("uniform"), rs);
            for (std::size_t i = 0; i < r.mask.size(); ++i)
                for (int c = 0; c < 3; ++c)
                    ASSERT_TRUE(!r.mask[i] || std::isfinite(r.image.pixels[i][c]));
            const auto [mean, se] = sphere_mean(r);
            if (std::string(microsurface) == "multiple") {
                EXPECT_LT(std::abs(mean - 1), 5 * se)
                    << stack.layers.size() << ": " << mean << " ± " << se;
                EXPECT_LT(se, 0.02);
            } else {
                EXPECT_GT(1 - mean, 5 * se) << "single: " << mean << " ± " << se;
            }
        }
}

TEST(Render, BrushedFrameFollowsTheCirclesOfLatitude) {
    // The brushed shading frame: orthonormal and right-handed about n, its tangent horizontal
    // (along the circle of latitude about y, so the field is smooth over the sphere: nearby
    // normals, nearby tangents), the branchless frame at the poles and without brushing.
    for (double theta = 0.05; theta < 3.1; theta += 0.3)
        for (double phi = 0; phi < 6.28; phi += 0.4) {
            // n over the sphere with the pole on y.
            const Vec3d n(std::sin(theta) * std::cos(phi), std::cos(theta),
                          std::sin(theta) * std::sin(phi));
            const Frame<double> f = shading_frame(n, true);
            EXPECT_NEAR(dot(f.s, f.s), 1, 1e-12);
            EXPECT_NEAR(dot(f.t, f.t), 1, 1e-12);
            EXPECT_NEAR(dot(f.s, n), 0, 1e-12);
            EXPECT_NEAR(dot(f.t, n), 0, 1e-12);
            EXPECT_NEAR(dot(f.s, f.t), 0, 1e-12);
            EXPECT_NEAR(length(cross(f.s, f.t) - n), 0, 1e-12);  // right-handed
            EXPECT_NEAR(f.s.y, 0, 1e-15);                        // along the latitude
            const Vec3d n2(std::sin(theta) * std::cos(phi + 1e-4), std::cos(theta),
                           std::sin(theta) * std::sin(phi + 1e-4));
            EXPECT_LT(length(shading_frame(n2, true).s - f.s), 2e-4);
        }
    const Vec3d pole(0, 1, 0), n(0.6, 0, 0.8);
    EXPECT_EQ(shading_frame(pole, true).s, Frame<double>::from_normal(pole).s);
    EXPECT_EQ(shading_frame(n, false).s, Frame<double>::from_normal(n).s);
    EXPECT_TRUE(brushed_for(test::make_stack(
        {layer_of(anisotropic(conductor_interface(Rgbd(0.2), Rgbd(3.0), 0.1), 0.1, 0.4, 0))})));
    EXPECT_FALSE(brushed_for(test::make_stack({test::dielectric_layer(1.5, 0.1)})));
}

TEST(Render, BrushedHighlightRunsAcrossTheBrushing) {
    // A lacquered metal brushed along the latitudes (tangent 0°: smooth along the circles about
    // the vertical axis, rough across them), lit by one light placed so that the highlight sits
    // up and right of the centre (normal (0.4, 0.4, 1)/|·|): the highlight is stretched across the
    // brushing, about vertically; brushed along the meridians (90°), about horizontally. The spread
    // of the highlight, as the brightness-weighted variance of the pixel coordinates over the
    // pixels above a tenth of the peak, says which.
    const auto spread = [](double tangent_deg) {
        Layer coat = with_medium(test::dielectric_layer(1.5, 0.02), Rgbd(0.02));
        const Layer metal = layer_of(
            anisotropic(conductor_interface(Rgbd(1.66, 0.88, 0.52), Rgbd(9.2, 6.3, 4.8), 0.05),
                        0.05, 0.4, tangent_deg));
        const Stack stack = test::make_stack({coat, metal});
        EXPECT_TRUE(brushed_for(stack));
        const auto model = make_model("openpbr-adobe", stack);
        EXPECT_TRUE(model->support().brdf) << model->support().reason;
        RenderSettings s = small(48, 4);
        s.brushed = true;
        s.lobe_alpha = lobe_alpha_for(stack);
        Environment env = Environment::named("dark");
        const Vec3d n = normalize(Vec3d(0.4, 0.4, 1)), view(0, 0, 1);
        env.sun = DirectionalLight{n * (2 * dot(n, view)) - view, Rgbd(1.0)};
        const Rendering r = render_sphere(*model, env, s);
        double peak = 0;
        for (const Rgbf& p : r.image.pixels)
            peak = std::max(peak, double(p[1]));
        double w = 0, mx = 0, my = 0, mxx = 0, myy = 0;
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                const double v = r.image.at(x, y)[1];
                if (v < 0.1 * peak) continue;
                w += v, mx += v * x, my += v * y, mxx += v * x * x, myy += v * y * y;
            }
        mx /= w, my /= w;
        return std::pair{mxx / w - mx * mx, myy / w - my * my};
    };
    const auto [x0, y0] = spread(0);
    EXPECT_GT(y0, 3 * x0) << "brushed along the latitudes: var x " << x0 << ", var y " << y0;
    const auto [x90, y90] = spread(90);
    EXPECT_GT(x90, 3 * y90) << "brushed along the meridians: var x " << x90 << ", var y " << y90;
}

TEST(Render, IdenticalAcrossThreadCounts) {
    const Stack s = load_stack(std::string(LAMINA_SOURCE_DIR) + "/examples/milky-coat.json");
    const auto rw = make_model("random-walk", s);
    Environment env = Environment::named("studio");
    env.sun = DirectionalLight{normalize(Vec3d(0.3, 0.5, 0.8)), Rgbd(2.0)};
    const Rendering one = render_sphere(*rw, env, small(20, 3, 1));
    const Rendering three = render_sphere(*rw, env, small(20, 3, 3));
    EXPECT_EQ(one.image.pixels, three.image.pixels);
    // A transparent sphere (its walks continue inside).
    const auto slab = make_model(
        "random-walk", load_stack(std::string(LAMINA_SOURCE_DIR) + "/examples/slab.json"));
    EXPECT_EQ(render_sphere(*slab, env, small(20, 3, 1)).image.pixels,
              render_sphere(*slab, env, small(20, 3, 2)).image.pixels);
    const auto ww = make_model("bel18-forward", load_stack(std::string(LAMINA_SOURCE_DIR) +
                                                           "/examples/metallic-paint.json"));
    EXPECT_EQ(render_sphere(*ww, env, small(20, 3, 1)).image.pixels,
              render_sphere(*ww, env, small(20, 3, 2)).image.pixels);
}

TEST(Render, ExrRoundTripAndPngAndSheet) {
    Image img(7, 5);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 7; ++x)
            img.at(x, y) = Rgbf(float(x) * 0.5f, float(y), 1e3f + float(x * y));
    const auto dir = std::filesystem::path(LAMINA_BINARY_DIR) / "render_test";
    std::filesystem::create_directories(dir);
    write_exr(dir / "a.exr", img);
    const Image back = read_exr(dir / "a.exr");
    EXPECT_EQ(back.width, 7);
    EXPECT_EQ(back.height, 5);
    EXPECT_EQ(back.pixels, img.pixels);
    write_png(dir / "a.png", img, 0);
    EXPECT_GT(std::filesystem::file_size(dir / "a.png"), 50u);
    EXPECT_EQ(tone_map_channel(0, 0), 0);
    EXPECT_EQ(tone_map_channel(1e9, 0), 255);
    const Image sheet =
        contact_sheet({{"ref", img, true, ""}, {"m", img, true, ""}, {"x", Image(), false, "why"}},
                      std::vector<char>(35, 1), 0);
    EXPECT_GT(sheet.width, 3 * 7);
}

}  // namespace
}  // namespace lamina

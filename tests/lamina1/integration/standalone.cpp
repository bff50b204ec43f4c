// lamina-1's header library on its own: this file and the worked integration it runs
// (pbrt_bxdf.h, the BxDF docs/lamina1.md shows) are compiled as C++17 with -Wall -Wextra -pedantic
// -Werror and no include path but include/ and this folder (tests/CMakeLists.txt, lamina1_header).
// Reads the data file `lamina export --lamina1-tables` writes and checks, on a plastic, a coated
// rough conductor and a rough slab: the reflection is reciprocal, the BxDF's f is the header's
// eval in pbrt's argument order, its light-from-below transmission is the reverse path times
// 1/η², Sample_f returns the f and PDF of the direction it draws, and a Monte Carlo estimate of
// the directional albedo with Sample_f (a fixed seed) is at most one plus five standard errors.
// Prints "ok" and exits 0, or names what failed and exits 1.
#include "pbrt_bxdf.h"

#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

int failures = 0;
std::string last_failure;

// Reports each failed check once in a row (a loop's 200 failures print one line).
void check(bool ok, const std::string& what) {
    if (!ok && what != last_failure) {
        std::printf("FAIL: %s\n", what.c_str());
        last_failure = what;
    }
    failures += !ok;
}

bool close(double a, double b, double rel) {
    return std::abs(a - b) <= rel * std::max(std::abs(a), std::abs(b)) + 1e-300;
}

lamina1::Vec3 direction(double u1, double u2, bool upper) {
    const double z = std::sqrt(1 - u1), r = std::sqrt(u1), phi = 2 * lamina1::kPi * u2;
    return {r * std::cos(phi), r * std::sin(phi), upper ? z : -z};
}

pbrt::Vector3f v3(const lamina1::Vec3& w) {
    return {float(w.x), float(w.y), float(w.z)};
}
lamina1::Vec3 l3(const pbrt::Vector3f& w) {
    return {w.x, w.y, w.z};
}

void run(const char* name, const lamina1::Layers& layers, const lamina1::Tables& tables) {
    const lamina1::Bsdf bsdf(layers, tables);
    check(bsdf.support().brdf, std::string(name) + ": supported");
    const pbrt::Lamina1BxDF bxdf(&bsdf);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const double eta = layers.eta0 * layers.base_eta[0];
    for (int i = 0; i < 200; ++i) {
        // float directions, as pbrt passes them, evaluated both ways from the same floats.
        const lamina1::Vec3 a = l3(v3(direction(U(rng), U(rng), true)));
        const lamina1::Vec3 b = l3(v3(direction(U(rng), U(rng), true)));
        const lamina1::Rgb ab = bsdf.eval(a, b), ba = bsdf.eval(b, a);
        const pbrt::SampledSpectrum f = bxdf.f(v3(b), v3(a), pbrt::TransportMode::Radiance);
        for (int c = 0; c < 3; ++c) {
            // 1e-6: the float directions are unit only to float precision, and each order
            // reads them differently (lamina's own test holds 1e-12 on double directions).
            check(close(ab[c], ba[c], 1e-6), std::string(name) + ": reflection is reciprocal (" +
                                                 std::to_string(ab[c]) + " vs " +
                                                 std::to_string(ba[c]) + ")");
            check(close(f[c], ab[c], 1e-6), std::string(name) + ": f(wo, wi) is eval(wi, wo)");
        }
        if (bsdf.support().btdf) {
            const lamina1::Vec3 d = l3(v3(direction(U(rng), U(rng), false)));
            const pbrt::SampledSpectrum up = bxdf.f(v3(a), v3(d), pbrt::TransportMode::Radiance);
            const pbrt::SampledSpectrum down = bxdf.f(v3(d), v3(a), pbrt::TransportMode::Radiance);
            const lamina1::Rgb t = bsdf.eval(a, d);
            for (int c = 0; c < 3; ++c) {
                check(close(down[c], t[c], 1e-6), std::string(name) + ": transmission downwards");
                check(close(up[c], t[c] / (eta * eta), 1e-6),
                      std::string(name) + ": light from below is the reverse path over eta^2");
            }
        }
    }
    // Sample_f: its f and pdf are f() and PDF() at the direction drawn; the albedo at ~60°.
    const pbrt::Vector3f wo = v3(direction(0.75, 0.1, true));
    double sum = 0, sum2 = 0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) {
        const auto s = bxdf.Sample_f(wo, float(U(rng)), {float(U(rng)), float(U(rng))},
                                     pbrt::TransportMode::Radiance);
        if (!s) continue;
        const pbrt::SampledSpectrum f = bxdf.f(wo, s->wi, pbrt::TransportMode::Radiance);
        const float pdf = bxdf.PDF(wo, s->wi, pbrt::TransportMode::Radiance);
        // 1e-5: the same expressions inlined at two call sites, contracted into different
        // fused multiply-adds at -O3 (-ffp-contract=fast), differ by up to 2e-6 here.
        check(close(s->pdf, pdf, 1e-5) && close(s->f[1], f[1], 1e-5),
              std::string(name) + ": Sample_f's f and pdf are f() and PDF() there (" +
                  std::to_string(s->pdf) + " vs " + std::to_string(pdf) + ", " +
                  std::to_string(s->f[1]) + " vs " + std::to_string(f[1]) + ")");
        const double w = s->f[1] * std::abs(s->wi.z) / s->pdf;
        sum += w;
        sum2 += w * w;
    }
    const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    check(mean > 0 && mean <= 1 + 5 * se, std::string(name) + ": albedo at most one (" +
                                              std::to_string(mean) + " ± " + std::to_string(se) +
                                              ")");
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::printf("usage: %s LAMINA1_TABLES\n", argv[0]);
        return 2;
    }
    lamina1::Tables tables;
    std::string error;
    if (!tables.read(argv[1], &error)) {
        std::printf("FAIL: %s\n", error.c_str());
        return 1;
    }
    lamina1::Layers plastic;
    plastic.eta0 = 1.5;
    plastic.alpha0 = 0.1;
    plastic.albedo = lamina1::Rgb(0.8, 0.5, 0.2);
    run("plastic", plastic, tables);

    lamina1::Layers gold;
    gold.eta0 = 1.5;
    gold.alpha0 = 0.2;
    gold.tau_a = lamina1::Rgb(0.1, 0.2, 0.3);
    gold.base = lamina1::Base::Conductor;
    gold.base_eta = lamina1::Rgb(0.18 / 1.5, 0.42 / 1.5, 1.37 / 1.5);
    gold.base_k = lamina1::Rgb(3.4 / 1.5, 2.35 / 1.5, 1.85 / 1.5);
    gold.alpha1 = 0.3;
    run("coated gold", gold, tables);

    lamina1::Layers slab;
    slab.eta0 = 1.5;
    slab.alpha0 = 0.2;
    slab.base = lamina1::Base::Dielectric;
    slab.base_eta = lamina1::Rgb(1.33 / 1.5);  // glass over water: water relative to glass
    slab.alpha1 = 0.3;
    run("slab", slab, tables);

    if (failures) return 1;
    std::printf("ok\n");
    return 0;
}

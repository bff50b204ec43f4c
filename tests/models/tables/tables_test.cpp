// The tables lamina computes for Belcour's model: FGD against direct integration, TIR against
// direct Monte Carlo, and the on-disk cache's refusal to trust anything that does not match.
#include "core/math.h"
#include "core/rng.h"
#include "models/tables/fgd_table.h"
#include "models/tables/table_cache.h"
#include "models/tables/tir_table.h"
#include "physics/conductor.h"
#include "physics/dielectric.h"
#include "physics/fresnel.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace lamina {
namespace {

TEST(FgdTable, FastComplexFresnelEqualsReference) {
    for (double c : {0.0, 0.1, 0.5, 0.9, 1.0})
        for (double eta : {0.2, 0.7, 1.0, 1.5, 3.0})
            for (double k : {0.0, 0.5, 3.0}) {
                const double want =
                    k == 0 ? fresnel_dielectric(c, eta) : fresnel_conductor(c, eta, k);
                EXPECT_NEAR(fresnel_complex_fast(c, eta, k), want, 1e-12);
                const Rgbd rgb = fresnel_complex_rgb(c, Rgbd(eta, 1.0, 2.0), Rgbd(k, 0.5, 1.0));
                EXPECT_NEAR(rgb[0], want, 1e-12);
                EXPECT_NEAR(rgb[2], fresnel_conductor(c, 2.0, 1.0), 1e-12);
            }
}

// The table's quadrature itself (visible-normal rule) against an independent integral in solid
// angle of the Walter et al. 2007 BRDF (DielectricInterface / ConductorInterface::eval, Eq. 20):
// FGD = ∫ f_r μo dωo, by a dense midpoint rule in (u = sin²θo, φ) — exact to ~1e-4 for α ≥ 0.2.
TEST(FgdTable, DirectIntegralEqualsSolidAngleIntegral) {
    const int nu = 1200, nphi = 600;
    for (double alpha : {0.2, 0.5})
        for (double c : {0.9, 0.4}) {
            const Vec3d wi(std::sqrt(1 - c * c), 0, c);
            const DielectricInterface<double> d{1.5, alpha};
            const ConductorInterface<double> m{Rgbd(0.2), Rgbd(3.0), alpha};
            double sd = 0, sm = 0;
            for (int a = 0; a < nu; ++a)
                for (int b = 0; b < nphi; ++b) {
                    const double u = (a + 0.5) / nu, phi = kPi<double> * (b + 0.5) / nphi;
                    const double s = std::sqrt(u);
                    const Vec3d wo(s * std::cos(phi), s * std::sin(phi), std::sqrt(1 - u));
                    sd += d.eval(wi, wo);  // f μo dω = f ½ du dφ, two halves in φ
                    sm += m.eval(wi, wo)[0];
                }
            const double norm = kPi<double> / (double(nu) * nphi);
            EXPECT_NEAR(FgdTable::direct(c, alpha, 1.5, 0), sd * norm, 3e-4) << alpha << " " << c;
            EXPECT_NEAR(FgdTable::direct(c, alpha, 0.2, 3.0), sm * norm, 3e-4) << alpha << " " << c;
        }
}

// Interpolated table against direct integration at random off-grid points. Tolerances are the
// measured interpolation error budget (docs/models.md, "FGD table"), per region of the domain:
// dielectrics η ∈ [1.05, 3]: max 3.4e-3, mean 1.4e-4; conductors κ ≥ 1: max 6.3e-3, mean 5e-4.
TEST(FgdTable, TableMatchesDirectIntegrationOffGrid) {
    const FgdTable& table = FgdTable::get();
    ParticleRng rng(11, 0, 0);
    double sum_d = 0, sum_c = 0;
    const int n = 300;
    for (int i = 0; i < n; ++i) {
        const double c = rng.uniform_double(), a = rng.uniform_double();
        const double eta_d = 1.05 + 1.95 * rng.uniform_double();
        const double err_d = std::abs(table(c, a, eta_d, 0) - FgdTable::direct(c, a, eta_d, 0));
        EXPECT_LT(err_d, 6e-3) << c << " " << a << " " << eta_d;
        sum_d += err_d;
        const double eta_c = std::exp2(-5 + 7 * rng.uniform_double());
        const double k = 1 + 9 * rng.uniform_double();
        const double err_c = std::abs(table(c, a, eta_c, k) - FgdTable::direct(c, a, eta_c, k));
        EXPECT_LT(err_c, 1e-2) << c << " " << a << " " << eta_c << " " << k;
        sum_c += err_c;
    }
    EXPECT_LT(sum_d / n, 4e-4);
    EXPECT_LT(sum_c / n, 1e-3);
}

// The RGB lookup equals three scalar lookups (one shared (c, α) part; the same interpolation).
TEST(FgdTable, RgbLookupEqualsScalarLookups) {
    const FgdTable& table = FgdTable::get();
    const std::array<FgdTable::Index, 3> at = {
        FgdTable::locate(0.18, 3.4), FgdTable::locate(0.42, 2.35), FgdTable::locate(1.37, 0.0)};
    for (double c : {0.05, 0.5, 0.93})
        for (double a : {0.0, 0.07, 0.3, 0.8}) {
            const Rgbd v = table.rgb(c, a, at);
            for (int i = 0; i < 3; ++i)
                EXPECT_NEAR(v[i], table(c, a, at[i].eta, at[i].k), 1e-12) << c << " " << a;
        }
}

// Smooth limit: α = 0 is the Fresnel factor itself, including total internal reflection.
TEST(FgdTable, SmoothLimitIsFresnel) {
    const FgdTable& table = FgdTable::get();
    EXPECT_NEAR(table(1.0, 0.0, 1.5, 0.0), 0.04, 1e-12);  // docs/physics.md §6.1
    EXPECT_EQ(table(0.3, 0.0, 1 / 1.5, 0.0), 1.0);        // TIR from inside glass
}

// TIR table against plain Monte Carlo (independent random numbers, 2·10⁵ samples, standard error
// ≤ 1.2e-3) at off-grid points with α ≥ 0.05. Budget: the measured error of the table (stratified
// MC noise + interpolation; docs/models.md): max 1.1e-2 (next to the critical angle, where τ is
// nearly a step), mean 1.8e-3 over 150 random points; tolerances 2e-2 / 4e-3.
TEST(TirTableStat, TableMatchesDirectMonteCarloOffGrid) {
    const TirTable& table = TirTable::get();
    ParticleRng rng(5, 0, 0);
    double sum = 0;
    const int n = 40;
    for (int i = 0; i < n; ++i) {
        const double c = rng.uniform_double(), a = 0.05 + 0.9 * rng.uniform_double();
        const double eta = 0.4 + 0.55 * rng.uniform_double();
        const double mc = TirTable::direct_mc(c, a, eta, 200000, 100 + i);
        const double err = std::abs(table(c, a, eta) - mc);
        EXPECT_LT(err, 2e-2) << c << " " << a << " " << eta;
        sum += err;
    }
    EXPECT_LT(sum / n, 4e-3);
    EXPECT_EQ(table(0.5, 0.3, 1.2), 1.0);  // no TIR towards a denser medium
}

// Smooth-interface limit of τ_TIR: a step at the critical cosine √(1 − η²).
TEST(TirTable, SmoothLimitIsTheCriticalAngle) {
    EXPECT_EQ(TirTable::direct_mc(0.9, 0.0, 1 / 1.5, 1000), 1.0);  // c above √(1 − 1/2.25) ≈ 0.745
    EXPECT_EQ(TirTable::direct_mc(0.6, 0.0, 1 / 1.5, 1000), 0.0);
    EXPECT_EQ(TirTable::get()(0.75, 0.0, 1 / 1.5), 1.0);  // just above: no interpolation blur
    EXPECT_EQ(TirTable::get()(0.74, 0.0, 1 / 1.5), 0.0);
}

class CacheDir : public ::testing::Test {
  protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("lamina-cache-test-" + std::to_string(::getpid()));
        std::filesystem::remove_all(dir_);
        const char* old = std::getenv("LAMINA_CACHE_DIR");
        had_old_ = old != nullptr;
        if (old) old_ = old;
        ::setenv("LAMINA_CACHE_DIR", dir_.c_str(), 1);
    }
    void TearDown() override {
        if (had_old_)
            ::setenv("LAMINA_CACHE_DIR", old_.c_str(), 1);
        else
            ::unsetenv("LAMINA_CACHE_DIR");
        std::filesystem::remove_all(dir_);
    }
    std::filesystem::path dir_;
    std::string old_;
    bool had_old_ = false;
};

TEST_F(CacheDir, RoundTripsAndRejectsCorruptOrMismatchedFiles) {
    const TableKey key{"unit", "test generator v1", {2, 3}};
    const std::vector<float> values{1, 2, 3, 4, 5, 6};
    EXPECT_FALSE(load_cached_table(key));
    ASSERT_TRUE(store_cached_table(key, values));
    EXPECT_EQ(table_cache_path(key).parent_path(), dir_);
    EXPECT_EQ(load_cached_table(key).value(), values);
    // Another generator (different content hash) or shape never reads this file's values.
    EXPECT_FALSE(load_cached_table(TableKey{"unit", "test generator v2", {2, 3}}));
    EXPECT_FALSE(load_cached_table(TableKey{"unit", "test generator v1", {3, 2}}));
    // One flipped byte in the values: the checksum catches it.
    {
        std::fstream f(table_cache_path(key), std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(-12, std::ios::end);
        f.put('\x7f');
    }
    EXPECT_FALSE(load_cached_table(key));
    // Truncation.
    ASSERT_TRUE(store_cached_table(key, values));
    std::filesystem::resize_file(table_cache_path(key), 20);
    EXPECT_FALSE(load_cached_table(key));
    // cached_table recomputes and rewrites.
    int computed = 0;
    const auto v = cached_table(key, [&] {
        ++computed;
        return values;
    });
    EXPECT_EQ(computed, 1);
    EXPECT_EQ(v, values);
    EXPECT_EQ(load_cached_table(key).value(), values);
}

}  // namespace
}  // namespace lamina

// The finite Fourier integral of a Gaussian (models/numerics/gaussian_fourier.h) against the real
// error function where b = 0 (∫ e^{−a t²} dt = √π/(2√a) (erf(√a t1) − erf(√a t0))), against
// composite Gauss–Legendre quadrature of the integrand elsewhere (from slowly to fast turning
// cosines, windows wide and narrow, intervals at and away from 0), and its symmetries.
#include "models/numerics/gaussian_fourier.h"
#include "models/numerics/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

namespace lamina {
namespace {

/// ∫_{t0}^{t1} e^{−a t²} e^{i b t} dt by 64-point Gauss–Legendre on `pieces` equal pieces.
std::complex<double> by_quadrature(double a, double b, double t0, double t1, int pieces) {
    const QuadratureRule rule = gauss_legendre(64);
    const double width = (t1 - t0) / pieces;
    std::complex<double> sum = 0;
    for (int p = 0; p < pieces; ++p)
        for (std::size_t i = 0; i < rule.x.size(); ++i) {
            const double t = t0 + width * (p + rule.x[i]);
            sum += std::exp(-a * t * t) * std::polar(1.0, b * t) * rule.w[i] * width;
        }
    return sum;
}

TEST(GaussianFourier, WithoutTheCosineIsTheErrorFunction) {
    for (double a : {0.01, 1.0, 37.0})
        for (auto [t0, t1] : {std::pair{0.0, 0.3}, {0.0, 5.0}, {0.2, 0.9}, {1.0, 40.0}}) {
            const double want = std::sqrt(std::numbers::pi) / (2 * std::sqrt(a)) *
                                (std::erf(std::sqrt(a) * t1) - std::erf(std::sqrt(a) * t0));
            const std::complex<double> got = gaussian_fourier_integral(a, 0, t0, t1);
            EXPECT_NEAR(got.real(), want, 1e-13 * (1 + std::abs(want))) << a << " " << t0;
            EXPECT_NEAR(got.imag(), 0, 1e-13) << a << " " << t0;
        }
}

TEST(GaussianFourier, MatchesQuadrature) {
    struct Case {
        double a, b, t0, t1;
    };
    // The last rows are Belcour & Barla's sensitivity lobes (variance and centre in metres⁻¹,
    // phases 2π·OPD·1e-9 for optical paths 0–600 nm and 350–3600 nm): y = b/(2√a) ≈ 12.8, where
    // the closed form's e^{−y²} is 1e-71 and everything rests on w(z).
    const Case cases[] = {
        {1, 1, 0, 2},
        {1, 10, 0, 3},
        {0.5, -3, 0.25, 6},
        {4, 25, 1, 1.5},
        {1e-3, 0.7, 0, 50},
        {4.3278e9, 1.6810e6, 0, 2 * std::numbers::pi * 600e-9},
        {9.3046e9, 1.7953e6, 2 * std::numbers::pi * 350e-9, 2 * std::numbers::pi * 3600e-9},
        {4.5282e9, 2.2399e6, 2 * std::numbers::pi * 1000e-9, 2 * std::numbers::pi * 1001e-9}};
    for (const Case& c : cases) {
        const std::complex<double> want = by_quadrature(c.a, c.b, c.t0, c.t1, 200);
        const std::complex<double> got = gaussian_fourier_integral(c.a, c.b, c.t0, c.t1);
        // Relative to the integral of the window alone, the scale of both parts.
        const double scale = gaussian_fourier_integral(c.a, 0, c.t0, c.t1).real();
        EXPECT_NEAR(got.real(), want.real(), 1e-11 * scale) << c.a << " " << c.b << " " << c.t0;
        EXPECT_NEAR(got.imag(), want.imag(), 1e-11 * scale) << c.a << " " << c.b << " " << c.t0;
    }
}

// Additive over adjacent intervals, zero on an empty one, conjugate for −b.
TEST(GaussianFourier, Symmetries) {
    const double a = 2, b = 7;
    const std::complex<double> whole = gaussian_fourier_integral(a, b, 0.1, 2.0),
                               parts = gaussian_fourier_integral(a, b, 0.1, 0.8) +
                                       gaussian_fourier_integral(a, b, 0.8, 2.0);
    EXPECT_NEAR(std::abs(whole - parts), 0, 1e-14);
    EXPECT_EQ(gaussian_fourier_integral(a, b, 0.6, 0.6), std::complex<double>(0));
    EXPECT_NEAR(std::abs(gaussian_fourier_integral(a, -b, 0.1, 2.0) - std::conj(whole)), 0, 1e-14);
}

}  // namespace
}  // namespace lamina

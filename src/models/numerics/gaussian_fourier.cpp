#include "models/numerics/gaussian_fourier.h"

#include <cerf.h>

#include <cmath>
#include <numbers>

namespace lamina {

namespace {

/// ∫_0^t e^{−a t'²} e^{i b t'} dt' for t ≥ 0 (the header's formula).
std::complex<double> from_zero(double a, double b, double t) {
    const double sqrt_a = std::sqrt(a);
    const double x = sqrt_a * t, y = b / (2 * sqrt_a);
    const std::complex<double> w(re_w_of_z(y, x), im_w_of_z(y, x));
    const std::complex<double> bracket =
        std::exp(-y * y) - std::exp(std::complex<double>(-x * x, 2 * x * y)) * w +
        std::complex<double>(0, 2 / std::sqrt(std::numbers::pi) * dawson(y));
    return std::sqrt(std::numbers::pi) / (2 * sqrt_a) * bracket;
}

}  // namespace

std::complex<double> gaussian_fourier_integral(double a, double b, double t0, double t1) {
    return from_zero(a, b, t1) - from_zero(a, b, t0);
}

}  // namespace lamina

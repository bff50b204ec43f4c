#pragma once
// The finite Fourier integral of a Gaussian, ∫ e^{−a t²} e^{i b t} dt over [t0, t1], in closed form
// through Faddeeva's function w(z) = e^{−z²} erfc(−iz) (libcerf). The thickness averages of the
// interference terms that Belcour & Barla 2017 write as Gaussian-windowed cosines of the optical
// path (models/production/film_fresnel.cpp) are such integrals.

#include <complex>

namespace lamina {

/// ∫_{t0}^{t1} e^{−a t²} e^{i b t} dt for a > 0, any real b, 0 ≤ t0 ≤ t1: its real part integrates
/// e^{−a t²} cos(b t), its imaginary part e^{−a t²} sin(b t). With x = √a·t and y = b/(2√a),
///   ∫_0^t = √π/(2√a) · [e^{−y²} − e^{−x²} e^{2ixy} w(y + ix) + (2i/√π) D(y)],
/// D Dawson's integral (completing the square in the exponent; erfc(z) = e^{−z²} w(iz); at
/// x = 0 the bracket vanishes, since w(y) = e^{−y²} + (2i/√π) D(y) for real y). w is taken in the
/// upper half-plane only, where it is bounded by 1: no cancellation between large terms.
std::complex<double> gaussian_fourier_integral(double a, double b, double t0, double t1);

}  // namespace lamina

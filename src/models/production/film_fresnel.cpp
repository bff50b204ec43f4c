#include "models/production/film_fresnel.h"

#include "core/math.h"
#include "models/numerics/quadrature.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace lamina {

namespace {

/// Nodes per period of the interference in the thickness averages.
constexpr int kNodesPerPeriod = 32;
constexpr int kMaxNodes = 2048;

/// The mean of f(d) over d uniform in [min_nm, max_nm]: composite Gauss–Legendre on pieces no
/// longer than period_nm (f is periodic in d with at least that period, smooth within it).
template <typename F>
Rgbd thickness_average(double min_nm, double max_nm, double period_nm, F&& f) {
    if (!(max_nm > min_nm)) return f(max_nm);
    static const QuadratureRule rule = gauss_legendre(kNodesPerPeriod);
    const double pieces_wanted = std::ceil((max_nm - min_nm) / std::max(period_nm, 1e-9));
    const int pieces = int(std::clamp(pieces_wanted, 1.0, double(kMaxNodes / kNodesPerPeriod)));
    const double width = (max_nm - min_nm) / pieces;
    Rgbd sum(0.0);
    for (int p = 0; p < pieces; ++p)
        for (std::size_t i = 0; i < rule.x.size(); ++i)
            sum += f(min_nm + width * (p + rule.x[i])) * rule.w[i];
    return sum / double(pieces);
}

/// Belcour & Barla 2017's sensitivity S(OPD, shift) in linear sRGB: the Fourier transform of the
/// CIE 1931 colour matching functions at the optical path difference OPD (nm), shifted in phase,
/// by the paper's fit of each as a sum of Gaussians (their supplemental material; the constants
/// as three.js's evalSensitivity carries them: the Gaussians' amplitudes, centres and variances
/// in the spatial frequency of metres, and the normalization 1.0685e-7 that makes the m = 0 term
/// white), then the XYZ → linear sRGB (Rec. 709 primaries, D65) matrix of IEC 61966-2-1.
Rgbd sensitivity_srgb(double opd_nm, const Rgbd& shift) {
    const double two_pi = 2 * std::numbers::pi;
    const double phase = two_pi * opd_nm * 1e-9;
    const double val[3] = {5.4856e-13, 4.4201e-13, 5.2481e-13};
    const double pos[3] = {1.6810e+06, 1.7953e+06, 2.2084e+06};
    const double var[3] = {4.3278e+09, 9.3046e+09, 6.6121e+09};
    double xyz[3];
    for (int i = 0; i < 3; ++i)
        xyz[i] = val[i] * std::sqrt(two_pi * var[i]) * std::cos(pos[i] * phase + shift[i]) *
                 std::exp(-phase * phase * var[i]);
    // X has a second lobe (the blue bump of x̄).
    xyz[0] += 9.7470e-14 * std::sqrt(two_pi * 4.5282e+09) *
              std::cos(2.2399e+06 * phase + shift[0]) * std::exp(-4.5282e+09 * phase * phase);
    for (double& v : xyz)
        v /= 1.0685e-7;
    return {3.2404542 * xyz[0] - 1.5371385 * xyz[1] - 0.4985314 * xyz[2],
            -0.9692660 * xyz[0] + 1.8760108 * xyz[1] + 0.0415560 * xyz[2],
            0.0556434 * xyz[0] - 0.2040259 * xyz[1] + 1.0572252 * xyz[2]};
}

/// Normal reflectance ((n_t − n_i)/(n_t + n_i))² of a dielectric boundary.
double normal_reflectance(double eta_t, double eta_i) {
    return sqr((eta_t - eta_i) / (eta_t + eta_i));
}

/// Schlick 1994 (Eq. 15) with f90 = 1 in three.js's spherical-Gaussian form.
double schlick_sg(double f0, double c) {
    return f0 + (1 - f0) * schlick_weight_spherical_gaussian(c);
}

}  // namespace

double schlick_weight_spherical_gaussian(double c) {
    return std::exp2((-5.55473 * c - 6.98316) * c);
}

Rgbd film_reflectance_exact(const FilmOptics& film, double cos_theta) {
    const double c = clamp(cos_theta, 0.0, 1.0);
    const double lambda_min =
        std::min({film.wavelength_nm[0], film.wavelength_nm[1], film.wavelength_nm[2]});
    // The round-trip phase 4π d Re(u_f)/λ with Re(u_f) ≤ |η_f|: a period of at least λ/(2|η_f|).
    const double period = lambda_min / (2 * std::max(std::abs(film.eta_film), 1e-3));
    return thickness_average(film.thickness_min_nm, film.thickness_max_nm, period, [&](double d) {
        Rgbd r;
        for (int i = 0; i < 3; ++i)
            r[i] = film.mueller(i, c, true, d).reflection.a;
        return r;
    });
}

std::complex<double> gulbrandsen_index(double r, double g) {
    const double rc = clamp(r, 0.0, 0.99), sr = std::sqrt(rc);
    const double n_min = (1 - rc) / (1 + rc), n_max = (1 + sr) / (1 - sr);
    const double n = n_max + (n_min - n_max) * g;
    const double k2 = (sqr(n + 1) * rc - sqr(n - 1)) / (1 - rc);
    return {n, std::sqrt(std::max(k2, 0.0))};
}

Rgbd openpbr_bsdf_film_reflectance(const FilmOptics& film, double cos_theta, const Rgbd& bare) {
    const double c = clamp(cos_theta, 0.0, 1.0);
    // Total reflection at the coat | film boundary: openpbr-bsdf reflects everything.
    const double sin_film = film.eta_above * std::sqrt(1 - c * c) / film.eta_film.real();
    const double lambda_min =
        std::min({film.wavelength_nm[0], film.wavelength_nm[1], film.wavelength_nm[2]});
    const double period = lambda_min / (2 * std::max(std::abs(film.eta_film), 1e-3));
    return thickness_average(film.thickness_min_nm, film.thickness_max_nm, period, [&](double d) {
        const double t = clamp((d - 1e-9) / (30 - 1e-9), 0.0, 1.0), presence = t * t * (3 - 2 * t);
        if (!(presence > 0)) return bare;
        Rgbd r(1.0);
        if (sin_film < 1)
            for (int i = 0; i < 3; ++i)
                r[i] = film.mueller(i, c, true, d).reflection.a;
        return bare * (1 - presence) + r * presence;
    });
}

Rgbd threejs_iridescence(double outside_ior, double film_ior, double cos_theta_1,
                         double thickness_nm, const Rgbd& base_f0) {
    const double pi = std::numbers::pi;
    // The film's index goes to the outside's as the thickness goes to 0 (over 0.03 nm).
    const double t = clamp(thickness_nm / 0.03, 0.0, 1.0);
    const double iridescence_ior = outside_ior + (film_ior - outside_ior) * t * t * (3 - 2 * t);
    // Snell's law into the film; total internal reflection reflects everything.
    const double sin2_theta_2 = sqr(outside_ior / iridescence_ior) * (1 - sqr(cos_theta_1));
    const double cos2_theta_2 = 1 - sin2_theta_2;
    if (cos2_theta_2 < 0) return Rgbd(1.0);
    const double cos_theta_2 = std::sqrt(cos2_theta_2);
    // The first boundary by Schlick's approximation; its phase 0 or π (Belcour & Barla, Eq. 9).
    const double R12 = schlick_sg(normal_reflectance(iridescence_ior, outside_ior), cos_theta_1);
    const double T121 = 1 - R12;
    const double phi12 = iridescence_ior < outside_ior ? pi : 0.0;
    const double phi21 = pi - phi12;
    // The base read as a dielectric of the index its F0 gives against air (F0 clamped to
    // [0, 0.9999]), Schlick's approximation at the film's cosine, its phase 0 or π.
    Rgbd R23, phi;
    for (int c = 0; c < 3; ++c) {
        const double s = std::sqrt(clamp(base_f0[c], 0.0, 0.9999));
        const double base_ior = (1 + s) / (1 - s);
        R23[c] = schlick_sg(normal_reflectance(base_ior, iridescence_ior), cos_theta_2);
        phi[c] = phi21 + (base_ior < iridescence_ior ? pi : 0.0);
    }
    // Belcour & Barla, Eq. 10: the DC term and the first two orders of the Airy sum in Fourier
    // space, each order's cosine integrated against the sensitivity.
    const double opd = 2 * iridescence_ior * thickness_nm * cos_theta_2;
    Rgbd I;
    for (int c = 0; c < 3; ++c) {
        const double R123 = clamp(R12 * R23[c], 1e-5, 0.9999);
        const double r123 = std::sqrt(R123);
        const double Rs = sqr(T121) * R23[c] / (1 - R123);
        I[c] = R12 + Rs;
        double Cm = Rs - T121;
        for (int m = 1; m <= 2; ++m) {
            Cm *= r123;
            I[c] += Cm * 2 * sensitivity_srgb(m * opd, Rgbd(m * phi[c]))[c];
        }
        I[c] = std::max(I[c], 0.0);
    }
    return I;
}

Rgbd threejs_iridescence_range(double outside_ior, double film_ior, double cos_theta_1,
                               double min_nm, double max_nm, const Rgbd& base_f0) {
    // The sensitivity's fastest cosine, 2.2399e6 m⁻¹ of optical path 2 η d cos θ2, has a period
    // in d of at least 1/(2.2399e6 · 1e-9 · 2 η) nm.
    const double period = 1 / (2.2399e6 * 1e-9 * 2 * std::max(film_ior, 1e-3));
    return thickness_average(min_nm, max_nm, period, [&](double d) {
        return threejs_iridescence(outside_ior, film_ior, cos_theta_1, d, base_f0);
    });
}

}  // namespace lamina

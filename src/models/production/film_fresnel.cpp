#include "models/production/film_fresnel.h"

#include "core/math.h"
#include "layers/colorimetry.h"
#include "models/numerics/gaussian_fourier.h"
#include "models/numerics/quadrature.h"
#include "models/production/production_coat.h"
#include "physics/thin_film_average.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

namespace lamina {

namespace {

/// Nodes per period of the interference in the thickness averages.
constexpr int kNodesPerPeriod = 32;
constexpr int kMaxNodes = 2048;

/// The mean of f(d) over d uniform in [min_nm, max_nm]: composite Gauss–Legendre on pieces no
/// longer than period_nm (f is periodic in d with at least that period, smooth within it). Any
/// one unit of length serves (the films' thickness in nm, Belcour & Barla's Dinc in µm).
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

/// The thickness (nm) past which `film` reflects light from above at cos_theta as an infinitely
/// thick one, to double precision: the Airy sums hold the film's round trip e^{2iδ}, of modulus
/// exp(−4π d η_above Im u_f / λ) with u_f the film's normal wave number relative to the medium
/// above (physics/thin_film.h), and past this thickness it is below 10⁻¹⁶ in every channel.
/// Infinite where the wave propagates without loss (a transparent film below its critical angle).
double opaque_thickness_nm(const FilmOptics& film, double cos_theta) {
    const double im_u =
        normal_wave_number(film.eta_film / film.eta_above, 1 - cos_theta * cos_theta).imag();
    const double lambda_max =
        std::max({film.wavelength_nm[0], film.wavelength_nm[1], film.wavelength_nm[2]});
    constexpr double kLn1e16 = 36.841361487904734;  // ln 10¹⁶
    if (!(im_u > 0)) return HUGE_VAL;
    return kLn1e16 * lambda_max / (4 * std::numbers::pi * film.eta_above * im_u);
}

/// thickness_average of f over [min_nm, max_nm] where f is constant from opaque_nm on: the
/// quadrature below it, f(max_nm) times the length above it (a thick absorbing film's range of
/// micrometres would otherwise take the 2048 nodes at every evaluation).
template <typename F>
Rgbd thickness_average_to_opaque(double min_nm, double max_nm, double period_nm, double opaque_nm,
                                 F&& f) {
    if (!(max_nm > opaque_nm) || !(max_nm > min_nm))
        return thickness_average(min_nm, max_nm, period_nm, f);
    const double split = std::max(min_nm, opaque_nm);
    const Rgbd thick = f(max_nm);
    if (!(split > min_nm)) return thick;
    return (thickness_average(min_nm, split, period_nm, f) * (split - min_nm) +
            thick * (max_nm - split)) /
           (max_nm - min_nm);
}

/// The exact reflectance of `film` for unpolarized light from above at cos_theta, per channel,
/// averaged over thickness uniform in [min_nm, max_nm] in closed form (physics/
/// thin_film_average.h); nothing where no closed form holds in some channel (an absorbing film,
/// an evanescent wave in the film, a range of less than a milliradian of phase).
std::optional<Rgbd> closed_form_mean(const FilmOptics& film, double cos_theta, double min_nm,
                                     double max_nm) {
    const double eta_i = film.eta_above;
    Rgbd r;
    for (int c = 0; c < 3; ++c) {
        const auto m = thin_film_reflectance_mean(
            cos_theta, film.eta_film / eta_i, film.eta_below[c] / eta_i,
            min_nm * eta_i / film.wavelength_nm[c], max_nm * eta_i / film.wavelength_nm[c]);
        if (!m) return std::nullopt;
        r[c] = (m->first + m->second) / 2;
    }
    return r;
}

/// A 3 × 3 matrix applied to an XYZ triple (of reals or complex values), row by row.
using Matrix3 = std::array<std::array<double, 3>, 3>;
template <typename V>
V apply_matrix(const Matrix3& m, const V& xyz) {
    return {m[0][0] * xyz[0] + m[0][1] * xyz[1] + m[0][2] * xyz[2],
            m[1][0] * xyz[0] + m[1][1] * xyz[1] + m[1][2] * xyz[2],
            m[2][0] * xyz[0] + m[2][1] * xyz[1] + m[2][2] * xyz[2]};
}

/// XYZ to linear sRGB (Rec. 709 primaries, D65) by the matrix of IEC 61966-2-1 to seven digits,
/// as three.js's evalSensitivity and Cycles' fallback colour space (util/colorspace.cpp,
/// get_xyz_to_rec709) carry it (layers/colorimetry.h has the standard's four-digit form).
constexpr Matrix3 kXyzToSrgb7 = {{{3.2404542, -1.5371385, -0.4985314},
                                  {-0.9692660, 1.8760108, 0.0415560},
                                  {0.0556434, -0.2040259, 1.0572252}}};
template <typename V>
V xyz_to_srgb_7_digits(const V& xyz) {
    return apply_matrix(kXyzToSrgb7, xyz);
}

/// One Gaussian of Belcour & Barla 2017's fit of the CIE 1931 colour matching functions' Fourier
/// transforms (their supplemental material; the constants as three.js's evalSensitivity carries
/// them): amplitude, centre and variance in the spatial frequency of metres, and which of X, Y, Z
/// it belongs to (X has a second lobe, the blue bump of x̄).
struct SensitivityGaussian {
    int xyz;
    double val, pos, var;
};
constexpr SensitivityGaussian kSensitivityGaussians[4] = {{0, 5.4856e-13, 1.6810e+06, 4.3278e+09},
                                                          {1, 4.4201e-13, 1.7953e+06, 9.3046e+09},
                                                          {2, 5.2481e-13, 2.2084e+06, 6.6121e+09},
                                                          {0, 9.7470e-14, 2.2399e+06, 4.5282e+09}};
/// The normalization that makes the m = 0 term white.
constexpr double kSensitivityNorm = 1.0685e-7;

/// The phase 2π·OPD of an optical path difference in nm, per metre of wavelength⁻¹.
double sensitivity_phase(double opd_nm) {
    return 2 * std::numbers::pi * opd_nm * 1e-9;
}

/// A Gaussian's weight val·√(2π var).
double sensitivity_weight(const SensitivityGaussian& g) {
    return g.val * std::sqrt(2 * std::numbers::pi * g.var);
}

/// The fit as complex values: G_j(OPD) = Σ_{g of j} w_g e^(i pos_g t) e^(−var_g t²) / norm, t the
/// phase 2π OPD, j ∈ {X, Y, Z}; the sensitivity turned by a shift ψ is Re(e^(iψ) G_j).
std::array<std::complex<double>, 3> sensitivity_xyz(double opd_nm) {
    const double phase = sensitivity_phase(opd_nm);
    std::array<std::complex<double>, 3> xyz{};
    for (const SensitivityGaussian& g : kSensitivityGaussians)
        xyz[std::size_t(g.xyz)] += sensitivity_weight(g) * std::exp(-phase * phase * g.var) *
                                   std::polar(1.0, g.pos * phase) / kSensitivityNorm;
    return xyz;
}

/// XYZ to CIE 1931 RGB (the CIE's primaries at 700, 546.1 and 435.8 nm, equal-energy white E): the
/// inverse of the CIE's RGB → XYZ matrix, to seven digits as Belcour & Barla's shader carries it
/// (its XYZ_TO_RGB).
constexpr Matrix3 kXyzToCieRgb7 = {{{2.3706743, -0.9000405, -0.4706338},
                                    {-0.5138850, 1.4253036, 0.0885814},
                                    {0.0052982, -0.0146949, 1.0093968}}};
template <typename V>
V xyz_to_cie_rgb_7_digits(const V& xyz) {
    return apply_matrix(kXyzToCieRgb7, xyz);
}

}  // namespace

Rgbd belcour_sensitivity_srgb(double opd_nm, const Rgbd& shift) {
    const std::array<std::complex<double>, 3> g = sensitivity_xyz(opd_nm);
    Rgbd xyz;
    for (int j = 0; j < 3; ++j)
        xyz[j] = (std::polar(1.0, shift[j]) * g[std::size_t(j)]).real();
    return xyz_to_srgb_7_digits(xyz);
}

namespace {

/// The mean of the fit's G (sensitivity_xyz) over OPD uniform in [opd0_nm, opd1_nm] (0 ≤ opd0 ≤
/// opd1): each Gaussian-windowed phasor integrated in closed form (models/numerics/
/// gaussian_fourier.h), ∫ e^{−var t²} e^{i pos t} dt over the phases. Below 1 nm of OPD, where the
/// difference of the two antiderivatives would lose digits to the division, by 4-point
/// Gauss–Legendre (exact to ~1e-12 there: the fastest phasor turns by 0.014 rad per nm).
std::array<std::complex<double>, 3> sensitivity_xyz_mean(double opd0_nm, double opd1_nm) {
    std::array<std::complex<double>, 3> xyz{};
    if (opd1_nm - opd0_nm < 1.0) {
        static const QuadratureRule rule = gauss_legendre(4);
        for (std::size_t i = 0; i < rule.x.size(); ++i) {
            const auto g = sensitivity_xyz(opd0_nm + (opd1_nm - opd0_nm) * rule.x[i]);
            for (std::size_t j = 0; j < 3; ++j)
                xyz[j] += g[j] * rule.w[i];
        }
        return xyz;
    }
    const double t0 = sensitivity_phase(opd0_nm), t1 = sensitivity_phase(opd1_nm);
    for (const SensitivityGaussian& g : kSensitivityGaussians)
        xyz[std::size_t(g.xyz)] += sensitivity_weight(g) *
                                   gaussian_fourier_integral(g.var, g.pos, t0, t1) / (t1 - t0) /
                                   kSensitivityNorm;
    return xyz;
}

/// The mean of belcour_sensitivity_srgb(OPD, shift) over OPD uniform in [opd0_nm, opd1_nm]:
/// Re(e^{i shift} ·) of sensitivity_xyz_mean, projected to linear sRGB.
Rgbd sensitivity_srgb_mean(double opd0_nm, double opd1_nm, const Rgbd& shift) {
    const std::array<std::complex<double>, 3> g = sensitivity_xyz_mean(opd0_nm, opd1_nm);
    Rgbd xyz;
    for (int j = 0; j < 3; ++j)
        xyz[j] = (std::polar(1.0, shift[j]) * g[std::size_t(j)]).real();
    return xyz_to_srgb_7_digits(xyz);
}

/// sup |S_c| over OPD ≥ 0 of the sensitivity whose X, Y and Z lobes are turned by 0 or π (signs
/// (+, sY, sZ) after taking the X sign out: |S| is the same for opposite patterns), per linear-sRGB
/// channel. The maxima of a sampling of OPD over [0, 20000] nm every 0.01 nm (beyond, every window
/// is below e⁻⁶⁸), rounded up by 0.01 to 0.02 — far more than a sample can miss between two
/// (h²/8 · max|S''| ≈ 10⁻⁶); tests/models/production/film_fresnel_test.cpp samples them again.
constexpr double kSensitivitySup[2][2][3] = {{{5.29, 2.90, 1.02}, {4.30, 2.82, 1.33}},
                                             {{2.22, 1.02, 1.22}, {1.80, 1.00, 0.98}}};

}  // namespace

Rgbd belcour_sensitivity_srgb_bound(double opd0_nm, const Rgbd& shift) {
    // Each Gaussian's window is largest at the smallest phase, and |cos| ≤ 1.
    const double phase = sensitivity_phase(opd0_nm);
    double xyz[3] = {0, 0, 0};
    for (const SensitivityGaussian& g : kSensitivityGaussians)
        xyz[g.xyz] += sensitivity_weight(g) * std::exp(-phase * phase * g.var) / kSensitivityNorm;
    const Rgbd x = xyz_to_srgb_7_digits(Rgbd(xyz[0], 0, 0)),
               y = xyz_to_srgb_7_digits(Rgbd(0, xyz[1], 0)),
               z = xyz_to_srgb_7_digits(Rgbd(0, 0, xyz[2]));
    Rgbd bound;
    for (int c = 0; c < 3; ++c)
        bound[c] = std::abs(x[c]) + std::abs(y[c]) + std::abs(z[c]);
    // Shifts of whole multiples of π (three.js's are): the sampled suprema of their pattern.
    bool multiples_of_pi = true;
    int sign[3];
    for (int k = 0; k < 3; ++k) {
        multiples_of_pi = multiples_of_pi && std::abs(std::sin(shift[k])) < 1e-9;
        sign[k] = std::cos(shift[k]) > 0 ? 1 : -1;
    }
    if (multiples_of_pi) {
        const int same_y = sign[1] == sign[0], same_z = sign[2] == sign[0];
        for (int c = 0; c < 3; ++c)
            bound[c] = std::min(bound[c], kSensitivitySup[same_y][same_z][c]);
    }
    return bound;
}

namespace {

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
    if (film.varies())
        if (const auto closed =
                closed_form_mean(film, c, film.thickness_min_nm, film.thickness_max_nm))
            return *closed;
    const ThinFilmBoundaries<double, 3> boundaries = film.boundaries_from_above(c);
    // (One thickness needs no opaque thickness: thickness_average takes it at once.)
    const double opaque = film.varies() ? opaque_thickness_nm(film, c) : HUGE_VAL;
    return thickness_average_to_opaque(film.thickness_min_nm, film.thickness_max_nm, period, opaque,
                                       [&](double d) {
                                           const auto m = film.reflection_from_above(boundaries, d);
                                           return Rgbd(m[0].a, m[1].a, m[2].a);
                                       });
}

std::complex<double> gulbrandsen_index(double r, double g, double r_max) {
    const double rc = clamp(r, 0.0, r_max), sr = std::sqrt(rc);
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
    constexpr double kFadeNm = 30;  // the film is wholly present from 30 nm on
    const ThinFilmBoundaries<double, 3> boundaries =
        sin_film < 1 ? film.boundaries_from_above(c) : ThinFilmBoundaries<double, 3>{};
    const auto at_thickness = [&](double d) {
        const double t = clamp((d - 1e-9) / (kFadeNm - 1e-9), 0.0, 1.0),
                     presence = t * t * (3 - 2 * t);
        if (!(presence > 0)) return bare;
        Rgbd r(1.0);
        if (sin_film < 1) {
            const auto m = film.reflection_from_above(boundaries, d);
            r = Rgbd(m[0].a, m[1].a, m[2].a);
        }
        return bare * (1 - presence) + r * presence;
    };
    const double lo = film.thickness_min_nm, hi = film.thickness_max_nm;
    if (film.varies() && sin_film < 1 && hi > kFadeNm) {
        // Above the fade the exact film alone, its mean in closed form; below it, numerically.
        const double split = std::max(lo, kFadeNm);
        if (const auto closed = closed_form_mean(film, c, split, hi)) {
            const double w_closed = (hi - split) / (hi - lo);
            if (!(split > lo)) return *closed;
            return *closed * w_closed +
                   thickness_average(lo, split, period, at_thickness) * (1 - w_closed);
        }
    }
    // Past the fade, and past where the film is opaque (or totally reflecting), at_thickness is
    // constant.
    const double opaque = !film.varies() ? HUGE_VAL
                          : sin_film < 1 ? std::max(opaque_thickness_nm(film, c), kFadeNm)
                                         : kFadeNm;
    return thickness_average_to_opaque(lo, hi, period, opaque, at_thickness);
}

namespace {

/// three.js's film fades into the outside medium over its first 0.03 nm of thickness.
constexpr double kThreejsFadeNm = 0.03;

/// What three.js's evalIridescence computes before the thickness enters, at thickness_nm: the
/// film's index, the cosine inside it, and per channel the Airy sum's DC term and its first two
/// orders' coefficients and phases (Belcour & Barla, Eq. 10). Beyond the fade all of it is the
/// same for every thickness.
struct ThreejsFilmTerms {
    bool total_reflection = false;
    double iridescence_ior = 1, cos_theta_2 = 1;
    Rgbd dc, c1, c2, phi;
};

ThreejsFilmTerms threejs_film_terms(double outside_ior, double film_ior, double cos_theta_1,
                                    double thickness_nm, const Rgbd& base_f0) {
    const double pi = std::numbers::pi;
    ThreejsFilmTerms out;
    // The film's index goes to the outside's as the thickness goes to 0 (over 0.03 nm).
    const double t = clamp(thickness_nm / kThreejsFadeNm, 0.0, 1.0);
    out.iridescence_ior = outside_ior + (film_ior - outside_ior) * t * t * (3 - 2 * t);
    // Snell's law into the film; total internal reflection reflects everything.
    const double sin2_theta_2 = sqr(outside_ior / out.iridescence_ior) * (1 - sqr(cos_theta_1));
    const double cos2_theta_2 = 1 - sin2_theta_2;
    if (cos2_theta_2 < 0) {
        out.total_reflection = true;
        return out;
    }
    out.cos_theta_2 = std::sqrt(cos2_theta_2);
    // The first boundary by Schlick's approximation; its phase 0 or π (Belcour & Barla, Eq. 9).
    const double R12 =
        schlick_sg(normal_reflectance(out.iridescence_ior, outside_ior), cos_theta_1);
    const double T121 = 1 - R12;
    const double phi12 = out.iridescence_ior < outside_ior ? pi : 0.0;
    const double phi21 = pi - phi12;
    // The base read as a dielectric of the index its F0 gives against air (F0 clamped to
    // [0, 0.9999]), Schlick's approximation at the film's cosine, its phase 0 or π.
    for (int c = 0; c < 3; ++c) {
        const double s = std::sqrt(clamp(base_f0[c], 0.0, 0.9999));
        const double base_ior = (1 + s) / (1 - s);
        const double R23 =
            schlick_sg(normal_reflectance(base_ior, out.iridescence_ior), out.cos_theta_2);
        out.phi[c] = phi21 + (base_ior < out.iridescence_ior ? pi : 0.0);
        // Belcour & Barla, Eq. 10: the DC term and the first two orders of the Airy sum in
        // Fourier space.
        const double R123 = clamp(R12 * R23, 1e-5, 0.9999);
        const double r123 = std::sqrt(R123);
        const double Rs = sqr(T121) * R23 / (1 - R123);
        out.dc[c] = R12 + Rs;
        out.c1[c] = (Rs - T121) * r123;
        out.c2[c] = out.c1[c] * r123;
    }
    return out;
}

/// The optical path difference 2 η d cos θ2 of one round trip in the film.
double threejs_opd(const ThreejsFilmTerms& terms, double thickness_nm) {
    return 2 * terms.iridescence_ior * thickness_nm * terms.cos_theta_2;
}

}  // namespace

std::optional<Rgbd> threejs_iridescence_range_closed_form(double outside_ior, double film_ior,
                                                          double cos_theta_1, double min_nm,
                                                          double max_nm, const Rgbd& base_f0) {
    if (!(min_nm >= kThreejsFadeNm && max_nm > min_nm)) return std::nullopt;
    const ThreejsFilmTerms terms =
        threejs_film_terms(outside_ior, film_ior, cos_theta_1, min_nm, base_f0);
    if (terms.total_reflection) return Rgbd(1.0);
    const double opd0 = threejs_opd(terms, min_nm), opd1 = threejs_opd(terms, max_nm);
    const Rgbd bound1 = belcour_sensitivity_srgb_bound(opd0, terms.phi),
               bound2 = belcour_sensitivity_srgb_bound(2 * opd0, terms.phi * 2.0);
    for (int c = 0; c < 3; ++c)
        if (terms.dc[c] - 2 * std::abs(terms.c1[c]) * bound1[c] -
                2 * std::abs(terms.c2[c]) * bound2[c] <
            0)
            return std::nullopt;
    const Rgbd s1 = sensitivity_srgb_mean(opd0, opd1, terms.phi),
               s2 = sensitivity_srgb_mean(2 * opd0, 2 * opd1, terms.phi * 2.0);
    Rgbd I;
    for (int c = 0; c < 3; ++c)
        I[c] = terms.dc[c] + terms.c1[c] * 2 * s1[c] + terms.c2[c] * 2 * s2[c];
    return I;
}

namespace {

/// three.js's film before its final clamp at 0 (Belcour & Barla, Eq. 10: each order's cosine
/// integrated against the sensitivity).
Rgbd threejs_unclamped(double outside_ior, double film_ior, double cos_theta_1, double thickness_nm,
                       const Rgbd& base_f0) {
    const ThreejsFilmTerms terms =
        threejs_film_terms(outside_ior, film_ior, cos_theta_1, thickness_nm, base_f0);
    if (terms.total_reflection) return Rgbd(1.0);
    const double opd = threejs_opd(terms, thickness_nm);
    const Rgbd s1 = belcour_sensitivity_srgb(opd, terms.phi),
               s2 = belcour_sensitivity_srgb(2 * opd, terms.phi * 2.0);
    Rgbd I;
    for (int c = 0; c < 3; ++c) {
        I[c] = terms.dc[c];
        I[c] += terms.c1[c] * 2 * s1[c];
        I[c] += terms.c2[c] * 2 * s2[c];
    }
    return I;
}

/// The root of a function of d with a sign change between lo and hi, by bisection to the last
/// bit.
template <typename F>
double bisect(double lo, double hi, F&& negative_at) {
    const bool negative_lo = negative_at(lo);
    for (int i = 0; i < 200; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi)) break;
        (negative_at(mid) == negative_lo ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

/// Where three.js's film over [min_nm, max_nm] jumps or kinks, so that quadrature between them
/// keeps its order: in the first 0.03 nm the film's index passes each channel's base index (its
/// phase shift jumps by π) and the index at which light is totally reflected in it, and the fade
/// ends; anywhere the
/// clamp at 0 may cut a channel (a kink: the sign changes of the unclamped value, sampled
/// `per_period` times per period of the interference and bisected).
std::vector<double> threejs_breakpoints(double outside_ior, double film_ior, double cos_theta_1,
                                        double min_nm, double max_nm, const Rgbd& base_f0,
                                        double period_nm) {
    std::vector<double> breaks;
    const double fade_hi = std::min(max_nm, kThreejsFadeNm);
    if (min_nm < fade_hi) {
        auto ior = [&](double d) {
            return threejs_film_terms(outside_ior, film_ior, cos_theta_1, d, base_f0)
                .iridescence_ior;
        };
        std::vector<double> jumps = {outside_ior * std::sqrt(std::max(0.0, 1 - sqr(cos_theta_1)))};
        for (int c = 0; c < 3; ++c) {
            const double s = std::sqrt(clamp(base_f0[c], 0.0, 0.9999));
            jumps.push_back((1 + s) / (1 - s));
        }
        for (double v : jumps)
            if ((ior(min_nm) - v) * (ior(fade_hi) - v) < 0)
                breaks.push_back(bisect(min_nm, fade_hi, [&](double d) { return ior(d) < v; }));
        // The fade's end, where the index's second derivative jumps (a feature far narrower than
        // a period).
        if (max_nm > kThreejsFadeNm) breaks.push_back(kThreejsFadeNm);
    }
    constexpr int per_period = 64;
    const int samples = int(std::clamp(std::ceil((max_nm - min_nm) / period_nm) * per_period,
                                       double(per_period), 4096.0));
    Rgbd previous = threejs_unclamped(outside_ior, film_ior, cos_theta_1, min_nm, base_f0);
    for (int i = 1; i <= samples; ++i) {
        const double lo = min_nm + (max_nm - min_nm) * (i - 1) / samples,
                     hi = min_nm + (max_nm - min_nm) * i / samples;
        const Rgbd next = threejs_unclamped(outside_ior, film_ior, cos_theta_1, hi, base_f0);
        for (int c = 0; c < 3; ++c)
            if ((previous[c] < 0) != (next[c] < 0))
                breaks.push_back(bisect(lo, hi, [&](double d) {
                    return threejs_unclamped(outside_ior, film_ior, cos_theta_1, d, base_f0)[c] < 0;
                }));
        previous = next;
    }
    std::sort(breaks.begin(), breaks.end());
    return breaks;
}

}  // namespace

Rgbd threejs_iridescence(double outside_ior, double film_ior, double cos_theta_1,
                         double thickness_nm, const Rgbd& base_f0) {
    Rgbd I = threejs_unclamped(outside_ior, film_ior, cos_theta_1, thickness_nm, base_f0);
    for (int c = 0; c < 3; ++c)
        I[c] = std::max(I[c], 0.0);
    return I;
}

Rgbd threejs_iridescence_range(double outside_ior, double film_ior, double cos_theta_1,
                               double min_nm, double max_nm, const Rgbd& base_f0) {
    if (!(max_nm > min_nm))
        return threejs_iridescence(outside_ior, film_ior, cos_theta_1, max_nm, base_f0);
    // Beyond the fade, in closed form where that is exact.
    const double split = clamp(kThreejsFadeNm, min_nm, max_nm);
    Rgbd sum(0.0);
    double rest_lo = min_nm, rest_hi = max_nm;
    if (max_nm > split)
        if (const auto closed = threejs_iridescence_range_closed_form(
                outside_ior, film_ior, cos_theta_1, split, max_nm, base_f0)) {
            sum += *closed * (max_nm - split);
            rest_hi = split;
        }
    if (rest_hi > rest_lo) {
        // The rest by quadrature between the film's jumps and kinks. The sensitivity's fastest
        // cosine, 2.2399e6 m⁻¹ of optical path 2 η d cos θ2, turns in the second order with a
        // period in d of at least 1/(2 · 2.2399e6 · 1e-9 · 2 η) nm (η at most the larger of the
        // film's and the outside's index, between which the fade moves it).
        const double period =
            1 / (2 * 2.2399e6 * 1e-9 * 2 * std::max({film_ior, outside_ior, 1e-3}));
        auto at_thickness = [&](double d) {
            return threejs_iridescence(outside_ior, film_ior, cos_theta_1, d, base_f0);
        };
        std::vector<double> edges = threejs_breakpoints(outside_ior, film_ior, cos_theta_1, rest_lo,
                                                        rest_hi, base_f0, period);
        edges.insert(edges.begin(), rest_lo);
        edges.push_back(rest_hi);
        for (std::size_t i = 0; i + 1 < edges.size(); ++i)
            if (edges[i + 1] > edges[i])
                sum += thickness_average(edges[i], edges[i + 1], period, at_thickness) *
                       (edges[i + 1] - edges[i]);
    }
    return sum / (max_nm - min_nm);
}

namespace {

/// A not-a-knot cubic spline through (x0 + i h, y_i) (de Boor, "A Practical Guide to Splines",
/// chapter IV: the third derivative continuous at the second and the last but one knot), as
/// scipy's CubicSpline builds it by default; 0 outside the knots.
class UniformSpline {
  public:
    UniformSpline(double x0, double h, std::vector<double> y) : x0_(x0), h_(h), y_(std::move(y)) {
        // Second derivatives m_i: m_{i−1} + 4 m_i + m_{i+1} = 6 (y_{i+1} − 2 y_i + y_{i−1})/h²
        // inside, m_0 − 2 m_1 + m_2 = 0 and its mirror at the end (not-a-knot), by Gaussian
        // elimination with partial pivoting (n ≈ 100).
        const int n = int(y_.size());
        std::vector<std::vector<double>> a(std::size_t(n), std::vector<double>(std::size_t(n + 1)));
        auto at = [&](int r, int c) -> double& { return a[std::size_t(r)][std::size_t(c)]; };
        at(0, 0) = 1, at(0, 1) = -2, at(0, 2) = 1;
        at(n - 1, n - 3) = 1, at(n - 1, n - 2) = -2, at(n - 1, n - 1) = 1;
        for (int i = 1; i + 1 < n; ++i) {
            at(i, i - 1) = 1, at(i, i) = 4, at(i, i + 1) = 1;
            at(i, n) = 6 *
                       (y_[std::size_t(i + 1)] - 2 * y_[std::size_t(i)] + y_[std::size_t(i - 1)]) /
                       (h_ * h_);
        }
        for (int c = 0; c < n; ++c) {
            int pivot = c;
            for (int r = c + 1; r < n; ++r)
                if (std::abs(at(r, c)) > std::abs(at(pivot, c))) pivot = r;
            std::swap(a[std::size_t(c)], a[std::size_t(pivot)]);
            for (int r = c + 1; r < n; ++r) {
                const double f = at(r, c) / at(c, c);
                if (f == 0) continue;
                for (int k = c; k <= n; ++k)
                    at(r, k) -= f * at(c, k);
            }
        }
        m_.assign(std::size_t(n), 0.0);
        for (int r = n - 1; r >= 0; --r) {
            double v = at(r, n);
            for (int k = r + 1; k < n; ++k)
                v -= at(r, k) * m_[std::size_t(k)];
            m_[std::size_t(r)] = v / at(r, r);
        }
    }
    double operator()(double x) const {
        const double t = (x - x0_) / h_;
        const int n = int(y_.size());
        if (!(t >= 0) || t > n - 1) return 0;
        const int i = std::min(int(t), n - 2);
        const double b = t - i, a = 1 - b;
        const auto u = std::size_t(i);
        return a * y_[u] + b * y_[u + 1] +
               ((a * a * a - a) * m_[u] + (b * b * b - b) * m_[u + 1]) * h_ * h_ / 6;
    }

  private:
    double x0_, h_;
    std::vector<double> y_, m_;
};

}  // namespace

CyclesFilmSensitivity::CyclesFilmSensitivity() {
    // The CIE rows continued by a zero row one step beyond each end.
    constexpr double kFirstNm = 360, kStepNm = 5;
    std::array<std::vector<double>, 3> rows;
    for (auto& r : rows)
        r.push_back(0.0);
    for (int i = 0; i < kCie1931Rows; ++i) {
        const Rgbd v = cie1931_cmf_row(i);
        for (int c = 0; c < 3; ++c)
            rows[std::size_t(c)].push_back(v[c]);
    }
    for (auto& r : rows)
        r.push_back(0.0);
    std::vector<UniformSpline> cmf;
    for (auto& r : rows)
        cmf.emplace_back(kFirstNm - kStepNm, kStepNm, r);
    // The functions of the wavenumber ν (µm⁻¹) on Cycles' grid: x̄(1/ν)/ν² (dλ = dν/ν²).
    constexpr int kSamples = 1022;
    const double dnu = std::numbers::pi / 60;
    std::vector<Rgbd> samples(kSamples, Rgbd(0.0));
    for (int k = 1; k < kSamples; ++k) {
        const double nu = k * dnu, lambda_nm = 1000 / nu;
        for (int c = 0; c < 3; ++c)
            samples[std::size_t(k)][c] = cmf[std::size_t(c)](lambda_nm) / (nu * nu);
    }
    // Their discrete Fourier transform, in linear sRGB, each channel over its DC term.
    using C = std::complex<double>;
    std::array<C, 3> dc{};
    for (int j = 0; j < kSize; ++j) {
        std::array<C, 3> xyz{};
        for (int k = 0; k < kSamples; ++k) {
            // e^(−2πi jk/N) with jk reduced modulo N (exact in integers).
            const double phase =
                -2 * std::numbers::pi * double((long(j) * k) % kSamples) / kSamples;
            const C w(std::cos(phase), std::sin(phase));
            for (int c = 0; c < 3; ++c)
                xyz[std::size_t(c)] += samples[std::size_t(k)][c] * w;
        }
        const std::array<C, 3> rgb = xyz_to_srgb_7_digits(xyz);
        if (j == 0)
            for (int c = 0; c < 3; ++c)
                dc[std::size_t(c)] = rgb[std::size_t(c)].real();
        for (int c = 0; c < 3; ++c)
            table_[c][j] = rgb[std::size_t(c)] / dc[std::size_t(c)];
    }
    for (int c = 0; c < 3; ++c) {
        running_[c][0] = 0;
        for (int j = 1; j < kSize; ++j)
            running_[c][j] = running_[c][j - 1] + (table_[c][j - 1] + table_[c][j]) / 2.0;
        for (int j = 0; j < kSize; ++j)
            max_magnitude_[c] = std::max(max_magnitude_[c], std::abs(table_[c][j]));
    }
}

const CyclesFilmSensitivity& CyclesFilmSensitivity::get() {
    static const CyclesFilmSensitivity table;
    return table;
}

std::complex<double> CyclesFilmSensitivity::operator()(int channel, double opd_nm) const {
    // The table spans kPerNm · OPD ∈ [0, 1]: OPD up to 60 µm/2π; beyond, its last entry.
    const double x = clamp(kPerNm * opd_nm, 0.0, 1.0) * (kSize - 1);
    const int i = std::min(int(x), kSize - 1), next = std::min(i + 1, kSize - 1);
    const double t = x - i;
    return table_[channel][i] * (1 - t) + table_[channel][next] * t;
}

std::complex<double> CyclesFilmSensitivity::integral(int channel, double x) const {
    const std::complex<double>* e = table_[channel];
    if (x >= kSize - 1)  // beyond the table the lookup holds its last entry
        return running_[channel][kSize - 1] + (x - (kSize - 1)) * e[kSize - 1];
    const int i = int(x);
    const double t = x - i;
    return running_[channel][i] + t * e[i] + (t * t / 2) * (e[i + 1] - e[i]);
}

std::complex<double> CyclesFilmSensitivity::mean(int channel, double opd0_nm,
                                                 double opd1_nm) const {
    const double to_x = kPerNm * (kSize - 1);
    const double x0 = std::max(opd0_nm, 0.0) * to_x, x1 = std::max(opd1_nm, 0.0) * to_x;
    if (!(x1 > x0)) return (*this)(channel, opd1_nm);
    return (integral(channel, x1) - integral(channel, x0)) / (x1 - x0);
}

namespace {

/// r/|r| (1 for r = 0): the phase of a reflection as a unit phasor, as Cycles forms it
/// (fresnel_dielectric_polarized's sign, fresnel_conductor_polarized's phasors).
std::complex<double> phasor(std::complex<double> r) {
    const double m = std::abs(r);
    return m > 0 ? r / m : std::complex<double>(1.0);
}

/// Belcour & Barla 2017, Eq. 10 to the third order (Cycles' iridescence_airy_summation_channel,
/// their shader's loop), R = (R12 + R_s) S(0) + Σ_m 2 C_m Re(e^(imφ) conj(S(m OPD))),
/// C_m = (R_s − T121) r123^m, for one polarization with the boundaries' reflectances R12, R23 and
/// the round trip's phasor e^(iφ); S(0) is real (1 for a sensitivity normalized to white, as
/// Cycles' table is). The sum R, its DC term (R12 + R_s) S(0), and the orders' largest swing about
/// it, Σ_m 2|C_m| s_max, for a sensitivity of magnitude at most s_max (|R − DC| ≤ swing whatever
/// the OPD).
struct AirySum {
    double R, dc, swing;
};
template <typename Sensitivity>
AirySum airy_summation(const Sensitivity& sensitivity, double R12, double R23, double opd,
                       std::complex<double> round_trip, double s_max) {
    const double T121 = 1 - R12, R123 = R12 * R23, r123 = std::sqrt(R123);
    const double Rs = T121 * T121 * R23 / (1 - R123);
    const double dc = (R12 + Rs) * sensitivity(0.0).real();
    AirySum out{dc, dc, 0};
    double Cm = Rs - T121;
    std::complex<double> power = round_trip;
    for (int m = 1; m <= 3; ++m) {
        Cm *= r123;
        const std::complex<double> S = sensitivity(m * opd);
        out.R += Cm * 2 * (power.real() * S.real() + power.imag() * S.imag());
        out.swing += std::abs(Cm) * 2 * s_max;
        power *= round_trip;
    }
    return out;
}

}  // namespace

namespace {

/// What Cycles' film sum takes from the boundaries at one incidence and film index: their
/// reflectances R12, R23 and the round trip's phasor, per polarization (s, p), and the film's
/// normal wave number u2 = √(η² − sin²θ1) (the OPD is 2 d u2); or a total reflection. For films of
/// 1 nm and more (where the index blend is over) nothing here depends on the thickness.
struct CyclesFilmTerms {
    bool total = true;
    double R12[2] = {}, R23[2] = {};
    std::complex<double> round_trip[2] = {};
    double u2 = 0;
};

/// The terms at the film index η = film_ior blended as Cycles blends it below 1 nm of thickness.
CyclesFilmTerms cycles_film_terms(double film_ior, double thickness_nm,
                                  const CyclesFilmSubstrate& substrate, double cos_theta_1) {
    using C = std::complex<double>;
    CyclesFilmTerms t;
    const double c1 = clamp(cos_theta_1, 0.0, 1.0), sin2 = 1 - c1 * c1;
    // Below 1 nm the film's index goes to the ambient's (1).
    double eta = film_ior;
    if (thickness_nm < 1) {
        const double b = clamp(thickness_nm, 0.0, 1.0);
        eta = 1 + (film_ior - 1) * b * b * (3 - 2 * b);
    }
    // Total reflection at the first boundary (Cycles: at η² − sin²θ1 ≤ 0).
    if (!(eta * eta - sin2 > 0)) return t;
    const C u1(c1), u2(std::sqrt(eta * eta - sin2));
    const FresnelAmplitudes<double> top = fresnel_amplitudes<double>(C(1), u1, C(eta), u2);
    // Grazing incidence: the first boundary reflects everything (Cycles returns 1 there too).
    if (std::norm(top.r_s) == 1 && std::norm(top.r_p) == 1) return t;
    // The second boundary, relative to the film (reference medium: the ambient, index 1).
    const C substrate_eta(substrate.n, substrate.conductor ? substrate.k : 0.0);
    if (!substrate.conductor && !(substrate.n * substrate.n - sin2 > 0)) return t;
    const C u3 = normal_wave_number(substrate_eta, sin2);
    const FresnelAmplitudes<double> bottom =
        fresnel_amplitudes<double>(C(eta), u2, substrate_eta, u3);
    double R23_s = std::norm(bottom.r_s), R23_p = std::norm(bottom.r_p);
    if (substrate.conductor && substrate.f82 >= 0) {
        // The F82 model with the normal reflectance of the metal relative to the film and the
        // value f82 at 82° (Cycles passes the metal's F82 against the ambient).
        const double n = substrate.n / eta, k = substrate.k / eta;
        const double f0 = (sqr(n - 1) + k * k) / (sqr(n + 1) + k * k);
        const double tint = substrate.f82 / f82_tint_fresnel(1.0 / 7, f0, 1.0);
        R23_s = R23_p = f82_tint_fresnel(u2.real() / eta, f0, tint);
    }
    // The round trip's phasor e^(i(φ23 + φ21)), φ21 = φ12 + π.
    t.total = false;
    t.R12[0] = std::norm(top.r_s);
    t.R12[1] = std::norm(top.r_p);
    t.R23[0] = R23_s;
    t.R23[1] = R23_p;
    t.round_trip[0] = -phasor(bottom.r_s) * phasor(top.r_s);
    t.round_trip[1] = -phasor(bottom.r_p) * phasor(top.r_p);
    t.u2 = u2.real();
    return t;
}

/// Cycles' film before its final clamp, from its terms at thickness_nm: the mean of the s and p
/// sums, their DC terms' mean and their swings' mean (AirySum); a total reflection is {1, 1, 0}.
template <typename Sensitivity>
AirySum cycles_film_sum(const Sensitivity& sensitivity, double s_max, const CyclesFilmTerms& t,
                        double thickness_nm) {
    if (t.total) return {1, 1, 0};
    const double opd = 2 * thickness_nm * t.u2;  // 2 η d cos θ2
    const AirySum R_s =
        airy_summation(sensitivity, t.R12[0], t.R23[0], opd, t.round_trip[0], s_max);
    const AirySum R_p =
        airy_summation(sensitivity, t.R12[1], t.R23[1], opd, t.round_trip[1], s_max);
    return {0.5 * (R_s.R + R_p.R), 0.5 * (R_s.dc + R_p.dc), 0.5 * (R_s.swing + R_p.swing)};
}

/// The same from the film's index, thickness, substrate and incidence.
template <typename Sensitivity>
AirySum cycles_film_sum(const Sensitivity& sensitivity, double s_max, double film_ior,
                        double thickness_nm, const CyclesFilmSubstrate& substrate,
                        double cos_theta_1) {
    return cycles_film_sum(sensitivity, s_max,
                           cycles_film_terms(film_ior, thickness_nm, substrate, cos_theta_1),
                           thickness_nm);
}

template <typename Sensitivity>
double cycles_film(const Sensitivity& sensitivity, double film_ior, double thickness_nm,
                   const CyclesFilmSubstrate& substrate, double cos_theta_1) {
    return clamp(
        cycles_film_sum(sensitivity, 1.0, film_ior, thickness_nm, substrate, cos_theta_1).R, 0.0,
        1.0);
}

}  // namespace

double cycles_film_reflectance(int channel, double film_ior, double thickness_nm,
                               const CyclesFilmSubstrate& substrate, double cos_theta_1) {
    const CyclesFilmSensitivity& table = CyclesFilmSensitivity::get();
    return cycles_film([&](double opd) { return table(channel, opd); }, film_ior, thickness_nm,
                       substrate, cos_theta_1);
}

double cycles_film_reflectance_monochromatic(double wavelength_nm, double film_ior,
                                             double thickness_nm,
                                             const CyclesFilmSubstrate& substrate,
                                             double cos_theta_1) {
    return cycles_film(
        [&](double opd) { return std::polar(1.0, -2 * std::numbers::pi * opd / wavelength_nm); },
        film_ior, thickness_nm, substrate, cos_theta_1);
}

namespace {

/// The Dinc (µm) from which Belcour & Barla's shader takes the film's own index.
constexpr double kBelcourBarlaBlendEndUm = 0.03;

/// airy_summation's bound on the sensitivity where its swing is not read.
constexpr double kNoBound = std::numeric_limits<double>::quiet_NaN();

/// Belcour & Barla's shader before its final clamp, channel c of its colour (CIE 1931 RGB, or
/// linear sRGB over white for the ablation; the shader's Fresnel term, its Airy function;
/// docs/models.md, "Belcour & Barla 2017"): the mean of the s and p sums. xyz_of_opd gives the
/// fit's G at an OPD (sensitivity_xyz, or a memo of it). The sums' swing is not read: no
/// closed-form mean over a thickness range is taken (the bound it would need, Σ_j |M_cj| G_j(0),
/// exceeds the DC term on every film tried, metals and MgF2 on glass alike).
template <typename XyzOfOpd>
double belcour_barla_sum(int channel, double film_ior, double dinc_um, double base_eta,
                         double base_kappa, double cos_theta_1, BelcourBarlaPrimaries primaries,
                         const XyzOfOpd& xyz_of_opd) {
    using C = std::complex<double>;
    // The sensitivity S = M·G of channel c (M the projection, G the fit's XYZ), handed to
    // airy_summation conjugated (it forms Re(e^(imφ) conj(·))): the shader's Σ M cos(pos t + mφ).
    const std::size_t c = std::size_t(channel);
    const std::array<std::complex<double>, 3> white_xyz = xyz_of_opd(0.0);
    const double srgb_white =
        primaries == BelcourBarlaPrimaries::Srgb ? xyz_to_srgb_7_digits(white_xyz)[c].real() : 1.0;
    const auto sensitivity = [&](double opd_nm) {
        const std::array<std::complex<double>, 3> xyz = xyz_of_opd(opd_nm);
        if (primaries == BelcourBarlaPrimaries::Srgb)
            return std::conj(xyz_to_srgb_7_digits(xyz)[c] / srgb_white);
        return std::conj(xyz_to_cie_rgb_7_digits(xyz)[c]);
    };
    // "Force eta_2 -> 1.0 when Dinc -> 0.0": the film's index blends from the ambient's over the
    // first 0.03 µm of Dinc (smoothstep); the optical path keeps Dinc itself.
    const double blend = clamp(dinc_um / kBelcourBarlaBlendEndUm, 0.0, 1.0);
    const double eta = 1 + (film_ior - 1) * blend * blend * (3 - 2 * blend);
    const double c1 = clamp(cos_theta_1, 0.0, 1.0), sin2 = 1 - c1 * c1;
    const double dc_only = sensitivity(0.0).real();
    // A film of lower index than the ambient would reflect totally at grazing facets, where the
    // shader leaves the reflectance unset: no value is the shader's there (the model refuses such
    // films); lamina returns total reflection. At grazing incidence the first boundary reflects
    // everything: the DC term alone.
    if (!(eta * eta - sin2 > 0) || c1 == 0) return dc_only;
    const C u1(c1), u2(std::sqrt(eta * eta - sin2));
    const FresnelAmplitudes<double> top = fresnel_amplitudes<double>(C(1), u1, C(eta), u2);
    // The base's index as the shader's fresnelConductor forms it: η3 (1 + iκ3), so that its
    // A = η3²(1 − κ3²) − sin²θ and 2η3²κ3 are the real and imaginary parts of η3²(1 + iκ3)² −
    // sin²θ.
    const C base(base_eta, base_eta * base_kappa);
    const FresnelAmplitudes<double> bottom =
        fresnel_amplitudes<double>(C(eta), u2, base, normal_wave_number(base, sin2));
    // Both boundaries reflecting everything (a facet so near grazing that R12 rounds to 1 over a
    // totally reflecting base): the sum's R_s is 0/0, its limit the DC term alone.
    for (const double product :
         {std::norm(top.r_s) * std::norm(bottom.r_s), std::norm(top.r_p) * std::norm(bottom.r_p)})
        if (!(product < 1)) return dc_only;
    const double opd = dinc_um * 1000 * (u2.real() / eta);  // Dinc cos θ2, nm
    // φ2 = φ21 + φ23 with φ21 = π − φ12.
    const auto round_trip = [](C r12, C r23) { return -std::conj(phasor(r12)) * phasor(r23); };
    const AirySum sum_s = airy_summation(sensitivity, std::norm(top.r_s), std::norm(bottom.r_s),
                                         opd, round_trip(top.r_s, bottom.r_s), kNoBound);
    const AirySum sum_p = airy_summation(sensitivity, std::norm(top.r_p), std::norm(bottom.r_p),
                                         opd, round_trip(top.r_p, bottom.r_p), kNoBound);
    return 0.5 * (sum_s.R + sum_p.R);
}

/// A function of the OPD remembered at its last four arguments: the three channels of one
/// evaluation, and each channel's s and p sums, read the fit at the same four OPDs (0 and the
/// three orders'), bit for bit the same arguments.
template <typename F>
class OpdMemo {
  public:
    explicit OpdMemo(const F& f) : f_(f) {}
    std::array<std::complex<double>, 3> operator()(double opd_nm) const {
        for (int i = 0; i < used_; ++i)
            if (key_[i] == opd_nm) return value_[i];
        const int slot = used_ < kSlots ? used_++ : (next_++ % kSlots);
        key_[slot] = opd_nm;
        value_[slot] = f_(opd_nm);
        return value_[slot];
    }

  private:
    static constexpr int kSlots = 4;
    const F& f_;
    mutable double key_[kSlots] = {};
    mutable std::array<std::complex<double>, 3> value_[kSlots] = {};
    mutable int used_ = 0, next_ = 0;
};

/// The period in Dinc (µm) of the sum's fastest term, the third order's phase 2π·3·Dinc cos θ2/λ,
/// at its shortest: λ = 360 nm.
constexpr double kBelcourBarlaPeriodUm = 0.36 / 3;

}  // namespace

double belcour_barla_fresnel(int channel, double film_ior, double dinc_um, double base_eta,
                             double base_kappa, double cos_theta_1,
                             BelcourBarlaPrimaries primaries) {
    return clamp(belcour_barla_sum(channel, film_ior, dinc_um, base_eta, base_kappa, cos_theta_1,
                                   primaries, sensitivity_xyz),
                 0.0, 1.0);
}

Rgbd belcour_barla_fresnel(double film_ior, double dinc_um, const Rgbd& base_eta,
                           const Rgbd& base_kappa, double cos_theta_1,
                           BelcourBarlaPrimaries primaries) {
    const auto fit = [](double opd_nm) { return sensitivity_xyz(opd_nm); };
    const OpdMemo<decltype(fit)> memo(fit);
    Rgbd F;
    for (int c = 0; c < 3; ++c)
        F[c] = clamp(belcour_barla_sum(c, film_ior, dinc_um, base_eta[c], base_kappa[c],
                                       cos_theta_1, primaries, memo),
                     0.0, 1.0);
    return F;
}

Rgbd belcour_barla_fresnel_range(double film_ior, double dinc_min_um, double dinc_max_um,
                                 const Rgbd& base_eta, const Rgbd& base_kappa, double cos_theta_1,
                                 BelcourBarlaPrimaries primaries) {
    constexpr double end = kBelcourBarlaBlendEndUm;
    const auto mean = [&](double lo, double hi) {
        return thickness_average(lo, hi, kBelcourBarlaPeriodUm, [&](double dinc) {
            return belcour_barla_fresnel(film_ior, dinc, base_eta, base_kappa, cos_theta_1,
                                         primaries);
        });
    };
    // The film's index stops blending at kBelcourBarlaBlendEndUm, where the term's second
    // derivative jumps: the quadrature takes the two sides apart.
    if (dinc_min_um < end && dinc_max_um > end)
        return (mean(dinc_min_um, end) * (end - dinc_min_um) +
                mean(end, dinc_max_um) * (dinc_max_um - end)) /
               (dinc_max_um - dinc_min_um);
    return mean(dinc_min_um, dinc_max_um);
}

namespace {

/// Cycles' F82-tint metal of channel c as its film sees it: Gulbrandsen's n + ik of
/// r = min(f0, 0.999) and g = the F82-tint reflectance at 1/7, and f82 = g.
CyclesFilmSubstrate cycles_f82_tint_substrate(double f0, double tint) {
    const double g = f82_tint_fresnel(1.0 / 7, f0, tint);
    const std::complex<double> index = gulbrandsen_index(std::min(f0, 0.999), g, 0.999);
    return {true, index.real(), index.imag(), g};
}

}  // namespace

Rgbd cycles_f82_tint_film(double film_ior, double thickness_nm, const Rgbd& f0, const Rgbd& tint,
                          double cos_theta) {
    Rgbd F;
    for (int c = 0; c < 3; ++c) {
        if (!(thickness_nm > kCyclesFilmCutoffNm)) {
            F[c] = f82_tint_fresnel(cos_theta, f0[c], tint[c]);
            continue;
        }
        F[c] = cycles_film_reflectance(c, film_ior, thickness_nm,
                                       cycles_f82_tint_substrate(f0[c], tint[c]), cos_theta);
    }
    return F;
}

namespace {

/// Cycles' film over the substrate of each channel averaged over the thickness range [min_nm,
/// max_nm]: the sensitivity's exact mean where Cycles' final clamp cannot act and the range lies
/// above the 1 nm of the index blend (cycles_f82_tint_film_range), else Gauss–Legendre of
/// `at_thickness` (the film at one thickness, the cutoff included). A range across the cutoff
/// or 1 nm is its parts' weighted means: no quadrature straddles the cutoff's step, and the exact
/// mean covers all but the first nanometre (by quadrature alone a range of 10 µm takes thousands
/// of films per call).
template <typename AtThickness>
Rgbd cycles_film_range(double film_ior, double min_nm, double max_nm,
                       const std::array<CyclesFilmSubstrate, 3>& substrate, double cos_theta,
                       AtThickness&& at_thickness) {
    for (const double split : {kCyclesFilmCutoffNm, 1.0})
        if (min_nm < split && max_nm > split) {
            const Rgbd below =
                cycles_film_range(film_ior, min_nm, split, substrate, cos_theta, at_thickness);
            const Rgbd above =
                cycles_film_range(film_ior, split, max_nm, substrate, cos_theta, at_thickness);
            return (below * (split - min_nm) + above * (max_nm - split)) / (max_nm - min_nm);
        }
    // From the thickness at which the first order's OPD, 2 d √(η² − sin²θ1), reaches the lookup's
    // end, every order reads its last entry: the film no longer changes with d (a range of
    // micrometres would otherwise take the quadrature's 2048 films at every call).
    if (const double u2_sq = film_ior * film_ior - (1 - sqr(clamp(cos_theta, 0.0, 1.0)));
        min_nm >= 1 && u2_sq > 0) {
        const double saturated_nm = 1 / (CyclesFilmSensitivity::kPerNm * 2 * std::sqrt(u2_sq));
        if (max_nm > saturated_nm) {
            const double split = std::max(min_nm, saturated_nm);
            const Rgbd thick = at_thickness(max_nm);
            if (!(split > min_nm)) return thick;
            return (cycles_film_range(film_ior, min_nm, split, substrate, cos_theta, at_thickness) *
                        (split - min_nm) +
                    thick * (max_nm - split)) /
                   (max_nm - min_nm);
        }
    }
    // The third order's phase 2π · 3 · 2 η d cos θ2/λ has a period in d of at least
    // λ_min/(6 η), λ_min = 360 nm.
    const double period = 360 / (6 * std::max(film_ior, 1e-3));
    if (!(max_nm > min_nm && min_nm >= 1))
        return thickness_average(min_nm, max_nm, period, at_thickness);
    // Every quantity but the OPD is the same at every thickness ≥ 1 nm (CyclesFilmTerms), and the
    // OPD is proportional to d: evaluated at max_nm, order m reads the sensitivity's mean over
    // [m OPD min_nm/max_nm, m OPD].
    const CyclesFilmSensitivity& table = CyclesFilmSensitivity::get();
    CyclesFilmTerms terms[3];
    for (int c = 0; c < 3; ++c)
        terms[c] = cycles_film_terms(film_ior, max_nm, substrate[std::size_t(c)], cos_theta);
    const double ratio = min_nm / max_nm;
    Rgbd F;
    bool exact = true;
    for (int c = 0; c < 3 && exact; ++c) {
        const AirySum sum =
            cycles_film_sum([&](double opd) { return table.mean(c, opd * ratio, opd); },
                            table.max_magnitude(c), terms[c], max_nm);
        exact = sum.dc - sum.swing >= 0 && sum.dc + sum.swing <= 1;
        F[c] = sum.R;
    }
    if (exact) return F;
    // Where the clamp can act: the film at each node from the same terms (the film at that
    // thickness, as at_thickness gives it).
    return thickness_average(min_nm, max_nm, period, [&](double d) {
        Rgbd R;
        for (int c = 0; c < 3; ++c)
            R[c] = clamp(
                cycles_film_sum([&](double opd) { return table(c, opd); }, 1.0, terms[c], d).R, 0.0,
                1.0);
        return R;
    });
}

}  // namespace

Rgbd cycles_f82_tint_film_range(double film_ior, double min_nm, double max_nm, const Rgbd& f0,
                                const Rgbd& tint, double cos_theta) {
    std::array<CyclesFilmSubstrate, 3> substrate;
    for (int c = 0; c < 3; ++c)
        substrate[std::size_t(c)] = cycles_f82_tint_substrate(f0[c], tint[c]);
    return cycles_film_range(film_ior, min_nm, max_nm, substrate, cos_theta, [&](double d) {
        return cycles_f82_tint_film(film_ior, d, f0, tint, cos_theta);
    });
}

Rgbd cycles_dielectric_film(double film_ior, double thickness_nm, double eta, double cos_theta) {
    // generalized_schlick_fresnel's real-Fresnel case (exponent −η, F0 and F90 the dielectric's
    // own): mix(F0, 1, (F − F0)/(1 − F0)) = F.
    if (!(thickness_nm > kCyclesFilmCutoffNm))
        return Rgbd(fresnel_dielectric(clamp(cos_theta, 0.0, 1.0), eta));
    const CyclesFilmSubstrate substrate{false, eta, 0.0, -1.0};
    Rgbd F;
    for (int c = 0; c < 3; ++c)
        F[c] = cycles_film_reflectance(c, film_ior, thickness_nm, substrate, cos_theta);
    return F;
}

}  // namespace lamina

#pragma once
// A thin film on an interface: the exact reflection and transmission of a homogeneous layer of
// thickness d and complex index η_f (η_f + ik_f, k_f ≥ 0 absorbing) between an incident medium and
// an exit medium (a dielectric, or a conductor of complex index), with the waves inside the film
// added coherently (docs/physics.md §9).
//
// Inside the film the partial waves reflected 0, 1, 2, … times between its two boundaries add as
// amplitudes. With the amplitudes of the boundaries incident | film (r12, t12) and film | exit
// (r23, t23) of fresnel_amplitudes (physics/fresnel.h), Stokes' relations r21 = −r12,
// t12 t21 = 1 − r12² and the phase δ = 2π η_f d cos θ_f / λ of one crossing of the film, the
// geometric series sums to the Airy formulas, separately for s and p (Born & Wolf, "Principles of
// Optics", 7th ed., §1.6.4, the reflection and transmission coefficients of a homogeneous film;
// §7.6.1 for the same sum as multiple-beam interference; Heavens 1955, "Optical Properties of Thin
// Solid Films", the single film):
//
//     r = (r12 + r23 e^{2iδ}) / (1 + r12 r23 e^{2iδ}),   t = t12 t23 e^{iδ} / (1 + r12 r23
//     e^{2iδ}),
//
// and the intensities R = |r|², T = Re(η_3 cos θ3)/(η_1 cos θ1) |t|² (the flux factor of the
// transmitted beam in a real exit medium). With real indices R is the Airy reflectance
// (r12² + r23² + 2 r12 r23 cos 2δ)/(1 + r12² r23² + 2 r12 r23 cos 2δ) that Belcour & Barla 2017,
// "A Practical Extension to Microfacet Theory for the Modeling of Varying Iridescence" (ACM TOG
// 36(4)), expand into Fourier terms. η_f cos θ_f is Snell's invariant carried into the film:
// u_f = √(η_f² − sin²θ1) in units of the incident medium's index, complex for an absorbing film or
// beyond the film's critical angle (frustrated total reflection: the wave tunnels through a thin
// enough film), its root taken with Im u_f ≥ 0 so that e^{2iδ} never grows.
//
// A parallel film does not change directions (Snell's invariant crosses it unchanged), so it acts
// as a modified Fresnel term of the interface it sits on: the Mueller matrices (physics/
// polarization.h, form (*)) of the film's r and t replace the bare interface's at every smooth or
// microfacet event.

#include "core/complex_math.h"
#include "physics/fresnel.h"
#include "physics/polarization.h"
#include "physics/thin_film_airy.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <numbers>

namespace lamina {

template <typename T>
inline LaneFresnelAmplitudes<T> lane_amplitudes(const FresnelAmplitudes<T>& a) {
    return {lane_complex(a.r_s), lane_complex(a.r_p), lane_complex(a.t_s), lane_complex(a.t_p)};
}

/// The film's amplitudes as a whole (r_s, r_p, t_s, t_p: incident medium to exit medium) and the
/// flux factor of its transmitted beam, Re(u_3)/cos θ1 (0 when the exit medium absorbs, a
/// conductor, or when the wave is evanescent there: nothing is transmitted).
template <typename T>
struct ThinFilmAmplitudes {
    FresnelAmplitudes<T> film;
    T transmitted_flux;
};

/// What the Airy sums of one angle of incidence share over every thickness: the film's normal
/// wave number u2 and the amplitudes of both boundaries (fresnel_amplitudes), per exit medium, and
/// the flux factor of the transmitted beam. Within 1e-6 of the film's critical angle in u2² (see
/// thin_film_amplitudes) there are two sets, at u2² ± 1e-6, whose sums are averaged.
template <typename T, std::size_t N>
struct ThinFilmBoundaries {
    int count = 1;  ///< 1, or 2 near the film's critical angle
    std::complex<T> u2[2];
    FresnelAmplitudes<T> upper[2];                 ///< incident | film
    std::array<FresnelAmplitudes<T>, N> lower[2];  ///< film | exit, per exit medium
    std::array<T, N> transmitted_flux;
};

/// The boundaries of thin_film_amplitudes for light arriving at cos_theta_i ∈ [0, 1] (clamped):
/// computed once per angle, then combined with any thickness.
template <typename T, std::size_t N>
ThinFilmBoundaries<T, N> thin_film_boundaries(T cos_theta_i, std::complex<T> eta_film,
                                              const std::array<std::complex<T>, N>& eta_exit) {
    using C = std::complex<T>;
    const T mu = std::min(std::max(cos_theta_i, T(0)), T(1));
    const T sin2 = T(1) - mu * mu;
    const C u1(mu);
    std::array<C, N> u3;
    ThinFilmBoundaries<T, N> b;
    for (std::size_t n = 0; n < N; ++n) {
        u3[n] = normal_wave_number(eta_exit[n], sin2);
        b.transmitted_flux[n] = eta_exit[n].imag() == T(0) && mu > T(0) ? u3[n].real() / mu : T(0);
    }
    // Near the film's critical angle two sums, at u2² ± h, averaged (thin_film_airy.h).
    const C w = eta_film * eta_film - sin2;
    constexpr T kNearCritical = T(kFilmNearCritical);
    if (near_film_critical<T, Lane<T>>(lane_complex(eta_film), sin2)) {
        b.count = 2;
        b.u2[0] = principal_sqrt(w + kNearCritical);
        b.u2[1] = principal_sqrt(w - kNearCritical);
    } else {
        b.u2[0] = normal_wave_number(eta_film, sin2);
    }
    for (int k = 0; k < b.count; ++k) {
        b.upper[k] = fresnel_amplitudes<T>(C(1), u1, eta_film, b.u2[k]);
        for (std::size_t n = 0; n < N; ++n)
            b.lower[k][n] = fresnel_amplitudes<T>(eta_film, b.u2[k], eta_exit[n], u3[n]);
    }
    return b;
}

/// The Airy sums of the header over the boundaries of thin_film_boundaries, the film's thickness
/// given per exit medium as `thickness_waves` = d η_1/λ (d in vacuum wavelengths times the
/// incident medium's absolute index, so that the phase of one crossing is δ = 2π
/// thickness_waves u_f). Thickness 0 gives the bare boundary incident | exit. At an index-matched
/// grazing boundary, where the amplitudes are 0/0, the grazing limit: total reflection
/// (r_s = r_p = −1), nothing transmitted.
template <typename T, std::size_t N>
std::array<ThinFilmAmplitudes<T>, N> thin_film_amplitudes(const ThinFilmBoundaries<T, N>& b,
                                                          const std::array<T, N>& thickness_waves) {
    using C = std::complex<T>;
    using Sums = std::array<FresnelAmplitudes<T>, N>;
    const auto airy = [&](int k) {
        const FresnelAmplitudes<T>& b12 = b.upper[k];
        Sums sums;
        for (std::size_t n = 0; n < N; ++n) {
            const LaneFresnelAmplitudes<T> a =
                airy_sums<T, Lane<T>>(lane_amplitudes(b12), lane_amplitudes(b.lower[k][n]),
                                      lane_complex(b.u2[k]), thickness_waves[n]);
            sums[n] = {std_complex(a.r_s), std_complex(a.r_p), std_complex(a.t_s),
                       std_complex(a.t_p)};
        }
        return sums;
    };
    Sums film;
    if (b.count == 2) {
        const Sums s0 = airy(0), s1 = airy(1);
        for (std::size_t n = 0; n < N; ++n)
            film[n] = {(s0[n].r_s + s1[n].r_s) / T(2), (s0[n].r_p + s1[n].r_p) / T(2),
                       (s0[n].t_s + s1[n].t_s) / T(2), (s0[n].t_p + s1[n].t_p) / T(2)};
    } else {
        film = airy(0);
    }
    std::array<ThinFilmAmplitudes<T>, N> out;
    for (std::size_t n = 0; n < N; ++n) {
        out[n].film = film[n];
        out[n].transmitted_flux = b.transmitted_flux[n];
        const bool finite =
            std::isfinite(squared_modulus(film[n].r_s) + squared_modulus(film[n].r_p) +
                          squared_modulus(film[n].t_s) + squared_modulus(film[n].t_p));
        if (!finite) {  // 0/0 at grazing incidence on an index-matched boundary
            out[n].film = {C(-1), C(-1), C(0), C(0)};
            out[n].transmitted_flux = T(0);
        }
    }
    return out;
}

/// The Airy sums of the header for light arriving from the incident medium at cos_theta_i ∈ [0, 1]
/// (clamped) on a film of complex index eta_film over an exit medium of complex index eta_exit,
/// both relative to the incident medium, with thickness_waves as above: the boundaries of
/// thin_film_boundaries combined with the thickness.
///
/// N films of the same index (relative to the same incident medium) at once, each over its own
/// exit medium and with its own thickness in waves (the channels of one film: their wavelengths
/// and the metal's index at each): the film's normal wave number and its upper boundary's
/// amplitudes are the same for all and computed once.
template <typename T, std::size_t N>
std::array<ThinFilmAmplitudes<T>, N> thin_film_amplitudes(
    T cos_theta_i, std::complex<T> eta_film, const std::array<std::complex<T>, N>& eta_exit,
    const std::array<T, N>& thickness_waves) {
    return thin_film_amplitudes(thin_film_boundaries(cos_theta_i, eta_film, eta_exit),
                                thickness_waves);
}

/// One film over one exit medium.
template <typename T>
ThinFilmAmplitudes<T> thin_film_amplitudes(T cos_theta_i, std::complex<T> eta_film,
                                           std::complex<T> eta_exit, T thickness_waves) {
    return thin_film_amplitudes<T, 1>(cos_theta_i, eta_film, {eta_exit}, {thickness_waves})[0];
}

/// The reflection and transmission Mueller matrices (form (*) of physics/polarization.h, in the s/p
/// frame of the plane of incidence) of the film of thin_film_amplitudes: reflection
/// mueller_of_amplitudes(r_s, r_p, 1), transmission mueller_of_amplitudes(t_s, t_p, Re u_3/cos θ1).
/// Their `a` are the unpolarized reflectance R = (R_s + R_p)/2 and transmittance T; without
/// absorption (real film and exit indices) R + T = 1 for each polarization, and 1 − R − T is what
/// an absorbing film or a conductor exit takes.
template <typename T>
struct ThinFilmMueller {
    InterfaceMueller<T> reflection, transmission;
};

template <typename T>
ThinFilmMueller<T> thin_film_mueller(T cos_theta_i, std::complex<T> eta_film,
                                     std::complex<T> eta_exit, T thickness_waves) {
    const ThinFilmAmplitudes<T> a =
        thin_film_amplitudes(cos_theta_i, eta_film, eta_exit, thickness_waves);
    return {mueller_of_amplitudes(a.film.r_s, a.film.r_p, T(1)),
            mueller_of_amplitudes(a.film.t_s, a.film.t_p, a.transmitted_flux)};
}

/// A film on one interface of a stack as the particle events see it (physics/thin_film_event.h):
/// absolute indices, the channels' wavelengths and the thickness or its range. Light arrives from
/// above (the medium of index eta_above) or, at a dielectric, from below (eta_below, real); the
/// indices relative to the side of arrival are formed here, in double.
struct FilmOptics {
    std::complex<double> eta_film{1.5, 0.0};
    double eta_above = 1.0;
    /// The region below: a dielectric's index (real, every channel) or a conductor's per channel.
    std::complex<double> eta_below[3] = {1.0, 1.0, 1.0};
    double wavelength_nm[3] = {630.0, 532.0, 465.0};
    double thickness_min_nm = 0.0, thickness_max_nm = 0.0;

    bool varies() const { return thickness_max_nm > thickness_min_nm; }
    /// The thickness at the uniform number u ∈ [0, 1): uniform over [min, max].
    double thickness_nm(double u) const {
        return thickness_min_nm + (thickness_max_nm - thickness_min_nm) * u;
    }
    /// The film's Mueller matrices in channel c for light arriving at the facet cosine cos_theta
    /// from above (from_above) or from below, the film thickness_nm thick.
    ThinFilmMueller<double> mueller(int c, double cos_theta, bool from_above,
                                    double thickness_nm) const {
        const double eta_i = from_above ? eta_above : eta_below[c].real();
        const std::complex<double> exit =
            from_above ? eta_below[c] : std::complex<double>(eta_above);
        return thin_film_mueller(cos_theta, eta_film / eta_i, exit / eta_i,
                                 thickness_nm * eta_i / wavelength_nm[c]);
    }
    /// What the film's reflection of light arriving from above at the facet cosine cos_theta
    /// shares over every thickness (its boundaries in the three channels): prepared once per angle
    /// for reflection_from_above at many thicknesses.
    ThinFilmBoundaries<double, 3> boundaries_from_above(double cos_theta) const {
        std::array<std::complex<double>, 3> exit;
        for (int c = 0; c < 3; ++c)
            exit[std::size_t(c)] = eta_below[c] / eta_above;
        return thin_film_boundaries<double, 3>(cos_theta, eta_film / eta_above, exit);
    }
    /// The film's reflection Mueller matrices in the three channels for light arriving from above,
    /// the film thickness_nm thick, from the boundaries of boundaries_from_above.
    std::array<InterfaceMueller<double>, 3> reflection_from_above(
        const ThinFilmBoundaries<double, 3>& boundaries, double thickness_nm) const {
        std::array<double, 3> waves;
        for (int c = 0; c < 3; ++c)
            waves[std::size_t(c)] = thickness_nm * eta_above / wavelength_nm[c];
        const std::array<ThinFilmAmplitudes<double>, 3> a =
            thin_film_amplitudes<double, 3>(boundaries, waves);
        std::array<InterfaceMueller<double>, 3> m;
        for (std::size_t c = 0; c < 3; ++c)
            m[c] = mueller_of_amplitudes(a[c].film.r_s, a[c].film.r_p, 1.0);
        return m;
    }
    /// The film's reflection Mueller matrices in the three channels for light arriving from above
    /// at the facet cosine cos_theta, the film thickness_nm thick: mueller(c, cos_theta, true,
    /// thickness_nm).reflection for c = 0, 1, 2, with what the channels share (the film's index
    /// relative to the medium above, so its wave number and upper boundary) evaluated once.
    std::array<InterfaceMueller<double>, 3> reflection_from_above(double cos_theta,
                                                                  double thickness_nm) const {
        return reflection_from_above(boundaries_from_above(cos_theta), thickness_nm);
    }
};

}  // namespace lamina

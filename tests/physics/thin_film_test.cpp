// The thin film's Airy sums (physics/thin_film.h) against closed forms (the bare interface at
// thickness 0, quarter-wave and half-wave films at normal incidence, MgF2 on glass) and against an
// independent computation written here: the characteristic-matrix method of stratified media
// (Born & Wolf §1.6.2; Macleod, "Thin-Film Optical Filters", ch. 2), 2×2 complex matrices with the
// tilted admittances of s and p light, which never forms a boundary's Fresnel amplitude.
#include "physics/thin_film.h"

#include "physics/fresnel.h"
#include "physics/polarization.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <numbers>

namespace lamina {
namespace {

using C = std::complex<double>;

double reflectance(const ThinFilmMueller<double>& m) {
    return m.reflection.a;
}

// One film by the characteristic matrix: with the tilted admittances y = η cos θ (s) and
// y = η / cos θ (p) of each medium (indices relative to the incident medium, cos θ complex in
// absorbing or evanescent media) and the film's phase thickness δ, the film's matrix is
// [[cos δ, −i sin δ / y_f], [−i y_f sin δ, cos δ]]; [B, C] = M [1, y_3] and
// r = (y_1 B − C)/(y_1 B + C), t_tangential = 2 y_1/(y_1 B + C), R = |r|²,
// T = 4 Re(y_1) Re(y_3) / |y_1 B + C|² for a real exit medium. In this formalism r_p is the ratio
// of tangential fields, the opposite sign of Born & Wolf's r_∥ (docs/physics.md §8's convention).
struct MatrixResult {
    C r;
    double R, T;
};
MatrixResult characteristic_matrix(bool s_polarized, double cos_i, C eta_film, C eta_exit,
                                   double thickness_waves) {
    const double sin_i = std::sqrt(1 - cos_i * cos_i);
    // cos θ in each medium from Snell's law n sin θ = sin θ_i (the root with the decaying wave).
    auto cos_in = [&](C eta) {
        C c = std::sqrt(C(1) - (sin_i / eta) * (sin_i / eta));
        if ((eta * c).imag() < 0) c = -c;
        return c;
    };
    const C cf = cos_in(eta_film), c3 = cos_in(eta_exit);
    auto admittance = [&](C eta, C cos_theta) {
        return s_polarized ? eta * cos_theta : eta / cos_theta;
    };
    const C y1 = admittance(C(1), C(cos_i)), yf = admittance(eta_film, cf),
            y3 = admittance(eta_exit, c3);
    const C delta = 2 * kPi<double> * thickness_waves * eta_film * cf;
    const C i(0, 1);
    const C m11 = std::cos(delta), m12 = -i * std::sin(delta) / yf, m21 = -i * yf * std::sin(delta),
            m22 = std::cos(delta);
    const C b = m11 + m12 * y3, c = m21 + m22 * y3;
    const C r = (y1 * b - c) / (y1 * b + c);
    const double T = 4 * y1.real() * y3.real() / std::norm(y1 * b + c);
    return {r, std::norm(r), eta_exit.imag() == 0 ? T : 0.0};
}

TEST(ThinFilm, ThicknessZeroIsTheBareInterface) {
    // Dielectric exit from both sides (below the critical angle and beyond it), and a conductor.
    for (double cos_i : {1.0, 0.9, 0.6, 0.3, 0.05}) {
        for (double eta : {1.5, 1 / 1.5, 2.4}) {
            const DielectricMueller<double> bare = fresnel_dielectric_mueller(cos_i, eta, 1 / eta);
            const ThinFilmMueller<double> film = thin_film_mueller(cos_i, C(1.38), C(eta), 0.0);
            EXPECT_NEAR(film.reflection.a, bare.reflection.a, 1e-12) << cos_i << " " << eta;
            EXPECT_NEAR(film.reflection.b, bare.reflection.b, 1e-12);
            EXPECT_NEAR(film.reflection.c, bare.reflection.c, 1e-12);
            EXPECT_NEAR(film.reflection.d, bare.reflection.d, 1e-12);
            EXPECT_NEAR(film.transmission.a, bare.transmission.a, 1e-12);
            EXPECT_NEAR(film.transmission.b, bare.transmission.b, 1e-12);
            EXPECT_NEAR(film.transmission.c, bare.transmission.c, 1e-12);
            EXPECT_NEAR(film.transmission.d, bare.transmission.d, 1e-12);
        }
        const InterfaceMueller<double> metal = fresnel_conductor_mueller(cos_i, 0.47, 2.4);
        const ThinFilmMueller<double> film =
            thin_film_mueller(cos_i, C(1.6, 0.2), C(0.47, 2.4), 0.0);
        EXPECT_NEAR(film.reflection.a, metal.a, 1e-12);
        EXPECT_NEAR(film.reflection.b, metal.b, 1e-12);
        EXPECT_NEAR(film.reflection.c, metal.c, 1e-12);
        EXPECT_NEAR(film.reflection.d, metal.d, 1e-12);
        EXPECT_EQ(film.transmission.a, 0.0);
    }
}

TEST(ThinFilm, ThicknessTendsContinuouslyToTheBareInterface) {
    const double bare = fresnel_dielectric(0.7, 1.52);
    double previous = 1;
    for (double d : {1e-1, 1e-2, 1e-3, 1e-4, 1e-5}) {  // in wavelengths
        const double gap = std::abs(reflectance(thin_film_mueller(0.7, C(2.2), C(1.52), d)) - bare);
        EXPECT_LT(gap, previous);
        previous = gap;
    }
    EXPECT_LT(previous, 1e-6);
}

TEST(ThinFilm, QuarterWaveAntiReflectionAtNormalIncidence) {
    // η_f = √(η_1 η_3), η_f d = λ/4: R = 0. At 550 nm on 1.52: η_f = 1.23288, d = 111.53 nm.
    const double n3 = 1.52, nf = std::sqrt(n3);
    const ThinFilmMueller<double> m = thin_film_mueller(1.0, C(nf), C(n3), 0.25 / nf);
    EXPECT_NEAR(reflectance(m), 0.0, 1e-12);
    EXPECT_NEAR(m.transmission.a, 1.0, 1e-12);
    // The thickness in nanometres at 550 nm (thickness_waves = d/λ in air).
    EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(1.23288), C(1.52), 111.53 / 550)), 0.0, 1e-9);
}

TEST(ThinFilm, QuarterWaveClosedForm) {
    // R = ((η1 η3 − η_f²)/(η1 η3 + η_f²))²; MgF2 (1.38) on glass (1.52) at 550 nm, d = 99.64 nm.
    for (double nf : {1.38, 1.8, 2.3}) {
        const double n3 = 1.52;
        const double expected = std::pow((n3 - nf * nf) / (n3 + nf * nf), 2);
        EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(nf), C(n3), 0.25 / nf)), expected, 1e-12);
    }
    EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(1.38), C(1.52), 0.25 / 1.38)), 0.0126008,
                1e-6);
}

TEST(ThinFilm, HalfWaveIsAbsentee) {
    // η_f d = λ/2: the bare substrate, ((1 − 1.52)/(1 + 1.52))² = 0.0425800, for any film index.
    for (double nf : {1.2, 1.38, 2.0})
        EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(nf), C(1.52), 0.5 / nf)), 0.0425800, 1e-6);
}

TEST(ThinFilm, SoapFilmInAir) {
    // air | 1.33 | air at normal incidence, λ = 550 nm: R = 2R0(1 − cos 2δ)/(1 + R0² − 2R0 cos 2δ).
    const double r0 = std::pow(0.33 / 2.33, 2);
    for (double d_nm : {0.0, 50.0, 103.4, 200.0, 300.0}) {
        const double two_delta = 4 * kPi<double> * 1.33 * d_nm / 550;
        const double expected =
            2 * r0 * (1 - std::cos(two_delta)) / (1 + r0 * r0 - 2 * r0 * std::cos(two_delta));
        EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(1.33), C(1.0), d_nm / 550)), expected,
                    1e-12)
            << d_nm;
    }
    EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(1.33), C(1.0), 50.0 / 550)), 0.038120, 1e-6);
    EXPECT_NEAR(reflectance(thin_film_mueller(1.0, C(1.33), C(1.0), 300.0 / 550)), 0.075430, 1e-6);
}

TEST(ThinFilm, BothPolarizationsAgreeWithTheCharacteristicMatrix) {
    struct Case {
        C film, exit;
    };
    // A dielectric film on glass, a high-index film, an absorbing film, a film on a metal, a film
    // seen from inside glass (exit index < 1: total reflection beyond 41.8°), frustrated total
    // reflection (an air gap between glasses, seen from the glass).
    const Case cases[] = {{C(1.38), C(1.52)},         {C(2.4), C(1.5)},
                          {C(1.8, 0.3), C(1.5)},      {C(1.45), C(0.47, 2.4)},
                          {C(1.2 / 1.5), C(1 / 1.5)}, {C(1 / 1.5), C(1.0)}};
    for (const Case& k : cases) {
        for (double cos_i : {1.0, 0.95, 0.8, 0.6, 0.4, 0.2, 0.05}) {
            for (double d : {0.05, 0.23, 0.61, 1.7}) {
                const ThinFilmAmplitudes<double> a = thin_film_amplitudes(cos_i, k.film, k.exit, d);
                const ThinFilmMueller<double> m = thin_film_mueller(cos_i, k.film, k.exit, d);
                const MatrixResult s = characteristic_matrix(true, cos_i, k.film, k.exit, d);
                const MatrixResult p = characteristic_matrix(false, cos_i, k.film, k.exit, d);
                const double Rs = m.reflection.a + m.reflection.b,
                             Rp = m.reflection.a - m.reflection.b;
                const double Ts = m.transmission.a + m.transmission.b,
                             Tp = m.transmission.a - m.transmission.b;
                EXPECT_NEAR(Rs, s.R, 1e-9) << k.film << k.exit << cos_i << " " << d;
                EXPECT_NEAR(Rp, p.R, 1e-9) << k.film << k.exit << cos_i << " " << d;
                EXPECT_NEAR(Ts, s.T, 1e-9) << k.film << k.exit << cos_i << " " << d;
                EXPECT_NEAR(Tp, p.T, 1e-9) << k.film << k.exit << cos_i << " " << d;
                // The phases: r_s equal, r_p of opposite sign (tangential-field convention).
                EXPECT_NEAR(std::abs(a.film.r_s - s.r), 0.0, 1e-9);
                EXPECT_NEAR(std::abs(a.film.r_p + p.r), 0.0, 1e-9);
                // c + id = r_s r_p* of the reflection matrix.
                const C x = s.r * std::conj(-p.r);
                EXPECT_NEAR(m.reflection.c, x.real(), 1e-9);
                EXPECT_NEAR(m.reflection.d, x.imag(), 1e-9);
            }
        }
    }
}

TEST(ThinFilm, LosslessFilmConservesEnergy) {
    // Real indices: R + T = 1 for s and for p, on either side of an interface, also under total
    // internal reflection (then T = 0, R = 1) and in frustrated total reflection (T > 0).
    for (double film : {1.2, 1.38, 2.4}) {
        for (double exit : {1.5, 1 / 1.5, 1.0}) {
            for (double cos_i = 0.01; cos_i <= 1.0; cos_i += 0.07) {
                for (double d : {0.0, 0.1, 0.37, 2.9}) {
                    const ThinFilmMueller<double> m = thin_film_mueller(cos_i, C(film), C(exit), d);
                    EXPECT_NEAR(m.reflection.a + m.transmission.a, 1.0, 1e-12);
                    EXPECT_NEAR(m.reflection.b + m.transmission.b, 0.0, 1e-12);
                }
            }
        }
    }
    // Beyond the exit's critical angle nothing is transmitted; beyond the film's only, a thin
    // film lets light tunnel through and a thick one does not.
    EXPECT_NEAR(thin_film_mueller(0.3, C(1.0), C(1 / 1.5), 0.2).reflection.a, 1.0, 1e-12);
    const double thin = thin_film_mueller(0.5, C(1 / 1.5), C(1.0), 0.02).transmission.a;
    const double thick = thin_film_mueller(0.5, C(1 / 1.5), C(1.0), 4.0).transmission.a;
    EXPECT_GT(thin, 0.5);
    EXPECT_LT(thick, 1e-6);
}

TEST(ThinFilm, ContinuousThroughTheFilmsCriticalAngle) {
    // Glass | film 1.2 | glass seen from the glass: the film's critical angle at sin θ = 0.8,
    // where the Airy sums are 0/0; on either side of it and at it they agree with the
    // characteristic matrix.
    const C film(1.2 / 1.5), exit(1.0);
    for (double sin2 : {0.64 - 1e-3, 0.64 - 1e-7, 0.64, 0.64 + 1e-9, 0.64 + 1e-5}) {
        const double cos_i = std::sqrt(1 - sin2);
        const ThinFilmMueller<double> m = thin_film_mueller(cos_i, film, exit, 0.3);
        const MatrixResult s = characteristic_matrix(true, cos_i, film, exit, 0.3);
        const MatrixResult p = characteristic_matrix(false, cos_i, film, exit, 0.3);
        EXPECT_NEAR(m.reflection.a + m.reflection.b, s.R, 1e-10) << sin2;
        EXPECT_NEAR(m.reflection.a - m.reflection.b, p.R, 1e-10) << sin2;
        EXPECT_NEAR(m.transmission.a + m.transmission.b, s.T, 1e-10) << sin2;
    }
}

TEST(ThinFilm, AbsorbingFilmAbsorbs) {
    for (double cos_i : {1.0, 0.5, 0.1}) {
        const ThinFilmMueller<double> m = thin_film_mueller(cos_i, C(2.0, 0.5), C(1.5), 0.3);
        EXPECT_LT(m.reflection.a + m.transmission.a, 1.0 - 1e-3);
        EXPECT_GT(m.transmission.a, 0.0);
    }
}

TEST(ThinFilm, PeriodAverageIsTheIncoherentSlab) {
    // Averaged over one period of thickness (δ over [0, π)), the coherent R of each polarization
    // is the incoherent sum R12 + T12² R23 / (1 − R12 R23) of the |r|² series (a lossless film).
    // 1 | 1.45 | 2.0 and 1 | 1.45 | 0.47 + 2.4i at 40°.
    const double cos_i = std::cos(40 * kPi<double> / 180);
    struct Case {
        C exit;
        double s, p;
    };
    for (const Case& k :
         {Case{C(2.0), 0.0969603, 0.0285874}, Case{C(0.47, 2.4), 0.7487527, 0.6816639}}) {
        const double sin2 = 1 - cos_i * cos_i;
        const C u2 = normal_wave_number(C(1.45), sin2);
        const double period = 1 / (2 * u2.real());  // thickness_waves for δ = π
        constexpr int kSteps = 4096;
        double sum_s = 0, sum_p = 0;
        for (int i = 0; i < kSteps; ++i) {
            const ThinFilmMueller<double> m =
                thin_film_mueller(cos_i, C(1.45), k.exit, (i + 0.5) / kSteps * period);
            sum_s += m.reflection.a + m.reflection.b;
            sum_p += m.reflection.a - m.reflection.b;
        }
        // The incoherent slab from the boundaries' own intensities.
        const FresnelAmplitudes<double> b12 =
            fresnel_amplitudes<double>(C(1), C(cos_i), C(1.45), u2);
        const C u3 = normal_wave_number(k.exit, sin2);
        const FresnelAmplitudes<double> b23 = fresnel_amplitudes<double>(C(1.45), u2, k.exit, u3);
        auto slab = [](double r12, double r23) {
            return r12 + (1 - r12) * (1 - r12) * r23 / (1 - r12 * r23);
        };
        const double slab_s = slab(std::norm(b12.r_s), std::norm(b23.r_s));
        const double slab_p = slab(std::norm(b12.r_p), std::norm(b23.r_p));
        EXPECT_NEAR(sum_s / kSteps, slab_s, 1e-9);
        EXPECT_NEAR(sum_p / kSteps, slab_p, 1e-9);
        EXPECT_NEAR(slab_s, k.s, 1e-7);
        EXPECT_NEAR(slab_p, k.p, 1e-7);
    }
}

TEST(ThinFilm, FresnelAmplitudesObeyStokesRelations) {
    const C eta_j(1.3, 0.1), eta_k(2.1, 0.4);
    const double sin2 = 0.3;
    const C uj = normal_wave_number(eta_j, sin2), uk = normal_wave_number(eta_k, sin2);
    const FresnelAmplitudes<double> jk = fresnel_amplitudes<double>(eta_j, uj, eta_k, uk);
    const FresnelAmplitudes<double> kj = fresnel_amplitudes<double>(eta_k, uk, eta_j, uj);
    EXPECT_NEAR(std::abs(jk.r_s + kj.r_s), 0.0, 1e-14);
    EXPECT_NEAR(std::abs(jk.r_p + kj.r_p), 0.0, 1e-14);
    EXPECT_NEAR(std::abs(jk.t_s * kj.t_s - (1.0 - jk.r_s * jk.r_s)), 0.0, 1e-14);
    EXPECT_NEAR(std::abs(jk.t_p * kj.t_p - (1.0 - jk.r_p * jk.r_p)), 0.0, 1e-14);
}

TEST(ThinFilm, MuellerOfAmplitudesIsTheKernelsReflectionMatrix) {
    // mueller_of_amplitudes (complex) and reflection_mueller (real arithmetic, the kernels') are
    // one definition.
    for (double cos_i : {1.0, 0.7, 0.2}) {
        const C eta(0.47, 2.4);
        const C u = normal_wave_number(eta, 1 - cos_i * cos_i);
        const FresnelAmplitudes<double> b = fresnel_amplitudes<double>(C(1), C(cos_i), eta, u);
        const InterfaceMueller<double> x = mueller_of_amplitudes(b.r_s, b.r_p, 1.0);
        const InterfaceMueller<double> y = reflection_mueller<double>(
            cos_i, (eta * eta).real(), (eta * eta).imag(), u.real(), u.imag());
        EXPECT_NEAR(x.a, y.a, 1e-14);
        EXPECT_NEAR(x.b, y.b, 1e-14);
        EXPECT_NEAR(x.c, y.c, 1e-14);
        EXPECT_NEAR(x.d, y.d, 1e-14);
    }
}

TEST(ThinFilm, ChannelsAtOnceAreEachChannel) {
    // FilmOptics::reflection_from_above (the channels sharing the film's wave number and upper
    // boundary) against mueller() channel by channel, and channel by channel against the
    // characteristic matrix: an oxide on three metals' indices at three wavelengths under a coat,
    // a film of lower index than the coat (its critical angle at sin θ = 0.8, in and around it),
    // an absorbing film, and an index-matched film and exit at grazing incidence.
    struct Case {
        C film;
        double above;
        C below[3];
        double thickness_nm;
    };
    const Case cases[] = {
        {C(2.5), 1.5, {C(2.7, 3.7), C(2.5, 3.4), C(2.2, 3.0)}, 60},
        {C(1.2), 1.5, {C(0.2, 3.9), C(0.4, 2.4), C(1.4, 1.6)}, 310},
        {C(2.3, 0.1), 1.0, {C(2.9, 3.1), C(2.95, 2.9), C(2.65, 2.8)}, 80},
        {C(1.5), 1.5, {C(1.5), C(1.5), C(1.5)}, 100},
    };
    for (const Case& k : cases) {
        FilmOptics film;
        film.eta_film = k.film;
        film.eta_above = k.above;
        film.thickness_min_nm = film.thickness_max_nm = k.thickness_nm;
        for (int c = 0; c < 3; ++c)
            film.eta_below[c] = k.below[c];
        for (double cos_i : {1.0, 0.83, 0.6 + 1e-9, 0.6, 0.6 - 1e-9, 0.3, 0.02, 0.0}) {
            const auto m = film.reflection_from_above(cos_i, k.thickness_nm);
            for (int c = 0; c < 3; ++c) {
                const InterfaceMueller<double> e =
                    film.mueller(c, cos_i, true, k.thickness_nm).reflection;
                const InterfaceMueller<double>& a = m[std::size_t(c)];
                EXPECT_NEAR(a.a, e.a, 1e-13) << k.film << " " << cos_i << " " << c;
                EXPECT_NEAR(a.b, e.b, 1e-13) << k.film << " " << cos_i << " " << c;
                EXPECT_NEAR(a.c, e.c, 1e-13) << k.film << " " << cos_i << " " << c;
                EXPECT_NEAR(a.d, e.d, 1e-13) << k.film << " " << cos_i << " " << c;
                // The matrix method is 0/0 at grazing incidence and at the film's critical angle
                // itself (its p admittance η/cos θ_f infinite).
                if (cos_i == 0.0 || cos_i == 0.6) continue;
                const double waves = k.thickness_nm * k.above / film.wavelength_nm[c];
                const MatrixResult s = characteristic_matrix(true, cos_i, k.film / k.above,
                                                             k.below[c] / k.above, waves);
                const MatrixResult p = characteristic_matrix(false, cos_i, k.film / k.above,
                                                             k.below[c] / k.above, waves);
                EXPECT_NEAR(a.a + a.b, s.R, 1e-9) << k.film << " " << cos_i << " " << c;
                EXPECT_NEAR(a.a - a.b, p.R, 1e-9) << k.film << " " << cos_i << " " << c;
            }
        }
    }
}

TEST(ThinFilm, GrazingIndexMatchedIsFinite) {
    const ThinFilmMueller<double> m = thin_film_mueller(0.0, C(1.0), C(1.0), 0.3);
    EXPECT_TRUE(std::isfinite(m.reflection.a));
    EXPECT_TRUE(std::isfinite(m.transmission.a));
    EXPECT_NEAR(m.reflection.a + m.transmission.a, 1.0, 1e-12);
}

}  // namespace
}  // namespace lamina

// Stokes vectors, frames and the Mueller matrices of smooth interfaces (physics/polarization.h)
// against closed forms and against an independent computation: the Jones calculus of Born & Wolf's
// complex amplitudes with std::complex, turned into a Mueller matrix from the definition of the
// Stokes parameters, and a perfect mirror's reflected field written as a 3-D vector.
#include "physics/polarization.h"

#include "core/math.h"
#include "core/rng.h"
#include "core/vec.h"
#include "physics/fresnel.h"
#include "support/chi2.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <complex>
#include <limits>

namespace lamina {
namespace {

using C = std::complex<double>;
using Matrix4 = std::array<std::array<double, 4>, 4>;
using Stokes = std::array<double, 4>;

// The Stokes vector of the field amplitudes (E_x, E_y) of the frame (docs/physics.md §8):
// S = (|Ex|² + |Ey|², |Ex|² − |Ey|², 2 Re(Ex Ey*), −2 Im(Ex Ey*)).
Stokes stokes_of(C ex, C ey) {
    return {std::norm(ex) + std::norm(ey), std::norm(ex) - std::norm(ey),
            2 * (ex * std::conj(ey)).real(), -2 * (ex * std::conj(ey)).imag()};
}

// The Mueller matrix of the Jones matrix J from the definition: the images of four pure states
// whose Stokes vectors are independent (x, y, +45°, circular), M = S_out S_in⁻¹ with S_in⁻¹
// written out (S_in has columns (1,1,0,0), (1,−1,0,0), (1,0,1,0), (1,0,0,1)).
using Jones = std::array<std::array<C, 2>, 2>;
Matrix4 mueller_of_jones(const Jones& jm) {
    const double r = 1 / std::sqrt(2.0);
    const std::array<std::array<C, 2>, 4> in = {
        {{C(1), C(0)}, {C(0), C(1)}, {C(r), C(r)}, {C(r), C(0, r)}}};
    std::array<Stokes, 4> out;
    for (int j = 0; j < 4; ++j)
        out[j] = stokes_of(jm[0][0] * in[j][0] + jm[0][1] * in[j][1],
                           jm[1][0] * in[j][0] + jm[1][1] * in[j][1]);
    // S_in⁻¹: e0 = (x + y)/2, e1 = (x − y)/2, e2 = d − e0, e3 = c − e0.
    Matrix4 m{};
    for (int i = 0; i < 4; ++i) {
        const double e0 = (out[0][i] + out[1][i]) / 2, e1 = (out[0][i] - out[1][i]) / 2;
        m[i] = {e0, e1, out[2][i] - e0, out[3][i] - e0};
    }
    return m;
}
Matrix4 mueller_of_jones(C a_s, C a_p) {
    return mueller_of_jones(Jones{{{a_s, C(0)}, {C(0), a_p}}});
}

Matrix4 expand(const InterfaceMueller<double>& m) {
    return {{{m.a, m.b, 0, 0}, {m.b, m.a, 0, 0}, {0, 0, m.c, m.d}, {0, 0, -m.d, m.c}}};
}

void expect_matrix_near(const Matrix4& a, const Matrix4& b, double tol, const std::string& what) {
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            EXPECT_NEAR(a[i][j], b[i][j], tol) << what << " element " << i << j;
}

// Born & Wolf §1.5.2 (Eqs. 20–21) with a complex relative index n (§14.2): the amplitude
// coefficients for light arriving at cos θi ∈ [0, 1], cos θt the principal root (Im ≥ 0: the field
// decays into the second medium, also under total internal reflection).
struct Amplitudes {
    C rs, rp, ts, tp;
    double flux_factor;  // Re(n cos θt)/cos θi: the transmitted flux per |t|² (real n)
};
Amplitudes born_wolf(double cos_i, C n) {
    const double sin2 = 1 - cos_i * cos_i;
    const C cos_t = std::sqrt(C(1) - sin2 / (n * n));
    Amplitudes a;
    a.rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    a.rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    a.ts = 2 * cos_i / (cos_i + n * cos_t);
    a.tp = 2 * cos_i / (n * cos_i + cos_t);
    a.flux_factor = (n * cos_t).real() / cos_i;
    return a;
}

// Every entry of (*) in double is a few arithmetic operations from the amplitudes; 1e-13 absolute.
constexpr double kTol = 1e-13;

TEST(Polarization, DielectricAgainstTheJonesCalculus) {
    ParticleRng rng(3, 0, 0);
    for (double eta : {1.5, 1 / 1.5, 1.33, 2.4, 1.0001}) {
        for (int k = 0; k < 200; ++k) {
            const double cos_i = k == 0 ? 1.0 : rng.uniform_double();
            const bool below = k % 2 == 1;  // from below the index crossed is 1/η
            const double crossed = below ? 1 / eta : eta;
            const auto fm =
                fresnel_dielectric_mueller<double>(below ? -cos_i : cos_i, eta, 1 / eta);
            const Amplitudes a = born_wolf(cos_i, C(crossed));
            expect_matrix_near(expand(fm.reflection), mueller_of_jones(a.rs, a.rp), kTol,
                               "reflection");
            const bool tir = (1 - cos_i * cos_i) / (crossed * crossed) >= 1;
            if (tir) {
                EXPECT_EQ(fm.transmission.a, 0.0);
                EXPECT_EQ(fm.transmission.c, 0.0);
                EXPECT_EQ(fm.cos_theta_t, 0.0);
                continue;
            }
            // The refracted beam's Mueller matrix is the flux factor (η cos θt)/(cos θi) times the
            // Jones calculus of t_s, t_p (Born & Wolf Eq. 30).
            Matrix4 t = mueller_of_jones(a.ts, a.tp);
            for (auto& row : t)
                for (double& x : row)
                    x *= a.flux_factor;
            expect_matrix_near(expand(fm.transmission), t, kTol, "transmission");
            // Nothing is absorbed: R + T = 1 for each polarization, so a_r + a_t = 1, b_r + b_t =
            // 0.
            EXPECT_NEAR(fm.reflection.a + fm.transmission.a, 1.0, kTol);
            EXPECT_NEAR(fm.reflection.b + fm.transmission.b, 0.0, kTol);
            EXPECT_NEAR(fm.cos_theta_t, std::sqrt(1 - (1 - cos_i * cos_i) / sqr(crossed)), kTol);
        }
    }
}

TEST(Polarization, ConductorAgainstTheJonesCalculus) {
    ParticleRng rng(4, 0, 0);
    for (const C n :
         {C(0.47, 2.4), C(0.143, 3.983), C(1.442, 1.603), C(2.5, 0.0), C(0.6, 0.0), C(3.0, 1e-3)}) {
        for (int k = 0; k < 200; ++k) {
            const double cos_i = k == 0 ? 1.0 : rng.uniform_double();
            const auto m = fresnel_conductor_mueller<double>(cos_i, n.real(), n.imag());
            const Amplitudes a = born_wolf(cos_i, n);
            expect_matrix_near(expand(m), mueller_of_jones(a.rs, a.rp), kTol, "conductor");
            // Its unpolarized reflectance is fresnel_conductor's.
            EXPECT_NEAR(m.a, fresnel_conductor(cos_i, n.real(), n.imag()), kTol);
        }
    }
}

TEST(Polarization, UnpolarizedReflectanceIsTheScalarFresnel) {
    for (double eta : {1.5, 1 / 1.5})
        for (double cos_i = -1; cos_i <= 1; cos_i += 1.0 / 64) {
            const auto fm = fresnel_dielectric_mueller<double>(cos_i, eta, 1 / eta);
            const auto fr = fresnel_dielectric_full<double>(cos_i, eta);
            EXPECT_NEAR(fm.reflection.a, fr.reflectance, kTol) << cos_i;
            EXPECT_EQ(fm.cos_theta_t, fr.cos_theta_t);
            EXPECT_EQ(fm.eta, fr.eta);
        }
}

// Normal incidence, η = 1.5: r_s = −0.2, r_p = +0.2 (r_p = −r_s in Born & Wolf's convention), so
// reflection is 0.04·diag(1, 1, −1, −1) (a half-wave retarder scaled by F0), from either side, and
// refraction 0.96·I (t_s = t_p, no phase). The same values as Mitsuba 3's test_mueller.py.
TEST(Polarization, NormalIncidence) {
    for (const double cos_i : {1.0, -1.0}) {
        const auto fm = fresnel_dielectric_mueller<double>(cos_i, 1.5, 1 / 1.5);
        expect_matrix_near(expand(fm.reflection),
                           {{{0.04, 0, 0, 0}, {0, 0.04, 0, 0}, {0, 0, -0.04, 0}, {0, 0, 0, -0.04}}},
                           1e-15, "reflection");
        expect_matrix_near(expand(fm.transmission),
                           {{{0.96, 0, 0, 0}, {0, 0.96, 0, 0}, {0, 0, 0.96, 0}, {0, 0, 0, 0.96}}},
                           1e-15, "transmission");
    }
}

// Brewster's angle tan θB = η: r_p = 0, so only the top-left block remains, all four entries
// R_s/2. At θB, cos θt = sin θB, so r_s = (cos θB − η sin θB)/(cos θB + η sin θB) =
// (1 − η²)/(1 + η²) = −5/13 for η = 1.5: R_s = 25/169 = 0.147929, R_s/2 = 0.0739645.
// Inside the glass at its own Brewster angle (tan = 1/η) the transmitted beam's matrix has
// T_s = 144/169, T_p = 1: a = (T_s + 1)/2 = 0.9260355, b = (T_s − 1)/2 = −0.0739645,
// c = √T_s = 12/13 = 0.9230769 (Mitsuba 3's values).
TEST(Polarization, BrewsterAngle) {
    const double rs2 = 25.0 / 169.0;
    const auto out = fresnel_dielectric_mueller<double>(std::cos(std::atan(1.5)), 1.5, 1 / 1.5);
    EXPECT_NEAR(out.reflection.a, rs2 / 2, 1e-15);
    EXPECT_NEAR(out.reflection.b, rs2 / 2, 1e-15);
    EXPECT_NEAR(out.reflection.c, 0.0, 1e-15);
    EXPECT_NEAR(out.reflection.d, 0.0, 1e-15);
    // p-polarized light (S1 = −S0) is not reflected at all: a − b = R_p = 0.
    EXPECT_NEAR(out.reflection.a - out.reflection.b, 0.0, 1e-15);
    const auto in = fresnel_dielectric_mueller<double>(-std::cos(std::atan(1 / 1.5)), 1.5, 1 / 1.5);
    EXPECT_NEAR(in.reflection.a - in.reflection.b, 0.0, 1e-15);
    EXPECT_NEAR(in.transmission.a, (144.0 / 169 + 1) / 2, 1e-15);
    EXPECT_NEAR(in.transmission.b, (144.0 / 169 - 1) / 2, 1e-15);
    EXPECT_NEAR(in.transmission.c, 12.0 / 13, 1e-15);
    EXPECT_NEAR(in.transmission.a, 0.9260355, 1e-7);
    EXPECT_NEAR(in.transmission.b, -0.0739645, 1e-7);
    EXPECT_NEAR(in.transmission.c, 0.9230769, 1e-7);
}

// Grazing incidence: r_s = r_p = −1, so reflection is the identity (r_s r_p* = 1), on dielectrics
// and conductors alike; nothing is refracted.
TEST(Polarization, GrazingIncidenceIsTheIdentity) {
    const Matrix4 identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}, {0, 0, 0, 1}}};
    for (double eta : {1.5, 1 / 1.5, 1.0}) {
        const auto fm = fresnel_dielectric_mueller<double>(0.0, eta, 1 / eta);
        expect_matrix_near(expand(fm.reflection), identity, 1e-15, "dielectric");
        EXPECT_EQ(fm.transmission.a, 0.0);
    }
    expect_matrix_near(expand(fresnel_conductor_mueller<double>(0.0, 0.47, 2.4)), identity, 1e-15,
                       "conductor");
}

// Total internal reflection (η = 1/1.5 from the glass): |r_s| = |r_p| = 1, and the phase between
// them, δ = arg(r_s r_p*) = atan2(d, c), runs from 0 at the critical angle through its maximum back
// to 0 at grazing. The maximum retardance is 2 atan((1 − n²)/(2n)) at cos θ = √((1 − n²)/(1 + n²))
// (n = 1/1.5: 45.24° at θ = 51.67°; Azzam 2004, "Phase shifts that accompany total internal
// reflection at a dielectric–dielectric interface", JOSA A 21(8)). The retarder conserves the
// degree of polarization: c² + d² = 1.
TEST(Polarization, TotalInternalReflectionRetardance) {
    const double n = 1 / 1.5;
    const double critical = std::sqrt(1 - n * n);  // cos of the critical angle
    const double expected_max = 2 * std::atan((1 - n * n) / (2 * n));
    EXPECT_NEAR(rad_to_deg(expected_max), 45.2397, 1e-4);
    double best = 0, best_cos = 0;
    for (int k = 1; k < 20000; ++k) {
        const double cos_i = critical * k / 20000.0;
        const auto m = fresnel_dielectric_mueller<double>(-cos_i, 1.5, 1 / 1.5).reflection;
        EXPECT_NEAR(m.a, 1.0, 1e-14);
        EXPECT_NEAR(m.b, 0.0, 1e-14);
        EXPECT_NEAR(m.c * m.c + m.d * m.d, 1.0, 1e-14);
        const double delta = std::abs(std::atan2(m.d, m.c));
        if (delta > best) best = delta, best_cos = cos_i;
    }
    EXPECT_NEAR(best, expected_max, 1e-8);
    EXPECT_NEAR(best_cos, std::sqrt((1 - n * n) / (1 + n * n)), 1e-4);
    // No retardance at the critical angle and at grazing.
    const auto at_critical = fresnel_dielectric_mueller<double>(-critical, 1.5, 1 / 1.5).reflection;
    EXPECT_NEAR(std::atan2(at_critical.d, at_critical.c), 0.0, 1e-6);
}

// A smooth interface does not depolarize: its Mueller matrix comes from a Jones matrix, so
// det of each block: (a + b)(a − b) = |r_s|²|r_p|² = |r_s r_p*|² = c² + d².
TEST(Polarization, SmoothInterfacesDoNotDepolarize) {
    ParticleRng rng(5, 0, 0);
    for (int k = 0; k < 1000; ++k) {
        const double cos_i = 2 * rng.uniform_double() - 1;
        const auto fm = fresnel_dielectric_mueller<double>(cos_i, 1.7, 1 / 1.7);
        for (const auto& m : {fm.reflection, fm.transmission})
            EXPECT_NEAR(m.a * m.a - m.b * m.b, m.c * m.c + m.d * m.d, 1e-14);
        const auto mc = fresnel_conductor_mueller<double>(std::abs(cos_i), 0.2, 3.1);
        EXPECT_NEAR(mc.a * mc.a - mc.b * mc.b, mc.c * mc.c + mc.d * mc.d, 1e-14);
    }
}

Vec3d to_vec(const LaneVec3<double>& v) {
    return {v.x, v.y, v.z};
}
LaneVec3<double> to_lane(const Vec3d& v) {
    return {v.x, v.y, v.z};
}
Vec3d perpendicular(const Vec3d& d, ParticleRng& rng) {
    return normalize(cross(d, test::uniform_sphere_direction(rng)));
}

// A complex field vector E ⊥ d and its Stokes vector in the frame x (y = d × x).
struct Field {
    std::array<C, 3> e;
    C along(const Vec3d& v) const { return e[0] * v.x + e[1] * v.y + e[2] * v.z; }
};
Stokes stokes_in_frame(const Field& f, const Vec3d& d, const Vec3d& x) {
    return stokes_of(f.along(x), f.along(cross(d, x)));
}
Field random_field(const Vec3d& d, const Vec3d& x, ParticleRng& rng) {
    const Vec3d y = cross(d, x);
    const C ex(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5);
    const C ey(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5);
    return {{ex * x.x + ey * y.x, ex * x.y + ey * y.y, ex * x.z + ey * y.z}};
}
StokesLanes<double> state_of(const Stokes& s, const Vec3d& x) {
    StokesLanes<double> st;
    st.x = to_lane(x);
    for (int c = 0; c < 3; ++c) {
        st.q[c] = s[1] / s[0];
        st.u[c] = s[2] / s[0];
        st.v[c] = s[3] / s[0];
    }
    return st;
}

// Turning the frame changes the numbers, not the light: the state turned from x to a new axis n
// equals the Stokes vector of the same field measured in the frame n.
TEST(Polarization, FrameRotationDescribesTheSameField) {
    ParticleRng rng(6, 0, 0);
    for (int k = 0; k < 500; ++k) {
        const Vec3d d = test::uniform_sphere_direction(rng);
        const Vec3d x = perpendicular(d, rng);
        const Field f = random_field(d, x, rng);
        const Stokes before = stokes_in_frame(f, d, x);
        StokesLanes<double> st = state_of(before, x);
        const Vec3d n = cross(d, test::uniform_sphere_direction(rng)) * 3.0;  // any length
        stokes_rotate_frame<double>(st, to_lane(d), to_lane(n), 1, true);
        const Stokes after = stokes_in_frame(f, d, normalize(n));
        EXPECT_NEAR(to_vec(st.x).x, normalize(n).x, 1e-14);
        EXPECT_NEAR(st.q[0], after[1] / after[0], 1e-12);
        EXPECT_NEAR(st.u[0], after[2] / after[0], 1e-12);
        EXPECT_NEAR(st.v[0], after[3] / after[0], 1e-12);
        // A frame x → −x is the same frame.
        const Stokes flipped = stokes_in_frame(f, d, -normalize(n));
        for (int i = 0; i < 4; ++i)
            EXPECT_NEAR(flipped[i], after[i], 1e-14);
    }
}

// The convention of the s/p frames checked against a field computed without it: a perfect mirror
// leaves the reflected field E_r = 2(E·m)m − E (the tangential field changes sign, the normal one
// does not: Born & Wolf §14.2 as |η + ik| → ∞). A conductor of index i·10⁹ is one to
// |r_s + 1|, |r_p − 1| ≤ 2·10⁻⁹/cos θ (r_s = (μ − ib)/(μ + ib), b = 10⁹, and likewise r_p). The
// polarized reflection at a facet of normal m — the frame turned into the plane of incidence, the
// Mueller matrix applied, the new frame the facet's s axis — must describe that field along the
// mirror direction, for any incidence, frame and state.
TEST(Polarization, FacetReflectionMatchesTheMirrorField) {
    ParticleRng rng(7, 0, 0);
    for (int k = 0; k < 500; ++k) {
        const Vec3d m = normalize(Vec3d(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5, 1));
        Vec3d d = test::uniform_sphere_direction(rng);
        if (dot(d, m) > 0) d = -d;  // arriving at the facet from the side m points to
        const Vec3d d_r = d - m * (2 * dot(d, m));
        const Vec3d x = perpendicular(d, rng);
        const Field f = random_field(d, x, rng);
        StokesLanes<double> st = state_of(stokes_in_frame(f, d, x), x);
        stokes_rotate_frame<double>(st, to_lane(d), to_lane(cross(d, m)), 1, true);
        const auto mirror = fresnel_conductor_mueller<double>(-dot(d, m), 0.0, 1e9);
        const double kept = stokes_apply<double>(mirror, st.q[0], st.u[0], st.v[0], true);
        const double tol = 1e-8 / -dot(d, m) + 1e-12;
        EXPECT_NEAR(kept, 1.0, tol);
        Field r;
        const C e_m = f.along(m);
        for (int i = 0; i < 3; ++i)
            r.e[i] = 2.0 * e_m * (i == 0 ? m.x : i == 1 ? m.y : m.z) - f.e[i];
        const Stokes expected = stokes_in_frame(r, d_r, to_vec(st.x));
        EXPECT_NEAR(st.q[0], expected[1] / expected[0], tol);
        EXPECT_NEAR(st.u[0], expected[2] / expected[0], tol);
        EXPECT_NEAR(st.v[0], expected[3] / expected[0], tol);
        // The new frame is ⊥ to the reflected direction.
        EXPECT_NEAR(dot(to_vec(st.x), d_r), 0.0, 1e-14);
    }
}

// The degree of polarization √(q² + u² + v²) of a pure state stays 1 through a smooth interface
// (no depolarization) and of a partial state stays ≤ 1.
TEST(Polarization, DegreeOfPolarizationStaysAtMostOne) {
    ParticleRng rng(8, 0, 0);
    for (int k = 0; k < 2000; ++k) {
        const double dop = k % 2 == 0 ? 1.0 : rng.uniform_double();
        const double z = 2 * rng.uniform_double() - 1, phi = 2 * kPi<double> * rng.uniform_double();
        const double r = std::sqrt(1 - z * z);
        double q = dop * r * std::cos(phi), u = dop * r * std::sin(phi), v = dop * z;
        const double cos_i = 2 * rng.uniform_double() - 1;
        const auto fm = fresnel_dielectric_mueller<double>(cos_i, 1.5, 1 / 1.5);
        const auto& m = k % 3 == 0 ? fm.transmission : fm.reflection;
        if (!(m.a + std::abs(m.b) > 0)) continue;
        stokes_apply<double>(m, q, u, v, true);
        const double after = std::sqrt(q * q + u * u + v * v);
        if (dop == 1.0)
            EXPECT_NEAR(after, 1.0, 1e-12);
        else
            EXPECT_LE(after, 1.0 + 1e-12);
    }
}

// Rounding cannot make a flux negative or a state non-finite: a matrix whose |b| exceeds a by a
// float ulp (a vanishing s or p reflectance), met by a state already at degree 1 + ulp, returns a
// factor ≥ 0 and a state of degree ≤ 1; a factor below 1e-30 (whose reciprocal overflows a float)
// keeps the state. Before this, a fuzzed conductor with k ≈ 0 in one channel gave a bin of −1e4.
TEST(Polarization, RoundingKeepsTheFluxNonNegativeAndTheStateFinite) {
    const float ulp = std::numeric_limits<float>::epsilon();
    const InterfaceMueller<float> brewster{0.1f, -0.1f * (1 + ulp), 0.f, 0.f};
    float q = 1 + ulp, u = 0.f, v = 0.f;  // a + b q = −a(2 ulp + ulp²) in exact arithmetic
    EXPECT_GE(stokes_apply<float>(brewster, q, u, v, true), 0.f);
    float q2 = 0.6f, u2 = 0.6f, v2 = 0.6f;  // degree 1.04: rounded states come back to ≤ 1
    const InterfaceMueller<float> plain{0.5f, 0.f, 0.5f, 0.f};
    EXPECT_GT(stokes_apply<float>(plain, q2, u2, v2, true), 0.f);
    EXPECT_LE(q2 * q2 + u2 * u2 + v2 * v2, 1.f + 4 * ulp);
    const InterfaceMueller<float> vanishing{1e-40f, 1e-40f, 0.f, 0.f};
    float q3 = 0.3f, u3 = -0.2f, v3 = 0.1f;
    const float factor = stokes_apply<float>(vanishing, q3, u3, v3, true);
    EXPECT_GE(factor, 0.f);
    EXPECT_LT(factor, 1e-30f);
    EXPECT_EQ(q3, 0.3f);  // kept
    EXPECT_EQ(u3, -0.2f);
    EXPECT_EQ(v3, 0.1f);
}

// The step of the Mueller tables' reciprocity (tests/simulator/mueller_test.cpp) that is pure
// algebra: the transpose of a Jones matrix has the Mueller matrix P Mᵀ P, P = diag(1, 1, 1, −1), in
// this header's convention S3 = −2 Im(E_x E_y*) (Jᵀ exchanges the roles of E_x* E_y and E_x E_y*,
// which flips S3 only), and diag(1, −1) has the Mueller matrix D = diag(1, 1, −1, −1).
TEST(Polarization, MuellerMatrixOfTheTransposedJonesMatrix) {
    ParticleRng rng(10, 0, 0);
    auto z = [&] { return C(rng.uniform_double() - 0.5, rng.uniform_double() - 0.5); };
    const double p[4] = {1, 1, 1, -1};
    for (int k = 0; k < 100; ++k) {
        const Jones j = {{{z(), z()}, {z(), z()}}};
        const Jones jt = {{{j[0][0], j[1][0]}, {j[0][1], j[1][1]}}};
        const Matrix4 m = mueller_of_jones(j), mt = mueller_of_jones(jt);
        Matrix4 expected{};
        for (int a = 0; a < 4; ++a)
            for (int b = 0; b < 4; ++b)
                expected[a][b] = p[a] * p[b] * m[b][a];
        expect_matrix_near(mt, expected, 1e-14, "transpose");
    }
    const Matrix4 d = mueller_of_jones(C(1), C(-1));
    expect_matrix_near(d, {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, -1, 0}, {0, 0, 0, -1}}}, 1e-15, "D");
}

// The tabulation frame: x ∝ ẑ × d, horizontal and ⊥ to d; ŷ straight up or down; for light in
// the x–z plane, x = ±ŷ, so S1 = +1 is s-polarized.
TEST(Polarization, BinFrame) {
    ParticleRng rng(9, 0, 0);
    for (int k = 0; k < 100; ++k) {
        const Vec3d d = test::uniform_sphere_direction(rng);
        const Vec3d x = to_vec(stokes_bin_frame<double>(to_lane(d)));
        EXPECT_NEAR(dot(x, d), 0.0, 1e-15);
        EXPECT_EQ(x.z, 0.0);
    }
    const Vec3d up = to_vec(stokes_bin_frame<double>({0, 0, 1}));
    EXPECT_EQ(up.y, 1.0);
    const Vec3d in_plane = normalize(to_vec(stokes_bin_frame<double>({-0.5, 0, -0.8})));
    EXPECT_NEAR(std::abs(in_plane.y), 1.0, 1e-15);
}

}  // namespace
}  // namespace lamina

// Polarized light: Stokes vectors, their reference frames, and the Mueller matrices of the events
// a particle meets (docs/physics.md §8).
//
// The Stokes reference frame, defined here once. A Stokes vector S = (S0, S1, S2, S3) describes a
// beam travelling along the unit direction d relative to a unit vector x ⊥ d, the frame's x axis;
// its y axis is y = d × x, so that (x, y, d) is right-handed. With the complex field amplitudes
// E_x, E_y along x and y (time dependence e^{−iωt}, the convention in which an absorbing index is
// η + ik with k > 0),
//
//     S0 = |E_x|² + |E_y|²,  S1 = |E_x|² − |E_y|²,  S2 = 2 Re(E_x E_y*),  S3 = −2 Im(E_x E_y*):
//
// S1 = +1 (times S0) is light polarized along x, S2 = +1 along (x + y)/√2, and S3 = +1 light whose
// field turns from x towards y (counter-clockwise for an observer who looks into the beam).
// Replacing x by −x changes no Stokes parameter, so a frame is an axis, not an oriented vector.
// Turning the frame about d by an angle φ (x' = cos φ x + sin φ y) turns (S1, S2) by −2φ:
//
//     S1' = cos 2φ S1 + sin 2φ S2,  S2' = −sin 2φ S1 + cos 2φ S2,  S3' = S3.
//
// At an interface or a microfacet of normal wm the natural frame is the plane of incidence: x = s
// ∝ d × wm, the normal of the plane that holds d, wm and the reflected and refracted directions
// (it is ⊥ to all of them), and y = p = d × s for the arriving and the leaving beam alike. In that
// frame the Fresnel coefficients of Born & Wolf (§1.5.2; r_p = −r_s at normal incidence) act on
// E_s and E_p separately, and the Mueller matrix of reflection and of refraction has the block form
//
//     [[a, b, 0, 0], [b, a, 0, 0], [0, 0, c, d], [0, 0, −d, c]]                          (*)
//
// (InterfaceMueller): reflection a = (R_s + R_p)/2, b = (R_s − R_p)/2, c + id = r_s r_p*;
// refraction the same with the transmittances T_s, T_p and (η_t cos θ_t)/(η_i cos θ_i) t_s t_p*
// (the flux factor of a refracted beam, so that a + a_t = 1 without absorption). This is the form
// of Collett, "Field Guide to Polarization" (SPIE 2005), and of Mitsuba 3's mueller.h, whose sign
// convention for d it shares (d = −c sin Δ with the retardance Δ = arg r_p − arg r_s).
//
// A particle carries its flux per channel (which is S0) and, per channel, its Stokes vector divided
// by S0 with the frame's x axis (StokesLanes): every event rotates the frame into the event's plane
// of incidence, applies (*), and leaves the particle in that frame (its x axis is ⊥ to the new
// direction as well), so no second rotation is needed. A dielectric has one index for all channels,
// so its Mueller matrix is achromatic; only a conductor whose index differs between channels makes
// the channels' states differ, and a stack without one keeps a single state for all channels
// (`channels` = 1).
//
// The frame in which the goniophotometer tabulates a direction of travel d (stokes_bin_frame): x ∝
// ẑ × d, horizontal and ⊥ to the vertical plane that holds d (for vertical d, x = ŷ). For light
// incident in the x–z plane x = ŷ: S1 = +1 is s-polarized light (field ⊥ to the plane of
// incidence), S1 = −1 p-polarized.

#include "core/complex_math.h"
#include "core/lane.h"
#include "core/lane_complex.h"
#include "core/lane_vec.h"

#include <cmath>
#include <complex>
#include <type_traits>

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_POLARIZATION_H
#define LAMINA_PHYSICS_POLARIZATION_H
#define LAMINA_PHYSICS_POLARIZATION_BODY
#endif
#elif defined(LAMINA_PHYSICS_POLARIZATION_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_POLARIZATION_TARGET
#undef LAMINA_PHYSICS_POLARIZATION_TARGET
#else
#define LAMINA_PHYSICS_POLARIZATION_TARGET
#endif
#define LAMINA_PHYSICS_POLARIZATION_BODY
#endif

#ifdef LAMINA_PHYSICS_POLARIZATION_BODY
#undef LAMINA_PHYSICS_POLARIZATION_BODY

LAMINA_LANE_BEGIN

/// The Mueller matrix (*) of a smooth interface in the s/p frame of its plane of incidence:
/// [[a, b, 0, 0], [b, a, 0, 0], [0, 0, c, d], [0, 0, −d, c]]. a is the flux factor for unpolarized
/// light, a + b for s-polarized and a − b for p-polarized light.
template <typename T>
struct InterfaceMueller {
    T a, b, c, d;
};

/// The Mueller matrix (*) of a pair of complex amplitudes a_s, a_p (the Jones matrix
/// diag(a_s, a_p) in the s/p frame) times the flux factor `flux`: a = flux (|a_s|² + |a_p|²)/2,
/// b = flux (|a_s|² − |a_p|²)/2, c + id = flux a_s a_p*. Reflection has flux 1; a refracted beam
/// the factor Re(η_t cos θt)/(η_i cos θi) of its real exit medium (Born & Wolf §1.5.2, Eq. 30).
/// The definition, on complex lane values (the films' amplitudes, physics/thin_film.h);
/// reflection_mueller below is the same for one boundary in real arithmetic.
template <typename T, typename L>
LAMINA_LANE_INLINE InterfaceMueller<T> mueller_of_amplitudes(LaneComplex<T> a_s, LaneComplex<T> a_p,
                                                             T flux) {
    const T n_s = squared_modulus(a_s), n_p = squared_modulus(a_p);
    const LaneComplex<T> x = times_conj(a_s, a_p);
    const T two = L::constant(2);
    return {flux * (n_s + n_p) / two, flux * (n_s - n_p) / two, flux * x.re, flux * x.im};
}

/// The same on one lane, on std::complex.
template <typename T>
InterfaceMueller<T> mueller_of_amplitudes(std::complex<T> a_s, std::complex<T> a_p, T flux) {
    return mueller_of_amplitudes<T, Lane<T>>(lane_complex(a_s), lane_complex(a_p), flux);
}

/// The reflection Mueller matrix from the complex reflection coefficients of a relative index
/// whose square is E = e1 + i e2 (e2 ≥ 0), at the incidence cosine mu ∈ [0, 1], given u = a + ib,
/// the root of E − sin²θ with b ≥ 0 (u = η cos θ_t, the field decaying into an absorbing or
/// totally reflecting medium). Born & Wolf §1.5.2 (Eqs. 21a–b) with the complex index of §14.2:
///     r_s = (μ − u)/(μ + u),  r_p = (E μ − u)/(E μ + u)  (r_p of Eq. 21a multiplied through by η).
/// a = (|r_s|² + |r_p|²)/2, b = (|r_s|² − |r_p|²)/2, c + id = r_s r_p*. At μ = u = 0 (grazing on an
/// index-matched interface, where both tend to −1) the identity.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE InterfaceMueller<T> reflection_mueller(T mu, T e1, T e2, T u_re, T u_im) {
    const T zero = L::constant(0), one = L::constant(1), half = L::constant(0.5);
    // Numerators and denominators N_s = μ − u, D_s = μ + u, N_p = Eμ − u, D_p = Eμ + u.
    const T ns_re = mu - u_re, ns_im = zero - u_im;
    const T ds_re = mu + u_re, ds_im = u_im;
    const T ep_re = e1 * mu, ep_im = e2 * mu;
    const T np_re = ep_re - u_re, np_im = ep_im - u_im;
    const T dp_re = ep_re + u_re, dp_im = ep_im + u_im;
    const T ns2 = L::mul_add(ns_re, ns_re, ns_im * ns_im);
    const T ds2 = L::mul_add(ds_re, ds_re, ds_im * ds_im);
    const T np2 = L::mul_add(np_re, np_re, np_im * np_im);
    const T dp2 = L::mul_add(dp_re, dp_re, dp_im * dp_im);
    // r_s r_p* = (N_s N_p*) (D_s D_p*)* / (|D_s|² |D_p|²).
    const T x_re = L::mul_add(ns_re, np_re, ns_im * np_im);
    const T x_im = L::mul_add(ns_im, np_re, zero - ns_re * np_im);
    const T y_re = L::mul_add(ds_re, dp_re, ds_im * dp_im);
    const T y_im = L::mul_add(ds_im, dp_re, zero - ds_re * dp_im);
    const T denominator = ds2 * dp2;
    const auto regular = L::less(zero, denominator);
    const T inv = one / L::select(regular, denominator, one);
    const T r_s = ns2 * dp2 * inv, r_p = np2 * ds2 * inv;
    InterfaceMueller<T> m;
    m.a = L::select(regular, half * (r_s + r_p), one);
    m.b = L::select(regular, half * (r_s - r_p), zero);
    m.c = L::select(regular, L::mul_add(x_re, y_re, x_im * y_im) * inv, one);
    m.d = L::select(regular, L::mul_add(x_im, y_re, zero - x_re * y_im) * inv, zero);
    return m;
}

/// The polarized Fresnel terms of a dielectric interface: the reflection and refraction Mueller
/// matrices (*) and, as fresnel_dielectric_full (fresnel.h) computes them, the refracted cosine
/// (0 under total internal reflection), the relative index crossed and its reciprocal.
template <typename T>
struct DielectricMueller {
    InterfaceMueller<T> reflection, transmission;
    T cos_theta_t, eta, inv_eta;
};

/// The reflection and refraction Mueller matrices of a dielectric interface (relative index eta
/// below over above, inv_eta = 1/eta) for light arriving at the cosine cos_theta_i ∈ [−1, 1]
/// (negative: from below, where the index crossed is 1/eta), in the s/p frame of the plane of
/// incidence. Refraction (real r, t; Born & Wolf §1.5.2, Eqs. 20–21 and the flux factor of Eq. 30,
/// (η cos θt)/cos θi): with μ = cos θi and u = η cos θt,
///     T_s = 4μu/(μ + u)²,  T_p = 4η²μu/(η²μ + u)²,  c_t = (u/μ) t_s t_p = 4ημu/((μ + u)(η²μ + u)),
/// d_t = 0 (no phase between s and p: t_s, t_p > 0), and T_s = 1 − R_s, T_p = 1 − R_p. Under total
/// internal reflection u = i √(sin²θi − η²): |r_s| = |r_p| = 1 with the retardance between them
/// (Born & Wolf §1.5.4), and nothing is refracted. A branch-free lane template (core/lane.h).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE DielectricMueller<T> fresnel_dielectric_mueller(T cos_theta_i, T eta,
                                                                   T inv_eta) {
    const T zero = L::constant(0), one = L::constant(1), four = L::constant(4);
    cos_theta_i = L::min(L::max(cos_theta_i, zero - one), one);
    const auto below = L::less(cos_theta_i, zero);
    DielectricMueller<T> r;
    r.eta = L::select(below, inv_eta, eta);
    r.inv_eta = L::select(below, eta, inv_eta);
    const T mu = L::abs(cos_theta_i);
    // As fresnel_dielectric_full: sin²θt = sin²θi/η², cos θt = √(1 − sin²θt) (0 under TIR).
    const T sin2_theta_t = (one - mu * mu) * (r.inv_eta * r.inv_eta);
    r.cos_theta_t = L::sqrt(L::max(one - sin2_theta_t, zero));
    const T u_re = r.eta * r.cos_theta_t;
    const T u_im = r.eta * L::sqrt(L::max(sin2_theta_t - one, zero));
    const T e1 = r.eta * r.eta;
    r.reflection = reflection_mueller<T, L>(mu, e1, zero, u_re, u_im);
    // Under total internal reflection R_s = R_p = 1 exactly (only the phase is computed).
    const auto tir = L::negate(L::less(sin2_theta_t, one));
    r.reflection.a = L::select(tir, one, r.reflection.a);
    r.reflection.b = L::select(tir, zero, r.reflection.b);
    const T ds = mu + u_re, dp = L::mul_add(e1, mu, u_re);
    const T mu_u4 = four * mu * u_re;
    const auto regular = L::less(zero, ds * dp);
    const T inv_ds = one / L::select(regular, ds, one), inv_dp = one / L::select(regular, dp, one);
    const T t_s = mu_u4 * inv_ds * inv_ds, t_p = mu_u4 * e1 * inv_dp * inv_dp;
    const T half = L::constant(0.5);
    r.transmission.a = L::select(regular, half * (t_s + t_p), zero);
    r.transmission.b = L::select(regular, half * (t_s - t_p), zero);
    r.transmission.c = L::select(regular, mu_u4 * r.eta * inv_ds * inv_dp, zero);
    r.transmission.d = zero;
    return r;
}

/// The reflection Mueller matrix (*) of a conductor of relative complex index eta + i k (k ≥ 0)
/// for light arriving from the dielectric side at cos_theta_i ∈ [0, 1]: reflection_mueller with
/// E = (η + ik)² and u = √(E − sin²θ) (Born & Wolf §14.2, the real-arithmetic root of
/// fresnel_conductor). Its a is fresnel_conductor's reflectance; with k = 0 it is the dielectric's
/// reflection, total internal reflection included. A branch-free lane template (core/lane.h).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE InterfaceMueller<T> fresnel_conductor_mueller(T cos_theta_i, T eta, T k) {
    const T zero = L::constant(0), one = L::constant(1), half = L::constant(0.5);
    const T mu = L::min(L::max(cos_theta_i, zero), one);
    const T sin2 = one - mu * mu;
    const T e1 = eta * eta - k * k, e2 = L::constant(2) * eta * k;
    const T w = e1 - sin2;
    const T modulus = L::sqrt(L::mul_add(w, w, e2 * e2));
    const T u_re = L::sqrt(L::max(half * (modulus + w), zero));
    const T u_im = L::sqrt(L::max(half * (modulus - w), zero));
    return reflection_mueller<T, L>(mu, e1, e2, u_re, u_im);
}

/// The polarization of the particles on a set of lanes: per channel the Stokes vector divided by
/// its intensity, (q, u, v) = (S1, S2, S3)/S0 (the flux the particle carries is S0), and the
/// frame's x axis (a unit vector ⊥ the direction of travel). Channels beyond the `channels` in use
/// (1 when all share one state) are not kept.
template <typename T>
struct StokesLanes {
    LaneVec3<T> x;
    T q[3], u[3], v[3];
};

/// What an interface event needs to follow polarization, and what it returns: the state (in/out),
/// the number of states in use (1: one for all channels; 3: one per channel), the particles' flux
/// per channel before the event (the branch choice's weights when the states differ), and the
/// event's flux factors per channel (out: a conductor's reflectance for the state; at a
/// dielectric with differing states, the reweighting of the branch choice; 1 otherwise).
template <typename T>
struct PolarizationLanes {
    StokesLanes<T> stokes;
    int channels = 1;
    const T* flux = nullptr;
    T factor[3];
};

/// The Mueller-matrix source of an unpolarized event: never called.
struct NoMueller {
    template <typename... A>
    void operator()(A&&...) const {}
};

/// Calls an interface's reflection source — Fresnel factors `source(cos θ, factors)` or Mueller
/// matrices `source(cos θ, m)` — for the lanes of `active`: with the mask where the source takes
/// one (a source that can skip the other lanes, whose values the events never use, as a thin
/// film's reflection skips vector halves without an active lane), else on every lane.
template <typename Source, typename T, typename Out, typename M>
LAMINA_LANE_INLINE void reflection_on_lanes(const Source& source, T cos_theta, Out* out, M active) {
    if constexpr (std::is_invocable_v<const Source&, T, Out*, M>)
        source(cos_theta, out, active);
    else
        source(cos_theta, out);
}

/// Unpolarized light (every channel) in the frame x.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE void stokes_depolarize(StokesLanes<T>& s, int channels, typename L::Mask m) {
    const T zero = L::constant(0);
    for (int c = 0; c < channels; ++c) {
        s.q[c] = L::select(m, zero, s.q[c]);
        s.u[c] = L::select(m, zero, s.u[c]);
        s.v[c] = L::select(m, zero, s.v[c]);
    }
}

/// Turns the frame of the lanes of m about their direction of travel d to the new x axis n (⊥ d,
/// any length): with cos φ = x·n̂ and sin φ = y·n̂ (y = d × x), cos 2φ = (c² − s²)/|n|² and
/// sin 2φ = 2cs/|n|² for c = x·n, s = y·n (no trigonometry), and (q, u) turned as the header says.
/// Where |n|² < 1e-12 (n ∥ d to rounding: normal incidence on the facet, where its s/p frame is
/// any frame and the Mueller matrix does not depend on it beyond O(|n|²)) the frame is kept.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE void stokes_rotate_frame(StokesLanes<T>& s, const LaneVec3<T>& d,
                                            const LaneVec3<T>& n, int channels,
                                            typename L::Mask m) {
    const T zero = L::constant(0), one = L::constant(1);
    const T n2 = lane_dot<T, L>(n, n);
    const auto turns = L::both(m, L::less(L::constant(1e-12), n2));
    const T cx = lane_dot<T, L>(s.x, n);
    const T cy = lane_dot<T, L>(lane_cross<T, L>(d, s.x), n);
    const T inv_n2 = one / L::select(turns, n2, one);
    const T cos2 = (cx * cx - cy * cy) * inv_n2;
    const T sin2 = (cx + cx) * cy * inv_n2;
    for (int c = 0; c < channels; ++c) {
        const T q = L::mul_add(cos2, s.q[c], sin2 * s.u[c]);
        const T u = L::mul_add(cos2, s.u[c], zero - sin2 * s.q[c]);
        s.q[c] = L::select(turns, q, s.q[c]);
        s.u[c] = L::select(turns, u, s.u[c]);
    }
    const T inv_n = L::inv_sqrt(L::select(turns, n2, one));
    s.x = lane_select<T, L>(turns, {n.x * inv_n, n.y * inv_n, n.z * inv_n}, s.x);
}

/// Applies the Mueller matrix (*) m to the state (q, u, v) of the lanes of `active`: returns the
/// intensity factor a + b q (the flux factor of the event for that state, never negative) and
/// replaces the state by the normalized result, ((b + a q), (c u + d v), (−d u + c v)) / (a + b q).
/// A Fresnel matrix keeps the degree of polarization ≤ 1 (a² = b² + c² + d²); in rounding it may
/// not, and a normalized state is rescaled to degree 1 where it comes out above it, so that no
/// later event sees a + b q < 0. Where the factor is below 1e-30 (a reflectance that vanishes,
/// whose normalization would overflow a float) the state is kept: no flux worth following
/// continues.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE T stokes_apply(const InterfaceMueller<T>& m, T& q, T& u, T& v,
                                  typename L::Mask active) {
    const T zero = L::constant(0), one = L::constant(1);
    const T intensity = L::mul_add(m.b, q, m.a);
    const auto keeps = L::both(active, L::less(L::constant(1e-30), intensity));
    const T inv = one / L::select(keeps, intensity, one);
    const T q_new = L::mul_add(m.a, q, m.b) * inv;
    const T u_new = L::mul_add(m.c, u, m.d * v) * inv;
    const T v_new = L::mul_add(m.c, v, zero - m.d * u) * inv;
    const T degree2 = L::mul_add(q_new, q_new, L::mul_add(u_new, u_new, v_new * v_new));
    const auto above = L::less(one, degree2);
    const T shrink = L::select(above, L::inv_sqrt(L::select(above, degree2, one)), one);
    q = L::select(keeps, q_new * shrink, q);
    u = L::select(keeps, u_new * shrink, u);
    v = L::select(keeps, v_new * shrink, v);
    return L::max(intensity, zero);
}

/// The polarized branch choice at a dielectric facet, the state already in the facet's s/p frame:
/// the probability of reflection for channel c is its reflected flux fraction P_c = a_r + b_r q_c.
/// With one state (channels = 1) the lanes reflect where uc < P_0 and the flux is unchanged (the
/// choice's probability cancels the Fresnel factor, as for unpolarized light). With one state per
/// channel the branch is one for all channels, drawn with the flux-weighted mixture P =
/// Σ_c p_c P_c, p_c = flux_c/Σ flux (one-sample MIS, balance heuristic: Veach 1997, §9.2.4, as the
/// media's spectral MIS, medium.h), and channel c's flux is multiplied by P_c/P (reflection) or
/// (1 − P_c)/(1 − P) (refraction), unbiased for every channel and keeping the sum of the channels'
/// fluxes (`flux`: the particles' flux per channel). The state of the lanes of `active` becomes
/// that of the chosen branch (stokes_apply); pol.factor holds the flux factors. Returns the mask
/// of reflecting lanes.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE typename L::Mask polarized_dielectric_choice(PolarizationLanes<T>& pol,
                                                                const DielectricMueller<T>& fm,
                                                                T uc, typename L::Mask active,
                                                                const T* flux) {
    const T zero = L::constant(0), one = L::constant(1);
    StokesLanes<T>& s = pol.stokes;
    T p_reflect[3];
    p_reflect[0] = L::mul_add(fm.reflection.b, s.q[0], fm.reflection.a);
    for (int c = 1; c < pol.channels; ++c)
        p_reflect[c] = L::mul_add(fm.reflection.b, s.q[c], fm.reflection.a);
    T p = p_reflect[0];
    if (pol.channels == 3) {
        const T total = flux[0] + flux[1] + flux[2];
        const auto has_flux = L::less(zero, total);
        const T mix = L::mul_add(flux[0], p_reflect[0],
                                 L::mul_add(flux[1], p_reflect[1], flux[2] * p_reflect[2]));
        p = L::select(has_flux, mix / L::select(has_flux, total, one), p_reflect[0]);
    }
    // Nothing refracts (total internal reflection, grazing light): reflection for sure, whatever
    // the mixture's rounding (a P of 1 − 2^-24 would let uc = 1 − 2^-24 refract).
    p = L::select(L::less(zero, fm.transmission.a), p, one);
    const auto reflects = L::less(uc, p);
    const InterfaceMueller<T> m = {L::select(reflects, fm.reflection.a, fm.transmission.a),
                                   L::select(reflects, fm.reflection.b, fm.transmission.b),
                                   L::select(reflects, fm.reflection.c, fm.transmission.c),
                                   L::select(reflects, fm.reflection.d, fm.transmission.d)};
    const T branch = L::select(reflects, p, one - p);
    const T inv_branch = one / L::select(L::less(zero, branch), branch, one);
    for (int c = 0; c < pol.channels; ++c) {
        const T intensity = stokes_apply<T, L>(m, s.q[c], s.u[c], s.v[c], active);
        pol.factor[c] = pol.channels == 3 ? L::select(active, intensity * inv_branch, one) : one;
    }
    if (pol.channels == 1) pol.factor[1] = pol.factor[2] = one;
    return reflects;
}

/// The frame x axis in which the goniophotometer tabulates the Stokes vector of a beam travelling
/// along d (the header's bin frame): ẑ × d = (−d_y, d_x, 0), not normalized; ŷ for vertical d
/// (d_x² + d_y² < 1e-12, where stokes_rotate_frame would not turn to ẑ × d).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE LaneVec3<T> stokes_bin_frame(const LaneVec3<T>& d) {
    const T zero = L::constant(0);
    const auto vertical = L::negate(L::less(L::constant(1e-12), L::mul_add(d.x, d.x, d.y * d.y)));
    return {L::select(vertical, zero, zero - d.y), L::select(vertical, L::constant(1), d.x), zero};
}

/// The Stokes vectors of the lanes of m as the goniophotometer tabulates them: the state (a copy)
/// turned into the bin frame of the direction of travel d, times the flux: out[c] = w_c (1, q, u,
/// v) with channel c's state (channel 0's when one serves all).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE void stokes_in_bin_frame(StokesLanes<T> s, const LaneVec3<T>& d, const T w[3],
                                            int channels, typename L::Mask m, T out[3][4]) {
    stokes_rotate_frame<T, L>(s, d, stokes_bin_frame<T, L>(d), channels, m);
    for (int c = 0; c < 3; ++c) {
        const int k = channels == 3 ? c : 0;
        out[c][0] = w[c];
        out[c][1] = w[c] * s.q[k];
        out[c][2] = w[c] * s.u[k];
        out[c][3] = w[c] * s.v[k];
    }
}

/// The state of incident light travelling along d: the incident Stokes vector (S1, S2, S3)/S0 =
/// stokes[0..2] in the bin frame of d, in every channel.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE StokesLanes<T> stokes_incident(const LaneVec3<T>& d, const float stokes[3]) {
    StokesLanes<T> s;
    s.x = lane_normalize<T, L>(stokes_bin_frame<T, L>(d));
    for (int c = 0; c < 3; ++c) {
        s.q[c] = L::constant(stokes[0]);
        s.u[c] = L::constant(stokes[1]);
        s.v[c] = L::constant(stokes[2]);
    }
    return s;
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_POLARIZATION_BODY

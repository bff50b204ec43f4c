// A homogeneous medium between two interfaces of a stack, as a particle crosses it: absorption
// along a straight path (Beer–Lambert), and in a scattering medium free flights and
// Henyey–Greenstein scattering events (phase.h), with per-channel (RGB) optical depths.
//
// Depth s ∈ [0, 1] across the layer (0 at its top, 1 at its bottom); a direction of travel d with
// |d.z| = μ crosses the whole layer along a path of optical depth τ/μ, so a free flight of optical
// length t at extinction τt (per unit of layer thickness) moves the particle by −d.z·t in depth
// and τt t is the flight's optical depth. `Medium` is any type with the fields of the compiled
// stack's medium (layers/compiled_stack.h CompiledMedium): tau_a, tau_s, tau_t, g, per channel
// (indexable by 0..2), single_scattering_albedo, and the flags uniform_tau_t (all channels share
// one τt) and uniform_g (one g).
//
// Spectral sampling. Free flights are drawn from a mixture of the channels' exponentials with
// channel probabilities p_c ∝ the particle's current flux, and each channel's flux is reweighted
// by its own density over the mixture density (one-sample spectral MIS, balance heuristic: Veach
// 1997, §9.2.4; Miller, Georgiev & Jarosz 2019, "A null-scattering path integral formulation of
// light transport", §6): unbiased for every channel whatever channel was drawn. A scattering
// event's direction is drawn the same way from the channels' phase functions, its channel drawn
// afresh ∝ the same p, so the joint density of (distance, direction) factorizes into the two
// mixtures used for the weights.
//
// Lane templates (core/lane.h): the scalar kernel (simulator/goniophotometer.cpp), the SIMD kernel
// (simulator/kernel_simd.cpp) and the random walk (randomwalk/random_walk.cpp) evaluate these
// lines; the medium's parameters are the same on every lane (CompiledMedium's numbers), or lane
// values (a spectral run's lanes on the SIMD kernel: each at its own wavelengths, medium_lane).

#include "core/lane.h"
#include "core/lane_vec.h"
#include "physics/phase.h"

#include <cmath>
#include <type_traits>

// A lane header (core/lane.h): included once as an ordinary header and once per SIMD target.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_MEDIUM_H
#define LAMINA_PHYSICS_MEDIUM_H
#define LAMINA_PHYSICS_MEDIUM_BODY
#endif
#elif defined(LAMINA_PHYSICS_MEDIUM_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_MEDIUM_TARGET
#undef LAMINA_PHYSICS_MEDIUM_TARGET
#else
#define LAMINA_PHYSICS_MEDIUM_TARGET
#endif
#define LAMINA_PHYSICS_MEDIUM_BODY
#endif

#ifdef LAMINA_PHYSICS_MEDIUM_BODY
#undef LAMINA_PHYSICS_MEDIUM_BODY

LAMINA_LANE_BEGIN

/// A medium's value on the lanes: a number (CompiledMedium's, the same on every lane) broadcast,
/// or already a lane value (a spectral run's lanes, each at its own wavelengths).
template <typename T, typename L, typename V>
LAMINA_LANE_INLINE T medium_lane(const V& v) {
    if constexpr (std::is_arithmetic_v<V>)
        return L::constant(double(v));
    else
        return v;
}

/// Beer–Lambert transmittance e^{−τ_c/μ} of the optical depths tau[c] (≥ 0, the same on every
/// lane) along a straight path across the layer, inv_mu = 1/|d.z|: out[c]. A channel without
/// extinction transmits 1, also along a horizontal path (inv_mu = ∞, where 0 · ∞ would be NaN:
/// found by the fuzz test); channels with equal τ share the exponential.
template <typename T, typename L = Lane<T>, typename Tau>
LAMINA_LANE_INLINE void beer_lambert_transmittance(const Tau& tau, T inv_mu, T out[3]) {
    for (int c = 0; c < 3; ++c) {
        if (c > 0 && tau[c] == tau[c - 1]) {
            out[c] = out[c - 1];  // a grey pair of channels
            continue;
        }
        out[c] = tau[c] > 0 ? L::exp(L::constant(-double(tau[c])) * inv_mu) : L::constant(1);
    }
}

/// beer_lambert_transmittance for optical depths that differ between the lanes (a spectral run's
/// lanes, each at its own wavelengths): tau[c] a lane value ≥ 0, the same e^{−τ_c/μ}, and 1 where
/// τ_c = 0 (whatever inv_mu).
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE void beer_lambert_transmittance_lanes(const T tau[3], T inv_mu, T out[3]) {
    for (int c = 0; c < 3; ++c)
        out[c] = L::select(L::less(L::constant(0), tau[c]),
                           L::exp((L::constant(0) - tau[c]) * inv_mu), L::constant(1));
}

/// The first half of a scattering-medium step: a free flight.
template <typename T, typename M>
struct MediumFlightLanes {
    M leaves;     ///< the flight reaches the layer's boundary (or the particle has no flux)
    T factor[3];  ///< the flux factors of the flight (both outcomes), per channel
    T depth;      ///< the depth of the scattering event (lanes that do not leave)
    T p[3];       ///< the channel probabilities ∝ flux (for the phase function's MIS)
};

/// A free flight of the particles on the lanes of `active` inside a scattering medium, at depth
/// `depth` travelling along d with flux w[3] (≥ 0): its channel c drawn ∝ flux (one uniform), its
/// length −ln(1 − u)/τt_c (one uniform). If it reaches the boundary along d (or the lane carries
/// no flux) the lane leaves, with factors T_c / Σ_k p_k T_k (T_k = e^{−τt_k t}, t the path to the
/// boundary; 1 without flux); otherwise it scatters at the flight's end, with factors
/// σs_c e^{−τt_c t} / Σ_k p_k σt_k e^{−τt_k t}. With one extinction for all channels the flight
/// density is every channel's own and the factors are 1 (leaving) and the single-scattering
/// albedo τs/τt (scattering). `uniform()` returns a lane of uniform numbers in [0, 1).
template <typename T, typename L = Lane<T>, typename Medium, typename Uniform>
LAMINA_LANE_INLINE MediumFlightLanes<T, typename L::Mask> medium_free_flight(const Medium& med,
                                                                             const LaneVec3<T>& d,
                                                                             const T w[3], T depth,
                                                                             Uniform&& uniform) {
    const T zero = L::constant(0), one = L::constant(1), infinity = L::constant(HUGE_VAL);
    MediumFlightLanes<T, typename L::Mask> r;
    const T mu = L::abs(d.z);
    const auto down = L::less(d.z, zero);
    const T to_boundary =
        L::select(L::less(zero, mu), L::select(down, one - depth, depth) / mu, infinity);
    const T total = w[0] + w[1] + w[2];
    const auto has_flux = L::less(zero, total);
    // Quotients, not products with a reciprocal: a flux of subnormal size (a base of albedo
    // 5e-324, found by the fuzz test) has an infinite reciprocal.
    const T safe_total = L::select(has_flux, total, one);
    r.p[0] = w[0] / safe_total;
    r.p[1] = w[1] / safe_total;
    r.p[2] = w[2] / safe_total;
    const T p01 = r.p[0] + r.p[1];
    const T u_channel = uniform();
    const auto first = L::less(u_channel, r.p[0]), second = L::less(u_channel, p01);
    auto pick = [&](const auto& v0, const auto& v1, const auto& v2) {
        return L::select(first, medium_lane<T, L>(v0),
                         L::select(second, medium_lane<T, L>(v1), medium_lane<T, L>(v2)));
    };
    const T sigma = pick(med.tau_t[0], med.tau_t[1], med.tau_t[2]);
    const T u_flight = uniform();
    // ln(1 − u) of a uniform number (a multiple of 2^-24 in float, 2^-53 in double: core/rng.h):
    // 1 − u is exact, so log1p is not needed.
    const auto extinct = L::less(zero, sigma);
    const T flight = L::select(
        extinct, (zero - L::log(one - u_flight)) / L::select(extinct, sigma, one), infinity);
    r.leaves = L::either(L::negate(has_flux), L::negate(L::less(flight, to_boundary)));
    const T t = L::select(r.leaves, to_boundary, flight);
    r.depth = L::min(L::max(L::neg_mul_add(d.z, flight, depth), zero), one);
    if (med.uniform_tau_t) {
        for (int c = 0; c < 3; ++c)
            r.factor[c] =
                L::select(r.leaves, one, medium_lane<T, L>(med.single_scattering_albedo[c]));
        return r;
    }
    T e[3], mix = zero, mix_scatter = zero;
    for (int c = 0; c < 3; ++c) {
        // A clear channel along a horizontal path (t = ∞): 0 · ∞ would be NaN; transmittance 1.
        const T tau_t = medium_lane<T, L>(med.tau_t[c]);
        if constexpr (std::is_arithmetic_v<std::remove_cvref_t<decltype(med.tau_t[c])>>)
            e[c] = med.tau_t[c] > 0 ? L::exp((zero - tau_t) * t) : one;
        else
            e[c] = L::select(L::less(zero, tau_t), L::exp((zero - tau_t) * t), one);
        mix = L::mul_add(r.p[c], e[c], mix);
        mix_scatter = L::mul_add(r.p[c] * tau_t, e[c], mix_scatter);
    }
    const T safe_mix = L::select(L::both(L::less(zero, mix), has_flux), mix, one);
    const T safe_mix_scatter = L::select(L::less(zero, mix_scatter), mix_scatter, one);
    for (int c = 0; c < 3; ++c)
        r.factor[c] = L::select(r.leaves, L::select(has_flux, e[c] / safe_mix, one),
                                medium_lane<T, L>(med.tau_s[c]) * e[c] / safe_mix_scatter);
    return r;
}

/// The second half: a scattering event of the lanes of `scatters` travelling along d, whose
/// flight's channel probabilities are p[3]: the phase function's channel drawn ∝ p (one uniform,
/// only when g differs per channel), the new direction drawn from HG of that channel's g
/// (sample_hg_direction, two uniforms), and, when g differs per channel, the flux factors
/// HG_c / Σ_k p_k HG_k at the new direction (factor[c]; 1 otherwise). Draws nothing when no lane
/// scatters (returns false); true otherwise.
template <typename T, typename L = Lane<T>, typename Medium, typename Uniform>
LAMINA_LANE_INLINE bool medium_scatter(const Medium& med, const LaneVec3<T>& d, const T p[3],
                                       typename L::Mask scatters, Uniform&& uniform,
                                       LaneVec3<T>& d_new, T factor[3]) {
    const T zero = L::constant(0), one = L::constant(1);
    factor[0] = factor[1] = factor[2] = one;
    if (L::none(scatters)) return false;
    T g = medium_lane<T, L>(med.g[0]);
    if (!med.uniform_g) {
        const T u_phase = uniform();
        g = L::select(L::less(u_phase, p[0]), g,
                      L::select(L::less(u_phase, p[0] + p[1]), medium_lane<T, L>(med.g[1]),
                                medium_lane<T, L>(med.g[2])));
    }
    const T u1 = uniform(), u2 = uniform();
    d_new = sample_hg_direction<T, L>(d, g, u1, u2);
    if (med.uniform_g) return true;
    const T cos_theta = lane_dot<T, L>(d, d_new);
    T phase[3], mix = zero;
    for (int c = 0; c < 3; ++c) {
        phase[c] = hg_phase<T, L>(cos_theta, medium_lane<T, L>(med.g[c]));
        mix = L::mul_add(p[c], phase[c], mix);
    }
    const T safe_mix = L::select(L::less(zero, mix), mix, one);
    for (int c = 0; c < 3; ++c)
        factor[c] = phase[c] / safe_mix;
    return true;
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_MEDIUM_BODY

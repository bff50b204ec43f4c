#pragma once
// Probes of the SIMD lanes, for the tests only (built into the test binary, never into lamina):
// each runs one piece of the SIMD kernel's lane code — its random numbers, its exit bins, the
// vector maths of core/lane_hwy.h, or a physics lane template instantiated with VecLane — on the
// dispatched instruction set's vectors (after select_simd_target, so LAMINA_SIMD_TARGET caps it),
// over plain arrays, so that a test compares it with the scalar instantiation or a reference.
// simd_target_name (simulator/kernel_simd.h) names the instruction set they ran on.

#include "layers/compiled_stack.h"
#include "simulator/kernel_simd.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace lamina {

/// the first `n_draws` uniform floats of particles [first, first + n_particles) as the
/// SIMD kernel's lanes draw them (row-major: particle, then draw). They must equal
/// ParticleRng(seed, stream, p).uniform_float() bit for bit.
std::vector<float> simd_particle_uniforms(std::uint64_t seed, std::uint64_t stream,
                                          std::uint64_t first, std::uint64_t n_particles,
                                          std::uint64_t n_draws);

/// the kernel's 1/√x (core/lane_hwy.h VecLane::inv_sqrt) of each x > 0.
std::vector<float> simd_inv_sqrt(const std::vector<float>& x);

/// the kernel's azimuth cos(2πu), sin(2πu) for u in [0, 1).
void simd_cos_sin_2pi(const std::vector<float>& u, std::vector<float>& c, std::vector<float>& s);

/// the exit bins the SIMD kernel computes on the dispatched instruction set's vectors
/// (d: 3 floats per unit direction), or −1 where it leaves the bin to HemisphereGrid::bin_of.
std::vector<std::int64_t> simd_lane_bins(const HemisphereGrid& grid, const std::vector<float>& d);

/// physics/microfacet.h smith_refraction_escape(r_i[j], r_o[j]) instantiated on the
/// dispatched instruction set's vectors (the lane test compares it with the scalar instantiation).
std::vector<float> simd_smith_refraction_escape(const std::vector<float>& r_i,
                                                const std::vector<float>& r_o);

/// physics/fresnel.h fresnel_dielectric_full(cos_theta[j], eta) on the dispatched
/// instruction set's vectors: its reflectance and refracted cosine.
void simd_fresnel_dielectric(const std::vector<float>& cos_theta, float eta,
                             std::vector<float>& reflectance, std::vector<float>& cos_theta_t);

/// physics/fresnel.h fresnel_conductor(cos_theta[j], eta, k) on the dispatched
/// instruction set's vectors.
std::vector<float> simd_fresnel_conductor(const std::vector<float>& cos_theta, float eta, float k);

/// physics/medium.h beer_lambert_transmittance_lanes with optical depth tau[j] (in every
/// channel) and inv_mu[j] on the dispatched instruction set's vectors, a depth per lane as a
/// spectral run's lanes have them.
std::vector<float> simd_beer_lambert_lanes(const std::vector<float>& tau,
                                           const std::vector<float>& inv_mu);

/// physics/phase.h hg_phase(x[j], g[j]) and sample_hg_cos_theta(g[j], x[j]) on the
/// dispatched instruction set's vectors.
void simd_henyey_greenstein(const std::vector<float>& g, const std::vector<float>& x,
                            std::vector<float>& phase, std::vector<float>& cos_theta);

/// physics/microfacet.h ggx_lambda(alpha², w) and ggx_sample_visible_normal_complete
/// (alpha, w, u1, u2) on the dispatched instruction set's vectors; w, wm: 3 floats per entry.
void simd_ggx_lanes(float alpha, const std::vector<float>& w, const std::vector<float>& u1,
                    const std::vector<float>& u2, std::vector<float>& lambda,
                    std::vector<float>& wm);

/// where microsurface walks left the microsurface (physics/microsurface_walk.h
/// microsurface_walk on the dispatched instruction set's vectors). Particle p arrives from
/// wi[3p..3p+2] and draws from ParticleRng(seed, 0, p) as the kernel's lanes draw; a dielectric
/// of relative index eta[0] (dielectric = true) or a conductor of index eta + i k per channel.
/// Per particle: wo (3 floats, the direction of travel out), weight (3), order, and outcome
/// (0 escaped, 1 stopped at the facet cap, 2 degenerate).
struct SimdWalkResult {
    std::vector<float> wo, weight;
    std::vector<int> order, outcome;
};
SimdWalkResult simd_microsurface_walk(const std::vector<float>& wi, float alpha, bool dielectric,
                                      const float eta[3], const float k[3], int max_order,
                                      std::uint64_t seed);

/// the interface events (physics/dielectric.h dielectric_event, conductor.h
/// conductor_event, lambertian.h lambertian_event) on the dispatched instruction set's vectors,
/// one lane per particle j arriving from wi[3j..3j+2] with uniforms u[j] (uc), u[n + j] (u1),
/// u[2n + j] (u2). kind 0: a dielectric, params {eta, alpha}, flags the DielectricEventShape
/// {smooth, index_matched, uncorrelated, smith_refraction}; kind 1: a conductor, params {alpha,
/// eta[3], k[3]}, flags {smooth, uncorrelated}; kind 2: a Lambertian (degenerate where wi.z = 0).
/// Per particle: wo (3), shadowing, the conductor's Fresnel factors (fresnel[c·n + j]; 1
/// otherwise), reflected and degenerate (0 or 1).
struct SimdEventResult {
    std::vector<float> wo, shadowing, fresnel;
    std::vector<std::int32_t> reflected, degenerate;
};
/// on_pairs: the template instantiated on pairs of vectors (VecLane2, the
/// kernel's two lane sets at one event), particles j and j + (the vector's lanes) side by side.
SimdEventResult simd_interface_events(int kind, const std::vector<float>& params,
                                      const std::vector<std::int32_t>& flags,
                                      const std::vector<float>& wi, const std::vector<float>& u,
                                      bool on_pairs = false);

/// one scattering-medium step (physics/medium.h medium_free_flight, then
/// medium_scatter for the lanes that scatter) on the dispatched instruction set's vectors, one
/// lane per particle j travelling along d[3j..3j+2] with flux w[c·n + j] at depth[j], its k-th
/// draw u[k·n + j] (at most 5). Per particle: leaves (0 or 1), the flight's factors
/// factor[c·n + j], the scattering depth, the new direction d (3; the old one where no lane
/// scatters), the phase factors phase[c·n + j] and the number of draws.
struct SimdMediumResult {
    std::vector<std::int32_t> leaves, draws;
    std::vector<float> factor, depth, d, phase;
};
SimdMediumResult simd_medium_step(const CompiledMedium<float>& medium, const std::vector<float>& d,
                                  const std::vector<float>& w, const std::vector<float>& depth,
                                  const std::vector<float>& u);

/// physics/polarization.h fresnel_dielectric_mueller(cos_theta[j], eta, 1/eta) (kind 0:
/// per entry the reflection's a, b, c, d, the refraction's a, b, c, d and the refracted cosine, 9
/// floats) or fresnel_conductor_mueller(cos_theta[j], eta, k) (kind 1: a, b, c, d) on the
/// dispatched instruction set's vectors.
std::vector<float> simd_fresnel_mueller(int kind, const std::vector<float>& cos_theta, float eta,
                                        float k);

/// the polarized interface events (dielectric_event and conductor_event with their
/// polarization, physics/polarization.h) on the dispatched instruction set's vectors, as
/// simd_interface_events (kinds 0 and 1, the same params, flags and draws), each lane also with
/// its state: the frame's x axis x[3j..3j+2], (q, u, v) of channel c at stokes[9j + 3c ..], the
/// flux flux[3j + c], `channels` states in use. Per particle: the event's results as
/// simd_interface_events, the state after it (x, stokes in the same layout) and the flux
/// factors factor[3j + c].
struct SimdPolarizedEventResult {
    SimdEventResult event;
    std::vector<float> x, stokes, factor;
};
SimdPolarizedEventResult simd_polarized_interface_events(
    int kind, const std::vector<float>& params, const std::vector<std::int32_t>& flags,
    const std::vector<float>& wi, const std::vector<float>& u, const std::vector<float>& x,
    const std::vector<float>& stokes, const std::vector<float>& flux, int channels);

/// simulator/lane_film.h FilmReflection (a thin film's reflection, each lane with its own film
/// and thickness) on the dispatched instruction set's vectors, entry j in lane j mod the lanes,
/// the lanes whose bit is set in `skip` inactive in every chunk; n_lanes: the vector's lanes.
/// Per entry (15 floats): the polarized operator's Mueller a, b, c, d of channels 0, 1, 2, then
/// the unpolarized operator's factor of each channel (inactive lanes: the identity and 1).
struct FilmOptics;
std::vector<float> simd_film_reflection(const std::vector<const FilmOptics*>& films,
                                        const std::vector<float>& cos_theta,
                                        const std::vector<double>& thickness_nm, std::uint64_t skip,
                                        std::size_t& n_lanes);

/// How far two float evaluations of physics/phase.h sample_hg_cos_theta(g, u) may differ when one
/// fuses multiply-adds and the other does not (SSE4 has none): twice a first-order bound on the
/// rounding of one, in double. s = (1 − g)(1 + g) / ((1 − |g|) + 2|g|(1 − u or u)), products and
/// sums of non-negative terms, carries 8 ulps relative; the cosine's numerator 1 + g² − s² then
/// loses (1 + g² + s²(1 + 2 · 8)) ulps, divided by 2|g| (its cancellation as g → 0), plus 2 ulps.
/// Where |g| < 1e-3 the cosine is 1 − 2u: 4 ulps.
inline double hg_cos_tolerance(float g_float, float u_float) {
    constexpr double ulp = 0x1p-24;
    const double g = g_float, u = u_float, a = std::abs(g);
    if (a < 1e-3) return 4 * ulp;
    const double s = (1 - g * g) / (1 + g - 2 * g * u);
    const double numerator_ulps = 1 + g * g + s * s * (1 + 2 * 8);
    return 2 * (numerator_ulps / (2 * a) + 2) * ulp;
}

/// hg_cos_tolerance's largest value over u in [0, 1] (65 points, the ends included), for a
/// sample whose uniform is not known.
inline double hg_cos_tolerance_max(float g) {
    double worst = 0;
    for (int k = 0; k <= 64; ++k)
        worst = std::max(worst, hg_cos_tolerance(g, std::min(float(k) / 64, 1 - 0x1p-24f)));
    return worst;
}

}  // namespace lamina

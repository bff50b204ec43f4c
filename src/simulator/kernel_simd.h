#pragma once
// The batched SIMD particle kernel (goniophotometer.h, Kernel::Simd).

#include "simulator/tally.h"

#include <cstdint>
#include <vector>

namespace lamina {

/// Traces the block's particles as lanes of SIMD vectors; same contract as trace_block_scalar.
void trace_block_simd(const BlockJob& job, Tally& tally, BlockBudget& block);

/// For tests: the first `n_draws` uniform floats of particles [first, first + n_particles) as the
/// SIMD kernel's lanes draw them (row-major: particle, then draw). They must equal
/// ParticleRng(seed, stream, p).uniform_float() bit for bit.
std::vector<float> simd_particle_uniforms(std::uint64_t seed, std::uint64_t stream,
                                          std::uint64_t first, std::uint64_t n_particles,
                                          std::uint64_t n_draws);

/// For tests: the kernel's azimuth cos(2πu), sin(2πu) for u in [0, 1).
void simd_cos_sin_2pi(const std::vector<float>& u, std::vector<float>& c, std::vector<float>& s);

/// For tests: physics/microfacet.h smith_refraction_escape(r_i[j], r_o[j]) instantiated on the
/// dispatched instruction set's vectors (the lane test compares it with the scalar instantiation).
std::vector<float> simd_smith_refraction_escape(const std::vector<float>& r_i,
                                                const std::vector<float>& r_o);

/// For tests: physics/fresnel.h fresnel_dielectric_full(cos_theta[j], eta) on the dispatched
/// instruction set's vectors: its reflectance and refracted cosine.
void simd_fresnel_dielectric(const std::vector<float>& cos_theta, float eta,
                             std::vector<float>& reflectance, std::vector<float>& cos_theta_t);

/// For tests: physics/fresnel.h fresnel_conductor(cos_theta[j], eta, k) on the dispatched
/// instruction set's vectors.
std::vector<float> simd_fresnel_conductor(const std::vector<float>& cos_theta, float eta, float k);

/// For tests: physics/phase.h hg_phase(x[j], g[j]) and sample_hg_cos_theta(g[j], x[j]) on the
/// dispatched instruction set's vectors.
void simd_henyey_greenstein(const std::vector<float>& g, const std::vector<float>& x,
                            std::vector<float>& phase, std::vector<float>& cos_theta);

/// For tests: physics/microfacet.h ggx_lambda(alpha², w) and ggx_sample_visible_normal_complete
/// (alpha, w, u1, u2) on the dispatched instruction set's vectors; w, wm: 3 floats per entry.
void simd_ggx_lanes(float alpha, const std::vector<float>& w, const std::vector<float>& u1,
                    const std::vector<float>& u2, std::vector<float>& lambda,
                    std::vector<float>& wm);

/// For tests: where microsurface walks left the microsurface (physics/microsurface_walk.h
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

/// Applies LAMINA_SIMD_TARGET (an instruction set name as simd_target_name prints it, e.g. AVX2 or
/// SSE4), which caps the dispatch at that set: the way to reproduce another machine's tables, or to
/// test every compiled set on one machine. Once per process; InputError for an unknown or
/// unsupported name.
void select_simd_target();

/// The instruction set the SIMD kernel dispatches to on this machine (e.g. "AVX3"), after
/// LAMINA_SIMD_TARGET.
const char* simd_target_name();

}  // namespace lamina

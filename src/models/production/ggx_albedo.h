#pragma once
// Directional albedos of a GGX reflection lobe with the height-correlated Smith masking-shadowing
// (Heitz 2014, "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT 3(2),
// Eq. 99), the integrals that engines tabulate to layer and to compensate their lobes (Cycles'
// tables, models/production/cycles_albedo.h; three.js's DFG texture,
// models/production/threejs_dfg.h). lamina computes each over the normals visible from wi (Heitz
// 2018, "Sampling the GGX distribution of visible normals", JCGT 7(4)), where sampling leaves the
// weight G2(wi, wo)/G1(wi) = (1 + Λi)/(1 + Λi + Λo); a normal whose reflection wo goes below the
// horizon contributes 0. n_r Gauss–Legendre nodes per piece of the visible-normal radius (split
// where wo crosses the horizon) × n_phi nodes in φ; μ is taken at ≥ 10⁻⁶.

#include "core/math.h"
#include "models/numerics/quadrature.h"
#include "models/numerics/visible_normal_quadrature.h"
#include "physics/microfacet.h"

#include <algorithm>

namespace lamina {

/// The smallest cosine the integrals are taken at (the μ = 0 node is the limit μ → 0).
inline constexpr double kAlbedoMuMin = 1e-6;

/// ∫ f(ggx, wi, wo, wi·h) dh over the normals h visible from wi (μ = wi.z) whose reflection wo
/// leaves above the horizon, the radius split where wo crosses it (the integrand has a kink
/// there); the albedos below and those of models/production/uncorrelated_albedo.h.
/// V the integrand's value (double, or a colour such as Rgbd).
template <typename V = double, typename Integrand>
V reflection_over_visible_normals(double mu, double alpha, Integrand&& f, int n_r, int n_phi) {
    mu = std::max(mu, kAlbedoMuMin);
    const Vec3d wi(safe_sqrt(1 - mu * mu), 0, mu);
    const GGX<double> ggx{alpha};
    const QuadratureRule q = gauss_legendre(n_r);
    auto outgoing_z = [&](const Vec3d& h) { return 2 * dot(wi, h) * h.z - wi.z; };
    auto integrand = [&](const Vec3d& h) -> V {
        const double cos_h = dot(wi, h);
        const Vec3d wo = h * (2 * cos_h) - wi;
        if (wo.z <= 0) return V{};
        return f(ggx, wi, wo, cos_h);
    };
    return integrate_visible_split<V>(ggx, wi, integrand, q, n_phi, 1e-7,
                                      Crossing{outgoing_z, 0.0});
}

/// E(μ, α): the directional albedo of the white lobe (F = 1), ∫ D_wi(h) G2/G1(wi) dh. μ ∈ [0, 1],
/// α ≥ 0 (α = 0 gives 1).
double correlated_ggx_albedo_white(double mu, double alpha, int n_r = 24, int n_phi = 48);

/// E split by Schlick's Fresnel weight w(c) = (1 − c)⁵ (Schlick 1994, Eq. 15) at c = wi·h into
/// scale and bias, E_F0 = F0 · scale + F90 · bias for F = F0 + (F90 − F0) w (Karis 2013, "Real
/// shading in Unreal Engine 4", the split-sum's environment BRDF): scale = ∫ (1 − w) …,
/// bias = ∫ w …; scale + bias = E.
struct SchlickSplit {
    double scale = 0, bias = 0;
};
SchlickSplit correlated_ggx_schlick_split(double mu, double alpha, int n_r = 24, int n_phi = 48);

/// s(μ, α, η): the mean over the same visible normals of the position of the exact dielectric
/// Fresnel between its ends, ŝ(c) = clamp((F(c; η) − F0)/(1 − F0), 0, 1) at c = wi·h, with
/// F0 = ((η − 1)/(η + 1))², η > 1 (a normal whose reflection goes below the horizon counts 0); no
/// masking weight. α = 0 gives ŝ(μ). Cycles takes F0 + (1 − F0) s as the albedo of a rough
/// dielectric's reflection relative to its own lobe.
double cycles_fresnel_factor(double mu, double alpha, double eta, int n_r = 24, int n_phi = 48);

}  // namespace lamina

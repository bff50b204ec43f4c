#pragma once
// Closed forms of docs/physics.md §6 used by several tests, each with its derivation.

#include "core/math.h"
#include "core/rgb.h"
#include "physics/fresnel.h"
#include "support/quadrature.h"

#include <cmath>

namespace lamina::test {

/// §6.3: a smooth coat (index η) over a Lambertian (ρ) with absorption τ between, all orders of
/// internal reflection:
///   f(μi, μo) = ρ/(πη²) (1 − F(μi)) e^{−τ/μi'} (1 − F(μo)) e^{−τ/μo'} / (1 − ρ r),
///   r = 2∫₀¹ F_inside(μ) e^{−2τ/μ} μ dμ (relative index 1/η; total reflection gives 1),
/// plus the mirror reflection F(μi). The diffuse albedo is
///   (1 − F(μi)) e^{−τ/μi'} ρ t / (1 − ρ r),  t = 2∫₀¹ (1 − F_inside(μ)) e^{−τ/μ} μ dμ
/// (the light diffused upwards is cosine-distributed: 2μ dμ; each pass through the coat at
/// inside cosine μ is attenuated by e^{−τ/μ}).
struct CoatedLambertianSeries {
    double eta;
    Rgbd tau, rho;
    Rgbd internal{0.0};  ///< r per channel
    Rgbd escape{0.0};    ///< t per channel

    CoatedLambertianSeries(double eta_, Rgbd tau_, Rgbd rho_) : eta(eta_), tau(tau_), rho(rho_) {
        const double mu_c = std::sqrt(1 - 1 / (eta * eta));  // critical cosine inside
        auto f_in = [&](double mu) { return fresnel_dielectric(mu, 1 / eta); };
        for (int c = 0; c < 3; ++c) {
            // Below μ_c the inside light is totally reflected (F_inside = 1) and never escapes.
            internal[c] =
                2 *
                (integrate([&](double mu) { return mu * std::exp(-2 * tau[c] / mu); }, 0, mu_c, 32,
                           8) +
                 integrate([&](double mu) { return f_in(mu) * std::exp(-2 * tau[c] / mu) * mu; },
                           mu_c, 1, 32, 8));
            escape[c] =
                2 *
                integrate([&](double mu) { return (1 - f_in(mu)) * std::exp(-tau[c] / mu) * mu; },
                          mu_c, 1, 32, 8);
        }
    }

    /// cos of the refracted angle inside the coat.
    double refracted_cos(double mu) const { return std::sqrt(1 - (1 - mu * mu) / (eta * eta)); }

    /// The diffuse part of f (1/sr) for outside cosines mu_i, mu_o.
    Rgbd diffuse(double mu_i, double mu_o) const {
        Rgbd f;
        for (int c = 0; c < 3; ++c)
            f[c] = rho[c] / (kPi<double> * eta * eta) * (1 - fresnel_dielectric(mu_i, eta)) *
                   std::exp(-tau[c] / refracted_cos(mu_i)) * (1 - fresnel_dielectric(mu_o, eta)) *
                   std::exp(-tau[c] / refracted_cos(mu_o)) / (1 - rho[c] * internal[c]);
        return f;
    }

    /// The mirror lobe's energy F(μi).
    double specular(double mu_i) const { return fresnel_dielectric(mu_i, eta); }

    /// The directional albedo, mirror lobe included.
    Rgbd albedo(double mu_i) const {
        const double F = specular(mu_i);
        Rgbd a;
        for (int c = 0; c < 3; ++c)
            a[c] = F + (1 - F) * std::exp(-tau[c] / refracted_cos(mu_i)) * rho[c] * escape[c] /
                           (1 - rho[c] * internal[c]);
        return a;
    }
};

}  // namespace lamina::test

#pragma once
// Closed forms of docs/physics.md §6 used by several tests, each with its derivation.

#include "core/math.h"
#include "core/rgb.h"
#include "physics/fresnel.h"
#include "support/quadrature.h"

#include <cmath>
#include <complex>

namespace lamina::test {

/// Born & Wolf §1.5.2 (Eqs. 20–21) with a complex relative index n (§14.2), for tests of polarized
/// transport, written here with std::complex independently of physics/polarization.h: the
/// amplitude coefficients of light arriving at cos θi ∈ [0, 1] (cos θt the principal root,
/// Im ≥ 0), the flux factor Re(n cos θt)/cos θi of the refracted beam (real n), the reflectances
/// R_s = |r_s|², R_p = |r_p|², and the products that act on S2 + iS3 (docs/physics.md §8: a Jones
/// matrix diag(A, B) multiplies S2 + iS3 = 2 E_x* E_y by A* B).
struct PolarizedFresnel {
    std::complex<double> rs, rp, ts, tp;
    double flux_factor = 0;
    double Rs() const { return std::norm(rs); }
    double Rp() const { return std::norm(rp); }
    std::complex<double> reflected_phase() const { return std::conj(rs) * rp; }
    std::complex<double> transmitted_phase() const { return flux_factor * std::conj(ts) * tp; }

    PolarizedFresnel(double cos_i, std::complex<double> n) {
        const double sin2 = 1 - cos_i * cos_i;
        const std::complex<double> cos_t = std::sqrt(1.0 - sin2 / (n * n));
        rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
        rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
        ts = 2 * cos_i / (cos_i + n * cos_t);
        tp = 2 * cos_i / (n * cos_i + cos_t);
        flux_factor = (n * cos_t).real() / cos_i;
    }
};

/// The unpolarized Fresnel reflectance ½(R_s + R_p) of relative index η + iκ at cos θi (1 under
/// total internal reflection, where |r_s| = |r_p| = 1).
inline double fresnel_ref(double cos_i, double eta, double kappa = 0) {
    const PolarizedFresnel f(cos_i, {eta, kappa});
    return 0.5 * (f.Rs() + f.Rp());
}
/// The same for a conductor (the name the production coats' tests read best with).
inline double conductor_ref(double cos_i, double eta, double kappa) {
    return fresnel_ref(cos_i, eta, kappa);
}

/// A smooth parallel stack keeps every event in one plane of incidence, so s- and p-polarized
/// light never mix: the exact (polarized) reflectance and transmittance of a smooth slab of
/// relative index η with one crossing's attenuation a, for unpolarized light, are the mean over s
/// and p of the incoherent geometric series of docs/physics.md §6.4 with that polarization's
/// Fresnel reflectance R_x at μi (the same at the inside angle):
///     R = ½ Σ_x [R_x + (1 − R_x)² R_x a² / (1 − R_x² a²)],  T = ½ Σ_x (1 − R_x)² a / (1 − R_x²
///     a²).
struct PolarizedSlab {
    double R = 0, T = 0;
    PolarizedSlab(double mu_i, double eta, double a) {
        const PolarizedFresnel f(mu_i, eta);
        for (const double Rx : {f.Rs(), f.Rp()}) {
            R += 0.5 * (Rx + (1 - Rx) * (1 - Rx) * Rx * a * a / (1 - Rx * Rx * a * a));
            T += 0.5 * (1 - Rx) * (1 - Rx) * a / (1 - Rx * Rx * a * a);
        }
    }
};

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

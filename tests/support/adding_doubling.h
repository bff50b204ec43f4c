#pragma once
// An independent reference for scattering media: the adding–doubling method for a homogeneous,
// index-matched plane-parallel slab, azimuthally averaged (the m = 0 Fourier component, which
// fixes every hemispherical quantity). Hansen & Travis 1974, "Light scattering in planetary
// atmospheres", Space Sci. Rev. 16, §3.3 (doubling) and Eqs. 64–65 (adding); van de Hulst 1980,
// "Multiple Light Scattering", ch. 4.
//
// Discrete ordinates: Gauss–Legendre nodes μ_k on (0, 1). Operators act on radiance vectors:
// L_out(μ_i) = Σ_j M_ij L_in(μ_j). A thin layer of optical depth Δτ ≪ 1 is initialized by single
// scattering, R_ij = 2π ω Δτ p0(↑μ_i, ↓μ_j) w_j / μ_i (radiative transfer: the source ω∫pL dω
// integrated along the path Δτ/μ_i), T likewise with forward geometry plus the direct beam
// e^{−Δτ/μ_i}; layers are then doubled, R' = R + T (I − R R)⁻¹ R T, T' = T (I − R R)⁻¹ T (a
// homogeneous slab is symmetric, so its operators from above and below coincide).

#include "core/math.h"
#include "physics/phase.h"
#include "support/quadrature.h"

#include <cmath>
#include <vector>

namespace lamina::test {

class AddingDoubling {
  public:
    /// Slab of optical depth tau, single-scattering albedo omega, HG asymmetry g; n nodes.
    /// `doublings`: the starting layer is 2^-doublings of the slab (keep τ·2^-doublings near
    /// 6e-8, the default's for τ = 1, for the same accuracy).
    AddingDoubling(double tau, double omega, double g, int n = 32, int doublings = 24) : n_(n) {
        const auto gl = gauss_legendre(n);
        for (const auto& [x, w] : gl) {
            mu_.push_back(0.5 * (x + 1));
            w_.push_back(0.5 * w);
        }
        // Thin starting layer: 2^-doublings of the slab. Its single scattering is exact (below),
        // so the error is its missing double scattering, O(Δτ²) per starting layer.
        const double dtau = std::ldexp(tau, -doublings);
        // Azimuthally averaged HG phase function between propagation cosines a and b.
        const auto gl_phi = gauss_legendre(128);
        auto p0 = [&](double a, double b) {
            double s = 0;
            for (const auto& [x, w] : gl_phi) {
                const double phi = kPi<double> * (x + 1);  // [0, 2π]
                const double c = a * b + std::sqrt((1 - a * a) * (1 - b * b)) * std::cos(phi);
                s += w * hg_phase(c, g);
            }
            return s * kPi<double> / (2 * kPi<double>);  // (1/2π) ∫ dφ, dφ = π dx
        };
        R_.assign(n * n, 0.0);
        T_.assign(n * n, 0.0);
        for (int i = 0; i < n; ++i) {
            for (int j = 0; j < n; ++j) {
                // Incident travelling down (cos −μ_j); reflected up (+μ_i), transmitted down
                // (−μ_i). Exact single scattering of a layer Δτ (van de Hulst 1980, §4.2):
                //   f_R = ω p (1 − e^{−Δτ(1/μ + 1/μ0)}) / (μ + μ0),
                //   f_T = ω p (e^{−Δτ/μ} − e^{−Δτ/μ0}) / (μ − μ0)   (→ ω p Δτ e^{−Δτ/μ}/μ² at μ =
                //   μ0),
                // and the operator entry is 2π f μ_j w_j.
                const double mi = mu_[i], mj = mu_[j];
                const double fr = (-std::expm1(-dtau * (1 / mi + 1 / mj))) / (mi + mj);
                const double ft = i == j
                                      ? dtau * std::exp(-dtau / mi) / (mi * mi)
                                      : (std::exp(-dtau / mi) - std::exp(-dtau / mj)) / (mi - mj);
                const double common = 2 * kPi<double> * omega * mj * w_[j];
                R_[i * n + j] = common * fr * p0(mi, -mj);
                T_[i * n + j] = common * ft * p0(-mi, -mj);
            }
            // The direct beam: a radiance vector passes unchanged in direction, attenuated.
            T_[i * n + i] += std::exp(-dtau / mu_[i]);
        }
        for (int k = 0; k < doublings; ++k)
            double_layer();
    }

    int size() const { return n_; }
    double mu(int j) const { return mu_[j]; }

    /// Directional-hemispherical reflectance and transmittance for a beam at node j.
    double albedo_reflected(int j) const { return flux(R_, j); }
    double albedo_transmitted(int j) const { return flux(T_, j); }

  private:
    using Matrix = std::vector<double>;

    Matrix mul(const Matrix& a, const Matrix& b) const {
        Matrix c(n_ * n_, 0.0);
        for (int i = 0; i < n_; ++i)
            for (int k = 0; k < n_; ++k) {
                const double aik = a[i * n_ + k];
                for (int j = 0; j < n_; ++j)
                    c[i * n_ + j] += aik * b[k * n_ + j];
            }
        return c;
    }

    // (I − A)⁻¹ B by Gauss–Jordan elimination with partial pivoting.
    Matrix solve(const Matrix& a, const Matrix& b) const {
        Matrix m(n_ * n_), x = b;
        for (int i = 0; i < n_ * n_; ++i)
            m[i] = (i / n_ == i % n_ ? 1.0 : 0.0) - a[i];
        for (int col = 0; col < n_; ++col) {
            int pivot = col;
            for (int r = col + 1; r < n_; ++r)
                if (std::abs(m[r * n_ + col]) > std::abs(m[pivot * n_ + col])) pivot = r;
            for (int c = 0; c < n_; ++c) {
                std::swap(m[col * n_ + c], m[pivot * n_ + c]);
                std::swap(x[col * n_ + c], x[pivot * n_ + c]);
            }
            const double inv = 1 / m[col * n_ + col];
            for (int c = 0; c < n_; ++c) {
                m[col * n_ + c] *= inv;
                x[col * n_ + c] *= inv;
            }
            for (int r = 0; r < n_; ++r) {
                if (r == col) continue;
                const double f = m[r * n_ + col];
                if (f == 0) continue;
                for (int c = 0; c < n_; ++c) {
                    m[r * n_ + c] -= f * m[col * n_ + c];
                    x[r * n_ + c] -= f * x[col * n_ + c];
                }
            }
        }
        return x;
    }

    void double_layer() {
        const Matrix rr = mul(R_, R_);
        const Matrix x_rt = solve(rr, mul(R_, T_));  // (I − RR)⁻¹ R T
        const Matrix x_t = solve(rr, T_);            // (I − RR)⁻¹ T
        const Matrix r_new = mul(T_, x_rt);
        const Matrix t_new = mul(T_, x_t);
        for (int i = 0; i < n_ * n_; ++i)
            R_[i] += r_new[i];
        T_ = t_new;
    }

    // A beam of unit irradiance at node j is the radiance vector e_j / (2π μ_j w_j); the flux
    // leaving is Σ_i 2π μ_i w_i L_out(μ_i).
    double flux(const Matrix& m, int j) const {
        double s = 0;
        for (int i = 0; i < n_; ++i)
            s += mu_[i] * w_[i] * m[i * n_ + j];
        return s / (mu_[j] * w_[j]);
    }

    int n_;
    std::vector<double> mu_, w_;
    Matrix R_, T_;
};

}  // namespace lamina::test

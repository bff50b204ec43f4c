#pragma once
// The axes of a table f(c, α, η) that steps at the critical cosine of total internal reflection
// (a rough interface's transmittance, the fraction of a lobe of light that leaves through an
// interface), and its interpolation.
//
// c in two pieces split at the critical cosine μc(η) = √(1 − η²) (μc = 0 for η ≥ 1): c = μc (1 −
// y²) below it (n_below nodes uniform in y) and c = μc + (1 − μc) x² above it (n_c nodes uniform in
// x; for η ≥ 1, c = x²), so that the (smoothed) step lies on one node line at every η and the nodes
// crowd towards it from both sides; α = s² (n_alpha nodes, s uniform in [0, 1]); η in two halves
// meeting at the node η = 1, uniform in log2 η up to 2^log2_eta_max above and uniform in μc(η) down
// to η = 2^log2_eta_min below (n_eta nodes in all; μc moves fastest with η near 1). Arguments
// outside are clamped.
//
// A table on these axes stores the residual f − w(α) f0(c, η) from the smooth limit f0 (the
// value at α = 0, a step or a kink at μc), w(α) = e^{−α/0.03}: a control variate for the nodes
// of small α, where f is nearly the step itself. The lookup interpolates the residual
// multilinearly at the query's own μc — the table at every η node holds f at the same fractions
// of the pieces below and above μc, so the step is never interpolated across — and adds w f0 back
// (the weight interpolated in α as the residual is). Layout: ((ic n_alpha + ia) n_eta + ie)
// components + k, ic over both pieces of c (n_below + n_c).

#include "core/math.h"

#include <cmath>
#include <vector>

namespace lamina {

/// The cosine of total internal reflection μc(η) = √(1 − η²) for a relative index η < 1 (light
/// from the denser side), 0 where there is none (η ≥ 1).
inline double critical_cosine(double eta) {
    return eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;
}

struct CriticalCosineAxes {
    int n_below, n_c, n_alpha, n_eta;
    double log2_eta_min, log2_eta_max;
    double c_min, alpha_min;  ///< the smallest c and α nodes (their exact 0 is singular)
    /// w(α) at the α nodes (alpha_weights_at, filled by the constructor).
    std::vector<double> alpha_weights;

    CriticalCosineAxes(int n_below_, int n_c_, int n_alpha_, int n_eta_, double log2_eta_min_,
                       double log2_eta_max_, double c_min_, double alpha_min_)
        : n_below(n_below_),
          n_c(n_c_),
          n_alpha(n_alpha_),
          n_eta(n_eta_),
          log2_eta_min(log2_eta_min_),
          log2_eta_max(log2_eta_max_),
          c_min(c_min_),
          alpha_min(alpha_min_) {
        for (int i = 0; i < n_alpha; ++i)
            alpha_weights.push_back(smooth_weight(alpha_node(i)));
    }

    int c_count() const { return n_below + n_c; }
    std::size_t count(int components = 1) const {
        return std::size_t(c_count()) * n_alpha * n_eta * components;
    }
    std::size_t index(int ic, int ia, int ie, int components = 1, int k = 0) const {
        return ((std::size_t(ic) * n_alpha + ia) * n_eta + ie) * components + k;
    }

    /// The cosine of node i of the c axis at η.
    double c_node(int i, double eta) const {
        const double mu_c = critical_cosine(eta);
        double c;
        if (i < n_below) {
            const double y = 1 - double(i) / (n_below - 1);
            c = mu_c * (1 - y * y);
        } else {
            const double x = double(i - n_below) / (n_c - 1);
            c = mu_c + (1 - mu_c) * x * x;
        }
        return std::max(c_min, c);
    }
    /// True for a node of the lower piece (c ≤ μc).
    bool below(int i) const { return i < n_below; }
    double alpha_node(int i) const { return std::max(alpha_min, sqr(double(i) / (n_alpha - 1))); }
    int eta_one() const { return (n_eta - 1) / 2; }
    double max_critical_cosine() const { return critical_cosine(std::exp2(log2_eta_min)); }
    double eta_node(int i) const {
        if (i >= eta_one())
            return std::exp2(log2_eta_max * (i - eta_one()) / (n_eta - 1 - eta_one()));
        const double mu_c = max_critical_cosine() * (eta_one() - i) / eta_one();
        return std::sqrt(1 - mu_c * mu_c);
    }
    /// The fractional node index of η (clamped to the axis).
    double eta_index(double eta) const {
        if (eta >= 1)
            return eta_one() +
                   std::min(std::log2(eta) / log2_eta_max, 1.0) * (n_eta - 1 - eta_one());
        return eta_one() * (1 - std::min(critical_cosine(eta) / max_critical_cosine(), 1.0));
    }

    /// The control variate's weight w(α) = e^{−α/0.03}.
    static double smooth_weight(double alpha) { return std::exp(-alpha / 0.03); }

    /// Interpolated component k of a table of these axes holding the residual from w(α) f0: c ∈
    /// [0, 1], α ∈ (0, 1], η clamped here; limit = f0 at the query (for a step, its value on the
    /// query's side: c < μc is the lower piece).
    double interpolate(const std::vector<float>& values, int components, int k, double c,
                       double alpha, double eta, double limit) const {
        eta = clamp(eta, std::exp2(log2_eta_min), std::exp2(log2_eta_max));
        const double mu_c = critical_cosine(eta);
        double fc;
        if (c < mu_c) {
            fc = (1 - std::sqrt(std::max(0.0, 1 - c / mu_c))) * (n_below - 1);
        } else {
            fc = n_below + std::sqrt(mu_c < 1 ? (c - mu_c) / (1 - mu_c) : 0.0) * (n_c - 1);
        }
        const double fa = std::sqrt(clamp(alpha, 0.0, 1.0)) * (n_alpha - 1);
        const double fe = eta_index(eta);
        const int ic_max = c < mu_c ? n_below - 2 : n_below + n_c - 2;
        const int ic = std::min(int(fc), ic_max), ia = std::min(int(fa), n_alpha - 2),
                  ie = std::min(int(fe), n_eta - 2);
        const double tc = fc - ic, ta = fa - ia, te = fe - ie;
        // The weight interpolated as the residual is (exact at the α nodes): the weight itself at
        // the query's α would add its own curvature in α to the interpolation error (2e-3 at
        // α = 0.05, η = 1.5, on a rough interface's transmittance, nearly constant there).
        const double weight = (1 - ta) * alpha_weights[ia] + ta * alpha_weights[ia + 1];
        double sum = 0;
        for (int dc = 0; dc < 2; ++dc)
            for (int da = 0; da < 2; ++da) {
                const double w = (dc ? tc : 1 - tc) * (da ? ta : 1 - ta);
                const float* row = values.data() + index(ic + dc, ia + da, ie, components, k);
                sum += w * ((1 - te) * row[0] + te * row[components]);
            }
        if (weight > 0) sum += weight * limit;
        return sum;
    }
};

}  // namespace lamina

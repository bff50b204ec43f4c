#pragma once
// The random walk's connection towards wo (randomwalk/random_walk.h): the directions a chain of
// smooth interfaces maps onto wo in every region, and the exact throughput of all delta chains
// from each region to the exit (the delta-chain ladder), with the small helpers the walk shares
// with it. Internal to randomwalk/.

#include "randomwalk/random_walk.h"

#include <cmath>
#include <vector>

namespace lamina {

// ---- The connection towards wo (docs/rendering.md §1.2) ----------------------------------------
// Regions r = 0..L: 0 the ambient medium, r the medium below interface r − 1, L below the base.
// At the Snell invariant of wo every region r has one horizontal component h_r = (η_e/η_r)·wo_xy
// (η_e the index of the exit region) and a cosine μ_r = √(1 − |h_r|²), or none (evanescent).
// up[k] / down[k] = throughput of every delta chain from light arriving at interface k from below
// / from above to the exit towards wo, per channel.
struct RandomWalkStack::Connection {
    bool top = true;  ///< the exit is upwards (BRDF) rather than downwards (BTDF)
    /// Strategy 2 applies: the exit interface (the top for the BRDF, the base for the BTDF) is a
    /// rough dielectric with a region on its inner side (`inner`, 1 or L − 1) whose vertices —
    /// interface `vertex_interface` (1 or L − 2) and scattering events — it connects.
    bool rough_exit = false;
    int exit_interface = 0, inner = 1, vertex_interface = 1;
    /// Propagation towards the exit in the inner region: +1 up (top), −1 down (base).
    double towards = 1;
    /// The depth-distance from depth s of the inner region to the exit interface.
    double distance(double s) const { return top ? s : 1 - s; }
    int L = 0;
    std::vector<char> valid;      ///< region r has a propagating direction
    std::vector<double> mu;       ///< its |cos|
    std::vector<Vec3d> dir_up;    ///< propagation direction up in region r
    std::vector<Vec3d> dir_down;  ///< and down
    std::vector<Rgbd> t;          ///< unscattered transmittance of region r's whole medium
    std::vector<double> scale;    ///< (η_e/η_r)²: radiance compression
    std::vector<Rgbd> up, down;   ///< A_k^↑, A_k^↓ (polarized: the mean of the s and p ones)
    /// Polarized walks: the ladders of s- and p-polarized light ([0] s, [1] p), each chain lying in
    /// one plane of incidence (the vertical plane of wo), where the two never mix.
    bool polarized = false;
    std::vector<Rgbd> up_sp[2], down_sp[2];

    /// Throughput of leaving upwards from the bottom of region r (just above interface r).
    Rgbd from_bottom_up(int r) const {
        if (!valid[r]) return Rgbd(0.0);
        if (r == 0) return Rgbd(top ? 1.0 : 0.0);
        return t[r] * up[r - 1];
    }
    /// Throughput of leaving downwards from the top of region r (just below interface r − 1).
    Rgbd from_top_down(int r) const {
        if (!valid[r]) return Rgbd(0.0);
        if (r == L) return Rgbd(top ? 0.0 : 1.0);
        return t[r] * down[r];
    }
    /// The same for light polarized along s (x = 0) or p (x = 1) of the chain's plane.
    Rgbd from_bottom_up(int r, int x) const {
        if (!valid[r]) return Rgbd(0.0);
        if (r == 0) return Rgbd(top ? 1.0 : 0.0);
        return t[r] * up_sp[x][r - 1];
    }
    Rgbd from_top_down(int r, int x) const {
        if (!valid[r]) return Rgbd(0.0);
        if (r == L) return Rgbd(top ? 0.0 : 1.0);
        return t[r] * down_sp[x][r];
    }
    /// The exit's flux of light with Stokes vectors e (per channel, in the tabulation frame of
    /// the chain's direction, whose x axis is the chain's s axis) entering the chains with the
    /// throughputs q_s, q_p: the s and p intensities (S0 ± S1)/2 times their own.
    static Rgbd through(const StokesRgb<double>& e, const Rgbd& q_s, const Rgbd& q_p) {
        Rgbd out;
        for (int c = 0; c < 3; ++c)
            out[c] = 0.5 * ((e.s[c][0] + e.s[c][1]) * q_s[c] + (e.s[c][0] - e.s[c][1]) * q_p[c]);
        return out;
    }
};

/// Builds c for the exit direction wo (upwards when top): every region's connection direction
/// and the delta-chain ladder, of flux factors, or of the walk's branch probabilities when
/// `probability` (pdf mode); with `polarized`, the s and p ladders too. The ladder's equations are
/// in connection.cpp.
void build_connection(const std::vector<double>& eta,
                      const std::vector<CompiledLayer<double>>& interfaces,
                      const std::vector<CompiledMedium<double>>& media, const Vec3d& wo, bool top,
                      bool probability, RandomWalkStack::Connection& c, bool polarized = false);

inline bool is_black(const Rgbd& w) {
    return w[0] == 0 && w[1] == 0 && w[2] == 0;
}

// A channel without extinction along a horizontal direction (an infinite path) has optical depth
// 0 · ∞ = NaN: its transmittance is 1 (found by the fuzz test).
inline Rgbd exp_neg(const Rgbd& x) {
    auto t = [](double depth) { return std::isnan(depth) ? 1.0 : std::exp(-depth); };
    return {t(x[0]), t(x[1]), t(x[2])};
}

// The probability that the walk, with flux weight W (per channel, ≥ 0) just after a vertex, is
// carried to the exit by the delta chains whose per-channel probability ladder is Q
// (docs/rendering.md §1.4): Σ_c W_c Q_c / Σ_c W_c. In a scattering medium the walk draws its
// free flight from channel c with probability ∝ W_c and then reweights W_c by e^{−τ_c ℓ}/(that
// mixture probability); across successive flights the mixture probabilities telescope to the
// W-weighted mean of the per-channel products. A black W kills the walk: probability 0.
inline double chain_probability(const Rgbd& W, const Rgbd& Q) {
    const double total = W[0] + W[1] + W[2];
    if (!(total > 0)) return 0;
    return (W[0] * Q[0] + W[1] * Q[1] + W[2] * Q[2]) / total;
}

inline bool is_grey(const Rgbd& x) {
    return x[0] == x[1] && x[1] == x[2];
}

}  // namespace lamina

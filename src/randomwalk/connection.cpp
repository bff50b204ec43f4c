#include "randomwalk/connection.h"

#include "physics/fresnel.h"
#include "physics/polarization.h"

#include <cmath>
#include <utility>

namespace lamina {

namespace {

// Solves M x = b (n ≤ a few dozen) by Gaussian elimination with partial pivoting.
void solve_dense(std::vector<double>& M, std::vector<double>& b, int n) {
    for (int col = 0; col < n; ++col) {
        int piv = col;
        for (int r = col + 1; r < n; ++r)
            if (std::abs(M[r * n + col]) > std::abs(M[piv * n + col])) piv = r;
        if (piv != col) {
            for (int c = 0; c < n; ++c)
                std::swap(M[col * n + c], M[piv * n + c]);
            std::swap(b[col], b[piv]);
        }
        const double p = M[col * n + col];
        if (p == 0) continue;  // an unreachable unknown: its row and column are zero
        for (int r = col + 1; r < n; ++r) {
            const double m = M[r * n + col] / p;
            if (m == 0) continue;
            for (int c = col; c < n; ++c)
                M[r * n + c] -= m * M[col * n + c];
            b[r] -= m * b[col];
        }
    }
    for (int r = n - 1; r >= 0; --r) {
        double s = b[r];
        for (int c = r + 1; c < n; ++c)
            s -= M[r * n + c] * b[c];
        b[r] = M[r * n + r] != 0 ? s / M[r * n + r] : 0.0;
    }
}

}  // namespace

// ---- Building the connection: the delta-chain ladder (docs/rendering.md §1.2) ----------------
// For interface k (regions k above, k + 1 below), with t_r the unscattered transmittance of
// region r at μ_r and E_top/E_bot = 1 for the exit side and 0 for the other:
// clang-format off
//   A_k^↑ = T_k^↑ · (k = 0 ? E_top : t_k A_{k−1}^↑) + R_k^↑ · (k + 1 = L ? E_bot : t_{k+1} A_{k+1}^↓)
//   A_k^↓ = R_k^↓ · (k = 0 ? E_top : t_k A_{k−1}^↑) + T_k^↓ · (k + 1 = L ? E_bot : t_{k+1} A_{k+1}^↓)
// clang-format on
// with Fresnel R, T = 1 − R of a smooth dielectric (T = G2/G1, R = 0 for a rough index-matched
// one), R = F_conductor for a smooth conductor, and A = 0 at a non-delta interface (a path that
// meets one has a later non-delta vertex, which connects instead).
//
// Probability mode (pdf, docs/rendering.md §1.4): the same ladder with the walk's *branch
// probabilities* instead of its flux factors: Fresnel R, T of a smooth dielectric (the walk's coin
// flip), 1 for a smooth conductor and an index-matched pass-through (always taken; their factors
// are weights), t_r = 1 through a non-scattering medium (a weight) and, through a scattering one,
// t_r = e^{−τt_c/μ_r} per channel: the probability that channel c's free flight crosses it.
//
// Polarized walks: every chain lies in the vertical plane of wo (smooth interfaces keep the
// azimuth), where s- and p-polarized light never mix: the ladder is solved for each, with the s or
// p Fresnel reflectance of every smooth interface (physics/polarization.h: a ± b), and `up`,
// `down` hold their mean (the throughput of unpolarized light, which a depolarizing vertex emits).
void build_connection(const std::vector<double>& eta,
                      const std::vector<CompiledLayer<double>>& interfaces,
                      const std::vector<CompiledMedium<double>>& media, const Vec3d& wo, bool top,
                      bool probability, RandomWalkStack::Connection& c, bool polarized) {
    const int L = int(interfaces.size());
    c.top = top;
    c.L = L;
    const int R = L + 1;
    c.valid.assign(R, 0);
    c.mu.assign(R, 0.0);
    c.dir_up.assign(R, Vec3d());
    c.dir_down.assign(R, Vec3d());
    c.t.assign(R, Rgbd(0.0));
    c.scale.assign(R, 0.0);
    c.up.assign(L, Rgbd(0.0));
    c.down.assign(L, Rgbd(0.0));
    c.exit_interface = top ? 0 : L - 1;
    c.inner = top ? 1 : L - 1;
    c.vertex_interface = top ? 1 : L - 2;
    c.towards = top ? 1 : -1;
    c.rough_exit = L >= 2 && interfaces[c.exit_interface].type == InterfaceType::Dielectric &&
                   !interfaces[c.exit_interface].delta;
    const int exit_region = top ? 0 : L;
    const double eta_e = eta[exit_region];
    const double sin2_exit = sqr(wo.x) + sqr(wo.y);
    // Regions are reachable from the exit only through propagating regions: walk away from it.
    bool reachable = true;
    for (int i = 0; i < R; ++i) {
        const int r = top ? i : L - i;
        const double ratio = eta_e / eta[r];
        const double sin2 = sqr(ratio) * sin2_exit;
        if (!(sin2 < 1)) reachable = false;
        if (!reachable) continue;
        c.valid[r] = 1;
        if (r == exit_region) {
            c.mu[r] = std::abs(wo.z);
        } else {
            c.mu[r] = std::sqrt(1 - sin2);
        }
        const Vec3d h(wo.x * ratio, wo.y * ratio, 0.0);
        c.dir_up[r] = Vec3d(h.x, h.y, c.mu[r]);
        c.dir_down[r] = Vec3d(h.x, h.y, -c.mu[r]);
        if (r == exit_region) (top ? c.dir_up[r] : c.dir_down[r]) = wo;
        const bool opaque_flight = probability ? media[r].scatters : !media[r].is_empty();
        c.t[r] = opaque_flight ? exp_neg(media[r].tau_t / c.mu[r]) : Rgbd(1.0);
        c.scale[r] = sqr(ratio);
    }
    // Unknowns x = (A_0^↑ … A_{L−1}^↑, A_0^↓ … A_{L−1}^↓), one system per channel (and, polarized,
    // per polarization: pol 0 s, 1 p; −1 unpolarized).
    c.polarized = polarized;
    for (int x = 0; x < 2; ++x) {
        c.up_sp[x].assign(polarized ? L : 0, Rgbd(0.0));
        c.down_sp[x].assign(polarized ? L : 0, Rgbd(0.0));
    }
    // The reflectance of a smooth dielectric (relative index eta) at the cosine mu, for light of
    // polarization pol, and of a smooth conductor's channel ch.
    auto dielectric_reflectance = [](double mu, double eta_rel, int pol) {
        if (pol < 0) return fresnel_dielectric(mu, eta_rel);
        const InterfaceMueller<double> m =
            fresnel_dielectric_mueller<double>(mu, eta_rel, 1 / eta_rel).reflection;
        return pol == 0 ? m.a + m.b : m.a - m.b;
    };
    auto conductor_reflectance = [](const auto& conductor, double mu, int ch, int pol) {
        if (pol < 0) return conductor.fresnel(mu)[ch];
        const InterfaceMueller<double> m =
            fresnel_conductor_mueller<double>(mu, conductor.eta[ch], conductor.k[ch]);
        return pol == 0 ? m.a + m.b : m.a - m.b;
    };
    const int n = 2 * L;
    for (int pol = polarized ? 0 : -1; pol < (polarized ? 2 : 0); ++pol)
        for (int ch = 0; ch < 3; ++ch) {
            std::vector<double> M(std::size_t(n) * n, 0.0), b(n, 0.0);
            for (int i = 0; i < n; ++i)
                M[i * n + i] = 1;
            auto up = [&](int k) { return k; };
            auto down = [&](int k) { return L + k; };
            // "Goes up into region k" and "goes down into region k + 1" from interface k.
            auto add_up = [&](int row, int k, double coeff) {
                if (coeff == 0 || !c.valid[k]) return;
                if (k == 0)
                    b[row] += coeff * (top ? 1.0 : 0.0);
                else
                    M[row * n + up(k - 1)] -= coeff * c.t[k][ch];
            };
            auto add_down = [&](int row, int k, double coeff) {
                if (coeff == 0 || !c.valid[k + 1]) return;
                if (k + 1 == L)
                    b[row] += coeff * (top ? 0.0 : 1.0);
                else
                    M[row * n + down(k + 1)] -= coeff * c.t[k + 1][ch];
            };
            for (int k = 0; k < L; ++k) {
                const auto& it = interfaces[k];
                if (!it.delta) continue;  // rows stay x = 0
                if (it.type == InterfaceType::Conductor) {
                    if (c.valid[k])
                        add_up(down(k), k,
                               probability ? 1.0
                                           : conductor_reflectance(it.conductor, c.mu[k], ch, pol));
                    continue;
                }
                const auto& d = it.dielectric;
                if (d.is_index_matched()) {
                    // A pass-through: T = G2(w, −w)/G1(w) (1 when smooth), R = 0.
                    auto pass = [&](const Vec3d& w) {
                        return d.is_smooth() || probability
                                   ? 1.0
                                   : d.masking_shadowing(w, -w) / d.distribution().G1(w);
                    };
                    if (c.valid[k + 1]) add_up(up(k), k, pass(-c.dir_up[k + 1]));
                    if (c.valid[k]) add_down(down(k), k, pass(-c.dir_down[k]));
                    continue;
                }
                if (c.valid[k + 1]) {  // arriving from below, cosine μ_{k+1}
                    const double F = dielectric_reflectance(-c.mu[k + 1], d.eta, pol);
                    add_up(up(k), k, 1 - F);
                    add_down(up(k), k, F);
                }
                if (c.valid[k]) {  // arriving from above, cosine μ_k
                    const double F = dielectric_reflectance(c.mu[k], d.eta, pol);
                    add_up(down(k), k, F);
                    add_down(down(k), k, 1 - F);
                }
            }
            solve_dense(M, b, n);
            for (int k = 0; k < L; ++k) {
                if (pol < 0) {
                    c.up[k][ch] = b[up(k)];
                    c.down[k][ch] = b[down(k)];
                } else {
                    c.up_sp[pol][k][ch] = b[up(k)];
                    c.down_sp[pol][k][ch] = b[down(k)];
                }
            }
        }
    if (polarized)
        for (int k = 0; k < L; ++k) {
            c.up[k] = (c.up_sp[0][k] + c.up_sp[1][k]) * 0.5;
            c.down[k] = (c.down_sp[0][k] + c.down_sp[1][k]) * 0.5;
        }
}

}  // namespace lamina

#pragma once
// lamina-1's scattering coat media (Henyey–Greenstein; lamina's docs/models.md, lamina-1,
// "Scattering media"): the energies of the scattered light that the closed forms of eval.h do
// not carry, by the azimuth-averaged adding–doubling of coat bottom, medium and base
// (lamina1/adding.h), and the curves the evaluation reads.

#include "lamina1/adding.h"
#include "lamina1/bsdf.h"

namespace lamina1 {

/// The scattered light's energies on the adding's inside cosines, per channel: what leaves
/// through the top beyond the explicit terms (top_left) and through a slab's bottom (bottom_left),
/// the explicit single scattering's own (single_left, single_bottom), and the energy of the
/// twice-scattered shape that carries the transmitted remainder (twice_bottom; its last entry at
/// μ' = 1).
struct Bsdf::AddingEnergies {
    CosineNodes nodes;
    std::array<std::vector<double>, 3> top_left{}, bottom_left{}, single_left{}, single_bottom{},
        twice_bottom{};
    /// The scattered light's whole exits, top and bottom (before the explicit single scattering
    /// is taken out): what a slab's bins weigh by their entry.
    std::array<std::vector<double>, 3> top_scattered{}, bottom_scattered{};

    /// Linear in μ' between the nodes, flat beyond the first and the last.
    Rgb at(const std::array<std::vector<double>, 3>& v, double mu_in) const {
        const int n = nodes.size();
        Rgb out(0.0);
        if (v[0].empty()) return out;
        int k = 0;
        while (k + 1 < n && nodes.mu[k + 1] < mu_in)
            ++k;
        double t = 0;
        if (mu_in <= nodes.mu[0]) {
            t = 0;
        } else if (k + 1 < n) {
            t = (mu_in - nodes.mu[k]) / (nodes.mu[k + 1] - nodes.mu[k]);
        }
        const int k1 = std::min(k + 1, n - 1);
        if (k + 1 >= n) t = 0;
        for (int c = 0; c < 3; ++c)
            out[c] = v[c][k] * (1 - t) + v[c][k1] * t;
        return out;
    }
};

inline void Bsdf::precompute_scattering() {
    for (int c = 0; c < 3; ++c)
        omega_[c] = tau_t_[c] > 0 ? layers_.tau_s[c] / tau_t_[c] : 0.0;
    g_uniform_ = layers_.g[0] == layers_.g[1] && layers_.g[0] == layers_.g[2];
    const bool lambertian = layers_.base == Base::Lambertian;
    single_on_ = ch_.medium_single || (ch_.medium_base_paths && !lambertian);
    base_paths_ = ch_.medium_base_paths && !lambertian;
    back_on_ = ch_.medium_single;
    if (!lambertian && alpha1_ > 0)
        mirror_albedo_curve_.fill([&](double mu) { return base_albedo(std::max(mu, 1e-6)); });
    orders_on_ = ch_.medium_orders;
    twice_on_ = orders_on_ && support_.btdf && ch_.medium_transmitted_twice;
    g_twice_ = layers_.g * layers_.g;
    precompute_scattering_curves(adding_energies());
}

/// The energies, by the azimuth-averaged adding of coat bottom, medium and base on 6 + 6 inside
/// cosines (split at the critical cosine, where the coat's bottom steps): a unit flux entering the
/// medium at node k reaches the outside (top) or the half-space below (bottom) with the fractions
/// e·L·(I − r L)⁻¹ and t_b·G·(I − r L)⁻¹, where the medium and base send back L = R + T B (I − R
/// B)⁻¹ T and down to the bottom G = (I − R B)⁻¹ T, r is the coat bottom's reflectance, e its exit
/// (T(μ) outside: the uniform-radiance exit of the first order), B the base (Lambertian: ρ 2μ_j
/// w_j; otherwise a mirror of albedo E_b(μ_j)). The shape's energy of the transmitted remainder
/// (HG(g²)) by its own finer rule (twice_shape_energy).
inline Bsdf::AddingEnergies Bsdf::adding_energies() const {
    AddingEnergies e;
    const bool lambertian = layers_.base == Base::Lambertian;
    const double mu_crit = std::sqrt(1 - sqr(inv_eta0_));
    e.nodes = split_cosine_nodes(6, mu_crit);
    const CosineNodes& nodes = e.nodes;
    const int n = nodes.size();
    std::vector<double> exit(n, 0.0), returned(n, 0.0), bottom(n, 0.0), bottom_single(n, 0.0);
    std::vector<Rgb> E_nodes(n), a_nodes(n);
    for (int j = 0; j < n; ++j) {
        const double mu = nodes.mu[j];
        double R = inside_reflectance(mu);
        if (mu > mu_crit) exit[j] = T_top_(safe_sqrt(1 - (1 - mu * mu) * sqr(eta0_)));
        // What the exit does not take is returned (as R_eff in precompute_albedos), below the
        // critical cosine too, where a rough coat's facets let out T_in(μ) that no exit takes.
        if (alpha0_ > 0) R = std::max(0.0, R + T_top_in_(mu) - exit[j]);
        returned[j] = R;
        if (support_.btdf) {
            bottom[j] = T_bot_in_(mu);
            // The once-scattered light's exit: T_b at the cosine it leaves with below.
            const double s2 = sqr(eta_s_) * (1 - mu * mu);
            bottom_single[j] = s2 < 1 ? T_bot_(std::sqrt(1 - s2)) : 0.0;
        }
        E_nodes[j] = lambertian ? layers_.albedo : mirror_albedo(mu);
        a_nodes[j] = attenuation(mu);
    }
    const FluxMatrix I = FluxMatrix::identity(n), r = FluxMatrix::diagonal(returned);
    AzimuthalPhase phase;
    std::vector<double> twice_phase;
    for (int c = 0; c < 3; ++c) {
        // Channels with the same medium and base share the computation.
        int same = -1;
        for (int c2 = 0; c2 < c && same < 0; ++c2) {
            bool eq =
                tau_t_[c2] == tau_t_[c] && omega_[c2] == omega_[c] && layers_.g[c2] == layers_.g[c];
            for (int j = 0; j < n && eq; ++j)
                eq = E_nodes[j][c2] == E_nodes[j][c];
            if (eq) same = c2;
        }
        if (same >= 0) {
            e.top_left[c] = e.top_left[same];
            e.bottom_left[c] = e.bottom_left[same];
            e.top_scattered[c] = e.top_scattered[same];
            e.bottom_scattered[c] = e.bottom_scattered[same];
            e.single_left[c] = e.single_left[same];
            e.single_bottom[c] = e.single_bottom[same];
            e.twice_bottom[c] = e.twice_bottom[same];
            continue;
        }
        // The phase matrices depend on g alone: computed once for channels of equal g.
        if (c == 0 || layers_.g[c] != layers_.g[c - 1]) phase = azimuthal_hg(nodes, layers_.g[c]);
        const SlabMatrices slab = hg_slab(nodes, phase, tau_t_[c], omega_[c]);
        FluxMatrix B(n);
        std::vector<double> E(n), a(n);
        for (int j = 0; j < n; ++j) {
            E[j] = E_nodes[j][c];
            a[j] = a_nodes[j][c];
            if (lambertian) {
                for (int k = 0; k < n; ++k)
                    B(j, k) = layers_.albedo[c] * 2 * nodes.mu[j] * nodes.w[j];
            } else {
                B(j, j) = E[j];
            }
        }
        const FluxMatrix G = inverse(I - slab.R * B) * slab.T;
        const FluxMatrix L = slab.R + slab.T * B * G;
        const FluxMatrix M = inverse(I - r * L);
        const FluxMatrix D = FluxMatrix::diagonal(a);
        const FluxMatrix L0 = D * B * D;
        const FluxMatrix M0 = inverse(I - r * L0);
        const std::vector<double> top = row_times(exit, L * M), top0 = row_times(exit, L0 * M0);
        FluxMatrix S(n);
        if (ch_.medium_single) S = hg_single_reflection(nodes, phase, tau_t_[c], omega_[c]);
        if (base_paths_) S = S + hg_single_mirror_paths(nodes, phase, tau_t_[c], omega_[c], E);
        const std::vector<double> single = row_times(exit, S);
        e.top_left[c].resize(n);
        e.top_scattered[c].resize(n);
        e.single_left[c] = single;
        for (int k = 0; k < n; ++k) {
            e.top_scattered[c][k] = top[k] - top0[k];
            e.top_left[c][k] = std::max(0.0, top[k] - top0[k] - (single_on_ ? single[k] : 0.0));
        }
        if (!support_.btdf) continue;
        const std::vector<double> bot = row_times(bottom, G * M), bot0 = row_times(bottom, D * M0);
        // The explicit once-scattered transmission (single_transmission), first exit.
        std::vector<double> bot1(n, 0.0);
        if (ch_.medium_single) {
            FluxMatrix ST(n);
            for (int j = 0; j < n; ++j)
                for (int k = 0; k < n; ++k)
                    ST(j, k) = 2 * kPi * nodes.w[j] * nodes.mu[j] * omega_[c] * phase.same(j, k) *
                               attenuation_slope(nodes.mu[j], nodes.mu[k], a[j], a[k], tau_t_[c]);
            bot1 = row_times(bottom_single, ST);
        }
        if (twice_on_) e.twice_bottom[c] = twice_shape_energy(c, nodes, twice_phase);
        e.bottom_left[c].resize(n);
        e.bottom_scattered[c].resize(n);
        for (int k = 0; k < n; ++k) {
            e.bottom_scattered[c][k] = bot[k] - bot0[k];
            e.bottom_left[c][k] = std::max(0.0, bot[k] - bot0[k] - bot1[k]);
            e.single_bottom[c].push_back(bot1[k]);
        }
    }
    return e;
}

/// The energy of the twice-scattered shape (the once-scattered transmission with HG(g²)) that
/// carries a slab's transmitted remainder, per unit flux entering at each node and at μ' = 1 (the
/// last entry: the shape's energy changes by 4% beyond the last node at g = 0.9), by its own finer
/// rule: 2 × 12 Gauss–Legendre cosines below the bottom's exit (split at its critical cosine), 16
/// azimuth nodes (φ = π t²): the adding's 12 cosines under-resolve the forward peak of HG(g²)
/// (≈ 3% low at g = 0.9), and this energy is what normalizes the lobe. twice_phase keeps the
/// azimuthal averages of HG(g²) between channels of equal g.
inline std::vector<double> Bsdf::twice_shape_energy(int c, const CosineNodes& nodes,
                                                    std::vector<double>& twice_phase) const {
    const int n = nodes.size();
    static const QuadratureRule qm = gauss_legendre(12), qp = gauss_legendre(16);
    const double mu_crit_b = eta_s_ > 1 ? std::sqrt(1 - 1 / sqr(eta_s_)) : 0.0;
    const int nm = 2 * int(qm.x.size());
    auto exit_cos = [&](int m) {
        const double width = 0.5 * (1 - mu_crit_b);
        return mu_crit_b + width * ((m >= nm / 2) + qm.x[m % (nm / 2)]);
    };
    // The azimuthal average of HG(g²) between the rule's cosines and the incidences (the nodes
    // and μ' = 1): it depends on g alone, computed once for equal g.
    if (c == 0 || g_twice_[c] != g_twice_[c - 1]) {
        twice_phase.assign(std::size_t(n + 1) * nm, 0.0);
        for (int k = 0; k <= n; ++k) {
            const double mu_k = k < n ? nodes.mu[k] : 1.0, s_k = safe_sqrt(1 - mu_k * mu_k);
            for (int m = 0; m < nm; ++m) {
                const double mu = exit_cos(m), s_m = safe_sqrt(1 - mu * mu);
                double p0 = 0;
                for (std::size_t b = 0; b < qp.x.size(); ++b) {
                    const double t = qp.x[b];
                    p0 += qp.w[b] * 2 * t *
                          hg_phase(mu * mu_k + s_m * s_k * std::cos(kPi * t * t), g_twice_[c]);
                }
                twice_phase[std::size_t(k) * nm + m] = p0;
            }
        }
    }
    // The rule's weights with the exit and the attenuation at its cosines.
    std::vector<double> exit_weight(nm, 0.0), a_exit(nm, 0.0);
    for (int m = 0; m < nm; ++m) {
        const double mu = exit_cos(m), s2 = sqr(eta_s_) * (1 - mu * mu);
        a_exit[m] = std::exp(-tau_t_[c] / mu);
        if (s2 < 1)
            exit_weight[m] = 0.5 * (1 - mu_crit_b) * qm.w[m % (nm / 2)] * 2 * kPi * mu * omega_[c] *
                             T_bot_(std::sqrt(1 - s2));
    }
    auto shape_energy = [&](int k) {
        const double mu_k = k < n ? nodes.mu[k] : 1.0, a_k = std::exp(-tau_t_[c] / mu_k);
        double e = 0;
        for (int m = 0; m < nm; ++m)
            if (exit_weight[m] > 0)
                e += exit_weight[m] * twice_phase[std::size_t(k) * nm + m] *
                     attenuation_slope(exit_cos(m), mu_k, a_exit[m], a_k, tau_t_[c]);
        return e;
    };
    std::vector<double> energy(n + 1, 0.0);
    for (int k = 0; k <= n; ++k)
        energy[k] = shape_energy(k);
    return energy;
}

/// The scattered light's curves over outside cosines: the explicit single scattering's energies
/// (the sampler's weights), the remainder's separable lobes and their normalizations.
inline void Bsdf::precompute_scattering_curves(const AddingEnergies& e) {
    const CosineNodes& nodes = e.nodes;
    const int n = nodes.size();
    single_energy_.fill(
        [&](double mu) { return e.at(e.single_left, inside_cos(mu)) * T_top_(mu); });
    if (support_.btdf && ch_.medium_single)
        single_energy_t_.fill(
            [&](double mu) { return e.at(e.single_bottom, inside_cos(mu)) * T_top_(mu); });
    if (!orders_on_) return;
    // The remainders per unit flux from outside at μ. The adding takes the light in at the macro
    // refraction; a slab's bins know where a rough coat sends it (into the trapped cosines, at
    // grazing incidence), and there the light's unscattered path, which the remainder is the
    // complement of, is longer: weighed by the bins' entry C_k(μ) (Σ C_k = T(μ)), the scattered
    // exits at each bin's centre, less the explicit single scattering at the macro refraction
    // (where eval puts it). At the macro refraction alone, a non-absorbing milky slab under a
    // coat of α0 0.3 returned 0.74 of the light at 80° (over a smooth bottom).
    auto remainder = [&](const std::array<std::vector<double>, 3>& left,
                         const std::array<std::vector<double>, 3>& scattered,
                         const std::array<std::vector<double>, 3>& single, bool single_out,
                         double mu) {
        const double T = T_top_(mu);
        if (!bins_ready_) return e.at(left, inside_cos(mu)) * T;
        const BinMoments C = coat_entry(mu);
        Rgb sum(0.0);
        for (int k = 0; k < kNbins; ++k)
            sum += e.at(scattered, 0.5 * (bin_edge_[k] + bin_edge_[k + 1])) * C.v[k];
        if (single_out) sum = sum - e.at(single, inside_cos(mu)) * T;
        return nonnegative(sum);
    };
    orders_.fill([&](double mu) {
        return remainder(e.top_left, e.top_scattered, e.single_left, single_on_, mu);
    });
    const Rgb orders_bar =
        integrate_split01<kGauss, Rgb>([&](double mu) { return orders_(mu) * (2 * mu); }, 0.0);
    for (int c = 0; c < 3; ++c)
        // A remainder below kNegligibleEnergy of the incident light is none (its normalization
        // would overflow: 1/Ē of a channel whose albedo is 1e-284).
        orders_norm_[c] = orders_bar[c] > kNegligibleEnergy ? kInvPi / orders_bar[c] : 0.0;
    if (!support_.btdf) return;
    auto bottom_remainder = [&](double mu) {
        return remainder(e.bottom_left, e.bottom_scattered, e.single_bottom, true, mu);
    };
    orders_t_.fill(bottom_remainder);
    const double T_bar =
        integrate_split01<kGauss, double>([&](double mu) { return T_bot_(mu) * (2 * mu); }, 0.0);
    orders_t_norm_ = T_bar > 0 ? kInvPi / T_bar : 0.0;
    if (!twice_on_) return;
    twice_.fill([&](double mu) {
        const double mu_in = inside_cos(mu);
        const Rgb left = bottom_remainder(mu) * (1 / std::max(T_top_(mu), 1e-300));
        Rgb shape = e.at(e.twice_bottom, mu_in);
        if (mu_in > nodes.mu[n - 1]) {  // towards the value at μ' = 1
            const double t = (mu_in - nodes.mu[n - 1]) / (1 - nodes.mu[n - 1]);
            for (int c = 0; c < 3; ++c)
                shape[c] = e.twice_bottom[c][n - 1] * (1 - t) + e.twice_bottom[c][n] * t;
        }
        Rgb K(0.0);
        for (int c = 0; c < 3; ++c)
            K[c] = shape[c] > kNegligibleEnergy ? left[c] / shape[c] : 0.0;
        return K;
    });
}

}  // namespace lamina1

#include "randomwalk/random_walk.h"

#include "randomwalk/connection.h"

#include "core/check.h"
#include "core/error.h"
#include "core/math.h"
#include "physics/fresnel.h"
#include "physics/medium.h"
#include "physics/microsurface_walk.h"
#include "physics/phase.h"
#include "physics/polarization.h"

#include <array>
#include <cmath>
#include <utility>

namespace lamina {

RandomWalkStack::RandomWalkStack(const Stack& stack, const TransportSettings& transport)
    : transmits_(stack.transmits()), transport_(transport) {
    LAMINA_CHECK(transport.max_events >= 1);
    LAMINA_CHECK(transport.max_microsurface_order >= 1);
    if (stack.has_film())
        throw InputError(stack.name, "film",
                         "thin films are not supported by the random walk (the goniophotometer "
                         "traces them: lamina simulate --kernel scalar)");
    const CompiledStack<double> compiled = compile_stack<double>(stack, transport);
    channels_ = compiled.polarization_channels;
    anisotropic_ = compiled.anisotropic;
    const int L = int(compiled.layers.size());
    interfaces_ = compiled.layers;
    eta_.assign(L + 1, 1.0);
    media_.assign(L + 1, Medium{});
    eta_[0] = compiled.eta_above;
    // For pdf_is_unbiased(): per-channel extinction in a scattering medium, and per-channel
    // weights of delta events that are not flights through one.
    bool chromatic_scatterer = false, chromatic_weight = false;
    for (int k = 0; k < L; ++k) {
        const Interface& it = interfaces_[k];
        eta_[k + 1] = it.eta_below;
        if (it.type == InterfaceType::Conductor && it.delta &&
            !(is_grey(it.conductor.eta) && is_grey(it.conductor.k)))
            chromatic_weight = true;
        const Medium& md = media_[k + 1] = it.medium;
        if (md.scatters && !md.uniform_tau_t) chromatic_scatterer = true;
        if (!md.scatters && !md.is_empty() && !md.uniform_tau_t) chromatic_weight = true;
    }
    pdf_unbiased_ = !(chromatic_scatterer && chromatic_weight) && !transport.polarization;
}

// ---- The second connection strategy through a rough top (docs/rendering.md §1.3) ---------------
// Under a rough top interface the first strategy (the walk reaches the top and evaluates the top's
// BTDF towards wo) is noisy for narrow lobes: the walk's direction must fall into the lobe. The
// second strategy samples the top's transmission from the viewer side, t ~ pdf_top(wo, t) (the
// adjoint of the exit), and connects a non-delta vertex v of region 1 along ω = −t:
//     w · k_v(ω) · T_v(ω) · f_top(t, wo) / pdf_top(wo, t),
// k_v = f_v·|cos ω| (interface) or the HG phase (medium), T_v the unscattered transmittance from v
// to the top. Both strategies sample the same paths (v → top → wo); they are combined with the
// balance heuristic w_s = p_s / (p_1 + p_2), with
//     p_1(ω) = pdf_v(ω) · P̃(ℓ),  P̃(ℓ) = exp(−mean_c(τt_c) · ℓ) in a scattering medium, else 1,
//     p_2(ω) = pdf_top(wo, −ω),
// ℓ = depth of v / |cos ω| the normal-optical-depth path factor. P̃ approximates the survival
// probability of the walk's free flight; the weights are unbiased for any such choice because both
// strategies compute them with the same function of the same path (Veach 1997, §9.2.2).
struct RandomWalkStack::WalkState {
    Vec3d d;      ///< propagation direction
    Rgbd w{1.0};  ///< flux weight
    int events = 0;
    bool delta_only = true;
    bool prev_mis = false;  ///< the last vertex was non-delta, in the inner region, and sent the
                            ///< walk towards the exit interface
    double prev_pdf = 0;    ///< its sampling density of the current direction
    double prev_depth =
        0;  ///< its depth-distance to the exit interface (1 at the vertex interface)
    StokesLanes<double> stokes;  ///< polarized walks: the particle's state (physics/polarization.h)
};

double RandomWalkStack::survival_proxy(int region, double path) const {
    const Medium& m = media_[region];
    return m.scatters ? std::exp(-m.tau_t.mean() * path) : 1.0;
}

template <typename ProxyPdf>
std::optional<RandomWalkStack::ExitDirection> RandomWalkStack::sample_exit_direction(
    const Connection& conn, const Vec3d& wo, double depth, ParticleRng& rng,
    const ProxyPdf& proxy_pdf) const {
    const Interface& exit_it = interfaces_[conn.exit_interface];
    const DielectricInterface<double>& exit = exit_it.dielectric;
    const double uc = rng.uniform_double(), u1 = rng.uniform_double(), u2 = rng.uniform_double();
    const auto st = with_roughness(
        [&](auto aniso) { return exit.sample<true, decltype(aniso)::value>(wo, uc, u1, u2); });
    if (!st || !st->is_transmission || st->shadowing == 0 || st->pdf <= 0) return std::nullopt;
    const Vec3d omega = -st->wo;
    if (omega.z * conn.towards <= 0) return std::nullopt;
    const double mu = std::abs(omega.z);
    const double p1 = proxy_pdf(omega) * survival_proxy(conn.inner, depth / mu);
    return ExitDirection{&exit_it, st->wo, st->pdf, omega, mu, st->pdf / (st->pdf + p1)};
}

// Strategy 2 at a vertex of the inner region that emits `k_v(ω)` (per channel, kernel incl. cos
// for an interface) with pdf `pdf_v(ω)`, at depth-distance `depth` from the exit (1: the vertex
// interface). The exit's transmission is sampled from wo (t on the inner side); ω = −t.
//
// Pdf mode (docs/rendering.md §1.4): the same two strategies estimate the exit density of the
// paths v → exit → wo, Σ over arrivals of pdf_exit(−d, wo): strategy 2 adds
//     pdf_v(ω) · P_v(ω) · pdf_exit(t, wo) / pdf_exit(wo, t) · w₂,
// P_v the probability that the walk's flight from v reaches the exit unscattered (chain
// probability of the weight w·k_v(ω), 1 through a non-scattering medium), with the same w₁, w₂.
//
// With multiple-scattering interfaces (docs/rendering.md §1.6) the exit's f (or exit density) and
// the vertex's kernel (or pdf × chain probability) are one walk's unbiased estimates each,
// independent of each other, so their product stays unbiased; t is still drawn from the exit's
// single-scattering sampler (any proposal with a known density will do), and the balance
// heuristic's densities are the single-scattering ones (`proxy_pdf`, pdf_interface) in both
// strategies: any weights that sum to one for each path, computed alike by both, keep the
// combination unbiased (Veach 1997, §9.2.2).
template <RandomWalkStack::Mode kMode, typename Kernel, typename PdfChain, typename ProxyPdf>
void RandomWalkStack::connect_through_exit(const Connection& conn, const Vec3d& wo, double depth,
                                           const Rgbd& w, ParticleRng& rng, const Kernel& kernel,
                                           const PdfChain& pdf_chain, const ProxyPdf& proxy_pdf,
                                           Rgbd& f) const {
    const std::optional<ExitDirection> ed = sample_exit_direction(conn, wo, depth, rng, proxy_pdf);
    if (!ed) return;
    const Interface& exit_it = *ed->exit;
    const Medium& m = media_[conn.inner];
    if constexpr (kMode == Mode::Pdf) {
        // The exit's density at wo: a dielectric walk carries all its flux, so its exit density
        // is its kernel f·|cos θo| (flux convention).
        const double p_exit = exit_it.multiple ? interface_kernel(exit_it, ed->wt, wo, rng)[0]
                                               : exit_it.dielectric.pdf(ed->wt, wo);
        if (p_exit == 0) return;
        const Rgbd pass = m.scatters ? exp_neg(m.tau_t * (depth / ed->mu)) : Rgbd(1.0);
        f[0] += pdf_chain(ed->omega, pass) * p_exit / ed->pdf * ed->mis;
    } else {
        const double f_exit = exit_it.multiple
                                  ? interface_kernel(exit_it, ed->wt, wo, rng)[0] / std::abs(wo.z)
                                  : exit_it.dielectric.eval(ed->wt, wo);
        if (f_exit == 0) return;
        const Rgbd kv = kernel(ed->omega);
        if (is_black(kv)) return;
        const Rgbd tr = m.is_empty() ? Rgbd(1.0) : exp_neg(m.tau_t * (depth / ed->mu));
        f += w * kv * tr * (f_exit / ed->pdf * ed->mis);
    }
}

template <typename Visit>
void RandomWalkStack::visit_microsurface(const Interface& it, const Vec3d& wi, ParticleRng& rng,
                                         Visit&& visit) const {
    auto uniform = [&] { return rng.uniform_double(); };
    if (it.type == InterfaceType::Dielectric) {
        const GGX<double> ggx = it.dielectric.distribution();
        const double eta = it.dielectric.eta;
        with_roughness([&](auto aniso) {
            walk_rough_dielectric_visiting<decltype(aniso)::value>(
                ggx, eta, wi, uniform, transport_.max_microsurface_order,
                [&](const MicrosurfaceFacet<double>& facet) {
                    visit([&](const Vec3d& wo) {
                        MicrosurfaceConnection<double> c;
                        c.density = microsurface_dielectric_connect(ggx, eta, facet, wo);
                        c.weight = Rgbd(1.0);
                        return c;
                    });
                });
        });
    } else {
        const ConductorInterface<double>& cond = it.conductor;
        const GGX<double> ggx = cond.distribution();
        auto fresnel = [&](double c) { return cond.fresnel(c); };
        with_roughness([&](auto aniso) {
            walk_rough_conductor_visiting<decltype(aniso)::value>(
                ggx, fresnel, wi, uniform, transport_.max_microsurface_order,
                [&](const MicrosurfaceFacet<double>& facet) {
                    visit([&](const Vec3d& wo) {
                        return microsurface_conductor_connect(ggx, fresnel, facet, wo);
                    });
                });
        });
    }
}

Rgbd RandomWalkStack::interface_kernel(const Interface& it, const Vec3d& wi, const Vec3d& wo,
                                       ParticleRng& rng) const {
    if (!it.multiple) return eval_interface(it, wi, wo) * std::abs(wo.z);
    Rgbd k(0.0);
    visit_microsurface(it, wi, rng, [&](const auto& connect) {
        const MicrosurfaceConnection<double> c = connect(wo);
        k += c.weight * c.density;
    });
    for (int ch = 0; ch < 3; ++ch)
        if (!std::isfinite(k[ch])) return Rgbd(0.0);
    return k;
}

double RandomWalkStack::interface_pdf_chain(const Interface& it, const Vec3d& wi, const Vec3d& wo,
                                            const Rgbd& w, const Rgbd& q, ParticleRng& rng) const {
    if (!it.multiple) {
        const double p = pdf_interface(it, wi, wo);
        return p > 0 ? p * chain_probability(w * eval_interface(it, wi, wo), q) : 0.0;
    }
    double p = 0;
    visit_microsurface(it, wi, rng, [&](const auto& connect) {
        const MicrosurfaceConnection<double> c = connect(wo);
        if (c.density > 0) p += c.density * chain_probability(w * c.weight, q);
    });
    return std::isfinite(p) ? p : 0.0;
}

// ---- Polarized connections (docs/physics.md §8) -------------------------------------------------
void RandomWalkStack::emission(const Interface& it, const Vec3d& wi, const Vec3d* d, int n,
                               const StokesLanes<double>& state, const Rgbd& w, ParticleRng& rng,
                               StokesRgb<double>* out, int channels) const {
    if (channels == 0) channels = channels_;
    for (int j = 0; j < n; ++j)
        out[j] = StokesRgb<double>{};
    if (it.type == InterfaceType::Lambertian) {  // a depolarizer
        for (int j = 0; j < n; ++j) {
            const Rgbd f = it.lambertian.eval(wi, d[j]) * std::abs(d[j].z);
            for (int c = 0; c < 3; ++c)
                out[j].s[c][0] = f[c];
        }
        return;
    }
    const auto mueller = [&](double c, InterfaceMueller<double>* m) { it.conductor.mueller(c, m); };
    if (!it.multiple) {
        // f·|cos| of the single-scattering BSDF with the state's fraction of its facet's Fresnel
        // branch (the facet of the pair wi, d: Walter et al. 2007, Eqs. 13 and 16).
        for (int j = 0; j < n; ++j) {
            const Rgbd f = eval_interface(it, wi, d[j]) * std::abs(d[j].z);
            if (is_black(f)) continue;
            const double scale[3] = {f[0], f[1], f[2]};
            if (it.type == InterfaceType::Dielectric) {
                const std::optional<Vec3d> wm = it.dielectric.half_vector(wi, d[j]);
                if (!wm) continue;
                const DielectricMueller<double> fm = fresnel_dielectric_mueller<double>(
                    dot(wi, *wm), it.dielectric.eta, 1 / it.dielectric.eta);
                const InterfaceMueller<double>& m =
                    same_hemisphere(wi, d[j]) ? fm.reflection : fm.transmission;
                microsurface_stokes_through(&m, false, wi, *wm, d[j], state, channels, scale,
                                            out[j]);
            } else {
                const Vec3d wm = normalize(wi + d[j]);
                InterfaceMueller<double> m[3];
                mueller(dot(wi, wm), m);
                microsurface_stokes_through(m, true, wi, wm, d[j], state, channels, scale, out[j]);
            }
        }
        return;
    }
    // One polarized visiting walk from wi (its own state, starting from the particle's): every
    // facet it meets connects towards each d[j] with the state it meets the facet in.
    auto uniform = [&] { return rng.uniform_double(); };
    PolarizationLanes<double> pol;
    const double flux[3] = {w[0], w[1], w[2]};
    pol.stokes = state;
    pol.channels = channels;
    pol.flux = flux;
    if (it.type == InterfaceType::Dielectric) {
        const GGX<double> ggx = it.dielectric.distribution();
        const double eta = it.dielectric.eta;
        with_roughness([&](auto aniso) {
            walk_rough_dielectric_polarized_visiting<decltype(aniso)::value>(
                ggx, eta, wi, uniform, transport_.max_microsurface_order, pol,
                [&](const MicrosurfaceFacet<double>& facet) {
                    for (int j = 0; j < n; ++j)
                        microsurface_dielectric_connect_polarized(ggx, eta, facet, d[j], pol.stokes,
                                                                  channels, out[j]);
                });
        });
    } else {
        const GGX<double> ggx = it.conductor.distribution();
        with_roughness([&](auto aniso) {
            walk_rough_conductor_polarized_visiting<decltype(aniso)::value>(
                ggx, mueller, wi, uniform, transport_.max_microsurface_order, pol,
                [&](const MicrosurfaceFacet<double>& facet) {
                    for (int j = 0; j < n; ++j)
                        microsurface_conductor_connect_polarized(ggx, mueller, facet, d[j],
                                                                 pol.stokes, channels, out[j]);
                });
        });
    }
    for (int j = 0; j < n; ++j)
        for (auto& channel : out[j].s)
            for (double& x : channel)
                if (!std::isfinite(x)) {
                    out[j] = StokesRgb<double>{};
                    break;
                }
}

// Strategy 2 (connect_through_exit) for a polarized walk: the vertex's light towards ω as Stokes
// vectors, and the exit's BTDF for it — single scattering: the unpolarized f_exit with the exit
// facet's transmission fraction a + b q of the light's state over its a (the facet of the pair
// t, wo: Walter et al. 2007, Eq. 16); multiple scattering: the exit's polarized emission towards
// wo for that state (a mixture of the vertex's per-channel states is the partially polarized
// state S/S0: the exit's response is linear in S).
template <typename Emit, typename ProxyPdf>
void RandomWalkStack::connect_through_exit_polarized(const Connection& conn, const Vec3d& wo,
                                                     double depth, const Rgbd& w, ParticleRng& rng,
                                                     const Emit& emit, const ProxyPdf& proxy_pdf,
                                                     Rgbd& f) const {
    const std::optional<ExitDirection> ed = sample_exit_direction(conn, wo, depth, rng, proxy_pdf);
    if (!ed) return;
    const Interface& exit_it = *ed->exit;
    const Medium& m = media_[conn.inner];
    StokesRgb<double> e;
    emit(ed->omega, e);
    // The light's state per channel, in the tabulation frame of ω.
    StokesLanes<double> state;
    state.x = stokes_bin_frame<double>({ed->omega.x, ed->omega.y, ed->omega.z});
    const double inv_len = 1 / std::sqrt(dot(Vec3d(state.x.x, state.x.y, state.x.z),
                                             Vec3d(state.x.x, state.x.y, state.x.z)));
    state.x = {state.x.x * inv_len, state.x.y * inv_len, state.x.z * inv_len};
    for (int c = 0; c < 3; ++c) {
        const double s0 = e.s[c][0];
        state.q[c] = s0 > 0 ? e.s[c][1] / s0 : 0;
        state.u[c] = s0 > 0 ? e.s[c][2] / s0 : 0;
        state.v[c] = s0 > 0 ? e.s[c][3] / s0 : 0;
    }
    Rgbd through(0.0);  // per unit S0: the exit's f for the light's state
    if (exit_it.multiple) {
        StokesRgb<double> out;
        emission(exit_it, ed->wt, &wo, 1, state, w, rng, &out, 3);
        for (int c = 0; c < 3; ++c)
            through[c] = out.s[c][0] / std::abs(wo.z);
    } else {
        const double f_exit = exit_it.dielectric.eval(ed->wt, wo);
        const std::optional<Vec3d> wm = exit_it.dielectric.half_vector(ed->wt, wo);
        if (f_exit == 0 || !wm) return;
        const DielectricMueller<double> fm = fresnel_dielectric_mueller<double>(
            dot(ed->wt, *wm), exit_it.dielectric.eta, 1 / exit_it.dielectric.eta);
        if (!(fm.transmission.a > 0)) return;
        const Vec3d n = cross(ed->wt, *wm);
        stokes_rotate_frame<double>(state, {ed->omega.x, ed->omega.y, ed->omega.z}, {n.x, n.y, n.z},
                                    3, true);
        for (int c = 0; c < 3; ++c)
            through[c] =
                f_exit * (fm.transmission.a + fm.transmission.b * state.q[c]) / fm.transmission.a;
    }
    const Rgbd tr = m.is_empty() ? Rgbd(1.0) : exp_neg(m.tau_t * (depth / ed->mu));
    const Rgbd kv(e.s[0][0], e.s[1][0], e.s[2][0]);
    f += w * kv * tr * through * (1 / ed->pdf * ed->mis);
}

// ---- Media (docs/physics.md §4), as the goniophotometer traverses them --------------------------
// Depth s ∈ [0, 1] across the layer (0 at its top). Returns true if the particle leaves through
// the top. Free flights from a mixture of the channels' exponentials with probabilities ∝ flux and
// per-channel weights (one-sample spectral MIS, balance heuristic: Veach 1997, §9.2.4), exactly as
// simulator/goniophotometer.cpp. Each scattering event is a non-delta vertex: it connects along
// d_r up and down with the channel's own HG phase and the unscattered transmittance to the
// boundary, e^{−τt·s/μ} (up) or e^{−τt·(1 − s)/μ} (down), and below a rough top by strategy 2.
template <RandomWalkStack::Mode kMode>
bool RandomWalkStack::traverse_medium(int region, WalkState& ws, ParticleRng& rng,
                                      const Connection* conn, const Vec3d& wo, Rgbd& f) const {
    constexpr bool kConnect = kMode == Mode::Eval;
    constexpr bool kEstimate = kMode != Mode::Sample;  // eval and pdf share strategy 2's MIS
    Vec3d& d = ws.d;
    Rgbd& w = ws.w;
    const Medium& m = media_[region];
    if (!m.scatters) {
        double transmittance[3];
        beer_lambert_transmittance<double>(m.tau_t, 1 / std::abs(d.z), transmittance);
        w *= Rgbd(transmittance[0], transmittance[1], transmittance[2]);
        return d.z > 0;
    }
    double s = d.z < 0 ? 0 : 1;
    auto uniform = [&] { return rng.uniform_double(); };
    while (true) {
        // The free flight (physics/medium.h, as the goniophotometer's kernels).
        const LaneVec3<double> dl = {d.x, d.y, d.z};
        const double wl[3] = {w[0], w[1], w[2]};
        const MediumFlightLanes<double, bool> flight =
            medium_free_flight<double>(m, dl, wl, s, uniform);
        const double* p = flight.p;
        w *= Rgbd(flight.factor[0], flight.factor[1], flight.factor[2]);
        if (flight.leaves) return d.z > 0;
        s = flight.depth;
        ws.delta_only = false;
        // The phase-sampling density: the mixture Σ p_k HG_k when g differs per channel.
        auto phase_pdf = [&](double cos_theta) {
            if (m.uniform_g) return hg_phase(cos_theta, m.g[0]);
            double q = 0;
            for (int k = 0; k < 3; ++k)
                q += p[k] * hg_phase(cos_theta, m.g[k]);
            return q;
        };
        if constexpr (kConnect) {
            // Next event: flux w scattered into dω_d with density p_c(d_in·d) becomes, through
            // the delta chains, flux w p Q (η_e/η_r)² cos_e/|cos d| dω_e.
            if (conn->valid[region]) {
                const double mu_r = conn->mu[region];
                const Rgbd above = region >= 1 ? conn->up[region - 1] : Rgbd(0.0);
                const Rgbd below = region < conn->L ? conn->down[region] : Rgbd(0.0);
                const Rgbd tr_up = exp_neg(m.tau_t * (s / mu_r));
                const Rgbd tr_down = exp_neg(m.tau_t * ((1 - s) / mu_r));
                const double cu = dot(d, conn->dir_up[region]);
                const double cd = dot(d, conn->dir_down[region]);
                const double k = conn->scale[region] / mu_r;
                for (int ch = 0; ch < 3; ++ch) {
                    const double g = m.g[ch];
                    f[ch] += w[ch] * k *
                             (hg_phase(cu, g) * tr_up[ch] * above[ch] +
                              hg_phase(cd, g) * tr_down[ch] * below[ch]);
                }
            }
        }
        if constexpr (kMode == Mode::Pdf) {
            // Exit density (docs/rendering.md §1.4): the phase-sampling density of d_r± times the
            // probability that the delta chains carry the walk from there to the exit (the rest
            // of this medium, then the ladder), times dω_r/dω_e = (η_e/η_r)² cos θ_e / μ_r. The
            // weight just after the vertex is ∝ w_c·HG_c(d·d_r) per channel.
            if (conn->valid[region]) {
                const double mu_r = conn->mu[region];
                const double jacobian = conn->scale[region] * std::abs(wo.z) / mu_r;
                const Rgbd above = conn->up[region - 1];
                const Rgbd below = region < conn->L ? conn->down[region] : Rgbd(0.0);
                const Rgbd q_up = exp_neg(m.tau_t * (s / mu_r)) * above;
                const Rgbd q_down = exp_neg(m.tau_t * ((1 - s) / mu_r)) * below;
                for (const auto& [dir, q] : {std::pair{conn->dir_up[region], q_up},
                                             std::pair{conn->dir_down[region], q_down}}) {
                    const double ct = dot(d, dir);
                    const Rgbd W =
                        w * Rgbd(hg_phase(ct, m.g[0]), hg_phase(ct, m.g[1]), hg_phase(ct, m.g[2]));
                    f[0] += phase_pdf(ct) * chain_probability(W, q) * jacobian;
                }
            }
        }
        if constexpr (kEstimate) {
            // The connection through a rough exit (eval and pdf alike): one walk's estimate.
            if (conn->rough_exit && region == conn->inner) {
                const Vec3d d_in = d;
                auto kernel = [&](const Vec3d& om) {
                    const double ct = dot(d_in, om);
                    return Rgbd(hg_phase(ct, m.g[0]), hg_phase(ct, m.g[1]), hg_phase(ct, m.g[2]));
                };
                auto proxy = [&](const Vec3d& om) { return phase_pdf(dot(d_in, om)); };
                connect_through_exit<kMode>(
                    *conn, wo, conn->distance(s), w, rng, kernel,
                    [&](const Vec3d& om, const Rgbd& pass) {
                        return proxy(om) * chain_probability(w * kernel(om), pass);
                    },
                    proxy, f);
            }
        }
        // The scattering event (physics/medium.h).
        LaneVec3<double> d_scattered;
        double phase[3];
        medium_scatter<double>(m, dl, p, true, uniform, d_scattered, phase);
        const Vec3d d_new(d_scattered.x, d_scattered.y, d_scattered.z);
        const double cos_theta = dot(d, d_new);
        w *= Rgbd(phase[0], phase[1], phase[2]);
        if (transport_.polarization && kMode != Mode::Pdf)  // docs/physics.md §8
            stokes_depolarize<double>(ws.stokes, 3, true);
        // The walk's own strategy for the same paths (strategy 1, weighted at the exit). Only
        // meaningful while connecting (conn is null for sample()).
        ws.prev_mis =
            kEstimate && conn->rough_exit && region == conn->inner && d_new.z * conn->towards > 0;
        ws.prev_pdf = phase_pdf(cos_theta);
        ws.prev_depth = kEstimate ? conn->distance(s) : 0;
        d = d_new;
        if (is_black(w)) return d.z > 0;
        if (++ws.events >= transport_.max_events) {
            w = Rgbd(0.0);
            return d.z > 0;
        }
    }
}

// ---- One walk ----------------------------------------------------------------------------------

// Strategy 1's balance-heuristic weight at the exit interface (1 for other paths): the particle,
// about to meet interface `at` (it, from wi_local), arrives from the inner region straight from a
// vertex that strategy 2 connects.
double RandomWalkStack::exit_mis(const Connection& conn, const WalkState& ws, const Interface& it,
                                 const Vec3d& wi_local, const Vec3d& wo, int at) const {
    if (!conn.rough_exit || at != conn.exit_interface || !ws.prev_mis || ws.d.z * conn.towards <= 0)
        return 1.0;
    const double p1 = ws.prev_pdf * survival_proxy(conn.inner, ws.prev_depth / std::abs(ws.d.z));
    const double p2 = it.dielectric.pdf(wo, wi_local);
    // Both densities vanish when strategy 2 cannot make this path (p2 = 0) and the survival proxy
    // underflows (a deep, dense medium): strategy 1 alone, weight 1.
    return p1 + p2 > 0 ? p1 / (p1 + p2) : 1.0;
}

// Strategy 2 from the vertex interface vi, met from wi_local (eval and pdf): its kernel, exit
// density × chain probability, and the balance heuristic's proxy density (single scattering).
template <RandomWalkStack::Mode kMode>
void RandomWalkStack::connect_from_vertex_interface(const Interface& vi, const Vec3d& wi_local,
                                                    WalkState& ws, ParticleRng& rng,
                                                    const Connection& conn, const Vec3d& wo,
                                                    bool polarized, Rgbd& f) const {
    const Rgbd& w = ws.w;
    if (polarized && kMode == Mode::Eval) {
        connect_through_exit_polarized(
            conn, wo, 1.0, w, rng,
            [&](const Vec3d& om, StokesRgb<double>& e) {
                emission(vi, wi_local, &om, 1, ws.stokes, w, rng, &e);
            },
            [&](const Vec3d& om) { return pdf_interface(vi, wi_local, om); }, f);
        return;
    }
    connect_through_exit<kMode>(
        conn, wo, 1.0, w, rng,
        [&](const Vec3d& om) { return interface_kernel(vi, wi_local, om, rng); },
        [&](const Vec3d& om, const Rgbd& pass) {
            return interface_pdf_chain(vi, wi_local, om, w, pass, rng);
        },
        [&](const Vec3d& om) { return pdf_interface(vi, wi_local, om); }, f);
}

// Next event at a non-delta interface k, met from wi_local (eval): into region k (up) and, for a
// dielectric, region k + 1 (down); the kernel f·|cos| and the Jacobian's 1/|cos| cancel. A
// multiple-scattering interface (docs/rendering.md §1.6): one microsurface walk from wi_local
// estimates the kernel towards both connection directions at once.
void RandomWalkStack::connect_at_interface(int k, const Vec3d& wi_local, WalkState& ws,
                                           ParticleRng& rng, const Connection& conn,
                                           const Vec3d& wo, bool polarized, Rgbd& f) const {
    const Interface& it = interfaces_[k];
    const Rgbd& w = ws.w;
    const bool up_ok = conn.valid[k];
    const bool down_ok = it.type == InterfaceType::Dielectric && conn.valid[k + 1];
    double mis_weight = -1;  // exit_mis, once per vertex (both connections read it)
    auto mis = [&] {
        if (mis_weight < 0) mis_weight = exit_mis(conn, ws, it, wi_local, wo, k);
        return mis_weight;
    };
    if (polarized) {
        // The vertex's light towards d_r, in the frame of its chain's plane (whose s and
        // p parts the chains carry apart); f·|cos| over |cos| of the connection.
        if (!it.delta && (up_ok || down_ok)) {
            Vec3d dirs[2];
            int n = 0;
            const int iu = up_ok ? n++ : -1, id = down_ok ? n++ : -1;
            if (up_ok) dirs[iu] = conn.dir_up[k];
            if (down_ok) dirs[id] = conn.dir_down[k + 1];
            StokesRgb<double> e[2];
            emission(it, wi_local, dirs, n, ws.stokes, w, rng, e);
            if (up_ok)
                f += w *
                     Connection::through(e[iu], conn.from_bottom_up(k, 0),
                                         conn.from_bottom_up(k, 1)) *
                     (conn.scale[k] * mis() / std::abs(dirs[iu].z));
            if (down_ok)
                f += w *
                     Connection::through(e[id], conn.from_top_down(k + 1, 0),
                                         conn.from_top_down(k + 1, 1)) *
                     (conn.scale[k + 1] * mis() / std::abs(dirs[id].z));
        }
    } else if (it.multiple && (up_ok || down_ok)) {
        Rgbd k_up(0.0), k_down(0.0);
        const Vec3d du = up_ok ? conn.dir_up[k] : Vec3d();
        const Vec3d dd = down_ok ? conn.dir_down[k + 1] : Vec3d();
        visit_microsurface(it, wi_local, rng, [&](const auto& connect) {
            if (up_ok) {
                const MicrosurfaceConnection<double> c = connect(du);
                k_up += c.weight * c.density;
            }
            if (down_ok) {
                const MicrosurfaceConnection<double> c = connect(dd);
                k_down += c.weight * c.density;
            }
        });
        // The kernel f·|cos| over |cos| of the connection: f.
        if (up_ok)
            f += w * k_up * conn.from_bottom_up(k) * (conn.scale[k] * mis() / std::abs(du.z));
        if (down_ok)
            f += w * k_down * conn.from_top_down(k + 1) *
                 (conn.scale[k + 1] * mis() / std::abs(dd.z));
    }
    if (!polarized && !it.delta && !it.multiple) {
        if (conn.valid[k]) {
            const Vec3d& du = conn.dir_up[k];
            Rgbd fv = eval_interface(it, wi_local, du);
            f += w * fv * conn.from_bottom_up(k) * (conn.scale[k] * mis());
        }
        if (it.type == InterfaceType::Dielectric && conn.valid[k + 1]) {
            const Vec3d& dd = conn.dir_down[k + 1];
            f += w * Rgbd(it.dielectric.eval(wi_local, dd)) * conn.from_top_down(k + 1) *
                 (conn.scale[k + 1] * mis());
        }
    }
    // Strategy 2 from the vertex interface emitting into the inner region.
    if (!it.delta && conn.rough_exit && k == conn.vertex_interface)
        connect_from_vertex_interface<Mode::Eval>(it, wi_local, ws, rng, conn, wo, polarized, f);
}

// Exit density at a non-delta interface (docs/rendering.md §1.4): its sampling density of
// d_r times the chains' probability of reaching the exit from there, times
// dω_r/dω_e = (η_e/η_r)² cos θ_e / μ_r (1 when r is the exit region). The weight just
// after the vertex is ∝ w·f (per channel; f·|cos|/pdf with grey |cos|/pdf).
void RandomWalkStack::exit_density_at_interface(int k, const Vec3d& wi_local, WalkState& ws,
                                                ParticleRng& rng, const Connection& conn,
                                                const Vec3d& wo, Rgbd& f) const {
    const Interface& it = interfaces_[k];
    const Rgbd& w = ws.w;
    const bool up_ok = conn.valid[k];
    const bool down_ok = it.type == InterfaceType::Dielectric && conn.valid[k + 1];
    double mis_weight = -1;  // exit_mis, once per vertex (both connections read it)
    auto mis = [&] {
        if (mis_weight < 0) mis_weight = exit_mis(conn, ws, it, wi_local, wo, k);
        return mis_weight;
    };
    if (it.multiple && (up_ok || down_ok)) {
        // Σ over the facets of the density of leaving towards d_r right after the facet
        // times the chains' probability for the weight that exit would carry.
        double p_up = 0, p_down = 0;
        const Vec3d du = up_ok ? conn.dir_up[k] : Vec3d();
        const Vec3d dd = down_ok ? conn.dir_down[k + 1] : Vec3d();
        const Rgbd q_up = up_ok ? conn.from_bottom_up(k) : Rgbd(0.0);
        const Rgbd q_down = down_ok ? conn.from_top_down(k + 1) : Rgbd(0.0);
        visit_microsurface(it, wi_local, rng, [&](const auto& connect) {
            if (up_ok) {
                const MicrosurfaceConnection<double> c = connect(du);
                if (c.density > 0) p_up += c.density * chain_probability(w * c.weight, q_up);
            }
            if (down_ok) {
                const MicrosurfaceConnection<double> c = connect(dd);
                if (c.density > 0) p_down += c.density * chain_probability(w * c.weight, q_down);
            }
        });
        const double cos_e = std::abs(wo.z);
        if (up_ok && std::isfinite(p_up)) f[0] += p_up * conn.scale[k] * cos_e / conn.mu[k] * mis();
        if (down_ok && std::isfinite(p_down))
            f[0] += p_down * conn.scale[k + 1] * cos_e / conn.mu[k + 1] * mis();
    }
    if (!it.delta && !it.multiple) {
        const double cos_e = std::abs(wo.z);
        if (conn.valid[k]) {
            const Vec3d& du = conn.dir_up[k];
            const double p = pdf_interface(it, wi_local, du);
            if (p > 0)
                f[0] += p *
                        chain_probability(w * eval_interface(it, wi_local, du),
                                          conn.from_bottom_up(k)) *
                        conn.scale[k] * cos_e / conn.mu[k] * mis();
        }
        if (it.type == InterfaceType::Dielectric && conn.valid[k + 1]) {
            const Vec3d& dd = conn.dir_down[k + 1];
            const double p = it.dielectric.pdf(wi_local, dd);
            if (p > 0)
                f[0] += p *
                        chain_probability(w * it.dielectric.eval(wi_local, dd),
                                          conn.from_top_down(k + 1)) *
                        conn.scale[k + 1] * cos_e / conn.mu[k + 1] * mis();
        }
    }
    if (!it.delta && conn.rough_exit && k == conn.vertex_interface)
        connect_from_vertex_interface<Mode::Pdf>(it, wi_local, ws, rng, conn, wo, false, f);
}

// The interface's event on a particle arriving from wi_local: its sample (direction and weight;
// the density is sample_density's, computed where it is read), or none where the sample failed or
// a microsurface walk was given up (the flux is dropped). Polarized walks: the state ws.stokes
// after the event.
std::optional<BsdfSample<double>> RandomWalkStack::sample_interface(const Interface& it,
                                                                    const Vec3d& wi_local,
                                                                    WalkState& ws, ParticleRng& rng,
                                                                    bool polarized) const {
    const Rgbd& w = ws.w;
    std::optional<BsdfSample<double>> s;
    // Polarized walks: the interfaces' polarized events on the walk's state, as the
    // goniophotometer's (the density, a proxy for strategy 2's weights, stays the
    // single-scattering unpolarized one).
    PolarizationLanes<double> pol;
    const double flux[3] = {w[0], w[1], w[2]};
    pol.stokes = ws.stokes;
    pol.channels = channels_;
    pol.flux = flux;
    const auto mueller = [&](double c, InterfaceMueller<double>* m) { it.conductor.mueller(c, m); };
    if (it.multiple) {
        // The microsurface walk (Heitz et al. 2016) to its exit; a walk given up at the facet
        // cap or degenerate loses its flux, as the goniophotometer's. The density is the
        // single-scattering one: only strategy 2's balance heuristic reads it (a proxy).
        auto uniform = [&] { return rng.uniform_double(); };
        const bool dielectric = it.type == InterfaceType::Dielectric;
        const std::optional<MicrosurfaceExit<double>> e = with_roughness([&](auto aniso) {
            constexpr bool kA = decltype(aniso)::value;
            return polarized    ? (dielectric
                                       ? walk_rough_dielectric_polarized<kA>(
                                          it.dielectric.distribution(), it.dielectric.eta, wi_local,
                                          uniform, transport_.max_microsurface_order, pol)
                                       : walk_rough_conductor_polarized<kA>(
                                          it.conductor.distribution(), mueller, wi_local, uniform,
                                          transport_.max_microsurface_order, pol))
                   : dielectric ? walk_rough_dielectric<kA>(it.dielectric.distribution(),
                                                            it.dielectric.eta, wi_local, uniform,
                                                            transport_.max_microsurface_order)
                                : walk_rough_conductor<kA>(
                                      it.conductor.distribution(),
                                      [&](double c) { return it.conductor.fresnel(c); }, wi_local,
                                      uniform, transport_.max_microsurface_order);
        });
        if (!e || !e->escaped) return std::nullopt;
        s = BsdfSample<double>{};
        s->wo = e->wo;
        s->weight = e->weight;
    } else
        switch (it.type) {
            case InterfaceType::Dielectric: {
                const double uc = rng.uniform_double(), u1 = rng.uniform_double(),
                             u2 = rng.uniform_double();
                if (polarized) {
                    s = with_roughness([&](auto aniso) {
                        return it.dielectric.sample_polarized<decltype(aniso)::value>(wi_local, uc,
                                                                                      u1, u2, pol);
                    });
                } else {
                    s = with_roughness([&](auto aniso) {
                        return it.dielectric.sample<false, decltype(aniso)::value>(wi_local, uc, u1,
                                                                                   u2);
                    });
                }
                break;
            }
            case InterfaceType::Conductor: {
                const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
                if (polarized) {
                    s = with_roughness([&](auto aniso) {
                        return it.conductor.sample_polarized<decltype(aniso)::value>(wi_local, u1,
                                                                                     u2, pol);
                    });
                } else {
                    s = with_roughness([&](auto aniso) {
                        return it.conductor.sample<false, decltype(aniso)::value>(wi_local, u1, u2);
                    });
                }
                break;
            }
            case InterfaceType::Lambertian: {
                const double u1 = rng.uniform_double(), u2 = rng.uniform_double();
                s = it.lambertian.sample(wi_local, u1, u2);
                stokes_depolarize<double>(pol.stokes, 3, true);
                break;
            }
        }
    if (polarized) ws.stokes = pol.stokes;
    return s;
}

// One walk from wi: at each interface the next events (eval) or exit densities (pdf) towards wo,
// then the interface's event and the medium behind it, until the particle leaves the stack (its
// exit into *exit, for sample()), is absorbed, dropped or cut off at max_events.
template <RandomWalkStack::Mode kMode>
void RandomWalkStack::walk(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng,
                           const Connection* conn, Rgbd& f,
                           std::optional<RandomWalkSample>* exit) const {
    constexpr bool kEstimate = kMode != Mode::Sample;  // eval and pdf share strategy 2's MIS
    const int L = int(interfaces_.size());
    WalkState ws;
    ws.d = -wi;
    Vec3d& d = ws.d;
    Rgbd& w = ws.w;
    // pdf() estimates the exit density of the unpolarized walk (random_walk.h): its walks are.
    const bool polarized = transport_.polarization && kMode != Mode::Pdf;
    if (polarized) {  // unpolarized incident light (docs/physics.md §8)
        const float unpolarized[3] = {0, 0, 0};
        ws.stokes = stokes_incident<double>({d.x, d.y, d.z}, unpolarized);
    }
    int k = 0;  // the interface the particle is about to meet
    while (ws.events++ < transport_.max_events) {
        const Interface& it = interfaces_[k];
        const Vec3d wi_local = -d;
        if constexpr (kMode == Mode::Eval)
            connect_at_interface(k, wi_local, ws, rng, *conn, wo, polarized, f);
        if constexpr (kMode == Mode::Pdf)
            exit_density_at_interface(k, wi_local, ws, rng, *conn, wo, f);
        const std::optional<BsdfSample<double>> s =
            sample_interface(it, wi_local, ws, rng, polarized);
        if (!s) return;  // a numerical degeneracy: the flux is dropped
        w *= s->weight;
        if (!it.delta) ws.delta_only = false;
        d = s->wo;
        if constexpr (kEstimate) {
            ws.prev_mis = conn->rough_exit && k == conn->vertex_interface && !it.delta &&
                          d.z * conn->towards > 0;
            // Only strategy 1's weight at the exit reads the density (exit_mis): computed for
            // the events that weight will meet.
            ws.prev_pdf = ws.prev_mis ? sample_density(it, wi_local, *s) : 0;
        }
        ws.prev_depth = 1;
        if (is_black(w) || d.z == 0) return;
        if (d.z > 0) {
            if (k == 0) {  // leaves upwards
                if (exit) *exit = RandomWalkSample{d, w, ws.delta_only};
                return;
            }
            bool up = true;
            if (!media_[k].is_empty()) up = traverse_medium<kMode>(k, ws, rng, conn, wo, f);
            if (is_black(w)) return;
            if (up) --k;
        } else {
            if (k == L - 1) {  // leaves through the final dielectric
                if (exit) *exit = RandomWalkSample{d, w, ws.delta_only};
                return;
            }
            bool up = false;
            if (!media_[k + 1].is_empty()) up = traverse_medium<kMode>(k + 1, ws, rng, conn, wo, f);
            if (is_black(w)) return;
            if (!up) ++k;
        }
    }
}

Rgbd RandomWalkStack::eval_interface(const Interface& it, const Vec3d& wi, const Vec3d& wo) {
    switch (it.type) {
        case InterfaceType::Dielectric:
            return Rgbd(it.dielectric.eval(wi, wo));
        case InterfaceType::Conductor:
            return it.conductor.eval(wi, wo);
        case InterfaceType::Lambertian:
            return it.lambertian.eval(wi, wo);
    }
    return Rgbd(0.0);
}

double RandomWalkStack::sample_density(const Interface& it, const Vec3d& wi,
                                       const BsdfSample<double>& s) {
    if (it.multiple) return pdf_interface(it, wi, s.wo);  // the single-scattering proxy
    if (s.is_delta || (it.type == InterfaceType::Conductor && s.wo.z <= 0)) return 0;
    return pdf_interface(it, wi, s.wo);
}

double RandomWalkStack::pdf_interface(const Interface& it, const Vec3d& wi, const Vec3d& wo) {
    switch (it.type) {
        case InterfaceType::Dielectric:
            return it.dielectric.pdf(wi, wo);
        case InterfaceType::Conductor:
            return it.conductor.pdf(wi, wo);
        case InterfaceType::Lambertian:
            return it.lambertian.pdf(wi, wo);
    }
    return 0;
}

Rgbd RandomWalkStack::eval_once(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng) const {
    if (wi.z <= 0 || wo.z == 0 || (wo.z < 0 && !transmits_)) return Rgbd(0.0);
    Connection conn;
    build_connection(eta_, interfaces_, media_, wo, wo.z > 0, false, conn, transport_.polarization);
    Rgbd f(0.0);
    walk<Mode::Eval>(wi, wo, rng, &conn, f, nullptr);
    return f;
}

std::vector<RandomWalkStack::DeltaExit> RandomWalkStack::delta_lobes(const Vec3d& wi) const {
    std::vector<DeltaExit> out;
    if (wi.z <= 0 || !interfaces_[0].delta) return out;
    // Light entering along −wi at interface 0 from above is A_0^↓ at wi's Snell invariant.
    const Vec3d mirror(-wi.x, -wi.y, wi.z);
    Connection conn;
    build_connection(eta_, interfaces_, media_, mirror, true, false, conn, transport_.polarization);
    if (conn.down[0].max() > 0) out.push_back({mirror, conn.down[0]});
    if (transmits_) {
        const int L = int(interfaces_.size());
        const double ratio = eta_[0] / eta_[L];
        const double sin2 = sqr(ratio) * (sqr(wi.x) + sqr(wi.y));
        if (sin2 < 1) {
            const Vec3d wt(-wi.x * ratio, -wi.y * ratio, -std::sqrt(1 - sin2));
            build_connection(eta_, interfaces_, media_, wt, false, false, conn,
                             transport_.polarization);
            if (conn.down[0].max() > 0) out.push_back({wt, conn.down[0]});
        }
    }
    return out;
}

RandomWalkEstimate RandomWalkStack::eval(const Vec3d& wi, const Vec3d& wo, std::uint64_t walks,
                                         std::uint64_t seed, std::uint64_t stream) const {
    RandomWalkEstimate e;
    e.walks = walks;
    if (walks == 0 || wi.z <= 0 || wo.z == 0 || (wo.z < 0 && !transmits_)) return e;
    Connection conn;
    build_connection(eta_, interfaces_, media_, wo, wo.z > 0, false, conn, transport_.polarization);
    Rgbd sum(0.0), sum_sq(0.0);
    for (std::uint64_t i = 0; i < walks; ++i) {
        ParticleRng rng(seed, stream, i);
        Rgbd f(0.0);
        walk<Mode::Eval>(wi, wo, rng, &conn, f, nullptr);
        sum += f;
        sum_sq += f * f;
    }
    const double n = double(walks);
    for (int c = 0; c < 3; ++c) {
        const double mean = sum[c] / n;
        e.f[c] = mean;
        e.se[c] = walks > 1 ? std::sqrt(std::max(0.0, sum_sq[c] / n - mean * mean) / (n - 1)) : 0;
    }
    return e;
}

double RandomWalkStack::pdf_once(const Vec3d& wi, const Vec3d& wo, ParticleRng& rng) const {
    if (wi.z <= 0 || wo.z == 0 || (wo.z < 0 && !transmits_)) return 0;
    Connection conn;
    build_connection(eta_, interfaces_, media_, wo, wo.z > 0, true, conn);
    Rgbd p(0.0);
    walk<Mode::Pdf>(wi, wo, rng, &conn, p, nullptr);
    return p[0];
}

RandomWalkPdf RandomWalkStack::pdf(const Vec3d& wi, const Vec3d& wo, std::uint64_t walks,
                                   std::uint64_t seed, std::uint64_t stream) const {
    RandomWalkPdf e;
    e.walks = walks;
    if (walks == 0 || wi.z <= 0 || wo.z == 0 || (wo.z < 0 && !transmits_)) return e;
    Connection conn;
    build_connection(eta_, interfaces_, media_, wo, wo.z > 0, true, conn);
    double sum = 0, sum_sq = 0;
    for (std::uint64_t i = 0; i < walks; ++i) {
        ParticleRng rng(seed, stream, i);
        Rgbd p(0.0);
        walk<Mode::Pdf>(wi, wo, rng, &conn, p, nullptr);
        sum += p[0];
        sum_sq += p[0] * p[0];
    }
    const double n = double(walks);
    e.pdf = sum / n;
    e.se = walks > 1 ? std::sqrt(std::max(0.0, sum_sq / n - e.pdf * e.pdf) / (n - 1)) : 0;
    return e;
}

std::optional<RandomWalkSample> RandomWalkStack::sample(const Vec3d& wi, ParticleRng& rng) const {
    std::optional<RandomWalkSample> exit;
    Rgbd unused(0.0);
    walk<Mode::Sample>(wi, wi, rng, nullptr, unused, &exit);
    return exit;
}

}  // namespace lamina

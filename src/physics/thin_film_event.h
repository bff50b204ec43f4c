#pragma once
// The particle events of a filmed interface (docs/physics.md §9), for one particle at a time (the
// scalar kernel). A film is on every facet of a rough interface: at each facet event the film's
// Mueller matrices at the facet's own cosine (physics/thin_film.h, per channel at the channel's
// wavelength) replace the bare interface's Fresnel terms, for the single-scattering facet, every
// facet of the microsurface walk (physics/microsurface_walk.h) and a smooth interface alike. The
// film does not change directions: a facet reflects about its normal or refracts by Snell's law
// between the media on either side, as without a film.
//
// The branch choice at a dielectric facet: channel c reflects the fraction P_r,c = a_r + b_r q_c of
// its state (q_c = S1/S0 in the facet's s/p frame; 0 for unpolarized light) and transmits
// P_t,c = a_t + b_t q_c; an absorbing film keeps 1 − P_r,c − P_t,c. The particle has one path, so
// the branch is drawn for all channels with the flux-weighted mixture P_r = Σ p_c P_r,c,
// P_t = Σ p_c P_t,c (p_c the channel's share of the flux), reflecting with probability
// P_r/(P_r + P_t), and channel c's flux is multiplied by P_r,c/π_r or P_t,c/π_t (π the branch's
// probability): one-sample MIS with the balance heuristic (Veach 1997, §9.2.4), unbiased per
// channel, as the polarized dielectric's choice with differing states (physics/polarization.h).
// Without absorption and with equal channels the factors are 1. The states leave through the
// chosen branch's Mueller matrix. The factors' departure from 1 (the film's absorption, and the
// reweighting between channels, zero in expectation) is what the kernel books as absorbed at the
// interface.

#include "core/lane.h"
#include "core/lane_vec.h"
#include "physics/fresnel.h"
#include "physics/microfacet.h"
#include "physics/polarization.h"
#include "physics/thin_film.h"

#include <cmath>

namespace lamina {

/// Where a film facet sent the particle: reflected or not, the new direction (away from the
/// surface: the mirror direction, or the refracted one on the other side) and the flux factors.
struct FilmFacetScatter {
    bool reflects = true;
    LaneVec3<float> wo;
    float factor[3] = {1.f, 1.f, 1.f};
};

/// One facet of a filmed interface: light arriving from w (unit, away from the surface) on the
/// facet of normal wm (unit, on w's side: cos_w_m = w·wm > 0), `above`: on the side the interface's
/// normal points to. `eta` is the bare interface's relative index (below over above) for Snell's
/// law; `thickness_nm` the film's thickness at this event; `uc` the uniform number of the branch
/// choice; `flux` the particle's flux per channel (the mixture's weights). Polarized (`pol` not
/// null, 3 states): the states are turned into the facet's plane of incidence and leave through the
/// chosen branch's Mueller matrix. `opaque`: a conductor below (reflection only; the factors are
/// the reflected fractions). Nothing here throws; a facet whose channels pass nothing (all
/// absorbed) reflects with factors 0.
inline FilmFacetScatter film_facet_scatter(const FilmOptics& film, bool opaque, float eta,
                                           double thickness_nm, const LaneVec3<float>& w,
                                           const LaneVec3<float>& wm, float cos_w_m, bool above,
                                           float uc, const float* flux,
                                           PolarizationLanes<float>* pol) {
    if (pol)
        stokes_rotate_frame<float>(pol->stokes, {-w.x, -w.y, -w.z}, lane_cross<float>(w, wm), 3,
                                   true);
    ThinFilmMueller<double> m[3];
    double p_r[3], p_t[3];
    double mix_r = 0, mix_t = 0, total_flux = 0;
    for (int c = 0; c < 3; ++c) {
        m[c] = film.mueller(c, double(cos_w_m), above, thickness_nm);
        const double q = pol ? double(pol->stokes.q[c]) : 0.0;
        p_r[c] = std::max(m[c].reflection.a + m[c].reflection.b * q, 0.0);
        p_t[c] = opaque ? 0.0 : std::max(m[c].transmission.a + m[c].transmission.b * q, 0.0);
        const double f = std::max(double(flux[c]), 0.0);
        mix_r += f * p_r[c];
        mix_t += f * p_t[c];
        total_flux += f;
    }
    if (!(total_flux > 0)) {  // no flux to weigh the channels by: equal weights
        mix_r = (p_r[0] + p_r[1] + p_r[2]) / 3;
        mix_t = (p_t[0] + p_t[1] + p_t[2]) / 3;
    }
    FilmFacetScatter out;
    const double mix = mix_r + mix_t;
    if (!(mix > 0)) {  // every channel absorbed
        out.factor[0] = out.factor[1] = out.factor[2] = 0.f;
    } else {
        const double pi_r = mix_r / mix;
        out.reflects = double(uc) < pi_r;
        const double pi_branch = out.reflects ? pi_r : 1 - pi_r;
        for (int c = 0; c < 3; ++c)
            out.factor[c] = float((out.reflects ? p_r[c] : p_t[c]) / pi_branch);
    }
    if (pol) {
        for (int c = 0; c < 3; ++c) {
            const InterfaceMueller<double>& md = out.reflects ? m[c].reflection : m[c].transmission;
            const InterfaceMueller<float> mf = {float(md.a), float(md.b), float(md.c), float(md.d)};
            StokesLanes<float>& s = pol->stokes;
            stokes_apply<float>(mf, s.q[c], s.u[c], s.v[c], true);
        }
    }
    const float two_cos = cos_w_m + cos_w_m;
    const LaneVec3<float> reflected = {two_cos * wm.x - w.x, two_cos * wm.y - w.y,
                                       two_cos * wm.z - w.z};
    out.wo = reflected;
    if (!out.reflects) {
        // Snell about wm (fresnel.h refract) with the relative index crossed from w's side; a
        // transmitted branch has P_t > 0, so the bare boundary refracts (cos θt > 0).
        const float eta_side = above ? eta : 1.f / eta;
        const FresnelDielectric<float> fr = fresnel_dielectric_full<float>(cos_w_m, eta_side);
        const float along = cos_w_m * fr.inv_eta - fr.cos_theta_t;
        out.wo = lane_normalize<float>({w.x * -fr.inv_eta + wm.x * along,
                                        w.y * -fr.inv_eta + wm.y * along,
                                        w.z * -fr.inv_eta + wm.z * along});
    }
    return out;
}

/// The walk's facet of a filmed dielectric (the Scatter of microsurface_walk at one lane): one
/// uniform number per facet for the branch choice, the flux weights multiplied by the factors of
/// film_facet_scatter, the mixture's weights the particle's flux times the walk's weights so far.
template <typename Uniform>
struct MicrosurfaceFilmFacet {
    const FilmOptics& film;
    float eta;
    double thickness_nm;
    Uniform& uniform;
    const float* flux;
    PolarizationLanes<float>* pol = nullptr;
    void operator()(const LaneVec3<float>& w, const LaneVec3<float>& wm, float cos_w_m, bool above,
                    bool walking, LaneVec3<float>& wr_new, bool& crosses, float* weight) const {
        const float uc = uniform();
        if (!walking) return;
        const float f[3] = {flux[0] * weight[0], flux[1] * weight[1], flux[2] * weight[2]};
        const FilmFacetScatter s =
            film_facet_scatter(film, false, eta, thickness_nm, w, wm, cos_w_m, above, uc, f, pol);
        for (int c = 0; c < 3; ++c)
            weight[c] *= s.factor[c];
        wr_new = s.wo;
        crosses = !s.reflects;
    }
};

/// The single-facet event of a filmed dielectric interface (as dielectric_event, one lane): a
/// visible facet normal drawn from u1, u2 for a rough interface (alpha > 0; the macro normal when
/// smooth), the film facet's branch and factors (film_facet_scatter, from uc), and the escape
/// fraction G2/G1 of the pair (ggx_escape_fraction; zero unless a reflection stays on wi's side
/// and a refraction crosses). `shadowing` is G2/G1 (1 when smooth); `degenerate` a grazing wi.
struct FilmEvent {
    FilmFacetScatter scatter;
    float shadowing = 1.f;
    bool degenerate = false;
};
inline FilmEvent film_dielectric_event(const FilmOptics& film, float eta, float alpha,
                                       bool uncorrelated, bool smith_refraction,
                                       double thickness_nm, const LaneVec3<float>& wi, float uc,
                                       float u1, float u2, const float* flux,
                                       PolarizationLanes<float>* pol) {
    FilmEvent e;
    if (!(std::abs(wi.z) > 0)) {
        e.degenerate = true;
        return e;
    }
    // Isotropic: a stack with a film has no anisotropic interface (validate_kernel_for).
    const GgxLanes<float, false> ggx = ggx_lanes<float>(alpha, alpha, 1, 0);
    const bool above = wi.z > 0;
    const float sign = above ? 1.f : -1.f;
    const LaneVec3<float> w_side = {sign * wi.x, sign * wi.y, sign * wi.z};
    LaneVec3<float> wm = {0.f, 0.f, 1.f};  // on the particle's side, seen from that side
    if (alpha > 0) wm = ggx_sample_visible_normal_complete<float>(ggx, w_side, u1, u2);
    const LaneVec3<float> wm_particle = {sign * wm.x, sign * wm.y, sign * wm.z};
    const float cos_w_m = std::min(lane_dot<float>(wi, wm_particle), 1.f);
    if (!(cos_w_m > 0)) {
        e.degenerate = true;
        return e;
    }
    e.scatter = film_facet_scatter(film, false, eta, thickness_nm, wi, wm_particle, cos_w_m, above,
                                   uc, flux, pol);
    if (alpha > 0) {
        const LaneVec3<float>& wo = e.scatter.wo;
        const bool same_side = wi.z * wo.z > 0;
        const bool escapes = std::abs(wo.z) > 0 && same_side == e.scatter.reflects;
        e.shadowing = escapes ? ggx_escape_fraction<float>(ggx, wi, wo, e.scatter.reflects, true,
                                                           uncorrelated, smith_refraction)
                              : 0.f;
    }
    return e;
}

}  // namespace lamina

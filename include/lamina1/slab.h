#pragma once
// lamina-1's slab (a dielectric base: the BTDF): the first order through the bottom's own BTDF
// and its energy E_1, the coat's mean transmitted direction, and the later orders as two
// populations of inside light (items 5 and 6 of lamina-1 in lamina's docs/models.md).

#include "lamina1/bsdf.h"

namespace lamina1 {

using SlabRule2 = Multi<Rgb, 2>;
using SlabRule4 = Multi<Rgb, 4>;

/// The populations' reflections (btdf_populations): ρ_r(μ), the coat's reflection of light inside
/// going up at μ into population r times the attenuation of the crossing down; and the bottom's
/// of light going down at μ into population q (v[0], v[1]), and that light after the coat's
/// return arriving down in population r (v[2 + r]).
struct Bsdf::SlabReflections {
    SplitCurve<(kNslab + 1) / 2, SlabRule2> rho;
    SplitCurve<(kNslab + 1) / 2, SlabRule4> bottom;
};

inline void Bsdf::precompute_slab() {
    // An index-matched bottom lets the light straight through (a delta, whatever its roughness):
    // no BTDF lobe of its own, the first order is the mirrored lobe of the coat's spread.
    bottom_lobe_ = support_.btdf && ch_.btdf_bottom_lobe && eta_b_ != 1;
    populations_ = support_.btdf && ch_.btdf_populations && ch_.inter_reflection && !ms_ &&
                   !(alpha0_ == 0 && alpha1_ == 0);
    if (!bottom_lobe_ && !populations_) return;
    const SlabReflections reflections = populations_ ? slab_reflections() : SlabReflections();
    const CosineCurve<Multi<Rgb, 3>, kNfirst> entry = slab_entry(reflections);
    if (bottom_lobe_) slab_first_order(entry);
    if (populations_) slab_populations(reflections, entry);
}

/// Inside directions fall into two populations: 0 within the coat's exit cone (μ ≥ μc), 1 beyond
/// it, where a smooth coat reflects everything back.
inline int slab_population(double mu, double mu_c) {
    return mu >= mu_c ? 0 : 1;
}

inline Bsdf::SlabReflections Bsdf::slab_reflections() const {
    SlabReflections out;
    const double mu_c = std::sqrt(1 - sqr(inv_eta0_));
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    // From inside the coat is an interface of relative index 1/η0 (total internal reflection
    // beyond μc); rough: its visible normals (Heitz 2018), weight F G2/G1, the reflected
    // direction split at μc.
    auto rho_at = [&](double mu) {
        SlabRule2 r;
        if (alpha0_ == 0) {
            r.v[slab_population(mu, mu_c)] = attenuation(mu) * fresnel_dielectric(mu, inv_eta0_);
            return r;
        }
        const GGX ggx0{alpha0_};
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        const double lambda_w = ggx0.lambda(w);
        return integrate_visible_split<SlabRule2, kSlabNr, kSlabNphi, kSlabBisections>(
            ggx0, w, mu_c, [&](const Vec3& wm) { return reflect(w, wm).z; },
            [&](const Vec3& wm) {
                SlabRule2 o;
                const Vec3 w2 = reflect(w, wm);
                if (w2.z <= 0) return o;
                const double escape = (1 + lambda_w) / (1 + lambda_w + ggx0.lambda(w2));
                o.v[slab_population(w2.z, mu_c)] =
                    attenuation(w2.z) * (fresnel_dielectric(dot(w, wm), inv_eta0_) * escape);
                return o;
            });
    };
    out.rho.fill(mu_c, [&](double mu) { return rho_at(std::max(mu, 1e-6)); });
    const auto& rho = out.rho;
    out.bottom.fill(mu_crit_b, [&](double mu_in) {
        const double mu = std::max(mu_in, 1e-6);
        SlabRule4 r;
        if (alpha1_ == 0) {
            const Rgb R = attenuation(mu) * fresnel_dielectric(mu, eta_b_);
            const SlabRule2 back = rho(mu);
            r.v[slab_population(mu, mu_c)] = R;
            r.v[2] = R * back.v[0];
            r.v[3] = R * back.v[1];
            return r;
        }
        const GGX ggx1{alpha1_};
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, mu);
        const double lambda_w = ggx1.lambda(w);
        return integrate_visible_split<SlabRule4, kSlabNr, kSlabNphi, kSlabBisections>(
            ggx1, w, mu_c, [&](const Vec3& wm) { return reflect(w, wm).z; },
            [&](const Vec3& wm) {
                SlabRule4 o;
                const Vec3 w2 = reflect(w, wm);
                if (w2.z <= 0) return o;
                const double escape = (1 + lambda_w) / (1 + lambda_w + ggx1.lambda(w2));
                const Rgb R = attenuation(w2.z) * (fresnel_dielectric(dot(w, wm), eta_b_) * escape);
                const SlabRule2 back = rho(w2.z);
                o.v[slab_population(w2.z, mu_c)] = R;
                o.v[2] = R * back.v[0];
                o.v[3] = R * back.v[1];
                return o;
            });
    });
    return out;
}

/// The light the coat lets in at outside cosine μ, per unit flux, by its own inside direction w'
/// (the coat's transmitted light t(μ → w'), as in X): E_1(μ) = ∫ t a T_b,in dω' leaves through the
/// bottom at once (the first order, v[0]); D_r(μ) = ∫ t a (R ρ_r)(μ_w') dω' comes back down in
/// population r after one reflection at the bottom and one at the coat (v[1 + r]). T_b,in and the
/// bottom's curve step at the bottom's critical cosine: the rule splits there. With a rough coat
/// the same rule gives the transmitted light's mean direction (mu_mean_).
inline CosineCurve<Multi<Rgb, 3>, kNfirst> Bsdf::slab_entry(const SlabReflections& reflections) {
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    auto entering = [&](double mu_in) {
        Multi<Rgb, 3> r;
        const Rgb a = attenuation(mu_in);
        r.v[0] = a * T_bot_in_(mu_in);
        if (populations_) {
            const SlabRule4 b = reflections.bottom(mu_in);
            r.v[1] = a * b.v[2];
            r.v[2] = a * b.v[3];
        }
        return r;
    };
    CosineCurve<Multi<Rgb, 3>, kNfirst> entry;
    if (alpha0_ == 0 || !ch_.directional_transmittance) {
        entry.fill([&](double mu) {
            const double mu_in = refract_in(Vec3(safe_sqrt(1 - mu * mu), 0, mu), inv_eta0_).z;
            return entering(mu_in) * T_top_(mu);
        });
        return entry;
    }
    const GGX ggx0{alpha0_};
    // The coat's orders ≥ 2 (multiple scattering) transmit ΔT(μ) more, taken as cosine-
    // distributed inside, as in X.
    const bool ms = ms_;
    const Rgb once_spread =
        ms ? integrate_split01<kGauss, Rgb>([&](double mu) { return entering(mu).v[0] * (2 * mu); },
                                            mu_crit_b)
           : Rgb(0.0);
    auto entry_at = [&](double mu) {
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
        const double lambda_w = ggx0.lambda(w);
        auto inside_z = [&](const Vec3& wm) {
            const auto wt = refract(w, wm, eta0_);
            return wt ? -wt->z : 0.0;
        };
        // v[3] (x, z, ·): the (1 − F)-weighted inside direction, the transmitted light's mean
        // direction for the lobe's centre (item 5 of lamina-1).
        Multi<Rgb, 4> sum =
            integrate_visible_split<Multi<Rgb, 4>, kSlabNr, kSlabNphi, kSlabBisections>(
                ggx0, w, mu_crit_b, inside_z, [&](const Vec3& wm) {
                    Multi<Rgb, 4> out;
                    const auto wt = refract(w, wm, eta0_);
                    if (!wt || wt->z >= 0) return out;
                    const double F = fresnel_dielectric(dot(w, wm), eta0_);
                    const double escape =
                        refraction_escape(ch_.masking, lambda_w, ggx0.lambda(*wt));
                    const Multi<Rgb, 3> e = entering(-wt->z) * ((1 - F) * escape);
                    for (int i = 0; i < 3; ++i)
                        out.v[i] = e.v[i];
                    out.v[3] = Rgb(wt->x, -wt->z, 0.0) * (1 - F);
                    return out;
                });
        if (ms) sum.v[0] += once_spread * ms_dielectric(fgd_top_, mu, alpha0_, eta0_).transmitted;
        return sum;
    };
    // The mean direction's curve has twice the nodes (its odd ones interpolated).
    static_assert(2 * (kNfirst - 1) == kNx - 1, "the mean direction shares the nodes");
    for (int i = 0; i < kNfirst; ++i) {
        const double mu = sqr(double(i) / (kNfirst - 1));
        const Multi<Rgb, 4> e = entry_at(mu);
        for (int k = 0; k < 3; ++k)
            entry.v[i].v[k] = e.v[k];
        if (mean_shift_) {
            // Stored as the shift from the macro refraction, as in precompute_mean_direction.
            const double len = std::hypot(e.v[3][0], e.v[3][1]);
            const double mu_in =
                refract_in(Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)), inv_eta0_).z;
            mu_mean_.v[2 * i] = (len > 0 ? e.v[3][1] / len : mu_in) - mu_in;
            if (i > 0) mu_mean_.v[2 * i - 1] = 0.5 * (mu_mean_.v[2 * i - 2] + mu_mean_.v[2 * i]);
        }
    }
    return entry;
}

/// The first order's curves (btdf-lobe): E_1 over T_lobe(μ), the energy of the bottom's lobe of
/// roughness α_b at the mean inside direction (both depend on wi only), and with btdf-lobe=shared
/// over Q_m, the mirrored lobe's, each lobe then carrying E_1.
inline void Bsdf::slab_first_order(const CosineCurve<Multi<Rgb, 3>, kNfirst>& entry) {
    const float* table = tables_->transmittance(ch_.masking);
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    first_order_.fill([&](double mu) {
        const Incident in = incident(Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)));
        Multi<Rgb, 3> r;
        r.v[1] = entry(mu).v[0];
        const double mu_in = in.ok ? in.wi_in.z : 0.0;
        if (in.ok && in.alpha_b > 0) {
            // By the transmittance table (Walter et al. 2007, Eq. 21 over the visible normals),
            // whose c axis puts the smoothed step of total internal reflection on a node line.
            const double T_lobe =
                TransmittanceFormat::lookup(table, in.wi_mean.z, in.alpha_b, eta_b_);
            if (T_lobe > 0) r.v[0] = r.v[1] * (1 / T_lobe);
        }
        // btdf-lobe=shared: Q_m = ∫_cone T_b,in(μv') q(w̄i', v'; β) μv' dωv', the mirrored lobe's
        // energy (as eval_btdf weights it), by the visible normals of β at w̄i', split where the
        // mirrored direction leaves the exit cone: twice the φ nodes of the other slab rules, as
        // that edge crosses some φ lines twice (within 2 % of a 1500 × 3000 solid-angle sum on
        // five slabs at θi 60°–85°, where 4 × 8 nodes were up to 7 % off).
        const double beta = in.ok ? transmission_roughness(in.k_top, in.k_bottom) : 0.0;
        if (ch_.btdf_lobe_shared && beta > 0) {
            const GGX ggx{beta};
            const Vec3& w = in.wi_mean;
            const double lambda_w = ggx.lambda(w);
            const double Q_m =
                integrate_visible_split<double, kSlabNr, 2 * kSlabNphi, kSlabBisections>(
                    ggx, w, mu_crit_b, [&](const Vec3& wm) { return reflect(w, wm).z; },
                    [&](const Vec3& wm) {
                        const Vec3 v_in = reflect(w, wm);
                        if (v_in.z <= mu_crit_b) return 0.0;
                        return T_bot_in_(v_in.z) * (1 + lambda_w) /
                               (1 + lambda_w + ggx.lambda(v_in));
                    });
            if (Q_m > 0) r.v[2] = r.v[1] * (1 / Q_m);
        }
        const Multi<Rgb, 2> smooth = first_order_smooth(mu, mu_in);
        r.v[0] = r.v[0] - smooth.v[0];
        r.v[1] = r.v[1] - smooth.v[1];
        r.v[2] = r.v[2] - smooth.v[0];
        return r;
    });
}

/// The later orders as two populations (btdf_populations; item 6 of lamina-1).
inline void Bsdf::slab_populations(const SlabReflections& reflections,
                                   const CosineCurve<Multi<Rgb, 3>, kNfirst>& entry) {
    const double mu_c = std::sqrt(1 - sqr(inv_eta0_));
    // T_{below→p}(μ): light arriving from below at μ that the bottom lets into population p. From
    // below the bottom is an interface of relative index η_s (into the denser coat); rough: its
    // visible normals, weight (1 − F) G_t/G1, the refracted direction split at μc.
    enter_below_.fill([&](double mu_out) {
        const double mu = std::max(mu_out, 1e-4);
        Multi<double, 2> r;
        if (alpha1_ == 0) {
            const double mu_in = safe_sqrt(1 - (1 - mu * mu) / sqr(eta_s_));
            r.v[slab_population(mu_in, mu_c)] = 1 - fresnel_dielectric(mu, eta_s_);
            return r;
        }
        const GGX ggx1{alpha1_};
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, mu);
        const double lambda_w = ggx1.lambda(w);
        auto inside_z = [&](const Vec3& wm) {
            const auto wt = refract(w, wm, eta_s_);
            return wt ? -wt->z : 0.0;
        };
        return integrate_visible_split<Multi<double, 2>, kSlabNr, kSlabNphi, kSlabBisections>(
            ggx1, w, mu_c, inside_z, [&](const Vec3& wm) {
                Multi<double, 2> out;
                const auto wt = refract(w, wm, eta_s_);
                if (!wt || wt->z >= 0) return out;
                out.v[slab_population(-wt->z, mu_c)] =
                    (1 - fresnel_dielectric(dot(w, wm), eta_s_)) *
                    refraction_escape(ch_.masking, lambda_w, ggx1.lambda(*wt));
                return out;
            });
    });
    // After the first return the light is taken as uniform radiance within each population
    // (A_p = ∫_p 2μ dμ): the bottom reflects population p into q with R_pq, the coat returns q
    // into r with ρ_qr, and the bottom lets p out with T_p = (2/(A_p η_s²)) ∫ T_{below→p} μ dμ
    // (reciprocity of the bottom's BTDF). With M = ρ R, the light arriving down summed over every
    // round trip is Φ = (1 − M)⁻¹ D.
    const double A[2] = {1 - sqr(mu_c), sqr(mu_c)};
    const double range[2][2] = {{mu_c, 1.0}, {0.0, mu_c}};
    double T_out[2] = {0, 0};
    Rgb R_pq[2][2], rho_qr[2][2];
    for (int p = 0; p < 2; ++p) {
        const double lo = range[p][0], hi = range[p][1];
        if (!(A[p] > 0)) continue;
        const SlabRule4 Rb = integrate_range<SlabRule4>(
            [&](double mu) {
                return reflections.bottom(std::min(mu, std::nextafter(hi, 0.0))) * (2 * mu);
            },
            lo, hi);
        const SlabRule2 rh = integrate_range<SlabRule2>(
            [&](double mu) {
                return reflections.rho(std::min(mu, std::nextafter(hi, 0.0))) * (2 * mu);
            },
            lo, hi);
        for (int q = 0; q < 2; ++q) {
            R_pq[p][q] = Rb.v[q] * (1 / A[p]);
            rho_qr[p][q] = rh.v[q] * (1 / A[p]);
        }
        T_out[p] = integrate_split01<kGauss, double>(
                       [&](double mu) { return enter_below_(mu).v[p] * (2 * mu); }, 0.0) /
                   (A[p] * sqr(eta_s_));
    }
    trapped_.fill([&](double mu) {
        const Multi<Rgb, 3> e = entry(mu);
        Multi<Rgb, 3> r;
        for (int c = 0; c < 3; ++c) {
            // M_rp = Σ_q ρ_qr R_pq; Φ = (1 − M)⁻¹ D by the 2 × 2 inverse.
            double M[2][2];
            for (int rr = 0; rr < 2; ++rr)
                for (int p = 0; p < 2; ++p)
                    M[rr][p] = rho_qr[0][rr][c] * R_pq[p][0][c] + rho_qr[1][rr][c] * R_pq[p][1][c];
            const double a = 1 - M[0][0], b = -M[0][1], cc = -M[1][0], d = 1 - M[1][1];
            const double det = a * d - b * cc;
            if (!(det > 0)) continue;
            const double D0 = e.v[1][c], D1 = e.v[2][c];
            const double phi[2] = {(d * D0 - b * D1) / det, (a * D1 - cc * D0) / det};
            for (int p = 0; p < 2; ++p) {
                if (!(A[p] > 0)) continue;
                r.v[p][c] = phi[p] * kInvPi / (A[p] * sqr(eta_s_));
                r.v[2][c] += phi[p] * T_out[p];
            }
        }
        return r;
    });
}

}  // namespace lamina1

#pragma once
// lamina-1's slab (a dielectric base): the first order through the bottom's own BTDF and its
// energy E_1, the coat's mean transmitted direction, and the later orders of both sides with the
// light inside in cosine bins (items 5 and 6 of lamina-1 in lamina's docs/models.md).

#include "lamina1/bsdf.h"

#include <algorithm>
#include <vector>

namespace lamina1 {

inline void Bsdf::precompute_slab() {
    // An index-matched bottom lets the light straight through (a delta, whatever its roughness):
    // no BTDF lobe of its own, the first order is the mirrored lobe of the coat's spread.
    bottom_lobe_ = support_.btdf && ch_.btdf_bottom_lobe && eta_b_ != 1;
    if (bottom_lobe_) slab_first_order(slab_entry());
    if (bins_) slab_bins();
}

inline Bsdf::SlabEnergies Bsdf::slab_energies(const Incident& in) const {
    SlabEnergies e;
    if (!in.ok || !support_.btdf) return e;
    const Rgb R_b = base_albedo(in.wi_in.z);
    e.first_reflected = R_b * in.a * in.a * (in.T * first_order_exit(in.wi_in.z));
    e.first_transmitted = bottom_lobe_ ? in.first_E : nonnegative(Rgb(1.0) - R_b) * in.a * in.T;
    if (bins_) {
        e.later_reflected = in.bins.v[6 * kNbins];
        e.later_transmitted = in.bins.v[6 * kNbins + 1];
    } else if (series_on_) {
        e.later_reflected = in.X * K_ * X_bar_;
        if (series_btdf_) e.later_transmitted = in.X * inv_one_minus_Er_;
    }
    return e;
}

/// polarization (lamina1/polarization.h): a slab whose bottom is there for the light; its
/// unscattered light (a scattering event depolarizes: a scattering medium's own terms are left as
/// they are, and the series attenuates by extinction). Rough: the factors on the outside cosine,
/// √k_R (the reflection takes it at μi and μo) and k_T, from the series' changes over the slab's
/// own energies; smooth (both interfaces): the delta lobes take the changes at μi.
inline void Bsdf::precompute_polarization() {
    if (!support_.btdf || !ch_.polarization || !ch_.inter_reflection || bottom_matched()) return;
    pol_.emplace(eta0_, alpha0_, eta_b_, alpha1_, ch_.masking, tau_t_);
    if (alpha0_ == 0 && alpha1_ == 0) return;
    for (int i = 0; i < kNfirst; ++i) {
        const double mu = std::max(sqr(double(i) / (kNfirst - 1)), 1e-4);
        const SlabEnergies e = slab_energies(incident(Vec3(std::sqrt(1 - mu * mu), 0, mu)));
        const Rgb R_body = e.first_reflected + e.later_reflected;
        const Rgb T = e.first_transmitted + e.later_transmitted;
        const PolarizationChange d = pol_->change(mu);
        for (int c = 0; c < 3; ++c) {
            // A change larger than the light it changes (the series and the slab's energies
            // disagree where both vanish, at grazing incidence) removes that light, no more.
            pol_R_.v[i][c] = R_body[c] > kNegligibleEnergy
                                 ? std::sqrt(max0(1 + d.reflected[c] / R_body[c]))
                                 : 1.0;
            pol_T_.v[i][c] = T[c] > kNegligibleEnergy ? max0(1 + d.transmitted[c] / T[c]) : 1.0;
        }
    }
    pol_on_ = true;
}

/// The light the coat lets in at outside cosine μ, per unit flux, by its own inside direction w'
/// (the coat's transmitted light t(μ → w'), as in X): E_1(μ) = ∫ t a T_b,in dω' leaves through the
/// bottom at once (the first order). T_b,in steps at the bottom's critical cosine: the rule splits
/// there. With a rough coat the same rule gives the transmitted light's mean direction (mu_mean_).
inline CosineCurve<Rgb, kNfirst> Bsdf::slab_entry() {
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    auto entering = [&](double mu_in) { return attenuation(mu_in) * T_bot_in_(mu_in); };
    CosineCurve<Rgb, kNfirst> entry;
    if (alpha0_ == 0 || !ch_.directional_transmittance) {
        entry.fill([&](double mu) {
            const double mu_in = refract_in(Vec3(safe_sqrt(1 - mu * mu), 0, mu), inv_eta0_).z;
            return entering(mu_in) * T_top_(mu);
        });
        return entry;
    }
    // The coat's orders ≥ 2 (multiple scattering) transmit ΔT(μ) more, taken as cosine-
    // distributed inside, as in X.
    const bool ms = ms_;
    const Rgb once_spread = ms ? integrate_split01<kGauss, Rgb>(
                                     [&](double mu) { return entering(mu) * (2 * mu); }, mu_crit_b)
                               : Rgb(0.0);
    auto entry_at = [&](double mu) {
        // v[1] (x, z, ·): the (1 − F)-weighted inside direction, the transmitted light's mean
        // direction for the lobe's centre (item 5 of lamina-1).
        Multi<Rgb, 2> sum =
            over_coat_transmission<Multi<Rgb, 2>, kSlabNr, kSlabNphi, kSlabBisections>(
                mu, mu_crit_b, [&](const Vec3& wt, double F, double escape) {
                    Multi<Rgb, 2> out;
                    out.v[0] = entering(-wt.z) * ((1 - F) * escape);
                    out.v[1] = Rgb(wt.x, -wt.z, 0.0) * (1 - F);
                    return out;
                });
        if (ms) sum.v[0] += once_spread * ms_dielectric(fgd_top_, mu, alpha0_, eta0_).transmitted;
        return sum;
    };
    // The mean direction's curve has twice the nodes (its odd ones interpolated).
    static_assert(2 * (kNfirst - 1) == kNx - 1, "the mean direction shares the nodes");
    for (int i = 0; i < kNfirst; ++i) {
        const double mu = sqr(double(i) / (kNfirst - 1));
        const Multi<Rgb, 2> e = entry_at(mu);
        entry.v[i] = e.v[0];
        if (mean_shift_) {
            // Stored as the shift from the macro refraction, as in precompute_mean_direction.
            const double len = std::hypot(e.v[1][0], e.v[1][1]);
            const double mu_in =
                refract_in(Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)), inv_eta0_).z;
            mu_mean_.v[2 * i] = (len > 0 ? e.v[1][1] / len : mu_in) - mu_in;
            if (i > 0) mu_mean_.v[2 * i - 1] = 0.5 * (mu_mean_.v[2 * i - 2] + mu_mean_.v[2 * i]);
        }
    }
    return entry;
}

/// The first order's curves (btdf-lobe): E_1, and with btdf-lobe=shared E_1 over Q_m, the
/// mirrored lobe's energy, which that lobe then carries (the bottom's own lobe carries E_1 over its
/// energy T_lobe, looked up per incidence in incident).
inline void Bsdf::slab_first_order(const CosineCurve<Rgb, kNfirst>& entry) {
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    first_order_.fill([&](double mu) {
        const Incident in = incident(Vec3(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4)));
        Multi<Rgb, 2> r;
        r.v[0] = entry(mu);
        const double mu_in = in.ok ? in.wi_in.z : 0.0;
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
                        return T_bot_in_(v_in.z) * reflection_escape(lambda_w, ggx.lambda(v_in));
                    });
            if (Q_m > 0) r.v[1] = r.v[0] * (1 / Q_m);
        }
        const Multi<Rgb, 2> smooth = first_order_smooth(mu, mu_in);
        r.v[0] = r.v[0] - smooth.v[1];
        r.v[1] = r.v[1] - smooth.v[0];
        return r;
    });
}

/// The bins as hat functions over an inside cosine (slab-orders=bins): each bin's φ_k is 1 at
/// its centre, falls linearly to 0 at its neighbours' centres within the same piece (between
/// critical cosines) and stays 1 from its centre to the piece's end where it has no neighbour;
/// Σ φ_k = 1, continuous within a piece, stepping at a critical cosine. Radiance Σ L_k φ_k(μ) is
/// then continuous where the physics is (bins of uniform radiance made the light leaving a nearly
/// smooth interface a staircase in θo).
inline Bsdf::Hat Bsdf::hat_of(double mu) const {
    const int k = int(std::upper_bound(bin_edge_.begin() + 1, bin_edge_.end() - 1, mu) -
                      (bin_edge_.begin() + 1));
    const double centre = 0.5 * (bin_edge_[k] + bin_edge_[k + 1]);
    const int other = mu < centre ? k - 1 : k + 1;
    if (other < 0 || other >= kNbins || bin_piece_[other] != bin_piece_[k]) return {k, k, 1.0, 0.0};
    const double centre_o = 0.5 * (bin_edge_[other] + bin_edge_[other + 1]);
    const double w = (mu - centre) / (centre_o - centre);
    return {k, other, 1 - w, w};
}

/// A rule for ∫ φ_k(μ) f(μ) 2μ dμ / A_k over bin k's support (kBinSub Gauss–Legendre nodes on
/// each side of its centre): nodes and weights (summing to 1), and A_k = ∫ φ_k 2μ dμ.
inline void Bsdf::hat_rule(int k, std::array<double, 2 * kBinSub>& mu,
                           std::array<double, 2 * kBinSub>& weight, double& area) const {
    static const QuadratureRule q = gauss_legendre(kBinSub);
    const double centre = 0.5 * (bin_edge_[k] + bin_edge_[k + 1]);
    auto neighbour_centre = [&](int o, double end) {
        if (o < 0 || o >= kNbins || bin_piece_[o] != bin_piece_[k]) return end;
        return 0.5 * (bin_edge_[o] + bin_edge_[o + 1]);
    };
    // The piece's ends: where the neighbour is in another piece, the hat is flat up to the edge.
    const double lo_end = bin_edge_[k], hi_end = bin_edge_[k + 1];
    const double lo = neighbour_centre(k - 1, lo_end), hi = neighbour_centre(k + 1, hi_end);
    const bool flat_lo = lo == lo_end, flat_hi = hi == hi_end;
    area = 0;
    for (int side = 0; side < 2; ++side) {
        const double a = side == 0 ? lo : centre, b = side == 0 ? centre : hi;
        for (int i = 0; i < kBinSub; ++i) {
            const double x = a + (b - a) * q.x[i];
            const double phi = side == 0 ? (flat_lo ? 1.0 : (x - lo) / (centre - lo))
                                         : (flat_hi ? 1.0 : (hi - x) / (hi - centre));
            mu[side * kBinSub + i] = x;
            weight[side * kBinSub + i] = q.w[i] * (b - a) * phi * 2 * x;
            area += weight[side * kBinSub + i];
        }
    }
    for (double& w : weight)
        w = area > 0 ? w / area : 0.0;
}

/// The light arriving at cosine μ on the outer side of an interface (the coat from outside: α0,
/// η0; the bottom from below: α1, η_s) that it lets into each inside bin, per unit flux: energy
/// v[k] and forward moment v[kNbins + k], the flux-weighted cosine of the refracted light's
/// horizontal direction against the incident light's. Rough: by its visible normals (weight
/// (1 − F) G_t/G1, Walter et al. 2007, Eq. 21), the orders ≥ 2 (ΔT) cosine-distributed.
inline Bsdf::BinMoments Bsdf::refracted_into_bins(double alpha, double eta, const FgdView& fgd,
                                                  double mu) const {
    BinMoments out;
    const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-4));
    auto deposit = [&](const Vec3& wt, double weight) {
        const Hat h = hat_of(-wt.z);
        const double s = std::hypot(wt.x, wt.y), c = s > 0 ? -wt.x / s : 1.0;
        out.v[h.k0] += weight * h.w0;
        out.v[kNbins + h.k0] += weight * h.w0 * c;
        out.v[h.k1] += weight * h.w1;
        out.v[kNbins + h.k1] += weight * h.w1 * c;
    };
    if (alpha == 0) {
        const auto wt = refract(w, Vec3(0, 0, 1), eta);
        if (wt && wt->z < 0) deposit(*wt, 1 - fresnel_dielectric(w.z, eta));
        return out;
    }
    const GGX ggx{alpha};
    const double lambda_w = ggx.lambda(w);
    for_visible_normals<kBinNr, kBinNphi>(ggx, w, [&](const Vec3& wm, double w_r) {
        const auto wt = refract(w, wm, eta);
        if (!wt || wt->z >= 0) return;
        const double F = fresnel_dielectric(dot(w, wm), eta);
        deposit(*wt, w_r * (1 - F) * refraction_escape(ch_.masking, lambda_w, ggx.lambda(*wt)));
    });
    if (ms_) {
        const double dT = ms_dielectric(fgd, mu, alpha, eta).transmitted;
        for (int k = 0; k < kNbins; ++k)
            out.v[k] += dT * bin_area_[k];
    }
    return out;
}

/// The slab's inter-reflections with the inside light in cosine bins (slab-orders=bins; lamina's
/// docs/models.md, lamina-1, item 6): the radiance in each bin's hat and its forward moment (the
/// azimuthal Fourier orders 0 and 1 about the incident light's horizontal direction; each
/// isotropic interface maps each order of each bin to the same order of every bin) through the
/// coat's and the bottom's reflection from inside (R_m, m = 0, 1), the medium's attenuation per
/// bin, summed over every round trip: D = (I − a R_c a R_b)⁻¹ a R_c P₁ C arriving at the bottom,
/// P₁ = a R_b a. Radiance L_k = Φ_k/(π A_k) in bin k leaves towards wo as L_k C_k(μo)/η² by
/// reciprocity of the interface's BTDF (C_k: the light from outside at μo that it lets into bin
/// k). The first orders (the bottom's first transmission E_1, the first reflection out through
/// the coat) are the first-order lobes'; the bins keep what those lobes leave out, and the later
/// transmission takes what is left of the bins' light.
inline void Bsdf::slab_bins() {
    const double mu_c = std::sqrt(1 - sqr(inv_eta0_));
    const double mu_crit_b = eta_b_ < 1 ? std::sqrt(1 - sqr(eta_b_)) : 0.0;
    // The edges: the critical cosines, and uniform in μ² between them (equal flux for uniform
    // radiance).
    std::vector<double> cuts{0.0, 1.0};
    for (double c : {mu_c, mu_crit_b})
        if (c > 1e-6 && c < 1 - 1e-6 && std::none_of(cuts.begin(), cuts.end(), [&](double x) {
                return std::abs(x - c) < 1e-6;
            }))
            cuts.push_back(c);
    std::sort(cuts.begin(), cuts.end());
    const int pieces = int(cuts.size()) - 1, per = kNbins / pieces;
    for (int p = 0, k = 0; p < pieces; ++p)
        for (int i = 0; i < per; ++i, ++k) {
            // In μ², crowding towards a critical cut from either side as t² does: above it, the
            // bins' images outside are then uniform in the outside cosine (grazing directions
            // as finely as the others).
            const double t = double(i) / per;
            const bool up = p > 0, down = p + 1 < pieces;
            const double x = up && down ? (t < 0.5 ? 2 * t * t : 1 - 2 * sqr(1 - t))
                             : up       ? t * t
                             : down     ? 1 - sqr(1 - t)
                                        : t;
            bin_edge_[k] = std::sqrt(sqr(cuts[p]) + (sqr(cuts[p + 1]) - sqr(cuts[p])) * x);
        }
    bin_edge_[kNbins] = 1;
    for (int k = 0; k < kNbins; ++k)
        bin_piece_[k] = k / per;
    // Each bin's rule over its hat (sub-directions and their weights) and its area A_k.
    std::array<std::array<double, 2 * kBinSub>, kNbins> sub_mu, sub_w;
    for (int k = 0; k < kNbins; ++k)
        hat_rule(k, sub_mu[k], sub_w[k], bin_area_[k]);
    const std::array<double, kNbins>& A = bin_area_;
    constexpr int kSub = 2 * kBinSub;

    // The entry curves: from outside through the coat, from below through the bottom, in
    // segments between the outer cosines that a smooth interface refracts onto the bins' edges and
    // centres (a smooth or nearly smooth interface's curves bend there).
    auto cuts_of = [&](double eta) {
        std::vector<double> outer{0.0, 1.0}, inside(bin_edge_.begin(), bin_edge_.end());
        for (int k = 0; k < kNbins; ++k)
            inside.push_back(0.5 * (bin_edge_[k] + bin_edge_[k + 1]));
        for (double e : inside) {
            const double s2 = sqr(eta) * (1 - e * e);
            if (s2 < 1) {
                const double mu = std::sqrt(1 - s2);
                if (mu > 1e-6 && mu < 1 - 1e-6) outer.push_back(mu);
            }
        }
        std::sort(outer.begin(), outer.end());
        outer.erase(std::unique(outer.begin(), outer.end(),
                                [](double x, double y) { return std::abs(x - y) < 1e-9; }),
                    outer.end());
        return outer;
    };
    coat_bins_.fill(cuts_of(eta0_),
                    [&](double mu) { return refracted_into_bins(alpha0_, eta0_, fgd_top_, mu); });
    bottom_bins_.fill(cuts_of(eta_s_), [&](double mu) {
        return refracted_into_bins(alpha1_, eta_s_, fgd_bottom_, mu);
    });
    // Their exits: the fraction of the flux in bin k an interface lets out, by reciprocity
    // (2/(A_k η²)) ∫ C_k(μ) μ dμ, integrated segment by segment as eval reads the curves; the
    // targets (the interfaces' own, below).
    std::array<double, kNbins> tau_c{}, tau_b{};
    auto exit_fractions = [&](const SegmentCurve<BinMoments, kBinPer>& curve, double eta,
                              std::array<double, kNbins>& tau) {
        for (std::size_t g = 0; g + 1 < curve.cut.size(); ++g) {
            const BinMoments sum = integrate_range<BinMoments>(
                [&](double mu) { return curve(mu) * (2 * mu); }, curve.cut[g], curve.cut[g + 1]);
            for (int k = 0; k < kNbins; ++k)
                tau[k] += sum.v[k] / (A[k] * sqr(eta));
        }
    };

    // The interfaces' reflection from inside between bins, orders m = 0, 1: the flux of bin k
    // (its hat, 2 kBinSub directions) reflected into bin j; rough: visible normals (weight
    // F G2/G1), the orders ≥ 2 (ΔR) cosine-distributed. Then made reciprocal: R_jk A_k = R_kj A_j.
    auto reflection = [&](double alpha, double eta, const auto& fgd, FluxMatrix R[2]) {
        R[0] = FluxMatrix(kNbins);
        R[1] = FluxMatrix(kNbins);
        const GGX ggx{alpha};
        for (int k = 0; k < kNbins; ++k)
            for (int s = 0; s < kSub; ++s) {
                const double mu = sub_mu[k][s], ws = sub_w[k][s];
                const Vec3 w(safe_sqrt(1 - mu * mu), 0, mu);
                auto deposit = [&](double mu_out, double weight, double c) {
                    const Hat h = hat_of(mu_out);
                    R[0](h.k0, k) += weight * h.w0;
                    R[1](h.k0, k) += weight * h.w0 * c;
                    R[0](h.k1, k) += weight * h.w1;
                    R[1](h.k1, k) += weight * h.w1 * c;
                };
                if (alpha == 0) {
                    deposit(mu, ws * fresnel_dielectric(mu, eta), 1.0);
                } else {
                    const double lambda_w = ggx.lambda(w);
                    for_visible_normals<kBinNr, kBinNphi>(ggx, w, [&](const Vec3& wm, double w_r) {
                        const Vec3 w2 = reflect(w, wm);
                        if (w2.z <= 0) return;
                        const double weight = ws * w_r * fresnel_dielectric(dot(w, wm), eta) *
                                              reflection_escape(lambda_w, ggx.lambda(w2));
                        const double sxy = std::hypot(w2.x, w2.y);
                        deposit(w2.z, weight, sxy > 0 ? -w2.x / sxy : 1.0);
                    });
                    if (ms_) {
                        const double dR = ms_dielectric(fgd, mu, alpha, eta).reflected;
                        for (int j = 0; j < kNbins; ++j)
                            R[0](j, k) += ws * dR * A[j];
                    }
                }
            }
    };
    auto bin_mean = [&](int k, auto&& f) {
        double sum = 0;
        for (int s = 0; s < kSub; ++s)
            sum += sub_w[k][s] * f(sub_mu[k][s]);
        return sum;
    };
    // The bins' exits: each bin lets out the fraction T̄_k of the interface's transmittance from
    // inside (T_in), flux-averaged over the bin, and the coat lets in T(μ) from outside in all
    // (what the coat's own reflection leaves). The coat's entry curve is scaled to both in turn
    // (the rule is within a few per cent of either; scaling a column of bins and a row of outside
    // cosines alternately converges as matrix balancing does), last to the rows: the light that
    // enters is then T(μ) exactly, and each bin's exit is taken as the curve lets it out. The
    // bottom's curve is scaled to its exits. The same curves let the light in and out
    // (reciprocity).
    for (int k = 0; k < kNbins; ++k) {
        tau_c[k] = bin_mean(k, [&](double mu) { return T_top_in_(mu); });
        tau_b[k] = bin_mean(k, [&](double mu) { return T_bot_in_(mu); });
    }
    auto scale_bins = [&](SegmentCurve<BinMoments, kBinPer>& curve, double eta,
                          const std::array<double, kNbins>& target) {
        std::array<double, kNbins> now{};
        exit_fractions(curve, eta, now);
        for (BinMoments& node : curve.v)
            for (int k = 0; k < kNbins; ++k) {
                const double f = now[k] > 0 ? target[k] / now[k] : 0.0;
                node.v[k] *= f;
                node.v[kNbins + k] *= f;
            }
    };
    for (int round = 0; round < 8; ++round) {
        scale_bins(coat_bins_, eta0_, tau_c);
        const int n = int(coat_bins_.cut.size()) - 1;
        for (int g = 0; g < n; ++g)
            for (int i = 0; i < kBinPer; ++i) {
                const double mu = coat_bins_.node(g, i);
                BinMoments& node = coat_bins_.v[std::size_t(g) * kBinPer + i];
                double sum = 0;
                for (int k = 0; k < kNbins; ++k)
                    sum += node.v[k];
                if (sum > 0) node = node * (T_top_(mu) / sum);
            }
    }
    scale_bins(bottom_bins_, eta_s_, tau_b);
    tau_c.fill(0.0);
    tau_b.fill(0.0);
    exit_fractions(coat_bins_, eta0_, tau_c);
    exit_fractions(bottom_bins_, eta_s_, tau_b);

    // Each bin's reflectance from inside: with the microsurfaces' orders ≥ 2 a clear interface
    // loses nothing, R̄_k = 1 − T̄_k with the exit just taken (the tables' reflectance and
    // transmittance, interpolated apart, add up to 1.05 in a bin by the critical cosine of a
    // nearly smooth coat, which the round trips between the interfaces amplify); with single
    // scattering the tables' reflectance flux-averaged over the bin, at most 1 − T̄_k. The rule
    // above gives where it goes; made reciprocal (S_jk = R_jk A_k symmetric) and scaled to R̄_k
    // as D S D, x_k (S x)_k = R̄_k A_k, by the symmetric form of matrix balancing (x ← √(x R̄ A /
    // S x), which converges for a nonnegative symmetric S with a positive diagonal): both hold
    // exactly, so a bin's light is conserved at every bounce.
    auto balance = [&](FluxMatrix R[2], const std::array<double, kNbins>& tau, auto&& reflectance) {
        std::array<double, kNbins> target{}, x{};
        for (int k = 0; k < kNbins; ++k) {
            const double R_max = std::max(0.0, 1 - tau[k]);
            target[k] = (ms_ ? R_max : std::min(R_max, bin_mean(k, reflectance))) * A[k];
            x[k] = 1;
        }
        for (FluxMatrix* m : {&R[0], &R[1]})
            for (int j = 0; j < kNbins; ++j)
                for (int k = j; k < kNbins; ++k) {
                    const double sym = 0.5 * ((*m)(j, k) * A[k] + (*m)(k, j) * A[j]);
                    (*m)(j, k) = (*m)(k, j) = sym;  // S, symmetric
                }
        for (int round = 0; round < 500; ++round) {
            double worst = 0;
            for (int k = 0; k < kNbins; ++k) {
                double Sx = 0;
                for (int j = 0; j < kNbins; ++j)
                    Sx += R[0](k, j) * x[j];
                if (!(Sx > 0)) continue;
                worst =
                    std::max(worst, std::abs(x[k] * Sx - target[k]) / std::max(target[k], 1e-300));
                x[k] = std::sqrt(x[k] * target[k] / Sx);
            }
            if (worst < 1e-13) break;
        }
        for (FluxMatrix* m : {&R[0], &R[1]})
            for (int j = 0; j < kNbins; ++j)
                for (int k = 0; k < kNbins; ++k)
                    (*m)(j, k) *= x[j] * x[k] / A[k];
    };
    FluxMatrix Rc[2], Rb[2];
    reflection(alpha0_, inv_eta0_, fgd_top_in_, Rc);
    reflection(alpha1_, eta_b_, fgd_base_in_, Rb);
    balance(Rc, tau_c, [&](double mu) { return inside_reflectance(mu); });
    balance(Rb, tau_b, [&](double mu) { return base_albedo(mu)[0]; });

    // Per channel and order: the attenuation a of a crossing per bin; the path from the entry
    // (arriving at the bottom) to the coat after the bottom's first reflection, P₁ = a R_b a, and
    // after every later round trip, P₂ = a R_b S a R_c P₁ with S = (I − a R_c a R_b)⁻¹; D = S a R_c
    // P₁ arrives at the bottom. P₁ and P₂ are palindromes of reciprocal factors, so W P is
    // symmetric (W = 1/(π A_j η0²)): the reflection C(μo)ᵀ W P C(μi) is reciprocal.
    auto product = [](const FluxMatrix& x, const FluxMatrix& y) { return x * y; };
    std::array<std::vector<double>, 3> att;
    std::array<std::array<FluxMatrix, 2>, 3> P1, P2, Dop;
    for (int c = 0; c < 3; ++c) {
        att[c].assign(kNbins, 0.0);
        for (int k = 0; k < kNbins; ++k)
            for (int s = 0; s < kSub; ++s)
                att[c][k] += sub_w[k][s] * attenuation(sub_mu[k][s])[c];
        const FluxMatrix a = FluxMatrix::diagonal(att[c]);
        for (int m = 0; m < 2; ++m) {
            P1[c][m] = product(a, product(Rb[m], a));
            const FluxMatrix a_Rc = product(a, Rc[m]);
            const FluxMatrix S =
                inverse(FluxMatrix::identity(kNbins) - product(a_Rc, product(a, Rb[m])));
            Dop[c][m] = product(S, product(a_Rc, P1[c][m]));
            P2[c][m] = product(a, product(Rb[m], Dop[c][m]));
            for (int j = 0; j < kNbins; ++j)
                for (int k = 0; k < kNbins; ++k) {
                    const double w = 1 / (kPi * A[j] * sqr(eta0_));
                    bins_first_[c][m][j * kNbins + k] = w * P1[c][m](j, k);
                    bins_later_[c][m][j * kNbins + k] = w * P2[c][m](j, k);
                }
        }
    }
    auto times = [](const FluxMatrix& R, const BinMoments& v, int m) {
        std::array<double, kNbins> out{};
        for (int j = 0; j < kNbins; ++j)
            for (int k = 0; k < kNbins; ++k)
                out[j] += R(j, k) * v.v[m * kNbins + k];
        return out;
    };
    // The first-order lobes against the bins' first exits, per incidence (kNslab cosines): the
    // reflected lobe carries E_lobe of the E_acc the bins let out through the coat after the
    // bottom's first reflection; the bins carry the rest, the part f = (E_acc − E_lobe)/E_acc (the
    // light a rough coat spreads beyond the cones, which the lobe about the macro directions
    // leaves out), reciprocally as √(f(μi) f(μo)). The transmitted lobe carries E_1 of the bins'
    // first transmission E1_bins (the rest f_T leaves with the bins). What these leave unbalanced
    // is the later transmission's: it is scaled to let out exactly the rest of the light that the
    // bins hold (s), so that the slab keeps the bins' energy.
    std::array<BinMoments, kNslab> entries;
    std::array<Rgb, kNslab> E_lobes, E_1s;
    for (int i = 0; i < kNslab; ++i) {
        const double mu = sqr(double(i) / (kNslab - 1));
        entries[i] = coat_entry(mu);
        if (bottom_lobe_)
            E_1s[i] =
                nonnegative(first_order_.v[i].v[0] + first_order_smooth(mu, inside_cos(mu)).v[1]);
        E_lobes[i] = first_order_energy(mu);
        for (int c = 0; c < 3; ++c) {
            const std::array<double, kNbins> u1 = times(P1[c][0], entries[i], 0);
            double E_acc = 0;
            for (int k = 0; k < kNbins; ++k)
                E_acc += tau_c[k] * u1[k];
            bins_g_.v[i][c] =
                E_acc > 0 ? std::sqrt(std::max(0.0, E_acc - E_lobes[i][c]) / E_acc) : 0.0;
        }
    }
    // γ_j = (2/(A_j η0²)) ∫ g(μ) C_j(μ) μ dμ: bin j's first exit through the coat with g.
    std::array<Rgb, kNbins> gamma{};
    for (std::size_t g = 0; g + 1 < coat_bins_.cut.size(); ++g)
        for (int c = 0; c < 3; ++c) {
            const BinMoments sum = integrate_range<BinMoments>(
                [&](double mu) { return coat_bins_(mu) * (2 * mu * bins_g_(mu)[c]); },
                coat_bins_.cut[g], coat_bins_.cut[g + 1]);
            for (int j = 0; j < kNbins; ++j)
                gamma[j][c] += sum.v[j] / (A[j] * sqr(eta0_));
        }
    for (int i = 0; i < kNslab; ++i) {
        const BinMoments& C = entries[i];
        Multi<Rgb, 2 * kNbins + 2>& down = bins_down_.v[i];
        for (int c = 0; c < 3; ++c) {
            const std::array<double, kNbins> u1 = times(P1[c][0], C, 0);
            const std::array<double, kNbins> U2 = times(P2[c][0], C, 0);
            const std::array<double, kNbins> D = times(Dop[c][0], C, 0);
            double E1_bins = 0, E_acc = 0, E_first = 0, E_R_later = 0, E_T_later = 0;
            for (int k = 0; k < kNbins; ++k) {
                E1_bins += tau_b[k] * att[c][k] * C.v[k];
                E_acc += tau_c[k] * u1[k];
                E_first += gamma[k][c] * u1[k];
                E_R_later += tau_c[k] * U2[k];
                E_T_later += tau_b[k] * D[k];
            }
            E_first *= bins_g_.v[i][c];
            const double extra_T = bottom_lobe_ ? E1_bins - E_1s[i][c] : 0.0;
            const double f_T = extra_T > 0 && E1_bins > 0 ? extra_T / E1_bins : 0.0;
            // What the bins hold beyond what leaves elsewhere, left to the later transmission.
            // Without the bottom's own lobe (an index-matched bottom, or btdf-lobe off) the first
            // transmission is the mirrored lobe's (eval_btdf), which carries the bins' first
            // exit E1_bins itself: none of it is left (counted there and here, a matched bottom
            // transmitted 1.8 of the light).
            const double first_rest = bottom_lobe_ ? E1_bins - E_1s[i][c] - f_T * E1_bins : 0.0;
            const double rest = first_rest + (E_acc - E_lobes[i][c] - E_first) + E_T_later;
            const double s = E_T_later > 0 ? std::max(0.0, rest / E_T_later) : 1.0;
            for (int m = 0; m < 2; ++m) {
                const std::array<double, kNbins> Dm = times(Dop[c][m], C, m);
                for (int k = 0; k < kNbins; ++k)
                    down.v[m * kNbins + k][c] =
                        (s * Dm[k] + f_T * att[c][k] * C.v[m * kNbins + k]) /
                        (kPi * A[k] * sqr(eta_s_));
            }
            down.v[2 * kNbins][c] = E_first + E_R_later;
            down.v[2 * kNbins + 1][c] = f_T * E1_bins + s * E_T_later;
        }
    }
    bins_ready_ = true;
}

/// The light from outside at μ the coat lets into each bin (energy, forward moment), as
/// scaled in slab_bins: by reciprocity also how the bins' light leaves through the coat.
inline Bsdf::BinMoments Bsdf::coat_entry(double mu) const {
    return coat_bins_(mu);
}

/// The same for the bottom, from below at μ.
inline Bsdf::BinMoments Bsdf::bottom_exit(double mu) const {
    return bottom_bins_(mu);
}

/// The cosine of the angle between wo's horizontal direction and that of the light arriving
/// from wi (0 where either is vertical).
inline double forward_cosine(const Vec3& wi, const Vec3& wo) {
    const double si = std::hypot(wi.x, wi.y), so = std::hypot(wo.x, wo.y);
    if (!(si > 0 && so > 0)) return 0;
    return -(wi.x * wo.x + wi.y * wo.y) / (si * so);
}

/// The bins' light leaving towards wo at forward cosine c: per channel the azimuthal average f0
/// (order 0) and the first order f1, which a truncated series f0 + 2 f1 c would make negative
/// behind strongly forward light (by 15 % of the energy at θi = 70° over a nearly smooth bottom).
/// The Poisson kernel f0 (1 − ρ²)/(1 − 2ρc + ρ²), ρ = f1/f0, has the same two orders, is positive,
/// and continues them as ρ^m (a wrapped Cauchy distribution in azimuth).
inline Rgb binned_exit(const Rgb& f0, const Rgb& f1, double c) {
    Rgb f(0.0);
    for (int ch = 0; ch < 3; ++ch) {
        if (!(f0[ch] > 0)) continue;
        const double rho = clamp(f1[ch] / f0[ch], -0.98, 0.98);
        f[ch] = f0[ch] * (1 - rho * rho) / (1 - 2 * rho * c + rho * rho);
    }
    return f;
}

/// The bins' reflection C(μo)ᵀ W (g(μo) P₁ g(μi) + P₂) C(μi) (slab_bins), its Fourier orders
/// 0 and 1 through the Poisson kernel.
inline Rgb Bsdf::bins_reflection(const Incident& in, const Vec3& wo) const {
    const BinMoments C = coat_entry(wo.z);
    const Rgb g = bins_g_(wo.z);
    Rgb f0(0.0), f1(0.0);
    for (int k = 0; k < kNbins; ++k) {
        f0 += (in.bins.v[k] * g + in.bins.v[2 * kNbins + k]) * C.v[k];
        f1 += (in.bins.v[kNbins + k] * g + in.bins.v[3 * kNbins + k]) * C.v[kNbins + k];
    }
    return binned_exit(f0, f1, forward_cosine(in.wi, wo));
}

inline Rgb Bsdf::bins_transmission(const Incident& in, const Vec3& wo) const {
    const BinMoments B = bottom_exit(-wo.z);
    Rgb f0(0.0), f1(0.0);
    for (int k = 0; k < kNbins; ++k) {
        f0 += in.bins.v[4 * kNbins + k] * B.v[k];
        f1 += in.bins.v[5 * kNbins + k] * B.v[kNbins + k];
    }
    return binned_exit(f0, f1, forward_cosine(in.wi, wo));
}

/// Incident::bins: g(μi) W P₁ C(μi) and W P₂ C(μi) (both orders), the light arriving at the
/// bottom, and the energies let out.
inline void Bsdf::incident_bins(Incident& in) const {
    const BinMoments C = coat_entry(in.wi.z);
    const Rgb g = bins_g_(in.wi.z);
    const int channels = has_absorption_ ? 3 : 1;
    for (int c = 0; c < channels; ++c)
        for (int m = 0; m < 2; ++m)
            for (int j = 0; j < kNbins; ++j) {
                const double* first = &bins_first_[c][m][j * kNbins];
                const double* later = &bins_later_[c][m][j * kNbins];
                double x = 0, y = 0;
                for (int k = 0; k < kNbins; ++k) {
                    x += first[k] * C.v[m * kNbins + k];
                    y += later[k] * C.v[m * kNbins + k];
                }
                in.bins.v[m * kNbins + j][c] = g[c] * x;
                in.bins.v[(2 + m) * kNbins + j][c] = y;
            }
    if (channels == 1)
        for (int k = 0; k < 4 * kNbins; ++k)
            in.bins.v[k] = Rgb(in.bins.v[k][0]);
    const Multi<Rgb, 2 * kNbins + 2> down = bins_down_(in.wi.z);
    for (int k = 0; k < 2 * kNbins; ++k)
        in.bins.v[4 * kNbins + k] = down.v[k];
    in.bins.v[6 * kNbins] = nonnegative(down.v[2 * kNbins]);
    in.bins.v[6 * kNbins + 1] = nonnegative(down.v[2 * kNbins + 1]);
}

}  // namespace lamina1

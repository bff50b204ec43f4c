#pragma once
// lamina-1's slab under polarized light (Options::polarization; lamina's docs/models.md,
// lamina-1, "Polarization"). Light arrives unpolarized, but every Fresnel event weighs its s and p
// parts differently, so the light inside a dielectric slab is partly polarized and the next event
// sees it so: a smooth plate of η 1.5 reflects 0.152 at 60°, where averaging the two
// reflectances at every bounce gives 0.164 (lamina's docs/physics.md §8). A conductor under a
// coat changes by under 1 % and a Lambertian base depolarizes what it reflects, so only a slab
// carries this.
//
// The light's state is kept as its first two Stokes parameters (S0, S1) in the plane of incidence
// of its direction on the macro surface, and each interface event as the 2 × 2 block of its
// Mueller matrix on them: for one facet of cosine c to the light, reflectances R_s, R_p (or the
// transmittances 1 − R), a = (R_s + R_p)/2 and b = (R_s − R_p)/2 (Born & Wolf, Principles of
// Optics, §1.5.2), between rotations from the macro planes of incidence of the arriving and the
// leaving direction into the facet's own plane (cos 2ψ_in, cos 2ψ_out; the rotation of a Stokes
// vector's frame, Chandrasekhar, Radiative Transfer, §15):
//
//     [ a              b cos 2ψ_in            ]
//     [ b cos 2ψ_out   a cos 2ψ_in cos 2ψ_out ],
//
// averaged over the normals visible from the arriving direction with the single-scattering
// escape of the leaving one (S2 and S3, which the rotations and a conductor's phase feed, average
// out of (S0, S1) for an isotropic interface). A smooth interface has ψ = 0 and this block is
// exact; a rough one turns part of S1 away, which is how roughness depolarizes. The slab is then
// the series of its events along the macro directions: entering through the coat (averaged per
// facet, with each facet's own inside direction), the bottom's reflection and the coat's from
// inside repeated, and the exit through the coat from inside or through the bottom:
//
//     R = a² T_out (I − a² R_b R_in)⁻¹ R_b T_entry,   T = a T_b (I − a² R_in R_b)⁻¹ T_entry,
//
// their (S0 ← S0) elements for unpolarized light, a the Beer–Lambert factor of one crossing. The
// same series with each block depolarized (b = 0) is the per-bounce average every unpolarized
// model computes; their differences ΔR and ΔT are what polarization changes. lamina-1 keeps its
// own slab for everything else and adds these differences to its own energies of that light
// (R_body beyond the coat's own reflection, and T), as the factors k_R = 1 + ΔR/R_body and
// k_T = 1 + ΔT/T: √(k_R(μi) k_R(μo)) on the reflection (reciprocal, and exact on the mirror
// direction) and k_T(μi) on the transmission. Differences, not the series' own ratios: the series
// follows each facet's light along its inside direction and misses what a rough interface turns
// into the other's exit cone (most of a rough coat's light at grazing incidence, over a smooth
// bottom), light those turns depolarize; the differences leave it as it is. For two smooth
// interfaces this is the exact polarized series.

#include "lamina1/curves.h"
#include "lamina1/physics.h"
#include "lamina1/quadrature.h"

namespace lamina1 {

/// The (S0, S1) block of a Mueller matrix, row-major: S0' = m00 S0 + m01 S1, S1' = m10 S0 + m11 S1.
struct StokesBlock {
    double m00 = 0, m01 = 0, m10 = 0, m11 = 0;

    StokesBlock& operator+=(const StokesBlock& o) {
        m00 += o.m00, m01 += o.m01, m10 += o.m10, m11 += o.m11;
        return *this;
    }
    StokesBlock operator+(const StokesBlock& o) const { return StokesBlock(*this) += o; }
    StokesBlock operator*(double s) const { return {m00 * s, m01 * s, m10 * s, m11 * s}; }
    StokesBlock operator*(const StokesBlock& o) const {
        return {m00 * o.m00 + m01 * o.m10, m00 * o.m01 + m01 * o.m11, m10 * o.m00 + m11 * o.m10,
                m10 * o.m01 + m11 * o.m11};
    }
    /// The block that keeps only the averaged factor (b = 0): unpolarized light stays so.
    StokesBlock depolarized() const { return {m00, 0, 0, m00}; }
};

/// Σ_n Mⁿ = (I − M)⁻¹ of the round trips M; nothing where it has no finite sum (light trapped
/// between two totally reflecting interfaces without absorption: what lets it out then is not
/// in these blocks).
inline std::optional<StokesBlock> stokes_series(const StokesBlock& M) {
    const double a = 1 - M.m00, b = -M.m01, c = -M.m10, d = 1 - M.m11;
    const double det = a * d - b * c;
    if (!(det > 1e-9) || !(a > 1e-9)) return std::nullopt;
    return StokesBlock{d / det, -b / det, -c / det, a / det};
}

/// An interface's reflection and transmission blocks for one arriving direction.
struct InterfaceBlocks {
    StokesBlock reflected, transmitted;

    InterfaceBlocks& operator+=(const InterfaceBlocks& o) {
        reflected += o.reflected;
        transmitted += o.transmitted;
        return *this;
    }
    InterfaceBlocks operator+(const InterfaceBlocks& o) const {
        return InterfaceBlocks(*this) += o;
    }
    InterfaceBlocks operator*(double s) const { return {reflected * s, transmitted * s}; }
};

/// cos 2ψ between the plane of incidence of v on the macro surface (normal z) and the plane
/// normal to s (a facet's plane of incidence, s = wm × v unnormalized): 2 (ŝ_macro · ŝ)² − 1,
/// with ŝ_macro = z × v / |z × v|. 1 where either plane is undefined (v along the normal, or the
/// facet seen head-on, where s and p coincide).
inline double plane_rotation_cos2(const Vec3& v, const Vec3& s) {
    const double sx = -v.y, sy = v.x;
    const double n_macro = sx * sx + sy * sy, n_facet = dot(s, s);
    if (!(n_macro > 1e-24) || !(n_facet > 1e-24)) return 1.0;
    const double c = sx * s.x + sy * s.y;
    return 2 * c * c / (n_macro * n_facet) - 1;
}

/// Both blocks of one facet wm for the light from w (pointing away from the surface, w.z > 0 on
/// the side where the relative index is eta): the reflected and the refracted light that leaves
/// the microsurface at once (reflection_escape, refraction_escape with `masking`; 1 when the
/// interface is smooth). lambda_w: Λ(w) of ggx. Returns the inside direction of the refracted
/// light too (pointing away on the other side; z = 0 where none).
inline InterfaceBlocks facet_blocks(const GGX& ggx, double eta, Masking masking, const Vec3& w,
                                    double lambda_w, const Vec3& wm, Vec3* refracted = nullptr) {
    InterfaceBlocks out;
    if (refracted) *refracted = Vec3(0, 0, 0);
    const double cos_wm = dot(w, wm);
    if (!(cos_wm > 0)) return out;
    const bool smooth = ggx.alpha == 0;
    const FresnelSp R = fresnel_dielectric_sp(cos_wm, eta);
    const Vec3 s = cross(wm, w);
    const double rot_in = plane_rotation_cos2(w, s);
    const Vec3 wr = reflect(w, wm);
    if (wr.z > 0) {
        const double e = smooth ? 1.0 : reflection_escape(lambda_w, ggx.lambda(wr));
        const double a = 0.5 * (R.s + R.p) * e, b = 0.5 * (R.s - R.p) * e;
        const double rot_out = plane_rotation_cos2(wr, s);
        out.reflected = {a, b * rot_in, b * rot_out, a * rot_in * rot_out};
    }
    if (R.s >= 1 && R.p >= 1) return out;
    const std::optional<Vec3> wt = refract(w, wm, eta);
    if (!wt || !(wt->z < 0)) return out;
    if (refracted) *refracted = *wt;
    const Vec3 wt_up(wt->x, wt->y, -wt->z);
    const double e = smooth ? 1.0 : refraction_escape(masking, lambda_w, ggx.lambda(wt_up));
    const double a = (1 - 0.5 * (R.s + R.p)) * e, b = 0.5 * (R.p - R.s) * e;
    const double rot_out = plane_rotation_cos2(*wt, s);
    out.transmitted = {a, b * rot_in, b * rot_out, a * rot_in * rot_out};
    return out;
}

/// An isotropic interface's blocks for light arriving at cosine μ from the side where the
/// relative index is eta, averaged over the normals visible from it (the split rule of
/// lamina1/quadrature.h: the facets' total internal reflection and the reflected light's horizon
/// are steps).
inline InterfaceBlocks interface_blocks(double alpha, double eta, Masking masking, double mu) {
    const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-6));
    const GGX ggx{alpha};
    if (alpha == 0) return facet_blocks(ggx, eta, masking, w, 0, Vec3(0, 0, 1));
    const double lambda_w = ggx.lambda(w);
    const double mu_critical = eta < 1 ? std::sqrt(1 - eta * eta) : 0.0;
    static const QuadratureRule q = gauss_legendre(kSlabNr);
    return integrate_visible_split<InterfaceBlocks>(
        ggx, w, [&](const Vec3& wm) { return facet_blocks(ggx, eta, masking, w, lambda_w, wm); }, q,
        kSlabNphi, 1.0 / double(1 << kSlabBisections),
        Crossing{[&](const Vec3& wm) { return dot(w, wm); }, mu_critical},
        Crossing{[&](const Vec3& wm) { return reflect(w, wm).z; }, 0.0});
}

/// What polarization changes in a slab's light at one outside cosine, per channel: its light
/// reflected beyond the coat's own reflection and its transmitted light, polarized less
/// depolarized (per unit incident flux).
struct PolarizationChange {
    Rgb reflected{0.0}, transmitted{0.0};
};

/// The slab's blocks along the inside cosine (both interfaces seen from inside the slab), and the
/// series above. coat: η0 (≥ 1) and α0; bottom: η_b = η_below/η_coat and α1; tau: the medium's
/// optical depth along the normal (one crossing at inside cosine μ' keeps exp(−τ/μ')).
class SlabPolarization {
  public:
    static constexpr int kN = 17;  ///< nodes on each side of an interface's critical cosine

    SlabPolarization(double eta0, double alpha0, double eta_b, double alpha1, Masking masking,
                     const Rgb& tau)
        : eta0_(eta0),
          alpha0_(alpha0),
          eta_b_(eta_b),
          alpha1_(alpha1),
          masking_(masking),
          tau_(tau) {
        const double inv_eta0 = 1 / eta0;
        if (alpha0 > 0)
            coat_in_.fill(std::sqrt(std::max(1 - inv_eta0 * inv_eta0, 0.0)), [&](double mu) {
                return interface_blocks(alpha0, inv_eta0, masking, mu);
            });
        if (alpha1 > 0)
            bottom_in_.fill(eta_b < 1 ? std::sqrt(1 - eta_b * eta_b) : 0.0, [&](double mu) {
                return interface_blocks(alpha1, eta_b, masking, mu);
            });
        grey_ = tau[0] == tau[1] && tau[1] == tau[2];
    }

    /// The change for light arriving from outside at cosine μ (μ > 0).
    PolarizationChange change(double mu) const {
        const Vec3 w(safe_sqrt(1 - mu * mu), 0, std::max(mu, 1e-6));
        const GGX ggx{alpha0_};
        Multi<Rgb, 4> sum;  // R, R depolarized, T, T depolarized
        auto entry = [&](const Vec3& wm, double lambda_w) {
            Vec3 wt;
            const InterfaceBlocks e = facet_blocks(ggx, eta0_, masking_, w, lambda_w, wm, &wt);
            return wt.z < 0 ? inside(e.transmitted, -wt.z) : Multi<Rgb, 4>{};
        };
        if (alpha0_ == 0) {
            sum = entry(Vec3(0, 0, 1), 0);
        } else {
            const double lambda_w = ggx.lambda(w);
            static const QuadratureRule q = gauss_legendre(kSlabNr);
            // The inside light steps where it crosses the coat's critical cosine (beyond it,
            // it is trapped by the coat's total internal reflection).
            auto inside_cos = [&](const Vec3& wm) {
                const std::optional<Vec3> wt = refract(w, wm, eta0_);
                return wt ? -wt->z : 0.0;
            };
            sum = integrate_visible_split<Multi<Rgb, 4>>(
                ggx, w, [&](const Vec3& wm) { return entry(wm, lambda_w); }, q, kSlabNphi,
                1.0 / double(1 << kSlabBisections),
                Crossing{inside_cos, std::sqrt(1 - 1 / (eta0_ * eta0_))});
        }
        return {sum.v[0] - sum.v[1], sum.v[2] - sum.v[3]};
    }

  private:
    /// The light a facet lets in with the block `entry` at inside cosine μ', through the series:
    /// R, R depolarized, T, T depolarized per channel.
    Multi<Rgb, 4> inside(const StokesBlock& entry, double mu_in) const {
        Multi<Rgb, 4> out;
        // A smooth interface's blocks are Fresnel's at μ' itself (exact; no curve).
        const InterfaceBlocks coat =
            alpha0_ == 0 ? interface_blocks(0, 1 / eta0_, masking_, mu_in) : coat_in_(mu_in);
        const InterfaceBlocks bottom =
            alpha1_ == 0 ? interface_blocks(0, eta_b_, masking_, mu_in) : bottom_in_(mu_in);
        for (int c = 0; c < (grey_ ? 1 : 3); ++c) {
            const double a = std::exp(-tau_[c] / mu_in), a2 = a * a;
            for (int depolarized = 0; depolarized < 2; ++depolarized) {
                auto block = [&](const StokesBlock& m) {
                    return depolarized ? m.depolarized() : m;
                };
                const StokesBlock T_entry = block(entry), R_in = block(coat.reflected),
                                  T_out = block(coat.transmitted), R_b = block(bottom.reflected),
                                  T_b = block(bottom.transmitted);
                const std::optional<StokesBlock> up = stokes_series(R_b * R_in * a2),
                                                 down = stokes_series(R_in * R_b * a2);
                // Trapped light (both interfaces totally reflecting, no absorption) is left out
                // of both forms alike.
                if (!up || !down) return Multi<Rgb, 4>{};
                out.v[depolarized][c] = a2 * (T_out * *up * R_b * T_entry).m00;
                out.v[2 + depolarized][c] = a * (T_b * *down * T_entry).m00;
            }
        }
        if (grey_)
            for (auto& v : out.v)
                v = Rgb(v[0]);
        return out;
    }

    double eta0_, alpha0_, eta_b_, alpha1_;
    Masking masking_;
    Rgb tau_;
    SplitCurve<kN, InterfaceBlocks, true> coat_in_, bottom_in_;
    bool grey_ = true;
};

}  // namespace lamina1

// The GGX (Trowbridge–Reitz) microfacet distribution as a value type.
//
// Local frame, z = macro-surface normal. α is the GGX roughness itself (no remapping), α > 0 (α =
// 0, a smooth interface, is handled by the interfaces as a delta lobe). The distribution may be
// anisotropic: α_x along the interface's tangent t = (cos ψ, sin ψ, 0) and α_y along its bitangent
// b = (−sin ψ, cos ψ, 0) (GgxAnisotropy). Every formula below is written once for that general
// case; an isotropic distribution (α_x = α_y, `GgxAnisotropy::on` false) is its instance, whose
// terms in α_y − α_x vanish and are skipped (one flag for all lanes), so that it is computed with
// exactly the operations of the isotropic formulas.
// Microfacet normals wm lie in the upper hemisphere. A direction w below the surface (w.z < 0)
// sees the same microsurface from below: its visible normals are those with w·wm < 0, and every
// function below treats such w through −w (the microsurface is point-symmetric).

#include "core/beta_function.h"
#include "core/lane.h"
#include "core/lane_vec.h"
#include "core/math.h"
#include "core/vec.h"
#include "physics/smith_masking.h"
#include "physics/transmission_masking.h"

#include <cmath>
#include <limits>
#include <string>

#ifndef LAMINA_PHYSICS_GGX_ANISOTROPY_H
#define LAMINA_PHYSICS_GGX_ANISOTROPY_H
namespace lamina {
/// The anisotropy of a GGX distribution whose `alpha` is α_x: α_y along the bitangent and the
/// tangent's direction (cos ψ, sin ψ, 0) in the interface's frame (ψ the tangent's angle from +x).
/// The default is isotropic. Defined once, outside the lane templates' namespaces.
template <typename T>
struct GgxAnisotropy {
    T alpha_y = 0;  ///< α along the bitangent; read only when `on`
    T tangent_cos = 1, tangent_sin = 0;
    bool on = false;  ///< α_y ≠ α_x

    /// α_x, α_y and the tangent angle psi (radians); `on` exactly when α_y ≠ α_x.
    static GgxAnisotropy make(T alpha_x, T alpha_y, double psi) {
        return {alpha_y, T(std::cos(psi)), T(std::sin(psi)), alpha_y != alpha_x};
    }
    bool operator==(const GgxAnisotropy&) const = default;
};
}  // namespace lamina
#endif

// A lane header (core/lane.h): its lane templates are included once as an ordinary header and
// once per SIMD target; the GGX type below them only once.
#ifndef LAMINA_LANE_TARGET
#ifndef LAMINA_PHYSICS_MICROFACET_LANES_H
#define LAMINA_PHYSICS_MICROFACET_LANES_H
#define LAMINA_PHYSICS_MICROFACET_BODY
#endif
#elif defined(LAMINA_PHYSICS_MICROFACET_TARGET) == defined(HWY_TARGET_TOGGLE)
#ifdef LAMINA_PHYSICS_MICROFACET_TARGET
#undef LAMINA_PHYSICS_MICROFACET_TARGET
#else
#define LAMINA_PHYSICS_MICROFACET_TARGET
#endif
#define LAMINA_PHYSICS_MICROFACET_BODY
#endif

#ifdef LAMINA_PHYSICS_MICROFACET_BODY
#undef LAMINA_PHYSICS_MICROFACET_BODY

LAMINA_LANE_BEGIN

/// A GGX roughness on lanes (ggx_lanes builds it): α_x along the tangent t, α_y along the
/// bitangent b = ẑ × t = (bx, by, 0). Whether it is anisotropic is a compile-time property
/// (kAnisotropic), so that the isotropic instance of every formula below is compiled as the
/// isotropic formula itself, with none of the anisotropic terms: the anisotropic formulas are
/// written as the isotropic one (α = α_x) plus the terms in α_y − α_x, which vanish at α_x = α_y.
template <typename T, bool kAnisotropic = false>
struct GgxLanes {
    T alpha, alpha2;  ///< α_x and α_x² (the isotropic α and α²)
    T d_alpha;        ///< α_y − α_x (anisotropic only)
    T d_alpha2;       ///< α_y² − α_x² (anisotropic only)
    T bx, by;         ///< the bitangent (−sin ψ, cos ψ) (anisotropic only)
};

/// The lanes of a GGX roughness α_x = alpha, and when kAnisotropic α_y = alpha_y with the tangent
/// (tangent_cos, tangent_sin, 0) (GgxAnisotropy's fields; plain numbers, so that no overload is
/// found by argument-dependent lookup in another lane namespace).
template <typename T, typename L = Lane<T>, bool kAnisotropic = false>
LAMINA_LANE_INLINE GgxLanes<T, kAnisotropic> ggx_lanes(double alpha, double alpha_y,
                                                       double tangent_cos, double tangent_sin) {
    const T alpha_x = L::constant(alpha), zero = L::constant(0);
    GgxLanes<T, kAnisotropic> g{alpha_x, alpha_x * alpha_x, zero, zero, zero, L::constant(1)};
    if constexpr (kAnisotropic) {
        const T a_y = L::constant(alpha_y);
        g.d_alpha = a_y - alpha_x;
        g.d_alpha2 = a_y * a_y - g.alpha2;
        g.bx = L::constant(-tangent_sin);
        g.by = L::constant(tangent_cos);
    }
    return g;
}

/// An isotropic GGX roughness alpha on lanes.
template <typename T, typename L = Lane<T>>
LAMINA_LANE_INLINE GgxLanes<T> ggx_isotropic_lanes(T alpha) {
    const T zero = L::constant(0);
    return {alpha, alpha * alpha, zero, zero, zero, L::constant(1)};
}

/// α(φ)² (x² + y²) for the direction (x, y, ·): the squared roughness projected on the direction's
/// azimuth, α(φ)² = cos²φ_t α_x² + sin²φ_t α_y² with φ_t the azimuth from the tangent (Heitz 2014,
/// "Understanding the masking-shadowing function in microfacet-based BRDFs", JCGT 3(2), the
/// anisotropic distributions of its §5: Λ of the anisotropic GGX is the isotropic one with this
/// α), written α_x² (x² + y²) + (α_y² − α_x²)(b·w)², since sin φ_t √(x² + y²) = b·w.
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE T ggx_projected_alpha2(const GgxLanes<T, kA>& g, T x, T y) {
    const T isotropic = g.alpha2 * (x * x + y * y);
    if constexpr (!kA) {
        return isotropic;
    } else {
        const T bw = L::mul_add(g.bx, x, g.by * y);
        return L::mul_add(g.d_alpha2, bw * bw, isotropic);
    }
}

/// The stretch of the GGX microsurface applied to the horizontal part (x, y) of a direction, from
/// the configuration of α = 1 to that of (α_x, α_y) (Heitz 2018, "Sampling the GGX distribution of
/// visible normals", JCGT 7(4), §3.2 and §3.4, Listing 1: (α_x V_t, α_y V_b, V_z) in the tangent
/// frame), written in the interface's frame: A = α_x I + (α_y − α_x) b bᵀ.
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE void ggx_stretch(const GgxLanes<T, kA>& g, T& x, T& y) {
    if constexpr (!kA) {
        x = g.alpha * x;
        y = g.alpha * y;
    } else {
        const T along_b = g.d_alpha * L::mul_add(g.bx, x, g.by * y);
        x = L::mul_add(along_b, g.bx, g.alpha * x);
        y = L::mul_add(along_b, g.by, g.alpha * y);
    }
}

/// Smith Λ(w) for GGX of roughness g, w = (x, y, z) a unit direction: Heitz 2014, Eq. 72 with the
/// projected roughness α(φ) of ggx_projected_alpha2: Λ = (−1 + √(1 + α(φ)² tan²θ)) / 2, written
/// x/(2(√(1 + x) + 1)) with x = α(φ)² tan²θ (no cancellation for small α). Symmetric in z; +∞ at
/// grazing (z = 0) and wherever α² tan²θ overflows (within a few ulps of grazing, where the formula
/// would give ∞/∞). A branch-free lane template (core/lane.h): GGX::lambda and the SIMD kernel's
/// microsurface walk evaluate it.
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE T ggx_lambda(const GgxLanes<T, kA>& g, T x, T y, T z) {
    const T alpha2_tan2 = ggx_projected_alpha2<T, L>(g, x, y) / (z * z);
    const T lambda =
        alpha2_tan2 / (L::constant(2) * (L::sqrt(L::constant(1) + alpha2_tan2) + L::constant(1)));
    // An infinite α² tan²θ, and NaN (0/0 at z = 0 with α = 0), fail the comparison: Λ = ∞.
    const T infinity = L::constant(HUGE_VAL);
    return L::select(L::less(alpha2_tan2, infinity), lambda, infinity);
}

/// A normal drawn from the distribution of GGX normals visible from the direction w (unit, any
/// side: below the horizon too, see GGX::D_visible_complete) by the spherical caps of Dupuy &
/// Benyoub 2023, "Sound and complete sampling of visible GGX normals with spherical caps", CGF
/// 42(8), Listing 3, from two uniform numbers in [0, 1): warp w to the hemisphere configuration
/// (α = 1), sample the spherical cap z ∈ (−wh.z, 1], take the halfway direction of the cap point
/// and wh, warp back; anisotropic by the stretch of ggx_stretch (Heitz 2018, §3). A branch-free
/// lane template (core/lane.h): GGX::sample_visible_normal_complete and the SIMD kernel evaluate
/// it.
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE LaneVec3<T> ggx_sample_visible_normal_complete(const GgxLanes<T, kA>& g,
                                                                  const LaneVec3<T>& w, T u1,
                                                                  T u2) {
    const T one = L::constant(1);
    // The hemisphere configuration is isotropic (α = 1): the stretched w in the interface's frame
    // (A w) has the visible normals A rotated into that frame, so the tangent frame is never built.
    T wx = w.x, wy = w.y;
    ggx_stretch<T, L>(g, wx, wy);
    const LaneVec3<T> wh = lane_normalize<T, L>({wx, wy, w.z});
    T cos_phi, sin_phi;
    L::cos_sin_2pi(u1, cos_phi, sin_phi);
    const T cap_height = (one - u2) * (one + wh.z);  // z + wh.z, the halfway vector's height
    const T z = cap_height - wh.z;
    const T sin_theta = L::sqrt(L::max(L::neg_mul_add(z, z, one), L::constant(0)));
    T hx = L::mul_add(sin_theta, cos_phi, wh.x), hy = L::mul_add(sin_theta, sin_phi, wh.y);
    // h.z = z + wh.z taken as (1 − u2)(1 + wh.z) itself: the sum cancels at the cap's rim
    // (u2 → 1), where its rounding could leave it ≤ 0 — a horizontal normal, a failed sample —
    // for a cap point strictly above −wh.
    const T hz = cap_height;
    ggx_stretch<T, L>(g, hx, hy);
    return lane_normalize<T, L>({hx, hy, L::max(hz, L::constant(0))});
}

/// |cos θ| √(1 + α(φ)² tan²θ) = √(cos²θ + α(φ)² sin²θ) = |cos θ| (1 + 2Λ(w)) (GGX::smith_root;
/// Heitz 2014, Eq. 72, with the projected roughness of ggx_projected_alpha2) for GGX of roughness
/// g, without a division: zero at grazing, where 1 + 2Λ is infinite. A branch-free lane template
/// (core/lane.h).
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE T ggx_smith_root_times_cos(const GgxLanes<T, kA>& g, const LaneVec3<T>& w) {
    const T isotropic = L::mul_add(g.alpha2, L::mul_add(w.x, w.x, w.y * w.y), w.z * w.z);
    if constexpr (!kA) {
        return L::sqrt(isotropic);
    } else {
        const T bw = L::mul_add(g.bx, w.x, g.by * w.y);
        return L::sqrt(L::mul_add(g.d_alpha2, bw * bw, isotropic));
    }
}

/// The weight G2(wi, wo)/G1(wi) a particle keeps after one facet of a single-scattering rough
/// interface of roughness g sent it from wi to wo (Heitz 2018, §2: visible-normal sampling leaves
/// G2/G1), from
/// the Smith roots (smith_masking.h): `reflected` lanes (wo on wi's side) escape with
/// smith_reflection_escape, refracted ones with smith_refraction_escape (`smith_refraction`,
/// TransmissionMasking::Smith; computed only when some lane of `active` refracts) or, as pbrt-v4,
/// with the reflection form; `uncorrelated`: G1(wo) = 2/(1 + r_o) = 2|z_o|/(|z_o| + s_o) (Heitz
/// 2014, Eq. 98). Zero for a grazing wo. A branch-free lane template (core/lane.h): the
/// interfaces' samplers (dielectric.h, conductor.h) and the SIMD kernel evaluate these lines.
template <typename T, typename L = Lane<T>, bool kA>
LAMINA_LANE_INLINE T ggx_escape_fraction(const GgxLanes<T, kA>& g, const LaneVec3<T>& wi,
                                         const LaneVec3<T>& wo, typename L::Mask reflected,
                                         typename L::Mask active, bool uncorrelated,
                                         bool smith_refraction) {
    const T z_o = L::abs(wo.z);
    const T s_o = ggx_smith_root_times_cos<T, L>(g, wo);
    if (uncorrelated) return L::min((z_o + z_o) / (z_o + s_o), L::constant(1));
    const T z_i = L::abs(wi.z);
    const T s_i = ggx_smith_root_times_cos<T, L>(g, wi);
    const T escape = smith_reflection_escape_scaled<T, L>(z_i, s_i, z_o, s_o);
    const auto refracts = L::both(active, L::negate(reflected));
    if (!smith_refraction || L::none(refracts)) return escape;
    return L::select(refracts, smith_refraction_escape<T, L>(s_i / z_i, s_o / z_o), escape);
}

LAMINA_LANE_END

#endif  // LAMINA_PHYSICS_MICROFACET_BODY

#if !defined(LAMINA_LANE_TARGET) && !defined(LAMINA_PHYSICS_MICROFACET_H)
#define LAMINA_PHYSICS_MICROFACET_H

namespace lamina {

template <typename T>
struct GGX {
    T alpha;  ///< α_x: along the tangent; an isotropic distribution's α
    GgxAnisotropy<T> anisotropy{};

    /// The anisotropic distribution of α_x, α_y with its tangent at psi radians from +x.
    static GGX anisotropic(T alpha_x, T alpha_y, double psi) {
        return {alpha_x, GgxAnisotropy<T>::make(alpha_x, alpha_y, psi)};
    }

    /// The roughness as the lane templates above take it, at one lane. kAnisotropic = false is the
    /// isotropic instance (α_y and the tangent are not read: for an isotropic distribution, or
    /// where the caller knows it is one); true is the general formula, which an isotropic
    /// distribution may take too (its terms in α_y − α_x are then zero).
    template <bool kAnisotropic>
    GgxLanes<T, kAnisotropic> lanes() const {
        if constexpr (kAnisotropic)
            if (!anisotropy.on) return ggx_lanes<T, Lane<T>, true>(alpha, alpha, 1, 0);
        return ggx_lanes<T, Lane<T>, kAnisotropic>(alpha, anisotropy.alpha_y,
                                                   anisotropy.tangent_cos, anisotropy.tangent_sin);
    }
    /// The stretch ggx_stretch of this distribution, applied to (x, y).
    void stretch(T& x, T& y) const {
        if (anisotropy.on) return stretch_anisotropic(x, y);
        ggx_stretch(lanes<false>(), x, y);
    }

    /// Normal distribution D(wm), 1/sr: the anisotropic GGX (Heitz 2014, the anisotropic
    /// distributions of §5) 1 / (π α_x α_y (m_t²/α_x² + m_b²/α_y² + m_z²)²), m_t, m_b the
    /// components of wm along the tangent and the bitangent (D_anisotropic); its isotropic
    /// instance (α_x = α_y = α) is Walter et al. 2007, "Microfacet models for refraction through
    /// rough surfaces", Eq. 33, written α² / (π (sin²θm + α² cos²θm)²) to keep precision for tiny
    /// α. Zero for wm.z ≤ 0. Normalized: ∫ D(wm) cos θm dωm = 1.
    T D(const Vec3<T>& wm) const {
        if (wm.z <= 0) return T(0);
        if (anisotropy.on) return D_anisotropic(wm);
        const T alpha2 = sqr(alpha);
        const T denom = sqr(wm.x) + sqr(wm.y) + alpha2 * sqr(wm.z);
        return alpha2 / (kPi<T> * sqr(denom));
    }

    /// Smith Λ(w) for GGX: Heitz 2014, "Understanding the masking-shadowing function in
    /// microfacet-based BRDFs", JCGT 3(2), Eq. 72: Λ = (−1 + sqrt(1 + α(φ)² tan²θ)) / 2, α(φ) the
    /// roughness projected on w's azimuth (ggx_projected_alpha2). Symmetric in w.z; infinite at
    /// grazing (w.z = 0). The lane template ggx_lambda.
    T lambda(const Vec3<T>& w) const {
        if (anisotropy.on) return lambda_anisotropic(w);
        return ggx_lambda(lanes<false>(), w.x, w.y, w.z);
    }

    /// Smith masking G1(w) = 1 / (1 + Λ(w)) (Heitz 2014, Eq. 43).
    T G1(const Vec3<T>& w) const { return T(1) / (T(1) + lambda(w)); }

    /// Height-correlated masking-shadowing G2 = 1 / (1 + Λ(wi) + Λ(wo)) (Heitz 2014, Eq. 99).
    /// The caller is responsible for the side checks (χ+ terms) of the lobe it evaluates.
    T G2(const Vec3<T>& wi, const Vec3<T>& wo) const {
        return T(1) / (T(1) + lambda(wi) + lambda(wo));
    }

    /// The Smith microsurface's height-correlated masking-shadowing for a refracted pair (wi and
    /// wo on opposite sides): B(1 + Λ(wi), 1 + Λ(wo)) (smith_refraction_escape says why). Zero if
    /// either direction is grazing.
    T G2_transmission(const Vec3<T>& wi, const Vec3<T>& wo) const {
        if (wi.z == 0 || wo.z == 0) return T(0);
        return beta_function_scaled<T>(T(1) + lambda(wi), T(1) + lambda(wo), T(1));
    }

    /// Uncorrelated (separable) masking-shadowing G1(wi) G1(wo) (Heitz 2014, Eq. 98); an option.
    T G2_uncorrelated(const Vec3<T>& wi, const Vec3<T>& wo) const { return G1(wi) * G1(wo); }

    /// Distribution of normals visible from w: D_w(wm) = G1(w) max(0, w·wm) D(wm) / cos θ
    /// (Heitz 2014, Eq. 38), with w below the surface seen through −w. ∫ D_w dωm = 1.
    T D_visible(const Vec3<T>& w, const Vec3<T>& wm) const {
        const T sign = w.z < 0 ? T(-1) : T(1);
        const T cos_w_wm = sign * dot(w, wm);
        if (cos_w_wm <= 0 || w.z == 0) return T(0);
        return G1(w) * cos_w_wm * D(wm) / std::abs(w.z);
    }

    /// Heitz 2018's sampler of visible normals prepared for one direction w (its Sections 3.2
    /// and 4.1: w in the hemisphere configuration and the basis around it), so that a quadrature
    /// over many (r, φ) pairs of one w builds the basis once and each φ's cosine and sine once.
    struct VisibleNormalFrame {
        T alpha;
        GgxAnisotropy<T> anisotropy;
        Vec3<T> vh, t1, t2;
        T s;  ///< the warp towards the visible half disk, (1 + vh.z)/2
        /// The visible normal of the point (r cos φ, r sin φ) of the unit disk (Sections 4.2-4.4).
        Vec3<T> normal(T r, T cos_phi, T sin_phi) const {
            const T p1 = r * cos_phi;
            const T p2 = (T(1) - s) * safe_sqrt(T(1) - sqr(p1)) + s * (r * sin_phi);
            // Section 4.3: reprojection onto the hemisphere.
            const Vec3<T> nh = t1 * p1 + t2 * p2 + vh * safe_sqrt(T(1) - sqr(p1) - sqr(p2));
            // Section 3.4: back to the ellipsoid configuration.
            T x = nh.x, y = nh.y;
            GGX<T>{alpha, anisotropy}.stretch(x, y);
            return normalize(Vec3<T>(x, y, max0(nh.z)));
        }
    };

    /// The prepared sampler of the normals visible from w (w.z < 0 through −w).
    VisibleNormalFrame visible_normal_frame(Vec3<T> w) const {
        if (w.z < 0) w = -w;
        // Section 3.2: the view direction in the hemisphere configuration (α = 1), stretched in
        // the interface's frame (ggx_stretch: the hemisphere configuration is isotropic).
        T x = w.x, y = w.y;
        stretch(x, y);
        const Vec3<T> vh = normalize(Vec3<T>(x, y, w.z));
        // Section 4.1: orthonormal basis around vh.
        const T len2 = sqr(vh.x) + sqr(vh.y);
        const Vec3<T> t1 =
            len2 > 0 ? Vec3<T>(-vh.y, vh.x, T(0)) / std::sqrt(len2) : Vec3<T>(T(1), T(0), T(0));
        return {alpha, anisotropy, vh, t1, cross(vh, t1), T(0.5) * (T(1) + vh.z)};
    }

    /// Samples wm ∝ D_w(wm) from two uniform numbers in [0, 1): Heitz 2018, "Sampling the GGX
    /// distribution of visible normals", JCGT 7(4), Listing 1 (the w.z < 0 case through −w):
    /// the disk point r = √u1, φ = 2π u2 (Section 4.2) through visible_normal_frame.
    Vec3<T> sample_visible_normal(Vec3<T> w, T u1, T u2) const {
        const T phi = T(2) * kPi<T> * u2;
        return visible_normal_frame(w).normal(std::sqrt(u1), std::cos(phi), std::sin(phi));
    }

    /// Samples the same density D_w(wm) as sample_visible_normal by the spherical-cap
    /// construction of Dupuy & Benyoub 2023, "Sound and complete sampling of visible GGX normals
    /// with spherical caps", CGF 42(8), Listing 3: fewer operations and no basis, used by the
    /// particle tracer's hot loop. w.z < 0 is handled through −w.
    Vec3<T> sample_visible_normal_caps(Vec3<T> w, T u1, T u2) const {
        if (w.z < 0) w = -w;
        return sample_visible_normal_complete(w, u1, u2);
    }

    /// The distribution of normals visible from any direction w, below the horizon too (a ray
    /// inside the microsurface after a first bounce, microsurface_walk.h): max(0, w·wm) D(wm) /
    /// A(w), with the projected area A(w) = ∫ max(0, w·wm) D(wm) dωm = cos θ (1 + Λ(w)) for
    /// w.z > 0 and |cos θ| Λ(w) for w.z < 0 (Heitz 2014, Eq. 8 with the signed Λ of Heitz et al.
    /// 2016). Unlike D_visible, a w below the horizon is *not* taken through −w. Zero at w.z = 0.
    T D_visible_complete(const Vec3<T>& w, const Vec3<T>& wm) const {
        const T cos_w_wm = dot(w, wm);
        if (cos_w_wm <= 0 || w.z == 0) return T(0);
        const T area = w.z > 0 ? w.z * (T(1) + lambda(w)) : -w.z * lambda(w);
        return cos_w_wm * D(wm) / area;
    }

    /// Samples D_visible_complete(w, ·) by the spherical caps of Dupuy & Benyoub 2023 (Listing 3):
    /// warp w to the hemisphere configuration (α = 1), sample a spherical cap z ∈ (−wh.z, 1], take
    /// the halfway direction of the cap point and wh, warp back. The construction holds for every
    /// w, below the horizon included (the "complete" of their title: the cap then covers less than
    /// a hemisphere). For w.z ≥ 0 it is sample_visible_normal_caps. The lane template
    /// ggx_sample_visible_normal_complete.
    Vec3<T> sample_visible_normal_complete(const Vec3<T>& w, T u1, T u2) const {
        if (anisotropy.on) return sample_visible_normal_complete_anisotropic(w, u1, u2);
        const LaneVec3<T> wm =
            ggx_sample_visible_normal_complete(lanes<false>(), {w.x, w.y, w.z}, u1, u2);
        return {wm.x, wm.y, wm.z};
    }

    /// √(1 + α(φ)² tan²θ) = 1 + 2Λ(w): the quantity from which G1 and G2 follow without
    /// cancellation.
    T smith_root(const Vec3<T>& w) const {
        const T cos2 = sqr(w.z);
        if (cos2 == 0) return std::numeric_limits<T>::infinity();
        if (anisotropy.on) return std::sqrt(T(1) + projected_alpha2_anisotropic(w) / cos2);
        return std::sqrt(T(1) + ggx_projected_alpha2(lanes<false>(), w.x, w.y) / cos2);
    }

    /// Density of sample_visible_normal, with respect to solid angle of wm.
    T pdf_visible_normal(const Vec3<T>& w, const Vec3<T>& wm) const { return D_visible(w, wm); }

  private:
    /// D of an anisotropic distribution (wm.z > 0), multiplied through by α_x² α_y² as the
    /// isotropic form: α_x α_y / (π (α_y² m_t² + α_x² m_b² + α_x² α_y² m_z²)²) · α_x² α_y².
    [[gnu::noinline]] T D_anisotropic(const Vec3<T>& wm) const {
        const T alpha_y = anisotropy.alpha_y;
        const T m_t = anisotropy.tangent_cos * wm.x + anisotropy.tangent_sin * wm.y;
        const T m_b = anisotropy.tangent_cos * wm.y - anisotropy.tangent_sin * wm.x;
        const T product2 = sqr(alpha * alpha_y);
        const T denom = sqr(alpha_y * m_t) + sqr(alpha * m_b) + product2 * sqr(wm.z);
        return alpha * alpha_y * product2 / (kPi<T> * sqr(denom));
    }

    // The anisotropic instances, out of line: the code around the isotropic instance is then
    // compiled as if there were no other (its floating-point contractions, hence its results, are
    // those of the isotropic formulas alone).
    [[gnu::noinline]] T lambda_anisotropic(const Vec3<T>& w) const {
        return ggx_lambda(lanes<true>(), w.x, w.y, w.z);
    }
    [[gnu::noinline]] T projected_alpha2_anisotropic(const Vec3<T>& w) const {
        return ggx_projected_alpha2(lanes<true>(), w.x, w.y);
    }
    [[gnu::noinline]] void stretch_anisotropic(T& x, T& y) const {
        ggx_stretch(lanes<true>(), x, y);
    }
    [[gnu::noinline]] Vec3<T> sample_visible_normal_complete_anisotropic(const Vec3<T>& w, T u1,
                                                                         T u2) const {
        const LaneVec3<T> wm =
            ggx_sample_visible_normal_complete(lanes<true>(), {w.x, w.y, w.z}, u1, u2);
        return {wm.x, wm.y, wm.z};
    }
};

}  // namespace lamina

#endif  // LAMINA_PHYSICS_MICROFACET_H

#pragma once
// The interface physics lamina-1 is built from, in scalar double precision: the GGX microfacet
// distribution and its Smith masking, Fresnel's equations, Walter's rough dielectric, the
// Henyey–Greenstein phase function and Beer–Lambert attenuation.
//
// These are the formulas of lamina's physics/ (its lane templates, which the goniophotometer's
// SIMD kernels instantiate on float vectors), written again here because this header library
// must compile with nothing but a C++17 standard library, and lamina's reference must not depend
// on the model it judges. The two are tested against each other to rounding
// (tests/models/lamina1/lamina1_header_test.cpp).

#include "lamina1/math.h"

#include <cmath>
#include <optional>

namespace lamina1 {

/// The amplitude ratios of Fresnel's equations for a dielectric interface (Born & Wolf,
/// Principles of Optics, §1.5.2, Eqs. 21a–b): r_p = a/b and r_s = c/d, or total internal
/// reflection. cos_theta_i ∈ [−1, 1] (negative: the light arrives from the other side, where the
/// relative index is 1/eta); eta > 0 the relative index beyond / here.
struct FresnelAmplitudes {
    bool total = false;  ///< total internal reflection: both reflectances 1
    double a = 0, b = 1, c = 0, d = 1;
};
inline FresnelAmplitudes fresnel_amplitudes(double cos_theta_i, double eta) {
    const double inv_eta = 1.0 / eta;
    cos_theta_i = std::min(std::max(cos_theta_i, -1.0), 1.0);
    const bool below = cos_theta_i < 0;
    const double eta_crossed = below ? inv_eta : eta;
    const double inv_eta_crossed = below ? eta : inv_eta;
    cos_theta_i = below ? -cos_theta_i : cos_theta_i;
    const double sin2_theta_t =
        (1 - cos_theta_i * cos_theta_i) * (inv_eta_crossed * inv_eta_crossed);
    FresnelAmplitudes r;
    if (!(sin2_theta_t < 1)) {
        r.total = true;
        return r;
    }
    const double cos_theta_t = std::sqrt(std::max(1 - sin2_theta_t, 0.0));
    r.a = eta_crossed * cos_theta_i - cos_theta_t;
    r.b = eta_crossed * cos_theta_i + cos_theta_t;
    r.c = cos_theta_i - eta_crossed * cos_theta_t;
    r.d = cos_theta_i + eta_crossed * cos_theta_t;
    return r;
}

/// Exact unpolarized Fresnel reflectance of a dielectric interface: the mean of the s and p
/// reflectances of fresnel_amplitudes, (R_s + R_p)/2. 1 under total internal reflection.
inline double fresnel_dielectric(double cos_theta_i, double eta) {
    const FresnelAmplitudes r = fresnel_amplitudes(cos_theta_i, eta);
    if (r.total) return 1.0;
    // r_parallel = a/b, r_perpendicular = c/d; (a²d² + c²b²) / (b²d²) needs a single division.
    const double bd = r.b * r.d, ad = r.a * r.d, cb = r.c * r.b;
    const double b2d2 = bd * bd;
    return 0 < b2d2 ? (ad * ad + cb * cb) / (b2d2 + b2d2) : 1.0;
}

/// The s and p reflectances themselves, R_s = (c/d)² and R_p = (a/b)² (both 1 under total
/// internal reflection, and where a ratio is 0/0: light exactly grazing onto an index-matched
/// interface).
struct FresnelSp {
    double s = 1, p = 1;
};
inline FresnelSp fresnel_dielectric_sp(double cos_theta_i, double eta) {
    const FresnelAmplitudes r = fresnel_amplitudes(cos_theta_i, eta);
    if (r.total || !(r.b * r.d > 0)) return {};
    return {sqr(r.c / r.d), sqr(r.a / r.b)};
}

/// Unpolarized Fresnel reflectance for a complex relative index η + iκ, light from the real side
/// at cos_theta ∈ [0, 1]: the closed form in a², b² (Pharr, Jakob & Humphreys, PBR 3rd ed.,
/// §8.2.1, FrConductor; Born & Wolf §14.2). κ = 0 and η < 1 give 1 under total internal
/// reflection.
inline double fresnel_complex(double cos_theta, double eta, double k) {
    cos_theta = clamp(cos_theta, 0.0, 1.0);
    const double cos2 = cos_theta * cos_theta;
    const double sin2 = 1 - cos2;
    const double eta2 = eta * eta, k2 = k * k;
    const double t0 = eta2 - k2 - sin2;
    const double a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta2 * k2);
    const double t1 = a2_plus_b2 + cos2;
    const double a = safe_sqrt(0.5 * (a2_plus_b2 + t0));
    const double t2 = 2 * cos_theta * a;
    if (t1 + t2 <= 0) return 1;  // grazing onto an index-matched interface: the limit c → 0
    // t1 − t2 = (a − cos θ)² + b² and t3 − t4 = (a cos θ − sin²θ)² + b² cos²θ are sums of
    // squares: clamped at 0 against the rounding that makes them slightly negative near η = 1.
    const double rs = max0(t1 - t2) / (t1 + t2);
    const double t3 = cos2 * a2_plus_b2 + sin2 * sin2;
    const double t4 = t2 * sin2;
    const double rp = rs * max0(t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

/// The same for three channels at once (one loop over 4 lanes, which compilers vectorize).
inline Rgb fresnel_complex_rgb(double cos_theta, const Rgb& eta, const Rgb& k) {
    cos_theta = clamp(cos_theta, 0.0, 1.0);
    const double cos2 = cos_theta * cos_theta;
    const double sin2 = 1 - cos2;
    alignas(32) double e[4] = {eta[0], eta[1], eta[2], 1.5}, kk[4] = {k[0], k[1], k[2], 0.0};
    alignas(32) double out[4];
    for (int c = 0; c < 4; ++c) {
        const double eta2 = e[c] * e[c], k2 = kk[c] * kk[c];
        const double t0 = eta2 - k2 - sin2;
        const double a2_plus_b2 = std::sqrt(t0 * t0 + 4 * eta2 * k2);
        const double t1 = a2_plus_b2 + cos2;
        const double a = std::sqrt(std::max(0.5 * (a2_plus_b2 + t0), 0.0));
        const double t2 = 2 * cos_theta * a;
        const double rs = std::max(t1 - t2, 0.0) / std::max(t1 + t2, 1e-300);
        const double t3 = cos2 * a2_plus_b2 + sin2 * sin2;
        const double t4 = t2 * sin2;
        const double rp = rs * std::max(t3 - t4, 0.0) / std::max(t3 + t4, 1e-300);
        out[c] = t1 + t2 > 0 ? 0.5 * (rp + rs) : 1.0;
    }
    return {out[0], out[1], out[2]};
}

/// Snell refraction of w (pointing away from the surface, either side) through an interface of
/// unit normal n and relative index eta = η(side n points away from) / η(side n points to): the
/// refracted direction pointing away on the other side, or nothing under total reflection.
inline std::optional<Vec3> refract(const Vec3& w, Vec3 n, double eta) {
    double cos_theta_i = dot(n, w);
    if (cos_theta_i < 0) {
        eta = 1.0 / eta;
        cos_theta_i = -cos_theta_i;
        n = -n;
    }
    const double sin2_theta_t = (1.0 - sqr(cos_theta_i)) / sqr(eta);
    if (sin2_theta_t >= 1.0) return std::nullopt;
    const double cos_theta_t = safe_sqrt(1.0 - sin2_theta_t);
    return -w / eta + n * (cos_theta_i / eta - cos_theta_t);
}

/// The largest argument of beta_function_scaled (a direction within 1e-15 of grazing).
constexpr double kBetaArgumentMax = 1e15;

/// scale · B(a, b), Euler's Beta function, for a, b ≥ 1: the recurrence Γ(x + 1) = x Γ(x)
/// (Abramowitz & Stegun 1964, Eq. 6.1.15) shifts the arguments by 4, and Stirling's series (A & S
/// Eq. 6.1.41) gives the shifted function without the cancellation of ln Γ(A) + ln Γ(B) −
/// ln Γ(A + B); 5e-11 relative.
inline double beta_function_scaled(double a, double b, double scale) {
    a = std::min(a, kBetaArgumentMax);
    b = std::min(b, kBetaArgumentMax);
    const double s = a + b;
    const double low = (s * (s + 1)) * ((s + 2) * (s + 3)) / ((a * (a + 1)) * (b * (b + 1)));
    const double s4 = s + 4;
    const double high =
        (s4 * (s4 + 1)) * ((s4 + 2) * (s4 + 3)) / (((a + 2) * (a + 3)) * ((b + 2) * (b + 3)));
    const double A = a + 4, B = b + 4, S = s + 8;
    // ω(x) = 1/(12x) − 1/(360x³) + 1/(1260x⁵) − 1/(1680x⁷) + 1/(1188x⁹) − 691/(360360x¹¹).
    auto omega = [](double x) {
        const double y = 1 / x, y2 = y * y;
        double p = 1.0 / 1188.0 - y2 * (691.0 / 360360.0);
        p = 1.0 / 1680.0 - y2 * p;
        p = 1.0 / 1260.0 - y2 * p;
        p = 1.0 / 360.0 - y2 * p;
        p = 1.0 / 12.0 - y2 * p;
        return y * p;
    };
    const double ratio = B / A;
    const double stirling = (omega(A) + omega(B) - omega(S) + 0.91893853320467274178) -
                            (A * std::log1p(ratio) + B * std::log1p(1 / ratio));
    return std::exp(stirling + std::log(scale * (low * high) * std::sqrt(S / (A * B))));
}

/// How a rough dielectric masks the light it refracts (its reflection always has the
/// height-correlated 1/(1 + Λi + Λo) of Heitz 2014, Eq. 99).
enum class Masking {
    /// The Smith microsurface's own height-correlated form for a pair on opposite sides,
    /// B(1 + Λi, 1 + Λo) (Heitz 2014, §6; Heitz et al. 2016, §5.3): the default.
    Smith,
    /// 1/(1 + Λi + Λo) as for reflection (Walter et al. 2007 with Heitz 2014's G2; pbrt-v4).
    Walter,
};

/// G2/G1(wi) of a reflected pair from Λ of both directions: the height-correlated G2 =
/// 1/(1 + Λi + Λo) (Heitz 2014, Eq. 99) over G1(wi) = 1/(1 + Λi) (Eq. 43), the share of the light
/// a facet visible from wi reflects that leaves the microsurface at once.
inline double reflection_escape(double lambda_i, double lambda_o) {
    return (1 + lambda_i) / (1 + lambda_i + lambda_o);
}

/// G2/G1(wi) of a refracted pair from Λ of both directions: (1 + Λi) B(1 + Λi, 1 + Λt) (Smith)
/// or (1 + Λi)/(1 + Λi + Λt) (Walter), written in the Smith roots r = 1 + 2Λ; 1 when α = 0.
inline double refraction_escape(Masking masking, double lambda_i, double lambda_t) {
    const double r_i = 1 + 2 * lambda_i, r_t = 1 + 2 * lambda_t;
    if (masking == Masking::Walter)
        return std::min((1.0 + r_i) * 1.0 / (r_i * 1.0 + r_t * 1.0), 1.0);
    const double one_plus_lambda_i = std::min(0.5 * (1.0 + r_i), kBetaArgumentMax);
    const double one_plus_lambda_t = 0.5 * (1.0 + r_t);
    return std::min(beta_function_scaled(one_plus_lambda_i, one_plus_lambda_t, one_plus_lambda_i),
                    1.0);
}

/// A slope covariance: the symmetric 2 × 2 matrix Σ (xx, xy, yy) of an anisotropic GGX
/// microsurface in the surface's frame (x, y the macro frame's axes). The GGX of α_x along the
/// tangent t = (cos ψ, sin ψ) and α_y along the bitangent b = (−sin ψ, cos ψ) is the α = 1
/// microsurface stretched by A = α_x t tᵀ + α_y b bᵀ (lamina's docs/physics.md §3), whose slopes
/// have the scale matrix Σ = A² = α_x² t tᵀ + α_y² b bᵀ (for an isotropic α, α² I). Independent
/// slope spreads add as these matrices (Weier & Belcour 2020, "Rendering layered materials with
/// anisotropic interfaces", JCGT 9(2), §3: a lobe's 2 × 2 covariance), however their tangents
/// are turned against each other.
struct SlopeCovariance {
    double xx = 0, xy = 0, yy = 0;

    /// α_x along the tangent at tangent_angle radians from +x, α_y along the bitangent.
    static SlopeCovariance of_axes(double alpha_x, double alpha_y, double tangent_angle) {
        const double c = std::cos(tangent_angle), s = std::sin(tangent_angle);
        const double ax2 = sqr(alpha_x), ay2 = sqr(alpha_y);
        return {ax2 * c * c + ay2 * s * s, (ax2 - ay2) * c * s, ax2 * s * s + ay2 * c * c};
    }
    /// The isotropic α: α² I.
    static SlopeCovariance isotropic(double alpha) { return {sqr(alpha), 0.0, sqr(alpha)}; }

    SlopeCovariance operator+(const SlopeCovariance& o) const {
        return {xx + o.xx, xy + o.xy, yy + o.yy};
    }
    SlopeCovariance operator*(double s) const { return {xx * s, xy * s, yy * s}; }
    double determinant() const { return xx * yy - xy * xy; }
    /// The root mean square of the two principal roughnesses, √(tr Σ / 2): the α an isotropic
    /// quantity (a table 1-D in α) reads for this microsurface; α itself when isotropic.
    double rms_alpha() const { return std::sqrt(0.5 * (xx + yy)); }
    /// (x, y) Σ (x, y)ᵀ.
    double quadratic(double x, double y) const { return xx * x * x + 2 * xy * x * y + yy * y * y; }
};

/// The stretch from the α = 1 GGX microsurface to one of roughness α, or of slope covariance Σ,
/// applied to a direction's horizontal part (Heitz 2018, "Sampling the GGX distribution of visible
/// normals", JCGT 7(4), §3.2: (α_x x, α_y y) in the tangent frame; A (x, y) in the surface's, A =
/// Σ^{1/2} symmetric).
struct GgxStretch {
    double alpha;
    bool anisotropic = false;
    double a_xx = 0, a_xy = 0, a_yy = 0;  ///< A (anisotropic only)
    Vec3 operator()(const Vec3& w) const {
        if (anisotropic) return {a_xx * w.x + a_xy * w.y, a_xy * w.x + a_yy * w.y, w.z};
        return {alpha * w.x, alpha * w.y, w.z};
    }
};

/// The GGX (Trowbridge–Reitz) distribution of roughness α > 0 (no remapping), isotropic, or
/// anisotropic of slope covariance Σ (SlopeCovariance; GGX::anisotropic). A direction below the
/// surface sees the microsurface through −w. The isotropic distribution is computed by the
/// isotropic formulas themselves: the anisotropic ones are their generalization (equal at
/// Σ = α² I to rounding) and are read only where `anisotropic` is set.
struct GGX {
    double alpha;  ///< the isotropic α; an anisotropic distribution's √(tr Σ / 2)
    bool anisotropic = false;
    SlopeCovariance sigma{};  ///< Σ (anisotropic only)
    /// The stretch A = Σ^{1/2} (symmetric; anisotropic only).
    double a_xx = 0, a_xy = 0, a_yy = 0;

    /// The distribution of slope covariance Σ (positive definite). The stretch is Σ's symmetric
    /// square root, (Σ + √det Σ I)/√(tr Σ + 2√det Σ) (the Cayley–Hamilton form for 2 × 2
    /// matrices): A = α_x t tᵀ + α_y b bᵀ for the Σ of SlopeCovariance::of_axes.
    static GGX anisotropic_of(const SlopeCovariance& sigma) {
        GGX g{sigma.rms_alpha()};
        g.anisotropic = true;
        g.sigma = sigma;
        const double s = std::sqrt(std::max(sigma.determinant(), 0.0));
        const double t = std::sqrt(sigma.xx + sigma.yy + 2 * s);
        g.a_xx = (sigma.xx + s) / t;
        g.a_xy = sigma.xy / t;
        g.a_yy = (sigma.yy + s) / t;
        return g;
    }

    /// D(wm), 1/sr: Walter et al. 2007, Eq. 33, as α² / (π (sin²θm + α² cos²θm)²); anisotropic
    /// (Heitz 2014, the anisotropic distributions of §5) 1/(π √det Σ cos⁴θm (1 + sᵀ Σ⁻¹ s)²), s the
    /// facet's slope, written det^{3/2} / (π (m_xyᵀ adj(Σ) m_xy + det m_z²)²); 0 below.
    double D(const Vec3& wm) const {
        if (wm.z <= 0) return 0.0;
        if (anisotropic) {
            const double det = sigma.determinant();
            // adj(Σ) = [[yy, −xy], [−xy, xx]]: m_xyᵀ adj(Σ) m_xy = det · m_xyᵀ Σ⁻¹ m_xy.
            const double q =
                sigma.yy * sqr(wm.x) - 2 * sigma.xy * wm.x * wm.y + sigma.xx * sqr(wm.y);
            return det * std::sqrt(det) / (kPi * sqr(q + det * sqr(wm.z)));
        }
        const double alpha2 = sqr(alpha);
        const double denom = sqr(wm.x) + sqr(wm.y) + alpha2 * sqr(wm.z);
        return alpha2 / (kPi * sqr(denom));
    }

    /// Smith Λ(w): Heitz 2014, "Understanding the masking-shadowing function in microfacet-based
    /// BRDFs", JCGT 3(2), Eq. 72, as x/(2(√(1 + x) + 1)) with x = α² tan²θ; +∞ at grazing. An
    /// anisotropic distribution's α is the roughness projected on w's azimuth (Heitz 2014, §5),
    /// α(φ)² (w.x² + w.y²) = w_xyᵀ Σ w_xy.
    double lambda(const Vec3& w) const {
        const double alpha2_tan2 =
            (anisotropic ? sigma.quadratic(w.x, w.y) : sqr(alpha) * (w.x * w.x + w.y * w.y)) /
            (w.z * w.z);
        const double value = alpha2_tan2 / (2.0 * (std::sqrt(1.0 + alpha2_tan2) + 1.0));
        return alpha2_tan2 < HUGE_VAL ? value : HUGE_VAL;
    }

    /// G1(w) = 1/(1 + Λ(w)) (Heitz 2014, Eq. 43).
    double G1(const Vec3& w) const { return 1.0 / (1.0 + lambda(w)); }

    /// Height-correlated G2 = 1/(1 + Λ(wi) + Λ(wo)) (Heitz 2014, Eq. 99).
    double G2(const Vec3& wi, const Vec3& wo) const {
        return 1.0 / (1.0 + lambda(wi) + lambda(wo));
    }

    /// G2 of a refracted pair on the Smith microsurface, B(1 + Λi, 1 + Λo); 0 at grazing.
    double G2_transmission(const Vec3& wi, const Vec3& wo) const {
        if (wi.z == 0 || wo.z == 0) return 0.0;
        return beta_function_scaled(1.0 + lambda(wi), 1.0 + lambda(wo), 1.0);
    }

    /// D_w(wm) = G1(w) max(0, w·wm) D(wm) / |cos θ| (Heitz 2014, Eq. 38), w below through −w.
    double D_visible(const Vec3& w, const Vec3& wm) const {
        const double sign = w.z < 0 ? -1.0 : 1.0;
        const double cos_w_wm = sign * dot(w, wm);
        if (cos_w_wm <= 0 || w.z == 0) return 0.0;
        return G1(w) * cos_w_wm * D(wm) / std::abs(w.z);
    }

    /// The stretch from the α = 1 microsurface to this one (GgxStretch).
    GgxStretch stretch() const { return {alpha, anisotropic, a_xx, a_xy, a_yy}; }

    /// Heitz 2018's sampler of visible normals prepared for one direction (Heitz 2018, "Sampling
    /// the GGX distribution of visible normals", JCGT 7(4), §3.2 and §4.1), anisotropic by the
    /// stretch: the α = 1 configuration is isotropic, so its frame may be any about the normal.
    struct VisibleNormalFrame {
        GgxStretch stretch;
        Vec3 vh, t1, t2;
        double s;  ///< the warp towards the visible half disk, (1 + vh.z)/2
        /// The visible normal of the disk point (r cos φ, r sin φ) (§4.2–4.4).
        Vec3 normal(double r, double cos_phi, double sin_phi) const {
            const double p1 = r * cos_phi;
            const double p2 = (1.0 - s) * safe_sqrt(1.0 - sqr(p1)) + s * (r * sin_phi);
            const Vec3 nh = t1 * p1 + t2 * p2 + vh * safe_sqrt(1.0 - sqr(p1) - sqr(p2));
            return normalize(stretch(Vec3(nh.x, nh.y, max0(nh.z))));
        }
    };

    VisibleNormalFrame visible_normal_frame(Vec3 w) const {
        if (w.z < 0) w = -w;
        const GgxStretch a = stretch();
        const Vec3 vh = normalize(a(w));
        const double len2 = sqr(vh.x) + sqr(vh.y);
        const Vec3 t1 = len2 > 0 ? Vec3(-vh.y, vh.x, 0.0) / std::sqrt(len2) : Vec3(1.0, 0.0, 0.0);
        return {a, vh, t1, cross(vh, t1), 0.5 * (1.0 + vh.z)};
    }

    /// wm ∝ D_w(wm) from two uniforms in [0, 1) (Heitz 2018, Listing 1).
    Vec3 sample_visible_normal(Vec3 w, double u1, double u2) const {
        const double phi = 2.0 * kPi * u2;
        return visible_normal_frame(w).normal(std::sqrt(u1), std::cos(phi), std::sin(phi));
    }
};

/// A single rough dielectric interface of relative index eta (beyond / here) and roughness alpha
/// (Walter et al. 2007, "Microfacet models for refraction through rough surfaces", EGSR).
struct RoughDielectric {
    double eta;
    double alpha;
    Masking masking = Masking::Smith;

    /// η(wo's side) / η(wi's side).
    double eta_ratio(const Vec3& wi, const Vec3& wo) const {
        if (wi.z * wo.z > 0) return 1.0;
        return wi.z > 0 ? eta : 1.0 / eta;
    }

    /// Generalized half vector in the upper hemisphere (Walter Eqs. 13, 16), or nothing.
    std::optional<Vec3> half_vector(const Vec3& wi, const Vec3& wo) const {
        Vec3 wm = wi + wo * eta_ratio(wi, wo);
        const double len2 = dot(wm, wm);
        if (len2 == 0) return std::nullopt;
        wm = wm / std::sqrt(len2);
        if (wm.z < 0) wm = -wm;
        if (dot(wm, wi) * wi.z <= 0 || dot(wm, wo) * wo.z <= 0) return std::nullopt;
        return wm;
    }

    /// Radiance BSDF, 1/sr, cosine excluded (Walter Eqs. 20, 21); 0 for smooth and index-matched
    /// interfaces (delta lobes).
    double eval(const Vec3& wi, const Vec3& wo) const {
        if (alpha == 0 || eta == 1.0 || wi.z == 0 || wo.z == 0) return 0.0;
        const auto wm = half_vector(wi, wo);
        if (!wm) return 0.0;
        const GGX ggx{alpha};
        const double F = fresnel_dielectric(dot(wi, *wm), eta);
        const bool reflected = wi.z * wo.z > 0;
        const double G =
            masking == Masking::Smith && !reflected ? ggx.G2_transmission(wi, wo) : ggx.G2(wi, wo);
        if (reflected) return F * ggx.D(*wm) * G / std::abs(4.0 * wi.z * wo.z);
        const double r = eta_ratio(wi, wo);  // η_o / η_i
        const double denom = sqr(dot(wi, *wm) + r * dot(wo, *wm));
        return (1.0 - F) * ggx.D(*wm) * G * sqr(r) * std::abs(dot(wi, *wm) * dot(wo, *wm)) /
               (std::abs(wi.z * wo.z) * denom);
    }
};

/// The Henyey–Greenstein phase function, 1/sr (Henyey & Greenstein 1941): (1 − g²) / (4π (1 + g²
/// − 2g cos θ)^{3/2}), cos θ between the propagation directions, clamped to [−1, 1].
inline double hg_phase(double cos_theta, double g) {
    cos_theta = std::min(std::max(cos_theta, -1.0), 1.0);
    const double denom = 1.0 + g * g - 2.0 * g * cos_theta;
    return (1.0 - g * g) / (4.0 * kPi * denom * std::sqrt(std::max(denom, 0.0)));
}

/// Beer–Lambert transmittance exp(−τ·path) per channel (path = Σ 1/μ ≥ 0): 1 where τ = 0.
inline Rgb beer_lambert(const Rgb& tau, double path) {
    Rgb t;
    for (int c = 0; c < 3; ++c)
        t[c] = tau[c] > 0 ? std::exp(-tau[c] * path) : 1.0;
    return t;
}

/// A cosine-distributed direction of the upper hemisphere from two uniforms in [0, 1) (Shirley
/// & Chiu 1997's concentric disk, lifted).
inline Vec3 sample_cosine_hemisphere(double u1, double u2) {
    const double a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0;
    double x = 0, y = 0;
    if (a != 0 || b != 0) {
        double r, phi;
        if (std::abs(a) > std::abs(b)) {
            r = a;
            phi = (kPi / 4.0) * (b / a);
        } else {
            r = b;
            phi = kPi / 2.0 - (kPi / 4.0) * (a / b);
        }
        x = r * std::cos(phi);
        y = r * std::sin(phi);
    }
    return {x, y, safe_sqrt(1.0 - sqr(x) - sqr(y))};
}

}  // namespace lamina1

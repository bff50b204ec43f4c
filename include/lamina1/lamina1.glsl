// lamina-1's eval in GLSL ES 3.00 (WebGL2): the reflection of lamina1::Bsdf::eval_with
// (lamina1/eval.h) line for line, in float32, reading the per-material state that
// Bsdf::gpu_state packs (lamina1/gpu.h documents the layout and what it covers) from an R32F
// texture 256 texels wide, `lamina1_state` (no filtering: texelFetch). Conventions as the C++:
// the local frame, z the macro normal; wi where the light arrives from (wi.z > 0), wo where it
// leaves to; lamina1_eval returns f in 1/sr, RGB, without the cosine (0 for wo.z <= 0: a slab's
// transmission is not in this form). Include it after declaring
//   uniform highp sampler2D lamina1_state;
// lamina's docs/models.md, "lamina-1", derives every term; docs/lamina1.md shows the use.

const float L1_PI = 3.14159265358979;
const float L1_INV_PI = 0.318309886183791;
const int L1_NMU = 65, L1_NX = 33, L1_NNORM = 17, L1_NFACET = 129;
const int L1_T_TOP = 64, L1_T_TOP_IN = L1_T_TOP + 2 * L1_NMU, L1_X = L1_T_TOP_IN + 2 * L1_NMU;
const int L1_LOBE_NORM = L1_X + 3 * L1_NX, L1_MIRROR = L1_LOBE_NORM + L1_NNORM;
const int L1_ENTERING = L1_MIRROR + 3 * L1_NMU, L1_LEAVING = L1_ENTERING + 3 * L1_NFACET;
const int L1_SLOPE_SUM = 1536, L1_SS_NX = 25, L1_SS_NY = 13, L1_SS_NU = 33;

float l1_at(int i) { return texelFetch(lamina1_state, ivec2(i % 256, i / 256), 0).r; }
vec3 l1_rgb(int i) { return vec3(l1_at(i), l1_at(i + 1), l1_at(i + 2)); }
bool l1_flag(int bit) { return ((int(l1_at(0)) >> bit) & 1) == 1; }

float l1_sqr(float x) { return x * x; }

// Exact unpolarized Fresnel reflectance of a dielectric (Born & Wolf §1.5.2, Eqs. 21a–b).
float l1_fresnel_dielectric(float cos_i, float eta) {
    cos_i = clamp(cos_i, -1.0, 1.0);
    bool below = cos_i < 0.0;
    float e = below ? 1.0 / eta : eta;
    cos_i = abs(cos_i);
    float sin2_t = (1.0 - cos_i * cos_i) / (e * e);
    if (!(sin2_t < 1.0)) return 1.0;
    float cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    float rpar = (e * cos_i - cos_t) / (e * cos_i + cos_t);
    float rper = (cos_i - e * cos_t) / (cos_i + e * cos_t);
    return 0.5 * (rpar * rpar + rper * rper);
}

// Fresnel for η + iκ (PBR 3rd ed., §8.2.1, FrConductor), per channel.
float l1_fresnel_complex(float c, float eta, float k) {
    c = clamp(c, 0.0, 1.0);
    float cos2 = c * c, sin2 = 1.0 - cos2, eta2 = eta * eta, k2 = k * k;
    float t0 = eta2 - k2 - sin2;
    float a2b2 = sqrt(t0 * t0 + 4.0 * eta2 * k2);
    float t1 = a2b2 + cos2;
    float a = sqrt(max(0.5 * (a2b2 + t0), 0.0));
    float t2 = 2.0 * c * a;
    if (t1 + t2 <= 0.0) return 1.0;
    float rs = max(t1 - t2, 0.0) / (t1 + t2);
    float t3 = cos2 * a2b2 + sin2 * sin2, t4 = t2 * sin2;
    float rp = rs * max(t3 - t4, 0.0) / (t3 + t4);
    return 0.5 * (rp + rs);
}

// GGX (Walter et al. 2007, Eq. 33) and Smith Λ (Heitz 2014, Eq. 72).
float l1_ggx_d(float alpha, vec3 m) {
    if (m.z <= 0.0) return 0.0;
    float a2 = alpha * alpha;
    float d = m.x * m.x + m.y * m.y + a2 * m.z * m.z;
    return a2 / (L1_PI * d * d);
}
float l1_lambda(float alpha, vec3 w) {
    float x = alpha * alpha * (w.x * w.x + w.y * w.y) / (w.z * w.z);
    return x / (2.0 * (sqrt(1.0 + x) + 1.0));
}

// The per-material curves (lamina1/curves.h): over μ = s² nodes, and the square-root-edge curve.
float l1_cosine_curve(int base, int n, int stride, int channel, float mu) {
    float s = sqrt(clamp(mu, 0.0, 1.0)) * float(n - 1);
    int i = min(int(s), n - 2);
    float t = s - float(i);
    return l1_at(base + stride * i + channel) * (1.0 - t) +
           l1_at(base + stride * (i + 1) + channel) * t;
}
vec3 l1_cosine_curve3(int base, int n, float mu) {
    return vec3(l1_cosine_curve(base, n, 3, 0, mu), l1_cosine_curve(base, n, 3, 1, mu),
                l1_cosine_curve(base, n, 3, 2, mu));
}
float l1_edge_curve(int base, float split, float mu) {
    bool lower = mu < split;
    float a = lower ? 0.0 : split, b = lower ? split : 1.0;
    float x = b > a ? clamp((mu - a) / (b - a), 0.0, 1.0) : 0.0;
    x = lower ? 1.0 - sqrt(1.0 - x) : sqrt(x);
    x *= float(L1_NMU - 1);
    int i = min(int(x), L1_NMU - 2);
    float t = x - float(i);
    int at = base + (lower ? 0 : L1_NMU) + i;
    return l1_at(at) * (1.0 - t) + l1_at(at + 1) * t;
}
// T(μ) of the coat from outside (which = 0) or inside (1).
float l1_transmittance(int which, float mu) {
    if (l1_flag(which == 0 ? 10 : 11))
        return 1.0 - l1_fresnel_dielectric(mu, l1_at(which == 0 ? 26 : 28));
    return l1_edge_curve(which == 0 ? L1_T_TOP : L1_T_TOP_IN, l1_at(which == 0 ? 25 : 27), mu);
}

vec3 l1_attenuation(float mu) {
    if (!l1_flag(1)) return vec3(1.0);
    if (mu <= 0.0) return vec3(0.0);
    return exp(-l1_rgb(7) / mu);
}
vec3 l1_refract_in(vec3 w) {
    float inv_eta = l1_at(3);
    return vec3(w.x * inv_eta, w.y * inv_eta,
                sqrt(max(1.0 - (1.0 - w.z * w.z) * inv_eta * inv_eta, 0.0)));
}
float l1_spread_factor(float mu, float mu_in) {
    float eta = l1_at(2);
    if (l1_flag(12)) return abs(1.0 - 1.0 / eta);
    return abs(1.0 - mu / (eta * mu_in));
}
float l1_exit_transmittance(float mu, float mu_in, float k) {
    float alpha0 = l1_at(4), alpha1 = l1_at(5);
    float spread2 = l1_sqr(0.5 * alpha0 * k);
    float u = spread2 > 0.0 ? alpha1 * alpha1 / (alpha1 * alpha1 + spread2) : 1.0;
    return u * l1_transmittance(0, mu) + (1.0 - u) * l1_transmittance(1, mu_in);
}
vec3 l1_base_fresnel(float c) {
    int base = int(l1_at(1));
    if (base == 1)
        return vec3(l1_fresnel_complex(c, l1_at(13), l1_at(16)),
                    l1_fresnel_complex(c, l1_at(14), l1_at(17)),
                    l1_fresnel_complex(c, l1_at(15), l1_at(18)));
    if (base == 2) return vec3(l1_fresnel_dielectric(c, l1_at(6)));
    return l1_rgb(10);
}
vec3 l1_x_at(float mu) {
    if (!l1_flag(3)) return l1_cosine_curve3(L1_X, L1_NX, mu);
    vec3 w = vec3(sqrt(max(1.0 - mu * mu, 0.0)), 0.0, mu);
    return l1_rgb(10) * l1_rgb(22) * l1_attenuation(l1_refract_in(w).z) * l1_transmittance(0, mu);
}

// The slope-sum table's ratio R(ρ; x, 1/2) (lamina1/table_lookups.h, SlopeSumFormat).
float l1_slope_ratio(float rho, float x) {
    x = clamp(x, 0.0, 1.0);
    float fx = acos(1.0 - 2.0 * x) * L1_INV_PI * float(L1_SS_NX - 1);
    float fy = float(L1_SS_NY - 1);  // y = 1/2: the last node
    int ix = min(int(fx), L1_SS_NX - 2), iy = min(int(fy), L1_SS_NY - 2);
    float tx = clamp(fx - float(ix), 0.0, 1.0), ty = clamp(fy - float(iy), 0.0, 1.0);
    rho = max(rho, 0.0);
    float u = rho / (1.0 + rho);
    float fu = u * float(L1_SS_NU - 1);
    int iu = min(int(fu), L1_SS_NU - 2);
    float tu = fu - float(iu);
    float sum = 0.0;
    for (int dx = 0; dx < 2; ++dx)
        for (int dy = 0; dy < 2; ++dy) {
            float wxy = (dx == 1 ? tx : 1.0 - tx) * (dy == 1 ? ty : 1.0 - ty);
            int row = L1_SLOPE_SUM + ((ix + dx) * L1_SS_NY + (iy + dy)) * L1_SS_NU + iu;
            sum += wxy * ((1.0 - tu) * l1_at(row) + tu * l1_at(row + 1));
        }
    return sum;
}
// One facet's deflection map (FacetDeflection::lookup): false beyond g_max.
bool l1_facet(int base, float g_max, float g, out float sin_d, out float cos_d, out float w) {
    sin_d = 0.0; cos_d = 1.0; w = 0.0;
    if (!(g < g_max)) return false;
    float f = g / g_max * float(L1_NFACET - 1);
    int i = min(int(f), L1_NFACET - 2);
    float t = f - float(i);
    int a = base + 3 * i;
    sin_d = l1_at(a) + t * (l1_at(a + 3) - l1_at(a));
    cos_d = l1_at(a + 1) + t * (l1_at(a + 4) - l1_at(a + 1));
    w = l1_at(a + 2) + t * (l1_at(a + 5) - l1_at(a + 2));
    return cos_d > 0.0 && w > 0.0;
}
float l1_density(float r, float s2, float sigma, float x) {
    return s2 * L1_INV_PI / l1_sqr(s2 + r * r) * l1_slope_ratio(r / sigma, x);
}
// The widened base lobe's NDF (Bsdf::first_order_ndf).
float l1_first_order_ndf(vec3 h, float k_i, float k_o) {
    float k = min(k_i, k_o);
    float a_b = l1_at(5), a_c = 0.5 * l1_at(4) * k;
    float s2 = a_b * a_b + 2.0 * a_c * a_c;
    float c2 = h.z * h.z;
    if (!(s2 > 0.0) || !(c2 > 0.0)) return 0.0;
    float sigma = sqrt(s2), x = a_b * a_b / s2;
    float t2 = max(0.0, 1.0 - c2) / c2, t = sqrt(t2);
    if (!l1_flag(8) || !(a_c > 0.0)) return l1_density(t, s2, sigma, x) / (c2 * c2);
    float p = x * l1_density(t, s2, sigma, x);
    float g = 2.0 * (1.0 - l1_at(3)) * atan(t) / k;
    for (int m = 0; m < 2; ++m) {
        float sin_d, cos_d, w;
        if (!l1_facet(m == 0 ? L1_ENTERING : L1_LEAVING, l1_at(m == 0 ? 29 : 30), g, sin_d, cos_d, w))
            continue;
        float S = 0.5 * k * sin_d / cos_d;
        float s_over_t = t > 1e-12 ? S / t : 1.0;
        p += 0.5 * (1.0 - x) * l1_density(S, s2, sigma, x) * s_over_t * w /
             (cos_d * cos_d * (1.0 + t2));
    }
    return p / (c2 * c2);
}
vec3 l1_base_lobe(vec3 wi_in, float k_top, float lobe_norm_i, float mu_o, vec3 wo_in) {
    if (int(l1_at(1)) == 0) return l1_rgb(10) * L1_INV_PI;
    float k_o = l1_spread_factor(mu_o, wo_in.z);
    float alpha1 = l1_at(5), alpha0 = l1_at(4);
    float alpha = l1_flag(13) ? alpha1
                              : sqrt(alpha1 * alpha1 + 0.25 * alpha0 * alpha0 * (k_top * k_top + k_o * k_o));
    if (alpha <= 0.0) return vec3(0.0);
    vec3 h = normalize(wi_in + wo_in);
    float G = 1.0 / (1.0 + l1_lambda(alpha, wi_in) + l1_lambda(alpha, wo_in));
    float D = l1_flag(7) ? l1_first_order_ndf(h, k_top, k_o) : l1_ggx_d(alpha, h);
    vec3 f = l1_base_fresnel(dot(wi_in, h)) * (D * G / (4.0 * wi_in.z * wo_in.z));
    if (l1_flag(6)) f *= lobe_norm_i * l1_cosine_curve(L1_LOBE_NORM, L1_NNORM, 1, 0, wo_in.z);
    return f;
}

// f(wi, wo): lamina1::Bsdf::eval for wo.z > 0 (Bsdf::incident, then eval_with).
vec3 lamina1_eval(vec3 wi, vec3 wo) {
    if (wi.z <= 0.0 || wo.z <= 0.0) return vec3(0.0);
    float eta0 = l1_at(2), inv_eta0 = l1_at(3), alpha0 = l1_at(4);
    // Bsdf::incident
    vec3 wi_in = l1_refract_in(wi);
    if (!(wi_in.z > 0.0)) return vec3(0.0);
    float T = l1_transmittance(0, wi.z);
    vec3 a = l1_attenuation(wi_in.z);
    vec3 X = l1_flag(2) ? l1_x_at(wi.z) : vec3(0.0);
    float lambda0 = alpha0 > 0.0 ? l1_lambda(alpha0, wi) : 0.0;
    float lobe_norm = l1_flag(6) ? l1_cosine_curve(L1_LOBE_NORM, L1_NNORM, 1, 0, wi_in.z) : 1.0;
    float k_top = l1_spread_factor(wi.z, wi_in.z);
    float T_pair = T;
    if (l1_flag(4)) T_pair = sqrt(T * l1_exit_transmittance(wi.z, wi_in.z, k_top));
    // Bsdf::eval_with
    vec3 f = vec3(0.0);
    if (alpha0 > 0.0) {
        vec3 h = normalize(wi + wo);
        float G = 1.0 / (1.0 + lambda0 + l1_lambda(alpha0, wo));
        f = vec3(l1_fresnel_dielectric(dot(wi, h), eta0) * l1_ggx_d(alpha0, h) * G /
                 (4.0 * wi.z * wo.z));
    }
    vec3 wo_in = l1_refract_in(wo);
    float T_o = l1_transmittance(0, wo.z);
    vec3 a_o = l1_attenuation(wo_in.z);
    vec3 fb = wi_in.z > 0.0 && wo_in.z > 0.0 ? l1_base_lobe(wi_in, k_top, lobe_norm, wo.z, wo_in)
                                            : vec3(0.0);
    float fb_max = max(fb.r, max(fb.g, fb.b));
    if (l1_flag(4) && fb_max > 0.0)
        T_o = sqrt(T_o * l1_exit_transmittance(wo.z, wo_in.z, l1_spread_factor(wo.z, wo_in.z)));
    vec3 rounds = vec3(1.0);
    if (l1_flag(5) && fb_max > 0.0)
        rounds = l1_cosine_curve3(L1_MIRROR, L1_NMU, wi_in.z) *
                 l1_cosine_curve3(L1_MIRROR, L1_NMU, wo_in.z);
    float eta2 = l1_flag(9) ? inv_eta0 * inv_eta0 : 1.0;
    f += fb * (a * a_o) * rounds * (T_pair * T_o * eta2);
    if (l1_flag(2)) f += X * l1_x_at(wo.z) * l1_rgb(19) * (L1_INV_PI * inv_eta0 * inv_eta0);
    return f;
}

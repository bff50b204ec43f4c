// lamina-1's eval in GLSL ES 3.00 (WebGL2): the reflection of lamina1::Bsdf::eval_with
// (lamina1/eval.h) line for line, in float32, reading the per-material state that
// Bsdf::gpu_state packs (lamina1/gpu.h documents the layout and what it covers) from an R32F
// texture 256 texels wide, `lamina1_state` (no filtering: texelFetch). Conventions as the C++:
// the local frame, z the macro normal; wi where the light arrives from (wi.z > 0), wo where it
// leaves to; lamina1_eval returns f in 1/sr, RGB, without the cosine (0 for wo.z <= 0: a slab's
// transmission is not in this form). lamina1_sample and lamina1_pdf are Bsdf::sample and pdf
// (lamina1/sampling.h) for the materials whose state has the sampling flag (not slabs). Include
// it after declaring
//   uniform highp sampler2D lamina1_state;
// lamina's docs/models.md, "lamina-1", derives every term; docs/lamina1.md shows the use.

const float L1_PI = 3.14159265358979;
const float L1_INV_PI = 0.318309886183791;
const int L1_NMU = 65, L1_NX = 33, L1_NNORM = 17, L1_NFACET = 129;
const int L1_T_TOP = 64, L1_T_TOP_IN = L1_T_TOP + 2 * L1_NMU, L1_X = L1_T_TOP_IN + 2 * L1_NMU;
const int L1_LOBE_NORM = L1_X + 3 * L1_NX, L1_MIRROR = L1_LOBE_NORM + L1_NNORM;
const int L1_ENTERING = L1_MIRROR + 3 * L1_NMU, L1_LEAVING = L1_ENTERING + 3 * L1_NFACET;
const int L1_BASE_ALBEDO = L1_LEAVING + 3 * L1_NFACET;
const int L1_DR_TOP = L1_BASE_ALBEDO + L1_NMU, L1_DE_BASE = L1_DR_TOP + L1_NMU;
const int L1_A_COAT = L1_DE_BASE + L1_NMU, L1_NFIRST = 17, L1_POL = L1_A_COAT + 3 * L1_NMU;
const int L1_SLOPE_SUM = 1860, L1_SS_NX = 25, L1_SS_NY = 13, L1_SS_NU = 33;
// A slab's bins (kGpuBins* in lamina1/gpu.h), after the slope-sum table.
const int L1_NBINS = 12, L1_BIN_PER = 4, L1_NSLAB = 17, L1_BINS_MAX_CUTS = 2 * L1_NBINS + 3;
const int L1_BINS_CUTS = L1_SLOPE_SUM + L1_SS_NX * L1_SS_NY * L1_SS_NU;
const int L1_BINS_NODES = L1_BINS_CUTS + 1 + L1_BINS_MAX_CUTS;
const int L1_BINS_G = L1_BINS_NODES + (L1_BINS_MAX_CUTS - 1) * L1_BIN_PER * 2 * L1_NBINS;
const int L1_BINS_FIRST = L1_BINS_G + 3 * L1_NSLAB;
const int L1_BINS_LATER = L1_BINS_FIRST + 6 * L1_NBINS * L1_NBINS;

float l1_at(int i) { return texelFetch(lamina1_state, ivec2(i % 256, i / 256), 0).r; }
vec3 l1_rgb(int i) { return vec3(l1_at(i), l1_at(i + 1), l1_at(i + 2)); }
bool l1_flag(int bit) { return ((int(l1_at(0)) >> bit) & 1) == 1; }

float l1_sqr(float x) { return x * x; }

// The s and p reflectances of a dielectric, (R_s, R_p) (Born & Wolf §1.5.2, Eqs. 21a–b).
vec2 l1_fresnel_sp(float cos_i, float eta) {
    cos_i = clamp(cos_i, -1.0, 1.0);
    bool below = cos_i < 0.0;
    float e = below ? 1.0 / eta : eta;
    cos_i = abs(cos_i);
    float sin2_t = (1.0 - cos_i * cos_i) / (e * e);
    if (!(sin2_t < 1.0)) return vec2(1.0);
    float cos_t = sqrt(max(1.0 - sin2_t, 0.0));
    float rpar = (e * cos_i - cos_t) / (e * cos_i + cos_t);
    float rper = (cos_i - e * cos_t) / (cos_i + e * cos_t);
    return vec2(rper * rper, rpar * rpar);
}

// Exact unpolarized Fresnel reflectance of a dielectric: the mean of R_s and R_p.
float l1_fresnel_dielectric(float cos_i, float eta) {
    vec2 r = l1_fresnel_sp(cos_i, eta);
    return 0.5 * (r.x + r.y);
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
// Bsdf::coat_attenuation: a rough absorbing coat's curve over the outside cosine, else the macro
// refraction's exp(−τ/μ').
vec3 l1_coat_attenuation(float mu, float mu_in) {
    if (l1_flag(19)) return l1_cosine_curve3(L1_A_COAT, L1_NMU, mu);
    return l1_attenuation(mu_in);
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
    // The base's orders >= 2, separable (Kulla & Conty 2017; Bsdf::base_lobe).
    if (l1_flag(17))
        f += l1_rgb(34) * (l1_cosine_curve(L1_DE_BASE, L1_NMU, 1, 0, wi_in.z) *
                           l1_cosine_curve(L1_DE_BASE, L1_NMU, 1, 0, wo_in.z) * L1_INV_PI / l1_at(38));
    return f;
}

// The round trips' lobe (Bsdf::round_trip): the base's Walter lobe of α_r² = α_e² + α1² + α0²,
// entering and leaving as the first order, times its scale s(μ) at both ends (outside cosines;
// solved in C++ so that it carries what the returned light lets out).
vec3 l1_round_trip(float mu_i, vec3 wi_in, float k_top, vec3 wo, vec3 wo_in, vec3 a_pair,
                   float T_pair, float eta2) {
    float alpha1 = l1_at(5), alpha0 = l1_at(4);
    float k_o = l1_spread_factor(wo.z, wo_in.z);
    float alpha_e2 = l1_flag(13) ? alpha1 * alpha1
                                 : alpha1 * alpha1 + 0.25 * alpha0 * alpha0 * (k_top * k_top + k_o * k_o);
    float alpha = sqrt(alpha_e2 + alpha1 * alpha1 + alpha0 * alpha0);
    vec3 h = normalize(wi_in + wo_in);
    float G = 1.0 / (1.0 + l1_lambda(alpha, wi_in) + l1_lambda(alpha, wo_in));
    vec3 fb = l1_base_fresnel(dot(wi_in, h)) * (l1_ggx_d(alpha, h) * G / (4.0 * wi_in.z * wo_in.z));
    float T_o = l1_transmittance(0, wo.z);
    if (l1_flag(4)) T_o = sqrt(T_o * l1_exit_transmittance(wo.z, wo_in.z, k_o));
    return fb * a_pair * l1_cosine_curve3(L1_MIRROR, L1_NX, mu_i) *
           l1_cosine_curve3(L1_MIRROR, L1_NX, wo.z) * (T_pair * T_o * eta2);
}

// ---- A slab's inside light in bins (lamina1/slab.h) ----

// The coat's entry curve C(μ) (SegmentCurve::operator()): where in the node array (segment g,
// node i) and the weight t of node i + 1.
void l1_bins_at(float mu, out int at, out float t) {
    int n = int(l1_at(L1_BINS_CUTS));
    int g = 0;
    for (int i = 1; i < L1_BINS_MAX_CUTS - 1; ++i)
        if (i < n - 1 && l1_at(L1_BINS_CUTS + 1 + i) <= mu) g = i;
    float lo = l1_at(L1_BINS_CUTS + 1 + g), span = l1_at(L1_BINS_CUTS + 2 + g) - lo;
    float x = span > 0.0 ? clamp((mu - lo) / span, 0.0, 1.0) * float(L1_BIN_PER - 1) : 0.0;
    int i = min(int(x), L1_BIN_PER - 2);
    t = x - float(i);
    at = L1_BINS_NODES + (g * L1_BIN_PER + i) * 2 * L1_NBINS;
}
float l1_bins_entry(int at, float t, int k) {
    return l1_at(at + k) * (1.0 - t) + l1_at(at + 2 * L1_NBINS + k) * t;
}

// Bsdf::bins_reflection through Bsdf::incident_bins: per channel and azimuthal order m,
// C_m(μo)ᵀ (g(μo) g(μi) W P₁ + W P₂) C_m(μi), joined in azimuth by the Poisson kernel
// (binned_exit) at the forward cosine of wo against wi. Without absorption every channel is the
// first's (as incident_bins, whose vectors carry g(μi) of the first channel then).
vec3 l1_bins_reflection(vec3 wi, vec3 wo) {
    int at_i, at_o;
    float t_i, t_o;
    l1_bins_at(wi.z, at_i, t_i);
    l1_bins_at(wo.z, at_o, t_o);
    float c_i[2 * L1_NBINS], c_o[2 * L1_NBINS];
    for (int k = 0; k < 2 * L1_NBINS; ++k) {
        c_i[k] = l1_bins_entry(at_i, t_i, k);
        c_o[k] = l1_bins_entry(at_o, t_o, k);
    }
    vec3 g_i = l1_cosine_curve3(L1_BINS_G, L1_NSLAB, wi.z);
    vec3 g_o = l1_cosine_curve3(L1_BINS_G, L1_NSLAB, wo.z);
    // Per channel of the matrices and order m: C_m(μo)ᵀ W P₁ C_m(μi) and C_m(μo)ᵀ W P₂ C_m(μi).
    int channels = l1_flag(1) ? 3 : 1;
    vec3 first[2], later[2];
    for (int mc = 0; mc < 3; ++mc) {
        if (mc >= channels) break;
        for (int m = 0; m < 2; ++m) {
            float x_sum = 0.0, y_sum = 0.0;
            for (int j = 0; j < L1_NBINS; ++j) {
                int row = (mc * 2 + m) * L1_NBINS * L1_NBINS + j * L1_NBINS;
                float x = 0.0, y = 0.0;
                for (int k = 0; k < L1_NBINS; ++k) {
                    x += l1_at(L1_BINS_FIRST + row + k) * c_i[m * L1_NBINS + k];
                    y += l1_at(L1_BINS_LATER + row + k) * c_i[m * L1_NBINS + k];
                }
                x_sum += x * c_o[m * L1_NBINS + j];
                y_sum += y * c_o[m * L1_NBINS + j];
            }
            first[m][mc] = x_sum;
            later[m][mc] = y_sum;
        }
    }
    float si = length(wi.xy), so = length(wo.xy);
    float c = si > 0.0 && so > 0.0 ? -dot(wi.xy, wo.xy) / (si * so) : 0.0;
    vec3 f = vec3(0.0);
    for (int ch = 0; ch < 3; ++ch) {
        int mc = ch < channels ? ch : 0;
        float f0 = g_i[mc] * g_o[ch] * first[0][mc] + later[0][mc];
        float f1 = g_i[mc] * g_o[ch] * first[1][mc] + later[1][mc];
        if (!(f0 > 0.0)) continue;
        float rho = clamp(f1 / f0, -0.98, 0.98);
        f[ch] = f0 * (1.0 - rho * rho) / (1.0 - 2.0 * rho * c + rho * rho);
    }
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
    vec3 a = l1_coat_attenuation(wi.z, wi_in.z);
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
        // Its orders >= 2, separable (Kulla & Conty 2017; Bsdf::eval_with).
        if (l1_flag(16))
            f += vec3(l1_cosine_curve(L1_DR_TOP, L1_NMU, 1, 0, wi.z) *
                      l1_cosine_curve(L1_DR_TOP, L1_NMU, 1, 0, wo.z) * L1_INV_PI / l1_at(37));
    }
    vec3 wo_in = l1_refract_in(wo);
    float T_o = l1_transmittance(0, wo.z);
    vec3 a_o = l1_coat_attenuation(wo.z, wo_in.z);
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
    // A rough slab's light beyond the coat's own reflection under polarization (flag 21).
    vec3 pol = l1_flag(21) && (alpha0 > 0.0 || l1_at(5) > 0.0)
                   ? l1_cosine_curve3(L1_POL, L1_NFIRST, wi.z) *
                         l1_cosine_curve3(L1_POL, L1_NFIRST, wo.z)
                   : vec3(1.0);
    f += fb * (a * a_o) * rounds * (T_pair * T_o * eta2) * pol;
    if (l1_flag(2)) f += X * l1_x_at(wo.z) * l1_rgb(19) * (L1_INV_PI * inv_eta0 * inv_eta0) * pol;
    if (l1_flag(20) && wo_in.z > 0.0) f += l1_round_trip(wi.z, wi_in, k_top, wo, wo_in, a * a_o, T_pair, eta2);
    if (l1_flag(18)) f += l1_bins_reflection(wi, wo) * pol;
    return f;
}

// The delta lobes' reflectance towards the mirror direction of wi: lamina1::Bsdf::delta_lobes's
// reflected lobes summed (they share that direction); 0 for a rough coat. A smooth coat reflects
// its Fresnel reflectance F(μi); over a smooth conductor or dielectric base every order is
// specular too: R_b a² T² Σ_k (F R_b a²)^k at the inside cosine (the sum with the choice
// inter-reflection, flag 15, else its first term). A renderer adds it times the radiance from the
// mirror direction (lamina render does: docs/rendering.md §2).
vec3 lamina1_delta(vec3 wi) {
    if (wi.z <= 0.0 || l1_at(4) > 0.0) return vec3(0.0);
    float F = l1_fresnel_dielectric(wi.z, l1_at(2));
    if (int(l1_at(1)) == 0 || l1_at(5) > 0.0) return vec3(F);
    vec3 w_in = l1_refract_in(wi);
    vec3 a = l1_attenuation(w_in.z);
    vec3 Rb = l1_base_fresnel(w_in.z);
    float T = 1.0 - F;
    if (l1_flag(21)) {
        // Polarized (flag 21): a smooth slab keeps its s and p light apart; the series per
        // polarization, averaged (lamina1/polarization.h).
        vec2 F_sp = l1_fresnel_sp(wi.z, l1_at(2)), Rb_sp = l1_fresnel_sp(w_in.z, l1_at(6));
        vec3 body = vec3(0.0);
        for (int p = 0; p < 2; ++p)
            for (int c = 0; c < 3; ++c) {
                float round_trip = F_sp[p] * Rb_sp[p] * a[c] * a[c];
                float series = round_trip < 1.0 ? 1.0 / (1.0 - round_trip) : 0.0;
                body[c] += 0.5 * Rb_sp[p] * a[c] * a[c] * series * l1_sqr(1.0 - F_sp[p]);
            }
        return vec3(F) + body;
    }
    vec3 series = vec3(1.0);
    if (l1_flag(15))
        for (int c = 0; c < 3; ++c) {
            // F R_b a² = 1 only where nothing enters (F = 1), where T = 0: no series.
            float round_trip = F * Rb[c] * a[c] * a[c];
            series[c] = round_trip < 1.0 ? 1.0 / (1.0 - round_trip) : 0.0;
        }
    return vec3(F) + Rb * a * a * series * (T * T);
}

// ---- Sampling (lamina1/sampling.h: the mixture of the lobes, each drawn by its own rule) ----

// D_w(wm) = G1(w) max(0, w·wm) D(wm) / cos θ (Heitz 2014, Eq. 38), w above.
float l1_d_visible(float alpha, vec3 w, vec3 m) {
    float c = dot(w, m);
    if (c <= 0.0 || w.z <= 0.0) return 0.0;
    return c * l1_ggx_d(alpha, m) / ((1.0 + l1_lambda(alpha, w)) * w.z);
}
// cos φ and sin φ to float precision: the built-in cos and sin may be coarse (SwiftShader's, the
// WebGL of headless Chromium, are off by up to 1.9e-4, which near the horizon turns a drawn
// direction by 2e-3). φ reduced by quarter turns to |r| ≤ π/4, then Taylor to r⁹ (error < 3e-9).
void l1_cos_sin(float phi, out float c, out float s) {
    float k = floor(phi / (0.5 * L1_PI) + 0.5);
    float r = phi - k * (0.5 * L1_PI), r2 = r * r;
    float sr = r * (1.0 - r2 / 6.0 * (1.0 - r2 / 20.0 * (1.0 - r2 / 42.0 * (1.0 - r2 / 72.0))));
    float cr = 1.0 - r2 / 2.0 * (1.0 - r2 / 12.0 * (1.0 - r2 / 30.0 * (1.0 - r2 / 56.0)));
    int q = int(k) & 3;
    c = q == 0 ? cr : q == 1 ? -sr : q == 2 ? -cr : sr;
    s = q == 0 ? sr : q == 1 ? cr : q == 2 ? -sr : -cr;
}

// A visible normal of w from (u1, u2) (Heitz 2018, "Sampling the GGX distribution of visible
// normals", JCGT 7(4), Listing 1), as GGX::sample_visible_normal.
vec3 l1_sample_visible_normal(float alpha, vec3 w, float u1, float u2) {
    vec3 vh = normalize(vec3(alpha * w.x, alpha * w.y, w.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) / sqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(vh, t1);
    float s = 0.5 * (1.0 + vh.z), r = sqrt(u1), cos_phi, sin_phi;
    l1_cos_sin(2.0 * L1_PI * u2, cos_phi, sin_phi);
    float p1 = r * cos_phi;
    float p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * (r * sin_phi);
    vec3 nh = t1 * p1 + t2 * p2 + vh * sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0));
    return normalize(vec3(alpha * nh.x, alpha * nh.y, max(nh.z, 0.0)));
}
// A cosine-distributed direction (Shirley & Chiu 1997's concentric disk, lifted).
vec3 l1_sample_cosine(float u1, float u2) {
    float a = 2.0 * u1 - 1.0, b = 2.0 * u2 - 1.0, x = 0.0, y = 0.0;
    if (a != 0.0 || b != 0.0) {
        float r, phi;
        if (abs(a) > abs(b)) {
            r = a;
            phi = (L1_PI / 4.0) * (b / a);
        } else {
            r = b;
            phi = L1_PI / 2.0 - (L1_PI / 4.0) * (a / b);
        }
        float c, sn;
        l1_cos_sin(phi, c, sn);
        x = r * c;
        y = r * sn;
    }
    return vec3(x, y, sqrt(max(1.0 - x * x - y * y, 0.0)));
}
float l1_mean(vec3 v) { return (v.r + v.g + v.b) / 3.0; }

// The mixture at wi (Bsdf::mixture): the lobes' probabilities (top reflection, base lobe,
// separable series) and the base lobe's roughness; false where nothing can be drawn.
bool l1_mixture(vec3 wi, out vec3 p, out float alpha_base, out vec3 wi_in) {
    p = vec3(0.0);
    alpha_base = 0.0;
    wi_in = l1_refract_in(wi);
    if (!l1_flag(14) || wi.z <= 0.0 || !(wi_in.z > 0.0)) return false;
    float alpha0 = l1_at(4), alpha1 = l1_at(5);
    float a = l1_mean(l1_coat_attenuation(wi.z, wi_in.z)), T = l1_transmittance(0, wi.z);
    if (alpha0 > 0.0) p.x = l1_fresnel_dielectric(wi.z, l1_at(2));
    float E_b = int(l1_at(1)) == 0 ? l1_mean(l1_rgb(10))
                                   : l1_cosine_curve(L1_BASE_ALBEDO, L1_NMU, 1, 0, wi_in.z);
    if (int(l1_at(1)) == 0) {
        p.y = T * a * E_b;
    } else {
        float k = l1_spread_factor(wi.z, wi_in.z);
        alpha_base = l1_flag(13) ? alpha1 : sqrt(alpha1 * alpha1 + 0.5 * alpha0 * alpha0 * k * k);
        if (alpha_base > 0.0) p.y = T * a * E_b;
    }
    if (l1_flag(2)) p.z = l1_mean(l1_x_at(wi.z) * l1_rgb(19) * l1_rgb(31));
    // The coat's separable orders >= 2, also cosine-distributed.
    if (l1_flag(16)) p.z += l1_cosine_curve(L1_DR_TOP, L1_NMU, 1, 0, wi.z);
    float total = p.x + p.y + p.z;
    if (!(total > 0.0)) return false;
    p /= total;
    return true;
}

float l1_pdf_with(vec3 wi, vec3 p, float alpha_base, vec3 wi_in, vec3 wo) {
    if (wo.z <= 0.0) return 0.0;
    float pdf = 0.0;
    if (p.x > 0.0) {
        vec3 h = normalize(wi + wo);
        pdf += p.x * l1_d_visible(l1_at(4), wi, h) / (4.0 * abs(dot(wo, h)));
    }
    if (p.y > 0.0) {
        if (int(l1_at(1)) == 0) {
            pdf += p.y * wo.z * L1_INV_PI;
        } else {
            vec3 wo_in = l1_refract_in(wo);
            if (wo_in.z > 0.0) {
                vec3 h = normalize(wi_in + wo_in);
                float pdf_in = l1_d_visible(alpha_base, wi_in, h) / (4.0 * abs(dot(wo_in, h)));
                pdf += p.y * pdf_in * wo.z / (l1_sqr(l1_at(2)) * wo_in.z);
            }
        }
    }
    if (p.z > 0.0) pdf += p.z * wo.z * L1_INV_PI;
    return pdf;
}

// The density (solid angle) of lamina1_sample's wo for light from wi.
float lamina1_pdf(vec3 wi, vec3 wo) {
    vec3 p, wi_in;
    float alpha_base;
    if (!l1_mixture(wi, p, alpha_base, wi_in)) return 0.0;
    return l1_pdf_with(wi, p, alpha_base, wi_in, wo);
}

// Draws wo for light from wi from three uniforms in [0, 1): true with wo, its density pdf and
// the weight f |cos θo| / pdf; false where the draw fails (as Bsdf::sample's nothing).
bool lamina1_sample(vec3 wi, vec3 u, out vec3 wo, out float pdf, out vec3 weight) {
    wo = vec3(0.0);
    pdf = 0.0;
    weight = vec3(0.0);
    vec3 p, wi_in;
    float alpha_base;
    if (!l1_mixture(wi, p, alpha_base, wi_in)) return false;
    float eta0 = l1_at(2);
    if (u.x < p.x) {
        vec3 m = l1_sample_visible_normal(l1_at(4), wi, u.y, u.z);
        wo = 2.0 * dot(wi, m) * m - wi;
    } else if (u.x < p.x + p.y) {
        if (int(l1_at(1)) == 0) {
            wo = l1_sample_cosine(u.y, u.z);
        } else {
            vec3 m = l1_sample_visible_normal(alpha_base, wi_in, u.y, u.z);
            vec3 wo_in = 2.0 * dot(wi_in, m) * m - wi_in;
            float s2 = eta0 * eta0 * (1.0 - wo_in.z * wo_in.z);
            if (wo_in.z <= 0.0 || s2 >= 1.0) return false;
            wo = vec3(wo_in.x * eta0, wo_in.y * eta0, sqrt(1.0 - s2));
        }
    } else if (p.z > 0.0) {
        wo = l1_sample_cosine(u.y, u.z);
    } else {
        return false;
    }
    if (wo.z <= 0.0) return false;
    pdf = l1_pdf_with(wi, p, alpha_base, wi_in, wo);
    if (!(pdf > 0.0)) return false;
    weight = lamina1_eval(wi, wo) * (wo.z / pdf);
    return true;
}

// lamina-coat in GLSL (OpenGL ES 3.0 / WebGL2; docs/lamina-coat.md): the same function as
// lamina_coat_eval in src/models/lamina_coat/lamina_coat.cpp, tested against it to 1e-4
// (tests/models/lamina_coat/glsl_test.sh). Directions in the shading frame (normal +z).
//
// lamina_coat_table: docs/lamina-coat/tables.png (or tables.csv) as a 32 × 577 R16UI texture,
// read with texelFetch (value = integer / 65535). The constants are docs/lamina-coat/fit.csv.

const float LC_GRAZING = 0.0;      // k_g
const float LC_ROUGHENING = 0.125;  // k_r
const float LC_TINT_PATH = 0.1;    // c_tau
const float LC_PI = 3.14159265358979;

uniform highp usampler2D lamina_coat_table;

struct LaminaCoatMaterial {
    float eta;         // coat index relative to the medium above, [1.1, 2.6]
    float alpha_coat;  // GGX alpha = r^2
    vec3 tau;          // the coat's optical depth at normal incidence
    bool conductor;
    vec3 albedo;                  // Lambertian base
    vec3 base_eta, base_k;        // conductor base, relative to the coat
    float alpha_base;
};

float lc_texel(int row, int column) {
    return float(texelFetch(lamina_coat_table, ivec2(column, row), 0).r) / 65535.0;
}

// x in [0, 1] on n nodes: the lower node and the weight of the upper one.
void lc_node(float x, int n, out int i, out float w) {
    float s = clamp(x, 0.0, 1.0) * float(n - 1);
    i = min(int(s), n - 2);
    w = s - float(i);
}

float lc_bilinear(int row, int stride, int xi, float xw, float yw) {
    float lo = mix(lc_texel(row, xi), lc_texel(row, xi + 1), xw);
    float hi = mix(lc_texel(row + stride, xi), lc_texel(row + stride, xi + 1), xw);
    return mix(lo, hi, yw);
}

float lc_eta_coordinate(float eta) { return (eta - 1.1) / 1.5; }

float lc_albedo(float mu, float r, float eta) {  // E_c
    int xi, yi, zi; float xw, yw, zw;
    lc_node(mu, 32, xi, xw); lc_node(r, 32, yi, yw); lc_node(lc_eta_coordinate(eta), 16, zi, zw);
    float lo = lc_bilinear(zi * 32 + yi, 1, xi, xw, yw);
    float hi = lc_bilinear((zi + 1) * 32 + yi, 1, xi, xw, yw);
    return mix(lo, hi, zw);
}

float lc_white_albedo(float mu, float r) {  // E_w
    int xi, yi; float xw, yw;
    lc_node(mu, 32, xi, xw); lc_node(r, 32, yi, yw);
    return lc_bilinear(512 + yi, 1, xi, xw, yw);
}

float lc_average_albedo(float r, float eta) {  // Ē_c
    int xi, zi; float xw, zw;
    lc_node(r, 32, xi, xw); lc_node(lc_eta_coordinate(eta), 16, zi, zw);
    return lc_bilinear(544 + zi, 1, xi, xw, zw);
}

float lc_white_average_albedo(float r) {  // Ē_w
    int xi; float xw;
    lc_node(r, 32, xi, xw);
    return mix(lc_texel(560, xi), lc_texel(560, xi + 1), xw);
}

float lc_internal_absorption(float tau, float eta) {  // K_tau
    int xi, zi; float xw, zw;
    lc_node(tau / (1.0 + tau), 32, xi, xw); lc_node(lc_eta_coordinate(eta), 16, zi, zw);
    return lc_bilinear(561 + zi, 1, xi, xw, zw);
}

float lc_fresnel_dielectric(float c, float eta) {
    float g2 = eta * eta - 1.0 + c * c;
    if (g2 <= 0.0) return 1.0;
    float g = sqrt(g2);
    float a = (g - c) / (g + c), b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    return 0.5 * a * a * (1.0 + b * b);
}

// The exact conductor Fresnel (lamina's physics/fresnel.h, fresnel_conductor), per channel.
vec3 lc_fresnel_conductor(float c, vec3 eta, vec3 k) {
    c = clamp(c, 0.0, 1.0);
    float cos2 = c * c, sin2 = 1.0 - cos2;
    vec3 t0 = eta * eta - k * k - sin2;
    vec3 ab = sqrt(t0 * t0 + 4.0 * eta * eta * k * k);
    vec3 a = sqrt(max(0.5 * (ab + t0), 0.0));
    vec3 t1 = ab + cos2, t2 = 2.0 * c * a;
    vec3 rs = max(t1 - t2, 0.0) / (t1 + t2);
    vec3 t3 = cos2 * ab + sin2 * sin2, t4 = t2 * sin2;
    vec3 rp = rs * max(t3 - t4, 0.0) / (t3 + t4);
    return 0.5 * (rs + rp);
}

// GGX D and the height-correlated Smith G2 (Heitz 2014, Eq. 99); D written with h.xy so that a
// small alpha keeps its precision in single precision.
float lc_ggx_lobe(vec3 wi, vec3 wo, vec3 h, float alpha) {
    float a2 = alpha * alpha;
    float d = a2 * h.z * h.z + dot(h.xy, h.xy);
    float D = a2 / (LC_PI * d * d);
    float li = 0.5 * (-1.0 + sqrt(1.0 + a2 * dot(wi.xy, wi.xy) / (wi.z * wi.z)));
    float lo = 0.5 * (-1.0 + sqrt(1.0 + a2 * dot(wo.xy, wo.xy) / (wo.z * wo.z)));
    return D / (1.0 + li + lo) / (4.0 * wi.z * wo.z);
}

float lc_transmittance(float mu, float r, float eta) {
    return max(0.0, 1.0 - lc_albedo(mu, r, eta) - LC_GRAZING * (1.0 - lc_white_albedo(mu, r)));
}

vec3 lamina_coat_eval(LaminaCoatMaterial m, vec3 wi, vec3 wo) {
    if (wi.z <= 0.0 || wo.z <= 0.0) return vec3(0.0);
    float r = sqrt(m.alpha_coat), eta = m.eta;
    vec3 tau = m.tau * (1.0 + LC_TINT_PATH * r);
    float coat = 0.0;
    if (m.alpha_coat > 0.0) {
        vec3 h = normalize(wi + wo);
        coat = lc_fresnel_dielectric(dot(wi, h), eta) * lc_ggx_lobe(wi, wo, h, m.alpha_coat);
    }
    float white_average = lc_white_average_albedo(r);
    if (white_average < 1.0 - 1e-6)
        coat += LC_GRAZING / (LC_PI * (1.0 - white_average)) * (1.0 - lc_white_albedo(wi.z, r)) *
                (1.0 - lc_white_albedo(wo.z, r));
    vec3 wi_in = vec3(wi.xy / eta, sqrt(1.0 - (1.0 - wi.z * wi.z) / (eta * eta)));
    vec3 wo_in = vec3(wo.xy / eta, sqrt(1.0 - (1.0 - wo.z * wo.z) / (eta * eta)));
    float t = lc_transmittance(wi.z, r, eta) * lc_transmittance(wo.z, r, eta);
    vec3 tint = exp(-tau * (1.0 / wi_in.z + 1.0 / wo_in.z));
    vec3 base;
    if (m.conductor) {
        float alpha_b = sqrt(m.alpha_base * m.alpha_base + LC_ROUGHENING * m.alpha_coat * m.alpha_coat);
        if (alpha_b <= 0.0) return vec3(coat);
        vec3 h = normalize(wi_in + wo_in);
        base = lc_fresnel_conductor(dot(wi_in, h), m.base_eta, m.base_k) *
               lc_ggx_lobe(wi_in, wo_in, h, alpha_b);
    } else {
        float average = lc_average_albedo(r, eta) + LC_GRAZING * (1.0 - white_average);
        float K0 = 1.0 - (1.0 - average) / (eta * eta);
        vec3 K = K0 * vec3(lc_internal_absorption(tau.r, eta), lc_internal_absorption(tau.g, eta),
                           lc_internal_absorption(tau.b, eta));
        base = m.albedo / (LC_PI * (1.0 - m.albedo * K));
    }
    return vec3(coat) + base * tint * (t / (eta * eta));
}

// The delta lobes' reflectance towards the mirror direction of wi (LaminaCoat's delta_lobes in
// src/models/lamina_coat/lamina_coat.cpp, summed: they share that direction): a smooth coat's
// Fresnel reflectance F(μi), and a smooth conductor base (α_b = 0: base and coat smooth) seen
// through it, t(μi)² e^(−2 s τ/μt) F_base(μt). A renderer adds it times the radiance from the
// mirror direction.
vec3 lamina_coat_delta(LaminaCoatMaterial m, vec3 wi) {
    if (wi.z <= 0.0) return vec3(0.0);
    float r = sqrt(m.alpha_coat), eta = m.eta;
    vec3 R = vec3(m.alpha_coat == 0.0 ? lc_fresnel_dielectric(wi.z, eta) : 0.0);
    float alpha_b = sqrt(m.alpha_base * m.alpha_base + LC_ROUGHENING * m.alpha_coat * m.alpha_coat);
    if (m.conductor && alpha_b <= 0.0) {
        float mu_t = sqrt(1.0 - (1.0 - wi.z * wi.z) / (eta * eta));
        float t = lc_transmittance(wi.z, r, eta);
        R += lc_fresnel_conductor(mu_t, m.base_eta, m.base_k) *
             exp(-2.0 * m.tau * (1.0 + LC_TINT_PATH * r) / mu_t) * (t * t);
    }
    return R;
}

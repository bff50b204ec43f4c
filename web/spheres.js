// Live sphere renderings in WebGL2 (docs/explorer.md, "Live spheres"): the scene of `lamina render`
// (docs/rendering.md §2: an orthographic camera looking along −z at a unit sphere over grey 0.18,
// under a procedural environment) rendered by a fragment shader that adds one Monte-Carlo sample
// per pixel per pass to a float accumulation target, with `lamina render`'s light-sampling mixture
// (cosine, a GGX lobe about the mirror of the view, the cap lights) and its one-sample balance
// weights, plus a smooth coat's delta lobes exactly (their reflectance times the radiance from the
// view's mirror direction), as lamina render adds them. The BRDF is one of:
//   - "lamina-1": include/lamina1/lamina1.glsl (lamina1_eval) on the state `lamina export
//     --lamina1-gpu` (or `lamina study`) writes, in an R32F texture 256 texels wide;
//   - "lamina-coat": docs/lamina-coat/lamina_coat.glsl (lamina_coat_eval) on a material of
//     uniforms (its parameters), with its 32 × 577 R16UI table;
//   - a binned table (the page data's hemisphere of a source at each of the study's incidences, at
//     most 32, on at most 63 × 63 bins),
//     interpolated linearly between bin centres in θo and φo and between incidences in θi.
// The GLSL of lamina-1 and lamina-coat is not restated here: the page loads the shipped files
// (explorer/glsl.js holds them as strings, window.LAMINA_GLSL).
(function () {
  "use strict";

  // The procedural environments of render/environment.cpp (Environment::named), the one other
  // definition: a gradient sky(d) = horizon + (zenith − horizon)·d.y above a ground colour that
  // blends into the horizon over d.y ∈ [−1/4, 0], plus round cap lights at infinity. Keep the two
  // equal (the browser test renders both and compares).
  const ENVIRONMENTS = {
    studio: {
      zenith: [0.35, 0.35, 0.35], horizon: [0.18, 0.18, 0.18], ground: [0.06, 0.06, 0.06],
      caps: [[[-0.6, 0.55, 0.6], 11, [14, 14, 14]], [[0.8, 0.15, 0.55], 18, [2.5, 2.5, 2.5]],
        [[0.2, 0.6, -0.75], 9, [10, 10, 10]]],
    },
    uniform: { zenith: [1, 1, 1], horizon: [1, 1, 1], ground: [1, 1, 1], caps: [] },
    sky: {
      zenith: [0.25, 0.45, 0.9], horizon: [0.8, 0.85, 0.9], ground: [0.15, 0.12, 0.1],
      caps: [[[-0.3, 0.8, 0.5], 1.5, [900, 850, 750]]],
    },
  };
  const MAX_CAPS = 4;
  const EXTENT = 1.15;      // half-width of the view in sphere radii (RenderSettings::extent)
  const BACKGROUND = 0.18;  // RenderSettings::background

  const VERTEX = `#version 300 es
    void main() { vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
                  gl_Position = vec4(p, 0.0, 1.0); }`;

  // The sample pass. MODEL is 0 (lamina-1), 1 (lamina-coat) or 2 (a binned table).
  function samplePass(model, glsl) {
    return `#version 300 es
precision highp float; precision highp int; precision highp sampler2D; precision highp usampler2D;
#define MODEL ${model}
uniform highp sampler2D lamina1_state;
#if MODEL != 1
uniform highp usampler2D lamina_coat_table;
#endif
uniform highp sampler2D accum;       // the sums so far: RGB and the sum of squares of the mean
uniform highp sampler2D bins;        // MODEL 2: f of bin (θo, φo) at incidence k: row k·nt + t
uniform int size, pass_index;
uniform vec3 sky_zenith, sky_horizon, sky_ground;
uniform int n_caps;
uniform vec3 cap_dir[${MAX_CAPS}], cap_L[${MAX_CAPS}];
uniform float cap_cos[${MAX_CAPS}];
uniform float lobe_alpha;            // the proposal's GGX roughness (lobe_alpha_for)
// MODEL 1: the lamina-coat material.
uniform float mc_eta, mc_alpha_coat, mc_alpha_base;
uniform vec3 mc_tau, mc_albedo, mc_base_eta, mc_base_k;
uniform int mc_conductor;
// MODEL 2: bin edges (degrees) and incidences.
uniform int n_theta, n_phi, n_inc;
uniform float theta_edges[64], phi_edges[64], theta_inc[32];
out vec4 color;
${glsl.lamina1}
${model === 1 ? glsl.laminaCoat : ""}

// ---- random numbers: a counter hash per (pixel, pass, draw) (PCG of O'Neill 2014, RXS-M-XS) ----
uint sp_state;
uint sp_pcg(uint v) {
  uint s = v * 747796405u + 2891336453u;
  uint w = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
  return (w >> 22u) ^ w;
}
float sp_uniform() { sp_state = sp_pcg(sp_state); return float(sp_state >> 8) * (1.0 / 16777216.0); }

// ---- the environment (render/environment.cpp) ----
vec3 env_background(vec3 d) {
  if (d.y < 0.0) return sky_ground + (sky_horizon - sky_ground) * max(0.0, 1.0 + 4.0 * d.y);
  return sky_horizon + (sky_zenith - sky_horizon) * d.y;
}
vec3 env_radiance(vec3 d) {
  vec3 L = env_background(d);
  for (int k = 0; k < ${MAX_CAPS}; ++k)
    if (k < n_caps && dot(d, cap_dir[k]) >= cap_cos[k]) L += cap_L[k];
  return L;
}

// ---- the BRDF, local frame (z the normal), light from wi towards wo, 1/sr without the cosine ----
#if MODEL == 2
int sp_find(float x, int n, bool theta) {  // the bin centre at or below x: -1 below the first
  int k = -1;
  for (int j = 0; j < 63; ++j) {
    if (j >= n) break;
    float c = theta ? 0.5 * (theta_edges[j] + theta_edges[j + 1]) : 0.5 * (phi_edges[j] + phi_edges[j + 1]);
    if (c <= x) k = j;
  }
  return k;
}
float sp_centre(int j, bool theta) {
  return theta ? 0.5 * (theta_edges[j] + theta_edges[j + 1]) : 0.5 * (phi_edges[j] + phi_edges[j + 1]);
}
// Linear between bin centres (clamped to the first and last centre: beyond them the value of the
// edge bin), separably in θo and φo, at incidence k.
vec3 sp_table(int k, float theta_o, float phi_o) {
  int t0 = sp_find(theta_o, n_theta, true), p0 = sp_find(phi_o, n_phi, false);
  int t1 = min(t0 + 1, n_theta - 1), p1 = min(p0 + 1, n_phi - 1);
  t0 = max(t0, 0); p0 = max(p0, 0);
  float ct0 = sp_centre(t0, true), ct1 = sp_centre(t1, true);
  float cp0 = sp_centre(p0, false), cp1 = sp_centre(p1, false);
  float u = t1 > t0 ? clamp((theta_o - ct0) / (ct1 - ct0), 0.0, 1.0) : 0.0;
  float v = p1 > p0 ? clamp((phi_o - cp0) / (cp1 - cp0), 0.0, 1.0) : 0.0;
  int row = k * n_theta;
  vec3 a = texelFetch(bins, ivec2(p0, row + t0), 0).rgb, b = texelFetch(bins, ivec2(p1, row + t0), 0).rgb;
  vec3 c = texelFetch(bins, ivec2(p0, row + t1), 0).rgb, d = texelFetch(bins, ivec2(p1, row + t1), 0).rgb;
  return mix(mix(a, b, v), mix(c, d, v), u);
}
#endif

#if MODEL == 1
LaminaCoatMaterial sp_material() {
  LaminaCoatMaterial m;
  m.eta = mc_eta; m.alpha_coat = mc_alpha_coat; m.tau = mc_tau; m.conductor = mc_conductor == 1;
  m.albedo = mc_albedo; m.base_eta = mc_base_eta; m.base_k = mc_base_k; m.alpha_base = mc_alpha_base;
  return m;
}
#endif

vec3 sp_eval(vec3 wi, vec3 wo) {
#if MODEL == 0
  return lamina1_eval(wi, wo);
#elif MODEL == 1
  return lamina_coat_eval(sp_material(), wi, wo);
#else
  if (wi.z <= 0.0 || wo.z <= 0.0) return vec3(0.0);
  // The table's frame: the light at φ = 0, wo at φo (folded tables: φo ∈ [0°, 180°]).
  float theta_i = degrees(acos(clamp(wi.z, -1.0, 1.0)));
  float theta_o = degrees(acos(clamp(wo.z, -1.0, 1.0)));
  float phi_o = abs(degrees(atan(wi.x * wo.y - wi.y * wo.x, wi.x * wo.x + wi.y * wo.y)));
  if (length(wi.xy) < 1e-6) phi_o = 0.0;
  int k0 = 0;
  for (int k = 0; k < 32; ++k)
    if (k < n_inc && theta_inc[k] <= theta_i) k0 = k;
  int k1 = min(k0 + 1, n_inc - 1);
  float t = k1 > k0 ? clamp((theta_i - theta_inc[k0]) / (theta_inc[k1] - theta_inc[k0]), 0.0, 1.0) : 0.0;
  return max(mix(sp_table(k0, theta_o, phi_o), sp_table(k1, theta_o, phi_o), t), vec3(0.0));
#endif
}

// The delta lobes' reflectance towards the mirror direction of wo (a smooth coat, and a smooth base
// under it): lamina1_delta, lamina_coat_delta; a binned table holds none (its bins average them).
vec3 sp_delta(vec3 wo) {
#if MODEL == 0
  return lamina1_delta(wo);
#elif MODEL == 1
  return lamina_coat_delta(sp_material(), wo);
#else
  return vec3(0.0);
#endif
}

// ---- the light-sampling mixture of render/renderer.cpp (Mixture) ----
float c_cos, c_lobe, c_cap;
void sp_mixture() {
  bool caps = n_caps > 0, lobe = lobe_alpha > 0.0;
  c_lobe = lobe ? (caps ? 0.3 : 0.5) : 0.0;
  c_cap = caps ? (lobe ? 0.4 : 0.5) / float(n_caps) : 0.0;
  c_cos = 1.0 - c_lobe - c_cap * float(n_caps);
}
float sp_alpha() { return max(lobe_alpha, 1e-3); }
void sp_basis(vec3 n, out vec3 t, out vec3 b) {  // any frame about n (Duff et al. 2017)
  float s = n.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (s + n.z), c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}
float sp_pdf(vec3 d, vec3 wi, vec3 wo) {
  float p = wi.z > 0.0 ? c_cos * wi.z * L1_INV_PI : 0.0;
  if (c_lobe > 0.0 && wi.z > 0.0) {
    vec3 wm = normalize(wi + wo);
    float c = dot(wo, wm);
    if (c > 0.0) p += c_lobe * l1_d_visible(sp_alpha(), wo, wm) / (4.0 * c);
  }
  for (int k = 0; k < ${MAX_CAPS}; ++k)
    if (k < n_caps && dot(d, cap_dir[k]) >= cap_cos[k]) p += c_cap / (2.0 * L1_PI * (1.0 - cap_cos[k]));
  return p;
}

void main() {
  ivec2 px = ivec2(gl_FragCoord.xy);
  vec4 sums = pass_index > 0 ? texelFetch(accum, px, 0) : vec4(0.0);
  sp_state = sp_pcg(uint(px.x + size * px.y) ^ sp_pcg(uint(pass_index) * 0x9E3779B9u + 1u));
  float step = 2.0 * ${EXTENT.toFixed(2)} / float(size);
  // Image row 0 is at the top (as lamina render's), gl_FragCoord.y counts from the bottom.
  float sx = -${EXTENT.toFixed(2)} + (float(px.x) + sp_uniform()) * step;
  float sy = -${EXTENT.toFixed(2)} + (float(px.y) + sp_uniform()) * step;
  float r2 = sx * sx + sy * sy;
  vec3 L = vec3(${BACKGROUND});
  if (r2 < 1.0) {
    L = vec3(0.0);
    vec3 n = vec3(sx, sy, sqrt(1.0 - r2)), t, b;
    sp_basis(n, t, b);
    vec3 wo = vec3(t.z, b.z, n.z);  // the view (0, 0, 1) in the shading frame
    if (wo.z > 1e-9) {
      sp_mixture();
      float us = sp_uniform(), u1 = sp_uniform(), u2 = sp_uniform();
      vec3 d;
      if (us < c_cos) {
        vec3 w = l1_sample_cosine(u1, u2);
        d = w.x * t + w.y * b + w.z * n;
      } else if (us < c_cos + c_lobe) {
        vec3 m = l1_sample_visible_normal(sp_alpha(), wo, u1, u2);
        vec3 w = 2.0 * dot(wo, m) * m - wo;
        d = w.x * t + w.y * b + w.z * n;
      } else {
        int k = min(n_caps - 1, int((us - c_cos - c_lobe) / c_cap));
        vec3 cd = cap_dir[0];
        float cm = cap_cos[0];
        for (int j = 1; j < ${MAX_CAPS}; ++j) if (j == k) { cd = cap_dir[j]; cm = cap_cos[j]; }
        float cos_t = 1.0 - u1 * (1.0 - cm), sin_t = sqrt(max(1.0 - cos_t * cos_t, 0.0)), c, s;
        l1_cos_sin(2.0 * L1_PI * u2, c, s);
        vec3 ct, cb;
        sp_basis(cd, ct, cb);
        d = sin_t * c * ct + sin_t * s * cb + cos_t * cd;
      }
      vec3 wi = vec3(dot(d, t), dot(d, b), dot(d, n));
      if (wi.z > 0.0) {
        float p = sp_pdf(d, wi, wo);
        if (p > 0.0) L = sp_eval(wi, wo) * env_radiance(d) * (wi.z / p);
      }
      // Delta lobes, exactly, as render/renderer.cpp adds them (reciprocity: the lobes seen from
      // wo): their reflectance times the radiance from the view's mirror direction 2(n·v)n − v.
      vec3 R = sp_delta(wo);
      if (R != vec3(0.0)) L += R * env_radiance(2.0 * n.z * n - vec3(0.0, 0.0, 1.0));
    }
  }
  float m = (L.r + L.g + L.b) / 3.0;
  color = sums + vec4(L, m * m);
}`;
  }

  // The display pass: the mean, exposure 2^EV, the ACES filmic fit of Narkowicz 2015 and the sRGB
  // transfer curve, as the PNGs of `lamina render` (render/image.cpp).
  const DISPLAY = `#version 300 es
precision highp float; precision highp sampler2D;
uniform highp sampler2D accum;
uniform float inv_n, exposure;
uniform int size;
out vec4 color;
float srgb(float x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055; }
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  vec3 x = texelFetch(accum, p, 0).rgb * inv_n * exposure;
  x = clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
  color = vec4(srgb(x.r), srgb(x.g), srgb(x.b), 1.0);
}`;

  // Decodes a base64 string of little-endian float32 (the lamina-1 state in the page data).
  function floatsOf(b64) {
    const s = atob(b64), bytes = new Uint8Array(s.length);
    for (let i = 0; i < s.length; ++i) bytes[i] = s.charCodeAt(i);
    return new Float32Array(bytes.buffer);
  }

  // lamina-1's state for variant k of the page data's states (config.json → lamina1_gpu): the
  // stack's own state (the first `state` floats of `all`) with the variant's per-material part
  // (`head` floats, then `tail` floats: a slab's bins, at the state's end) in place; k < 0 or
  // null: the stack's own.
  function variantState(all, layout, k) {
    const state = all.slice(0, layout.state);
    if (k === null || k < 0) return state;
    const tail = layout.tail || 0, at = layout.state + k * (layout.head + tail);
    state.set(all.subarray(at, at + layout.head));
    if (tail) state.set(all.subarray(at + layout.head, at + layout.head + tail), layout.state - tail);
    return state;
  }

  // A renderer on `canvas` (size × size pixels), or null with `why` when the browser has no WebGL2
  // float render targets. `glsl` holds the shipped GLSL: {lamina1, laminaCoat, laminaCoatTable}.
  function createRenderer(canvas, size, glsl) {
    const gl = canvas.getContext("webgl2", { antialias: false, preserveDrawingBuffer: true });
    if (!gl) return { why: "This browser has no WebGL2: the live spheres need it." };
    if (!gl.getExtension("EXT_color_buffer_float"))
      return { why: "This browser's WebGL2 cannot render to float targets (EXT_color_buffer_float)." };
    if (!glsl || !glsl.lamina1) return { why: "The page's GLSL (explorer/glsl.js) is missing." };
    canvas.width = canvas.height = size;
    const compile = (type, text) => {
      const s = gl.createShader(type);
      gl.shaderSource(s, text);
      gl.compileShader(s);
      if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
      return s;
    };
    const link = (fsText) => {
      const p = gl.createProgram();
      gl.attachShader(p, compile(gl.VERTEX_SHADER, VERTEX));
      gl.attachShader(p, compile(gl.FRAGMENT_SHADER, fsText));
      gl.linkProgram(p);
      if (!gl.getProgramParameter(p, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(p));
      return p;
    };
    const programs = {};
    const program = (model) => (programs[model] = programs[model] || link(samplePass(model, glsl)));
    const display = link(DISPLAY);
    const texture = (unit, w, h, internal, format, type, data, filter) => {
      const t = gl.createTexture();
      gl.activeTexture(gl.TEXTURE0 + unit);
      gl.bindTexture(gl.TEXTURE_2D, t);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, filter || gl.NEAREST);
      gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, filter || gl.NEAREST);
      gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
      return t;
    };
    // Ping-pong accumulation targets.
    const targets = [0, 1].map(() => {
      const t = texture(0, size, size, gl.RGBA32F, gl.RGBA, gl.FLOAT, null);
      const fb = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, t, 0);
      return { t, fb };
    });
    const empty = { state: null, coat: null, bins: null };
    const dummy = () => texture(1, 1, 1, gl.R32F, gl.RED, gl.FLOAT, new Float32Array(1));
    empty.state = dummy();
    empty.bins = texture(3, 1, 1, gl.RGBA32F, gl.RGBA, gl.FLOAT, new Float32Array(4));
    empty.coat = texture(2, 1, 1, gl.R16UI, gl.RED_INTEGER, gl.UNSIGNED_SHORT, new Uint16Array(1));
    let coatTable = null;
    let scene = null, passes = 0, current = 0, fence = null;
    const r = {
      size,
      get samples() { return passes; },
      // scene: {model: "lamina-1" | "lamina-coat" | "table", env, lobeAlpha, state (floats),
      // material (lamina-coat), table: {theta_edges, phi_edges, theta_i, values (Float32Array of
      // [incidence][θ][φ][3])}}. Restarts the accumulation.
      setScene(s) {
        if (scene && scene.stateTex) gl.deleteTexture(scene.stateTex);
        if (scene && scene.binsTex) gl.deleteTexture(scene.binsTex);
        scene = Object.assign({}, s);
        const model = s.model === "lamina-1" ? 0 : s.model === "lamina-coat" ? 1 : 2;
        scene.index = model;
        scene.program = program(model);
        if (model === 0) {
          const rows = Math.ceil(s.state.length / 256), a = new Float32Array(rows * 256);
          a.set(s.state);
          scene.stateTex = texture(1, 256, rows, gl.R32F, gl.RED, gl.FLOAT, a);
        }
        if (model === 1 && !coatTable) {
          const t = glsl.laminaCoatTable;  // 577 rows of 32 16-bit integers
          coatTable = texture(2, 32, t.length / 32, gl.R16UI, gl.RED_INTEGER, gl.UNSIGNED_SHORT, new Uint16Array(t));
        }
        if (model === 2) {
          const tb = s.table, nt = tb.theta_edges.length - 1, np = tb.phi_edges.length - 1, ni = tb.theta_i.length;
          const a = new Float32Array(ni * nt * np * 4);
          for (let k = 0; k < ni * nt * np; ++k)
            for (let c = 0; c < 3; ++c) a[4 * k + c] = Number.isFinite(tb.values[3 * k + c]) ? tb.values[3 * k + c] : 0;
          scene.binsTex = texture(3, np, ni * nt, gl.RGBA32F, gl.RGBA, gl.FLOAT, a);
        }
        passes = 0;
      },
      // Adds `n` samples per pixel.
      step(n) {
        if (!scene) return;
        const p = scene.program, env = ENVIRONMENTS[scene.env] || ENVIRONMENTS.studio;
        gl.useProgram(p);
        const u = (name) => gl.getUniformLocation(p, name);
        gl.uniform1i(u("size"), size);
        gl.uniform3fv(u("sky_zenith"), env.zenith);
        gl.uniform3fv(u("sky_horizon"), env.horizon);
        gl.uniform3fv(u("sky_ground"), env.ground);
        gl.uniform1i(u("n_caps"), env.caps.length);
        if (env.caps.length) {
          const dirs = [], cosines = [], L = [];
          for (const [d, halfDeg, rad] of env.caps) {
            const l = Math.hypot(d[0], d[1], d[2]);
            dirs.push(d[0] / l, d[1] / l, d[2] / l);
            cosines.push(Math.cos((halfDeg * Math.PI) / 180));
            L.push(...rad);
          }
          gl.uniform3fv(u("cap_dir"), dirs);
          gl.uniform1fv(u("cap_cos"), cosines);
          gl.uniform3fv(u("cap_L"), L);
        }
        gl.uniform1f(u("lobe_alpha"), scene.lobeAlpha || 0);
        gl.uniform1i(u("lamina1_state"), 1);
        gl.uniform1i(u("lamina_coat_table"), 2);
        gl.uniform1i(u("bins"), 3);
        gl.uniform1i(u("accum"), 0);
        gl.activeTexture(gl.TEXTURE1);
        gl.bindTexture(gl.TEXTURE_2D, scene.stateTex || empty.state);
        gl.activeTexture(gl.TEXTURE2);
        gl.bindTexture(gl.TEXTURE_2D, coatTable || empty.coat);
        gl.activeTexture(gl.TEXTURE3);
        gl.bindTexture(gl.TEXTURE_2D, scene.binsTex || empty.bins);
        if (scene.index === 1) {
          const m = scene.material;
          gl.uniform1f(u("mc_eta"), m.eta);
          gl.uniform1f(u("mc_alpha_coat"), m.alpha_coat);
          gl.uniform1f(u("mc_alpha_base"), m.alpha_base);
          gl.uniform3fv(u("mc_tau"), m.tau);
          gl.uniform3fv(u("mc_albedo"), m.albedo);
          gl.uniform3fv(u("mc_base_eta"), m.base_eta);
          gl.uniform3fv(u("mc_base_k"), m.base_k);
          gl.uniform1i(u("mc_conductor"), m.conductor ? 1 : 0);
        }
        if (scene.index === 2) {
          const tb = scene.table;
          gl.uniform1i(u("n_theta"), tb.theta_edges.length - 1);
          gl.uniform1i(u("n_phi"), tb.phi_edges.length - 1);
          gl.uniform1i(u("n_inc"), tb.theta_i.length);
          gl.uniform1fv(u("theta_edges"), tb.theta_edges);
          gl.uniform1fv(u("phi_edges"), tb.phi_edges);
          gl.uniform1fv(u("theta_inc"), tb.theta_i);
        }
        gl.viewport(0, 0, size, size);
        for (let k = 0; k < n; ++k) {
          const from = targets[current], to = targets[1 - current];
          gl.activeTexture(gl.TEXTURE0);
          gl.bindTexture(gl.TEXTURE_2D, from.t);
          gl.bindFramebuffer(gl.FRAMEBUFFER, to.fb);
          gl.uniform1i(u("pass_index"), passes);
          gl.drawArrays(gl.TRIANGLES, 0, 3);
          current = 1 - current;
          ++passes;
        }
        if (fence) gl.deleteSync(fence);
        fence = gl.fenceSync(gl.SYNC_GPU_COMMANDS_COMPLETE, 0);
        gl.flush();
      },
      // Whether the passes of the last step are still running (WebGL runs asynchronously: a page
      // that steps again before they finish only queues work and stops responding).
      busy() {
        if (!fence) return false;
        if (gl.getSyncParameter(fence, gl.SYNC_STATUS) !== gl.SIGNALED) return true;
        gl.deleteSync(fence);
        fence = null;
        return false;
      },
      // Draws the mean so far on the canvas, tone-mapped as lamina render's PNG.
      show(exposure) {
        if (!passes) return;
        gl.useProgram(display);
        gl.activeTexture(gl.TEXTURE0);
        gl.bindTexture(gl.TEXTURE_2D, targets[current].t);
        gl.uniform1i(gl.getUniformLocation(display, "accum"), 0);
        gl.uniform1f(gl.getUniformLocation(display, "inv_n"), 1 / passes);
        gl.uniform1f(gl.getUniformLocation(display, "exposure"), Math.pow(2, exposure || 0));
        gl.bindFramebuffer(gl.FRAMEBUFFER, null);
        gl.viewport(0, 0, size, size);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
      },
      // The sums so far, rows from the top of the image: RGB sums and the sum of squares of the
      // channels' mean, per pixel (4 floats each).
      readSums() {
        gl.bindFramebuffer(gl.FRAMEBUFFER, targets[current].fb);
        const out = new Float32Array(4 * size * size), flipped = new Float32Array(4 * size * size);
        gl.readPixels(0, 0, size, size, gl.RGBA, gl.FLOAT, out);
        for (let y = 0; y < size; ++y)
          flipped.set(out.subarray(4 * size * (size - 1 - y), 4 * size * (size - y)), 4 * size * y);
        return flipped;
      },
      // Waits for the passes drawn so far (a one-pixel read back: gl.finish does not block in
      // every browser).
      finish() {
        gl.bindFramebuffer(gl.FRAMEBUFFER, targets[current].fb);
        gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.FLOAT, new Float32Array(4));
      },
    };
    return r;
  }

  window.LAMINA_SPHERES = { createRenderer, floatsOf, variantState, ENVIRONMENTS };
})();

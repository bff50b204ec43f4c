// docs/lamina-coat/lamina_coat.glsl evaluated by WebGL2 in headless Chromium, against the C++
// model's values (lamina eval): every pair and channel to 1e-4 relative (1e-7 absolute below).
// Usage: node glsl_test.js SRC_DIR WORK_DIR N_STACKS (WORK_DIR holds stackI.json, cppI.csv).
"use strict";
const fs = require("fs");
const path = require("path");
const { launchChromium } = require("../../support/chromium.js");

const [src, work, nStacks] = process.argv.slice(2);
const glsl = fs.readFileSync(path.join(src, "docs/lamina-coat/lamina_coat.glsl"), "utf8");
const table = fs.readFileSync(path.join(src, "docs/lamina-coat/tables.csv"), "utf8")
  .split("\n").filter((l) => l && !l.startsWith("#")).map((l) => l.split(",").map(Number));

const rgb = (v) => (Array.isArray(v) ? v : [v, v, v]);
const dir = (thetaDeg, phiDeg) => {
  const t = (thetaDeg * Math.PI) / 180, p = (phiDeg * Math.PI) / 180;
  return [Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t)];
};

const cases = [];
for (let s = 0; s < Number(nStacks); ++s) {
  const stack = JSON.parse(fs.readFileSync(path.join(work, `stack${s}.json`), "utf8"));
  const coat = stack.layers[0], base = stack.layers[1].interface;
  const eta = coat.interface.eta;
  const material = {
    eta, alpha_coat: coat.interface.alpha, tau: rgb(coat.medium ? coat.medium.tau_a : 0),
    conductor: base.type === "conductor", albedo: rgb(base.albedo || 0),
    base_eta: rgb(base.eta || 1).map((x) => x / eta), base_k: rgb(base.k || 0).map((x) => x / eta),
    alpha_base: base.alpha || 0,
  };
  const rows = fs.readFileSync(path.join(work, `cpp${s}.csv`), "utf8").trim().split("\n").slice(1)
    .map((l) => l.split(",")).map((c) => ({
      wi: dir(Number(c[0]), 0), wo: dir(Number(c[1]), Number(c[2])),
      f: [Number(c[4]), Number(c[5]), Number(c[6])],
    }));
  cases.push({ material, rows });
}

// Unpolarized Fresnel reflectance onto index n + iκ (relative) at cos θ = c, written
// independently of lamina: r_s = (c − n cos θt)/(c + n cos θt), r_p = (n² c − n cos θt)/(n² c +
// n cos θt), n cos θt = √(n² − sin²θ) (Born & Wolf §1.5.2, §14.2), in complex arithmetic.
function fresnel(c, n, k) {
  const mul = (a, b) => [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]];
  const div = (a, b) => {
    const d = b[0] * b[0] + b[1] * b[1];
    return [(a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d];
  };
  const sqrt = (a) => {
    const r = Math.hypot(a[0], a[1]), re = Math.sqrt((r + a[0]) / 2);
    return [re, re > 0 ? a[1] / (2 * re) : Math.sqrt((r - a[0]) / 2)];
  };
  const n2 = mul([n, k], [n, k]), ncos = sqrt([n2[0] - (1 - c * c), n2[1]]), n2c = [n2[0] * c, n2[1] * c];
  const ratio = (a, b) => { const q = div([a[0] - b[0], a[1] - b[1]], [a[0] + b[0], a[1] + b[1]]); return q[0] * q[0] + q[1] * q[1]; };
  return 0.5 * (ratio([c, 0], ncos) + ratio(n2c, ncos));
}
// lamina-coat's smooth limits at cos θi = mu: 0 for a rough coat; a smooth coat's F(μi; η) (to
// float32: 1e-4); with a smooth conductor base also t(μi)² e^(−2sτ/μt) F(μt; η1 + iκ1), t the
// coat's transmittance from its albedo table at r = 0, here 1 − F(μi) (the table's fit of a smooth
// interface's albedo, which is F: within 1e-2; measured 1.7e-3).
function smoothDelta(m, mu) {
  if (m.alpha_coat > 0) return { value: [0, 0, 0], tol: 1e-4 };
  const F = fresnel(mu, m.eta, 0);
  if (!m.conductor || m.alpha_base > 0) return { value: [F, F, F], tol: 1e-4 };
  const muT = Math.sqrt(1 - (1 - mu * mu) / (m.eta * m.eta));
  return { value: [0, 1, 2].map((c) => F + (1 - F) ** 2 * Math.exp(-2 * m.tau[c] / muT) *
    fresnel(muT, m.base_eta[c], m.base_k[c])), tol: 1e-2 };
}

// In the page: the table as an R16UI texture, the pairs as an RGBA32F texture (row 0: wi, row 1:
// wo), one fragment per pair into an RGBA32F framebuffer.
function evaluate({ glsl, table, cases }) {
  const canvas = document.createElement("canvas");
  const gl = canvas.getContext("webgl2");
  if (!gl) return { error: "no WebGL2" };
  if (!gl.getExtension("EXT_color_buffer_float")) return { error: "no EXT_color_buffer_float" };
  const compile = (type, text) => {
    const s = gl.createShader(type);
    gl.shaderSource(s, text);
    gl.compileShader(s);
    if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
    return s;
  };
  const program = gl.createProgram();
  gl.attachShader(program, compile(gl.VERTEX_SHADER, `#version 300 es
    void main() { vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
                  gl_Position = vec4(p, 0.0, 1.0); }`));
  gl.attachShader(program, compile(gl.FRAGMENT_SHADER, `#version 300 es
    precision highp float; precision highp int;
    ${glsl}
    uniform highp sampler2D pairs;
    uniform LaminaCoatMaterial material;
    uniform int delta;
    out vec4 color;
    void main() {
      int i = int(gl_FragCoord.x);
      vec3 wi = texelFetch(pairs, ivec2(i, 0), 0).xyz, wo = texelFetch(pairs, ivec2(i, 1), 0).xyz;
      color = vec4(delta == 1 ? lamina_coat_delta(material, wi) : lamina_coat_eval(material, wi, wo), 1.0);
    }`));
  gl.linkProgram(program);
  if (!gl.getProgramParameter(program, gl.LINK_STATUS)) throw new Error(gl.getProgramInfoLog(program));
  gl.useProgram(program);

  const texture = (unit, internal, format, type, w, h, data) => {
    const t = gl.createTexture();
    gl.activeTexture(gl.TEXTURE0 + unit);
    gl.bindTexture(gl.TEXTURE_2D, t);
    gl.pixelStorei(gl.UNPACK_ALIGNMENT, 1);
    gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
    gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
    return t;
  };
  texture(0, gl.R16UI, gl.RED_INTEGER, gl.UNSIGNED_SHORT, 32, table.length, new Uint16Array(table.flat()));
  gl.uniform1i(gl.getUniformLocation(program, "lamina_coat_table"), 0);
  gl.uniform1i(gl.getUniformLocation(program, "pairs"), 1);
  const u = (name) => gl.getUniformLocation(program, `material.${name}`);
  const results = [], deltas = [];
  for (const { material: m, rows } of cases) {
    const n = rows.length, data = new Float32Array(n * 2 * 4);
    rows.forEach((r, i) => { data.set([...r.wi, 0], i * 4); data.set([...r.wo, 0], (n + i) * 4); });
    texture(1, gl.RGBA32F, gl.RGBA, gl.FLOAT, n, 2, data);
    gl.uniform1f(u("eta"), m.eta); gl.uniform1f(u("alpha_coat"), m.alpha_coat);
    gl.uniform3fv(u("tau"), m.tau); gl.uniform1i(u("conductor"), m.conductor ? 1 : 0);
    gl.uniform3fv(u("albedo"), m.albedo); gl.uniform3fv(u("base_eta"), m.base_eta);
    gl.uniform3fv(u("base_k"), m.base_k); gl.uniform1f(u("alpha_base"), m.alpha_base);
    const target = texture(2, gl.RGBA32F, gl.RGBA, gl.FLOAT, n, 1, null);
    const fb = gl.createFramebuffer();
    gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
    gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
    gl.viewport(0, 0, n, 1);
    const pass = (delta) => {
      gl.uniform1i(gl.getUniformLocation(program, "delta"), delta);
      gl.drawArrays(gl.TRIANGLES, 0, 3);
      const out = new Float32Array(n * 4);
      gl.readPixels(0, 0, n, 1, gl.RGBA, gl.FLOAT, out);
      return Array.from(out);
    };
    results.push(pass(0));
    deltas.push(pass(1));
  }
  return { results, deltas, renderer: gl.getParameter(gl.RENDERER) };
}

async function main() {
  const { page, close } = await launchChromium({ width: 64, height: 64 });
  try {
    await page.setContent("<!doctype html><title>lamina-coat</title>");
    const r = await page.evaluate(evaluate, { glsl, table, cases });
    if (r.error) throw new Error(r.error);
    let worst = 0, failures = 0;
    cases.forEach((c, s) => c.rows.forEach((row, i) => {
      for (let ch = 0; ch < 3; ++ch) {
        const g = r.results[s][i * 4 + ch], f = row.f[ch];
        const err = Math.abs(g - f) / Math.max(Math.abs(f), 1e-3);
        worst = Math.max(worst, err);
        if (!(Math.abs(g - f) <= 1e-4 * Math.abs(f) + 1e-7)) {
          ++failures;
          console.log(`stack ${s} pair ${i} channel ${ch}: GLSL ${g}, C++ ${f}`);
        }
      }
    }));
    console.log(`${r.renderer}: ${cases.length * cases[0].rows.length} pairs, worst relative difference ${worst.toExponential(2)}`);
    // lamina_coat_delta against the smooth limits' closed forms (docs/lamina-coat.md).
    cases.forEach((c, s) => {
      let worstDelta = 0, largest = 0;
      c.rows.forEach((row, i) => {
        const want = smoothDelta(c.material, row.wi[2]);
        for (let ch = 0; ch < 3; ++ch) {
          const g = r.deltas[s][i * 4 + ch], err = Math.abs(g - want.value[ch]) / Math.max(want.value[ch], 1e-6);
          largest = Math.max(largest, want.value[ch]);
          worstDelta = Math.max(worstDelta, isNaN(err) ? Infinity : err);
        }
      });
      const tol = smoothDelta(c.material, 1).tol;
      console.log(`stack ${s}: lamina_coat_delta (largest ${largest.toFixed(4)}) against the closed form, ` +
        `max relative difference ${worstDelta.toExponential(2)} (bound ${tol})`);
      if (!(worstDelta <= tol)) {
        ++failures;
        console.log(`FAIL stack ${s}: lamina_coat_delta`);
      }
    });
    process.exitCode = failures ? 1 : 0;
  } finally {
    await close();
  }
}
main().catch((e) => { console.error(e); process.exit(1); });

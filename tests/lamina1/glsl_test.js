// lamina-1's GLSL form (include/lamina1/lamina1.glsl) in headless Chromium's WebGL2 against the
// C++ model: for each case, the state `lamina export --lamina1-gpu` wrote goes into an R32F
// texture, the directions into an RGBA32F one, one fragment per direction pair evaluates
// lamina1_eval into an RGBA32F target, and the values read back must equal `lamina eval
// --directions` (the C++) to TOL relative (float32 arithmetic; docs/lamina1.md).
// lamina1_delta(wi), the delta lobes' reflectance towards the mirror direction, against the closed
// form of a smooth coat (computed here, independently of lamina): 0 for a rough coat; the Fresnel
// reflectance F(μi; η0) (Born & Wolf §1.5.2) over a Lambertian or rough base; over a smooth
// conductor base, the incoherent sum of the two interfaces' reflections,
// F + R_b a² (1 − F)² / (1 − F R_b a²), with R_b the conductor's Fresnel reflectance for η + iκ
// relative to the coat at the refracted cosine μt (complex Snell's law) and a = e^(−τ/μt) the
// coat's transmittance (without inter-reflection, the series' first term: 1 in place of
// 1/(1 − F R_b a²)), to TOL relative.
// usage: node glsl_test.js REPO_ROOT DIR CASE...   (DIR/CASE.state, CASE.dirs.csv, CASE.ref.csv,
// CASE.stack.json, CASE.options)
"use strict";
const fs = require("fs");
const path = require("path");
const [root, dir, ...cases] = process.argv.slice(2);
const { launchChromium } = require(path.resolve(root, "tests/support/chromium.js"));
const TOL = 1e-4;

function readCsv(file) {
  const lines = fs.readFileSync(file, "utf8").trim().split("\n");
  const head = lines[0].split(",");
  return lines.slice(1).map((l) => {
    const v = l.split(",");
    const row = {};
    head.forEach((h, i) => (row[h] = v[i]));
    return row;
  });
}

function direction(thetaDeg, phiDeg) {
  const t = (thetaDeg * Math.PI) / 180, p = (phiDeg * Math.PI) / 180;
  return [Math.sin(t) * Math.cos(p), Math.sin(t) * Math.sin(p), Math.cos(t)];
}

// Complex numbers as [re, im].
const cx = {
  add: (a, b) => [a[0] + b[0], a[1] + b[1]],
  sub: (a, b) => [a[0] - b[0], a[1] - b[1]],
  mul: (a, b) => [a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0]],
  div: (a, b) => {
    const d = b[0] * b[0] + b[1] * b[1];
    return [(a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d];
  },
  sqrt: (a) => {
    const r = Math.hypot(a[0], a[1]), re = Math.sqrt((r + a[0]) / 2);
    return [re, re > 0 ? a[1] / (2 * re) : Math.sqrt((r - a[0]) / 2)];
  },
  abs2: (a) => a[0] * a[0] + a[1] * a[1],
};
// Unpolarized Fresnel reflectance from a medium of index 1 onto index n (complex: n + iκ) at
// cos θ = c: r_s = (c − n cos θt)/(c + n cos θt), r_p = (n c − cos θt)/(n c + cos θt) =
// (n² c − n cos θt)/(n² c + n cos θt), with n cos θt = √(n² − sin²θ) (Born & Wolf §1.5.2, §14.2).
// [R_s, R_p]; fresnel, their mean.
function fresnelSp(c, n) {
  const ncos = cx.sqrt(cx.sub(cx.mul(n, n), [1 - c * c, 0])), cc = [c, 0];
  const rs = cx.div(cx.sub(cc, ncos), cx.add(cc, ncos));
  const n2c = cx.mul(cx.mul(n, n), cc);
  const rp = cx.div(cx.sub(n2c, ncos), cx.add(n2c, ncos));
  return [cx.abs2(rs), cx.abs2(rp)];
}
function fresnel(c, n) {
  const [s, p] = fresnelSp(c, n);
  return 0.5 * (s + p);
}
const rgb = (v) => (Array.isArray(v) ? v : [v, v, v]);
// The closed form of the smooth coat's specular reflection of `stack` at cos θi = mu (RGB). A
// smooth slab (a dielectric base) is polarized unless polarization=off: the series per
// polarization, averaged (the s and p light stay apart between two smooth interfaces).
function smoothDelta(stack, options, mu) {
  const coat = stack.layers[0], base = stack.layers[1].interface;
  const eta0 = coat.interface.eta / (stack.ambient_eta || 1);
  if (coat.interface.alpha > 0) return [0, 0, 0];
  const F = fresnel(mu, [eta0, 0]);
  if (base.type === "lambertian" || base.alpha > 0) return [F, F, F];
  const muT = Math.sqrt(1 - (1 - mu * mu) / (eta0 * eta0));
  const tau = rgb(coat.medium ? coat.medium.tau_a : 0), series = !/inter-reflection=off/.test(options);
  if (base.type === "dielectric" && series && !/polarization=off/.test(options)) {
    const F_sp = fresnelSp(mu, [eta0, 0]), Rb_sp = fresnelSp(muT, [base.eta / coat.interface.eta, 0]);
    return [0, 1, 2].map((c) => {
      const a2 = Math.exp(-2 * tau[c] / muT);
      let R = 0;
      for (let p = 0; p < 2; p++)
        R += 0.5 * (F_sp[p] + (Rb_sp[p] * a2 * (1 - F_sp[p]) * (1 - F_sp[p])) / (1 - F_sp[p] * Rb_sp[p] * a2));
      return R;
    });
  }
  return [0, 1, 2].map((c) => {
    const Rb = base.type === "conductor"
      ? fresnel(muT, [rgb(base.eta)[c] / coat.interface.eta, rgb(base.k)[c] / coat.interface.eta])
      : fresnel(muT, [base.eta / coat.interface.eta, 0]);
    const a2 = Math.exp(-2 * tau[c] / muT);
    return F + (Rb * a2 * (1 - F) * (1 - F)) / (series ? 1 - F * Rb * a2 : 1);
  });
}

// The GLSL sampler against the C++ one (sampling.csv: pdf at wo; the sample drawn from u, its
// validity, direction and density): pdf to PDF_TOL relative (the mixture's base-lobe weight reads
// an interpolated curve on the GPU, the FGD table in C++), the same lobe and direction (to 1e-4)
// wherever u is not within 1e-3 of a lobe boundary, and each GLSL sample's density equal to the
// GLSL pdf at its direction (1e-5: the sampler and pdf agree, as a renderer needs). The directions
// hold to 1e-4 because the GLSL computes its own cos and sin (SwiftShader's are off by 1.9e-4).
const PDF_TOL = 1e-3;
function checkSampling(name, rows, pdfs, samples) {
  let worstPdf = 0, worstDir = 0, worstSelf = 0, compared = 0, skipped = 0, bad = 0;
  rows.forEach((r, i) => {
    const pdf = pdfs[4 * i];
    worstPdf = Math.max(worstPdf, Math.abs(pdf - +r.pdf) / Math.max(+r.pdf, 1e-30));
    const ok = pdfs[4 * i + 1] === 1;
    if (ok) {
      worstSelf = Math.max(worstSelf, Math.abs(pdfs[4 * i + 2] - pdfs[4 * i + 3]) / pdfs[4 * i + 3]);
    }
    if (+r.boundary < 1e-3) {
      skipped++;
      return;
    }
    if (ok !== (r.valid === "1")) {
      bad++;
      return;
    }
    if (!ok) return;
    compared++;
    for (let c = 0; c < 3; c++) worstDir = Math.max(worstDir, Math.abs(samples[4 * i + c] - +r[`ws${c}`]));
  });
  console.log(`${name} sampling: pdf max relative difference ${worstPdf.toExponential(2)}, ` +
    `${compared} samples' directions within ${worstDir.toExponential(2)} (${skipped} at a lobe ` +
    `boundary skipped, ${bad} drawn differently), sample pdf vs pdf ${worstSelf.toExponential(2)}`);
  const fail = !(worstPdf <= PDF_TOL) || !(worstDir <= 1e-4) || bad > 0 || !(worstSelf <= 1e-5) ||
    compared < rows.length / 2;
  if (fail) console.log(`FAIL ${name} sampling`);
  return fail ? 1 : 0;
}

(async () => {
  const glsl = fs.readFileSync(path.join(root, "include/lamina1/lamina1.glsl"), "utf8");
  const { page, close } = await launchChromium({ width: 64, height: 64 });
  await page.setContent("<canvas id=c></canvas>");
  let failures = 0;
  for (const name of cases) {
    const state = Array.from(new Float32Array(fs.readFileSync(path.join(dir, name + ".state")).buffer.slice(0)));
    const dirs = readCsv(path.join(dir, name + ".dirs.csv"));
    const ref = readCsv(path.join(dir, name + ".ref.csv"));
    // wi at φ = 0 (lamina's convention), wo at (θo, φo).
    const pairs = dirs.map((d) => [direction(+d.theta_i, 0), direction(+d.theta_o, +d.phi_o)]);
    const modes = [0, 3];
    const samplingFile = path.join(dir, name + ".sampling.csv");
    const sampling = fs.existsSync(samplingFile) ? readCsv(samplingFile) : null;
    if (sampling) {
      // wi, wo and u of each pair from the sampling file (the same wi and wo as dirs.csv).
      sampling.forEach((r, i) => pairs[i].push([+r.u0, +r.u1, +r.u2]));
      modes.push(1, 2);
    }
    const outs = await page.evaluate(({ glsl, state, pairs, modes }) => {
      const gl = document.getElementById("c").getContext("webgl2");
      if (!gl || !gl.getExtension("EXT_color_buffer_float")) return "no WebGL2 float targets";
      const vs = `#version 300 es
        in vec2 p; void main() { gl_Position = vec4(p, 0.0, 1.0); }`;
      const fs = `#version 300 es
        precision highp float; precision highp int; precision highp sampler2D;
        uniform highp sampler2D lamina1_state;
        uniform highp sampler2D pairs;
        uniform int mode;
        out vec4 color;
        ${glsl}
        void main() {
          int i = int(gl_FragCoord.x);
          vec3 wi = texelFetch(pairs, ivec2(3 * i, 0), 0).xyz;
          vec3 wo = texelFetch(pairs, ivec2(3 * i + 1, 0), 0).xyz;
          vec3 u = texelFetch(pairs, ivec2(3 * i + 2, 0), 0).xyz;
          if (mode == 0 || mode == 3) {
            color = vec4(mode == 0 ? lamina1_eval(wi, wo) : lamina1_delta(wi), 1.0);
            return;
          }
          vec3 ws, weight;
          float pdf_s;
          bool ok = lamina1_sample(wi, u, ws, pdf_s, weight);
          if (mode == 1)  // the density at wo, and the sample's own density against pdf() there
            color = vec4(lamina1_pdf(wi, wo), ok ? 1.0 : 0.0, pdf_s, ok ? lamina1_pdf(wi, ws) : 0.0);
          else
            color = vec4(ws, weight.g);
        }`;
      const shader = (type, src) => {
        const s = gl.createShader(type);
        gl.shaderSource(s, src);
        gl.compileShader(s);
        if (!gl.getShaderParameter(s, gl.COMPILE_STATUS)) throw new Error(gl.getShaderInfoLog(s));
        return s;
      };
      const prog = gl.createProgram();
      try {
        gl.attachShader(prog, shader(gl.VERTEX_SHADER, vs));
        gl.attachShader(prog, shader(gl.FRAGMENT_SHADER, fs));
      } catch (e) {
        return "compile: " + e.message;
      }
      gl.linkProgram(prog);
      if (!gl.getProgramParameter(prog, gl.LINK_STATUS)) return "link: " + gl.getProgramInfoLog(prog);
      gl.useProgram(prog);
      const texture = (unit, w, h, internal, format, data) => {
        const t = gl.createTexture();
        gl.activeTexture(gl.TEXTURE0 + unit);
        gl.bindTexture(gl.TEXTURE_2D, t);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MIN_FILTER, gl.NEAREST);
        gl.texParameteri(gl.TEXTURE_2D, gl.TEXTURE_MAG_FILTER, gl.NEAREST);
        gl.texImage2D(gl.TEXTURE_2D, 0, internal, w, h, 0, format, gl.FLOAT, data);
        return t;
      };
      const rows = Math.ceil(state.length / 256);
      const s = new Float32Array(rows * 256);
      s.set(state);
      texture(0, 256, rows, gl.R32F, gl.RED, s);
      const n = pairs.length;
      const d = new Float32Array(n * 12);
      pairs.forEach(([wi, wo, u], i) => {
        d.set([...wi, 0, ...wo, 0, ...(u || [0, 0, 0]), 0], 12 * i);
      });
      texture(1, 3 * n, 1, gl.RGBA32F, gl.RGBA, d);
      gl.uniform1i(gl.getUniformLocation(prog, "lamina1_state"), 0);
      gl.uniform1i(gl.getUniformLocation(prog, "pairs"), 1);
      const target = gl.createTexture();
      gl.activeTexture(gl.TEXTURE2);
      gl.bindTexture(gl.TEXTURE_2D, target);
      gl.texImage2D(gl.TEXTURE_2D, 0, gl.RGBA32F, n, 1, 0, gl.RGBA, gl.FLOAT, null);
      const fb = gl.createFramebuffer();
      gl.bindFramebuffer(gl.FRAMEBUFFER, fb);
      gl.framebufferTexture2D(gl.FRAMEBUFFER, gl.COLOR_ATTACHMENT0, gl.TEXTURE_2D, target, 0);
      gl.viewport(0, 0, n, 1);
      const buf = gl.createBuffer();
      gl.bindBuffer(gl.ARRAY_BUFFER, buf);
      gl.bufferData(gl.ARRAY_BUFFER, new Float32Array([-1, -1, 3, -1, -1, 3]), gl.STATIC_DRAW);
      const loc = gl.getAttribLocation(prog, "p");
      gl.enableVertexAttribArray(loc);
      gl.vertexAttribPointer(loc, 2, gl.FLOAT, false, 0, 0);
      const outs = [];
      for (const mode of modes) {
        gl.uniform1i(gl.getUniformLocation(prog, "mode"), mode);
        gl.drawArrays(gl.TRIANGLES, 0, 3);
        const out = new Float32Array(4 * n);
        gl.readPixels(0, 0, n, 1, gl.RGBA, gl.FLOAT, out);
        outs.push(Array.from(out));
      }
      return outs;
    }, { glsl, state, pairs, modes });
    if (typeof outs === "string") {
      console.log(`FAIL ${name}: ${outs}`);
      failures++;
      continue;
    }
    const got = outs[0];
    let worst = 0, where = "";
    for (let i = 0; i < ref.length; i++) {
      const r = [+ref[i].f_r, +ref[i].f_g, +ref[i].f_b];
      for (let c = 0; c < 3; c++) {
        const g = got[4 * i + c];
        const rel = Math.abs(g - r[c]) / Math.max(Math.abs(r[c]), 1e-30);
        if (!(rel <= worst) && !(Math.abs(g - r[c]) === 0)) {
          worst = Math.max(worst, isNaN(rel) ? Infinity : rel);
          where = `θi ${dirs[i].theta_i} θo ${dirs[i].theta_o} φo ${dirs[i].phi_o} ch ${c}: ${g} vs ${r[c]}`;
        }
      }
    }
    console.log(`${name}: ${ref.length} pairs, max relative difference ${worst.toExponential(2)} (${where})`);
    if (!(worst <= TOL)) {
      console.log(`FAIL ${name}: above ${TOL}`);
      failures++;
    }
    // lamina1_delta against the closed form.
    const stack = JSON.parse(fs.readFileSync(path.join(dir, name + ".stack.json"), "utf8"));
    const options = fs.readFileSync(path.join(dir, name + ".options"), "utf8");
    let worstDelta = 0, whereDelta = "", largest = 0;
    pairs.forEach(([wi], i) => {
      const want = smoothDelta(stack, options, wi[2]);
      for (let c = 0; c < 3; c++) {
        const g = outs[1][4 * i + c], err = Math.abs(g - want[c]) / Math.max(want[c], 1e-6);
        largest = Math.max(largest, want[c]);
        if (!(err <= worstDelta)) {
          worstDelta = isNaN(err) ? Infinity : err;
          whereDelta = `θi ${dirs[i].theta_i} ch ${c}: ${g} vs ${want[c]}`;
        }
      }
    });
    console.log(`${name}: lamina1_delta (largest ${largest.toFixed(4)}) against the closed form, max ` +
      `relative difference ${worstDelta.toExponential(2)} (${whereDelta})`);
    if (!(worstDelta <= TOL)) {
      console.log(`FAIL ${name}: lamina1_delta above ${TOL}`);
      failures++;
    }
    if (sampling) failures += checkSampling(name, sampling, outs[2], outs[3]);
  }
  await close();
  process.exit(failures ? 1 : 0);
})();

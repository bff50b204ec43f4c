// The explorer's live spheres (web/spheres.js) in headless Chromium's WebGL2 (SwiftShader: software
// GL) against `lamina render`'s EXR of the same scene (model, stack, environment, 64² pixels, the
// same samples per pixel), docs/explorer.md "Live spheres".
//
// The browser's image G and two of lamina render's, A and B (seeds 1 and 2), are three independent
// estimates of the same image by the same estimator (the light-sampling mixture of
// render/renderer.cpp with its probabilities), so over the n pixels fully on the sphere, with x the
// mean of a pixel's channels:
//   - bias: z = mean(x_G − (x_A + x_B)/2) / (sd/√n) must satisfy |z| < 4 (pixels independent);
//   - no more spread than the renderer's own noise: δ = |x_G − x_A| − |x_B − x_A| has mean 0 when
//     G is distributed as B; z = mean(δ)/(sd(δ)/√n) < 4.
// Smooth coats (α = 0) put part of the image in delta lobes, which both renderers add exactly (their
// reflectance times the radiance from the view's mirror direction): the same statistics hold.
// Deliberately wrong variants (a cap light 10% brighter, a smooth coat without its mirror
// reflection) must be rejected by the same two z tests: the comparison can fail.
// Plus, with no C++ needed: a binned table of constant f = ρ/π (a Lambertian of albedo ρ) under the
// uniform environment must render ρ at every pixel (the furnace), mean within 4 se.
// usage: node spheres_test.js REPO_ROOT DIR   (DIR: CASE.l1gpu and CASE-{1,2}.exr per case)
"use strict";
const fs = require("fs");
const path = require("path");
const [root, dir] = process.argv.slice(2);
const { launchChromium } = require(path.resolve(root, "tests/support/chromium.js"));
const { readExr } = require(path.resolve(root, "tests/support/exr_reader.js"));
const SIZE = 64, SPP = 256, Z = 4;

const glsl = {
  lamina1: fs.readFileSync(path.join(root, "include/lamina1/lamina1.glsl"), "utf8"),
  laminaCoat: fs.readFileSync(path.join(root, "docs/lamina-coat/lamina_coat.glsl"), "utf8"),
  laminaCoatTable: fs.readFileSync(path.join(root, "docs/lamina-coat/tables.csv"), "utf8")
    .split("\n").filter((l) => l && !l.startsWith("#")).flatMap((l) => l.split(",").map(Number)),
};

// Pixels fully on the sphere, as render_sphere's mask.
function onSphere(x, y) {
  const px = (2 * 1.15) / SIZE, cx = -1.15 + (x + 0.5) * px, cy = 1.15 - (y + 0.5) * px;
  return Math.hypot(Math.abs(cx) + px / 2, Math.abs(cy) + px / 2) < 1;
}
const meanSd = (v) => {
  const m = v.reduce((s, x) => s + x, 0) / v.length;
  return [m, Math.sqrt(v.reduce((s, x) => s + (x - m) * (x - m), 0) / (v.length - 1))];
};

// 1 when G differs from lamina render's A and B beyond Z standard errors (FAIL printed unless
// `expected`: a wrong variant's rejection).
function compare(name, sums, passes, A, B, expected) {
  const g = [], a = [], b = [];
  for (let y = 0; y < SIZE; ++y)
    for (let x = 0; x < SIZE; ++x) {
      if (!onSphere(x, y)) continue;
      const p = y * SIZE + x;
      g.push((sums[4 * p] + sums[4 * p + 1] + sums[4 * p + 2]) / (3 * passes));
      a.push((A[3 * p] + A[3 * p + 1] + A[3 * p + 2]) / 3);
      b.push((B[3 * p] + B[3 * p + 1] + B[3 * p + 2]) / 3);
    }
  const n = g.length;
  const [bias, sdBias] = meanSd(g.map((v, i) => v - 0.5 * (a[i] + b[i])));
  const zBias = bias / (sdBias / Math.sqrt(n));
  const [spread, sdSpread] = meanSd(g.map((v, i) => Math.abs(v - a[i]) - Math.abs(b[i] - a[i])));
  const zSpread = spread / (sdSpread / Math.sqrt(n));
  const meanA = a.reduce((s, x) => s + x, 0) / n;
  const madG = g.reduce((s, v, i) => s + Math.abs(v - a[i]), 0) / n / meanA;
  const madB = b.reduce((s, v, i) => s + Math.abs(v - a[i]), 0) / n / meanA;
  console.log(`${name}: ${n} pixels, ${passes} spp: mean |G − A| ${(100 * madG).toFixed(2)}% of the ` +
    `mean (lamina render's own seed-to-seed |B − A| ${(100 * madB).toFixed(2)}%), bias ` +
    `${bias.toExponential(2)} (z ${zBias.toFixed(2)}), spread z ${zSpread.toFixed(2)}`);
  if (!(Math.abs(zBias) < Z) || !(zSpread < Z)) {
    console.log(`${expected ? "rejected as it must be" : "FAIL"} ${name}: beyond ${Z} standard errors`);
    return 1;
  }
  return 0;
}

(async () => {
  const { page, close } = await launchChromium({ width: 200, height: 200 });
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.setContent("<canvas id=c></canvas>");
  await page.addScriptTag({ path: path.join(root, "web/spheres.js") });
  // Renders a scene, returns the sums and the time per pass.
  const run = (scene) => page.evaluate(({ glsl, scene, SIZE, SPP }) => {
    const S = window.LAMINA_SPHERES;
    const r = S.createRenderer(document.getElementById("c"), SIZE, glsl);
    if (r.why) return r.why;
    if (scene.envDef) S.ENVIRONMENTS[scene.env] = scene.envDef;  // a wrong variant's environment
    if (scene.stateB64) scene.state = S.floatsOf(scene.stateB64);
    if (scene.table) scene.table.values = new Float32Array(scene.table.values);
    try {
      r.setScene(scene);
      r.step(1);
      r.finish();
    } catch (e) {
      return String(e.message || e);
    }
    const t0 = performance.now();
    r.step(SPP - 1);
    r.finish();
    const seconds = (performance.now() - t0) / 1000;
    r.show(0);
    return { sums: Array.from(r.readSums()), passes: r.samples, seconds };
  }, { glsl, scene, SIZE, SPP });

  let failures = 0;
  // A copy of one of spheres.js's environments with cap k's radiance times `scale`.
  const brighterCap = (env, k, scale) => {
    const e = JSON.parse(JSON.stringify(ENVIRONMENTS[env]));
    e.caps[k][2] = e.caps[k][2].map((x) => x * scale);
    return e;
  };
  const ENVIRONMENTS = await page.evaluate(() => window.LAMINA_SPHERES.ENVIRONMENTS);
  // `wrong`: a deliberately wrong variant of the scene of `tag`, which the comparison must reject
  // (the test can fail): `env` and `envDef` a changed environment, `coat` changed lamina-coat
  // parameters.
  const scenes = [
    { name: "lamina-1 plastic, studio", file: "plastic", env: "studio", model: "lamina-1" },
    { name: "lamina-1 plastic, uniform", file: "plastic", env: "uniform", model: "lamina-1" },
    { name: "lamina-1 frosted gold, studio", file: "frosted-gold", env: "studio", model: "lamina-1" },
    { name: "lamina-1 slab (its reflection), studio", file: "slab", env: "studio", model: "lamina-1" },
    { name: "lamina-coat plastic, studio", file: "plastic", env: "studio", model: "lamina-coat" },
    { name: "lamina-1 plastic, sky", file: "plastic", env: "sky", model: "lamina-1" },
    { name: "lamina-1 smooth plastic, studio", file: "smooth-plastic", env: "studio", model: "lamina-1" },
    { name: "lamina-1 smooth plastic, sky", file: "smooth-plastic", env: "sky", model: "lamina-1" },
    { name: "lamina-coat smooth plastic, studio", file: "smooth-plastic", env: "studio", model: "lamina-coat" },
    { name: "lamina-1 smooth gold (coat and base), studio", file: "smooth-gold", env: "studio", model: "lamina-1" },
    { name: "lamina-coat smooth gold (coat and base), studio", file: "smooth-gold", env: "studio",
      model: "lamina-coat" },
    { name: "WRONG lamina-1 plastic, studio with the key light 10% brighter", file: "plastic", env: "studio",
      model: "lamina-1", wrong: { env: "studio-key", envDef: brighterCap("studio", 0, 1.1) } },
    { name: "WRONG lamina-1 plastic, sky with the sun 10% brighter", file: "plastic", env: "sky",
      model: "lamina-1", wrong: { env: "sky-sun", envDef: brighterCap("sky", 0, 1.1) } },
    { name: "WRONG lamina-coat smooth plastic, studio without the mirror reflection (coat α 1e-4)",
      file: "smooth-plastic", env: "studio", model: "lamina-coat", wrong: { coat: { alpha_coat: 1e-4 } } },
  ];
  for (const s of scenes) {
    const stack = JSON.parse(fs.readFileSync(path.join(dir, s.file + ".json"), "utf8"));
    const tag = `${s.file}-${s.model}-${s.env}`;
    const scene = { model: s.model, env: s.env, lobeAlpha: Math.min(Math.max(stack.layers[0].interface.alpha, 0.02), 1) };
    if (s.wrong && s.wrong.env) Object.assign(scene, { env: s.wrong.env, envDef: s.wrong.envDef });
    if (s.model === "lamina-1")
      scene.stateB64 = fs.readFileSync(path.join(dir, s.file + ".l1gpu")).toString("base64");
    else {
      const coat = stack.layers[0], base = stack.layers[1].interface, eta = coat.interface.eta;
      const rgb = (v) => (Array.isArray(v) ? v : [v, v, v]);
      scene.material = {
        eta, alpha_coat: coat.interface.alpha, tau: rgb(coat.medium ? coat.medium.tau_a : 0),
        conductor: base.type === "conductor", albedo: rgb(base.albedo || 0),
        base_eta: rgb(base.eta || 1).map((x) => x / eta), base_k: rgb(base.k || 0).map((x) => x / eta),
        alpha_base: base.alpha || 0,
      };
      if (s.wrong && s.wrong.coat) Object.assign(scene.material, s.wrong.coat);
    }
    const out = await run(scene);
    if (typeof out === "string") {
      console.log(`FAIL ${s.name}: ${out}`);
      failures++;
      continue;
    }
    console.log(`${s.name}: ${(out.seconds / (out.passes - 1) * 1000).toFixed(1)} ms per pass of ` +
      `${SIZE}², ${((SIZE * SIZE * (out.passes - 1)) / out.seconds / 1e6).toFixed(2)} M samples/s (software GL)`);
    const A = readExr(path.join(dir, tag + "-1.exr")).rgb, B = readExr(path.join(dir, tag + "-2.exr")).rgb;
    const rejected = compare(s.name, out.sums, out.passes, A, B, !!s.wrong);
    if (s.wrong && !rejected) console.log(`FAIL ${s.name}: not rejected`);
    failures += s.wrong ? (rejected ? 0 : 1) : rejected;
  }

  // The furnace of the table path: a table of constant f = ρ/π on a 10° × 20° grid at three
  // incidences, under radiance 1, is ρ at every pixel.
  const rho = [0.8, 0.5, 0.2];
  const edges = (n, top) => Array.from({ length: n + 1 }, (_, k) => (top * k) / n);
  const nt = 9, np = 9, inc = [0, 40, 80], values = [];
  for (let k = 0; k < inc.length * nt * np; ++k) values.push(...rho.map((x) => x / Math.PI));
  const out = await run({ model: "table", env: "uniform", lobeAlpha: 0.3,
    table: { theta_edges: edges(nt, 90), phi_edges: edges(np, 180), theta_i: inc, values } });
  if (typeof out === "string") {
    console.log(`FAIL table furnace: ${out}`);
    failures++;
  } else {
    for (let c = 0; c < 3; ++c) {
      const v = [];
      for (let y = 0; y < SIZE; ++y)
        for (let x = 0; x < SIZE; ++x) if (onSphere(x, y)) v.push(out.sums[4 * (y * SIZE + x) + c] / out.passes);
      const [m, sd] = meanSd(v), z = (m - rho[c]) / (sd / Math.sqrt(v.length));
      console.log(`table furnace channel ${c}: mean ${m.toFixed(5)} for ρ ${rho[c]} (z ${z.toFixed(2)})`);
      if (!(Math.abs(z) < Z)) {
        console.log("FAIL table furnace");
        failures++;
      }
    }
  }
  // A variant's state as the page composes it (variantState, config.json → lamina1_gpu): the
  // slab's own state with the rougher slab's per-material part (its first HEAD floats and its
  // bins at the end) in place must be the rougher slab's state, float for float.
  const HEAD = 1860;  // lamina1::kGpuSlopeSum
  const slabOwn = fs.readFileSync(path.join(dir, "slab.l1gpu"));
  const slabRough = fs.readFileSync(path.join(dir, "slab-rough.l1gpu"));
  const composed = await page.evaluate(({ own, rough, HEAD }) => {
    const S = window.LAMINA_SPHERES, a = S.floatsOf(own), b = S.floatsOf(rough);
    const tail = a.length - 12585;  // lamina1::kGpuSize: the bins after it
    const all = new Float32Array(a.length + HEAD + tail);
    all.set(a);
    all.set(b.subarray(0, HEAD), a.length);
    all.set(b.subarray(b.length - tail), a.length + HEAD);
    const layout = { state: a.length, head: HEAD, tail };
    const v = S.variantState(all, layout, 0), own0 = S.variantState(all, layout, -1);
    let same = v.length === b.length, sameOwn = own0.length === a.length, differ = 0;
    for (let i = 0; i < b.length; ++i) if (v[i] !== b[i]) same = false;
    for (let i = 0; i < a.length; ++i) if (own0[i] !== a[i]) sameOwn = false;
    for (let i = 0; i < a.length; ++i) if (a[i] !== b[i]) ++differ;
    return { same, sameOwn, tail, differ };
  }, { own: slabOwn.toString("base64"), rough: slabRough.toString("base64"), HEAD });
  console.log(`variant state: ${JSON.stringify(composed)}`);
  if (!(composed.same && composed.sameOwn && composed.tail > 0 && composed.differ > 0)) {
    console.log("FAIL a variant's state composed as the page does it is not the variant's own state");
    failures++;
  }
  // No WebGL2: the renderer says why instead of throwing.
  const none = await page.evaluate(() => {
    const c = document.createElement("canvas");
    c.getContext("2d");  // a canvas holds one kind of context: WebGL2 is then unavailable on it
    return window.LAMINA_SPHERES.createRenderer(c, 8, { lamina1: "x" }).why || "";
  });
  console.log(`without WebGL2: "${none}"`);
  if (!/WebGL2/.test(none)) failures++;
  if (errors.length) {
    console.log("FAIL page errors: " + errors.join("; "));
    failures++;
  }
  await close();
  process.exit(failures ? 1 : 0);
})();

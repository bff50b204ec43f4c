// The explorer page of a small real study of one brushed configuration (an anisotropic stack:
// unfolded tables, lit from several azimuths; docs/explorer.md) in headless Chromium: it loads with
// no error, offers the light's azimuth φi, and turning φi draws that incidence — the slice along the
// plane φ = φi (its reference bit for bit the mean of tables.lza's bins on that plane) and the full
// hemisphere (φ over 0°–360°). Usage: node browser_unfolded.js STUDY_DIR SCREENSHOT
"use strict";
const fs = require("fs");
const path = require("path");
const { runStrictPageTest } = require("../support/chromium.js");
const { openExplorer } = require("./explorer_page.js");
const { readPacked } = require("../support/packed_reader.js");
const { expectedSrgb } = require("./browser_colour.js");

const [studyDir, shot] = process.argv.slice(2);

async function main(page, check) {
  const { shown, cfg } = await openExplorer(page, studyDir);
  check(Array.isArray(cfg.phi_i) && /unfolded/.test(cfg.grid), `${shown} is unfolded (test premise)`);
  const options = await page.evaluate(() => {
    const row = document.getElementById("w-phi-i-row");
    return { visible: !row.hidden && row.offsetParent !== null,
      values: Array.from(document.getElementById("w-phi-i").options).map((o) => Number(o.value)) };
  });
  check(options.visible, "the light's azimuth φi is offered");
  check(JSON.stringify(options.values) === JSON.stringify([...new Set(cfg.phi_i)].sort((a, b) => a - b)),
    `its values are the configuration's azimuths (${options.values})`);

  const tab = readPacked(path.resolve(studyDir, "configs", shown, "tables.lza"));
  const [, I, D, T, P] = tab.shape;
  check(P === 2 * JSON.parse(fs.readFileSync(path.resolve(studyDir, "study.json"), "utf8")).grid.n_phi,
    `tables.lza has the unfolded φ bins (${P})`);
  // The bins of the half-plane at azimuth a: the one it crosses, or the two it separates.
  const planeBins = (a) => {
    const u = (((a % 360) + 360) % 360) / (360 / P), k = Math.round(u);
    return Math.abs(u - k) < 1e-9 ? [(k + P - 1) % P, k % P] : [Math.floor(u) % P];
  };
  let before = await page.evaluate(() => Number(document.body.dataset.renders));
  for (const phi of [90, 45]) {
    await page.selectOption("#w-phi-i", String(phi));
    await page.waitForFunction((n) => Number(document.body.dataset.renders) > n, before, { timeout: 20000 });
    before = await page.evaluate(() => Number(document.body.dataset.renders));
    const st = await page.evaluate(() => window.LAMINA_EXPLORER.state);
    const title = await page.evaluate(() => document.getElementById("slice").layout.title.text);
    check(title.includes("φi = " + phi + "°"), `the slice shows φi = ${phi}° (${title.split(" · ").slice(0, 2).join(" · ")})`);
    // Which incidence: the page's θi at this φi.
    const theta = JSON.parse(fs.readFileSync(path.resolve(studyDir, "study.json"), "utf8")).theta_i[st.incidence];
    const inc = cfg.theta_i.findIndex((t, k) => t === theta && cfg.phi_i[k] === phi);
    check(inc >= 0 && inc < I, `the configuration has (θi, φi) = (${theta}°, ${phi}°)`);
    const at = (t, p) => tab.values[((inc * D + 0) * T * P + t * P + p) * 3];
    const mean = (bins, t) => { let v = 0; for (const p of bins) v += at(t, p); return Math.fround(v / bins.length); };
    const light = planeBins(phi), mirror = planeBins(phi + 180);
    const want = [];
    for (let x = 0; x < 2 * T; ++x) want.push(x < T ? mean(light, T - 1 - x) : mean(mirror, x - T));
    const drawn = await page.evaluate(() => Array.from(document.getElementById("slice").data.find((t) => t.name === "reference").y));
    check(drawn.length === want.length && drawn.every((v, x) => Math.abs(v - want[x]) <= 1e-6 * Math.abs(want[x])) && want.some((v) => v > 0),
      `the slice's reference is tables.lza's plane φ = ${phi}° (${drawn.slice(T - 2, T + 2)} against ${want.slice(T - 2, T + 2)})`);
    // The hemisphere: the map covers the whole disk (values below the plane φ = 0 too) and its
    // brightest pixel lies on the mirror side of the light, in the half-plane φ = φi + 180°.
    const hemi = await page.evaluate(() => {
      const t = document.getElementById("iso-ref").data[0];
      let best = -Infinity, bx = 0, by = 0, below = 0;
      t.z.forEach((row, j) => row.forEach((v, i) => {
        if (v === null) return;
        if (t.y[j] < -0.1) ++below;
        if (v > best) { best = v; bx = t.x[i]; by = t.y[j]; }
      }));
      return { bx, by, below };
    });
    check(hemi.below > 100, `the map covers the half-disk below the plane φ = 0 (${hemi.below} pixels)`);
    // Displayed at (x, y) = −sinθ (cos φ, sin φ): the mirror direction φi + 180° is at +(cos φi, sin φi).
    const c = Math.cos(phi * Math.PI / 180), s = Math.sin(phi * Math.PI / 180);
    check(hemi.bx * c + hemi.by * s > 0.2, `the reference's peak is on the mirror side of φi = ${phi}° (${hemi.bx.toFixed(2)}, ${hemi.by.toFixed(2)})`);
    // The polarization view (the study stored reference_stokes.lza): on the unfolded disk each
    // pixel shows its own bin's degree and angle, φ = atan2(−y, −x), no mirror image (red channel).
    const pol = await page.evaluate(() => {
      const dop = document.getElementById("pol-dop").data[0], aolp = document.getElementById("pol-aolp").data[0];
      return { state: document.body.dataset.polarization, x: Array.from(dop.x), y: Array.from(dop.y), dop: dop.z, aolp: aolp.z };
    });
    check(pol.state === "drawn", `the polarization view is drawn (${pol.state})`);
    const stokes = readPacked(path.resolve(studyDir, "configs", shown, "reference_stokes.lza"));
    const S = (k, t, p) => stokes.values[(((inc * D * 3) + k) * T * P + t * P + p) * 3];
    let worstDop = 0, worstAngle = 0, compared = 0, angles = 0;
    pol.dop.forEach((row, j) => row.forEach((v, i) => {
      const x = pol.x[i], y = pol.y[j], r = Math.hypot(x, y);
      if (v === null || r > 1) return;
      const ut = Math.asin(r) * 180 / Math.PI / (90 / T), up = ((Math.atan2(-y, -x) * 180 / Math.PI + 360) % 360) / (360 / P);
      if (Math.abs(ut - Math.round(ut)) < 0.05 || Math.abs(up - Math.round(up)) < 0.05) return;
      const t = Math.floor(ut), p = Math.floor(up) % P;
      worstDop = Math.max(worstDop, Math.abs(v - Math.min(1, Math.hypot(S(0, t, p), S(1, t, p), S(2, t, p)) / at(t, p))));
      ++compared;
      const a = pol.aolp[j][i];
      if (a !== null) { worstAngle = Math.max(worstAngle, Math.abs(a - 0.5 * Math.atan2(S(1, t, p), S(0, t, p)) * 180 / Math.PI)); ++angles; }
    }));
    check(compared > 3000 && angles > 100 && worstDop < 1e-4 && worstAngle < 0.01,
      `every pixel's degree and angle of polarization is its own bin's (${compared} pixels, ${angles} angles; worst ${worstDop}, ${worstAngle}°)`);
    // The colour view on the unfolded disk: each pixel the colour of its own bin (φ = atan2(−y, −x)
    // over 0°–360°, no mirror image), at the exposure of whole stops below the reference's
    // largest channel (18 × 36 bins: not merged), to one 8-bit step (16-bit codes).
    const col = await page.evaluate(() => {
      const t = document.getElementById("colour-disks").children[0].data[0];
      return { z: t.z, x0: t.x0, dx: t.dx, k: Number(document.getElementById("colour-view").dataset.exposure) };
    });
    let m = 0;
    for (let t = 0; t < T; ++t) for (let p = 0; p < P; ++p) for (let ch = 0; ch < 3; ++ch)
      m = Math.max(m, tab.values[((inc * D + 0) * T * P + t * P + p) * 3 + ch]);
    const k = Math.pow(2, -Math.ceil(Math.log2(m)));
    let worstColour = 0, colours = 0, opaqueBelow = 0;
    col.z.forEach((row, j) => row.forEach((v, i) => {
      const x = col.x0 + i * col.dx, y = col.x0 + j * col.dx, r = Math.hypot(x, y);
      if (r > 1 || v[3] !== 1) return;
      if (y < -0.1) ++opaqueBelow;
      const ut = Math.asin(r) * 180 / Math.PI / (90 / T), up = ((Math.atan2(-y, -x) * 180 / Math.PI + 360) % 360) / (360 / P);
      if (Math.abs(ut - Math.round(ut)) < 0.05 || Math.abs(up - Math.round(up)) < 0.05) return;
      const t = Math.floor(ut), p = Math.floor(up) % P;
      const want = expectedSrgb([0, 1, 2].map((ch) => tab.values[((inc * D + 0) * T * P + t * P + p) * 3 + ch] * k));
      worstColour = Math.max(worstColour, ...want.map((w, ch) => Math.abs(w - v[ch])));
      ++colours;
    }));
    check(col.k === k && opaqueBelow > 100 && colours > 3000 && worstColour <= 1,
      `the colour view's reference: every pixel is its own bin's sRGB at exposure ${col.k} (${colours} pixels; worst ${worstColour} step)`);
  }
  const hash = await page.evaluate(() => location.hash);
  check(hash.includes("phi=45"), `the address keeps φi (${hash})`);
  // An anisotropic stack has no live model: lamina-1's and lamina-coat's GLSL are isotropic and
  // an unfolded table has no interpolation here. The view says so.
  const live = await page.evaluate(() => ({ state: document.body.dataset.live,
    note: document.getElementById("live-note").textContent, hidden: document.getElementById("live-canvas").hidden,
    widgets: document.getElementById("live-coat").hidden && document.getElementById("live-l1").hidden }));
  check(live.state === "none" && /No model/.test(live.note) && live.hidden && live.widgets,
    `the live view has no model to render, and shows no model's widgets (${JSON.stringify(live)})`);
  await page.screenshot({ path: shot, fullPage: true });
  // Normal incidence is lit once (from φi = 0°): with the φi widget at 90° the slice says which
  // plane it shows rather than claiming the widget's.
  const thetas = JSON.parse(fs.readFileSync(path.resolve(studyDir, "study.json"), "utf8")).theta_i;
  const normal = thetas.indexOf(0);
  check(normal >= 0, "the study has θi = 0 (test premise)");
  let n = await page.evaluate(() => Number(document.body.dataset.renders));
  await page.selectOption("#w-phi-i", "90");
  await page.waitForFunction((k) => Number(document.body.dataset.renders) > k, n, { timeout: 20000 });
  n = await page.evaluate(() => Number(document.body.dataset.renders));
  await page.selectOption("#w-incidence", String(normal));
  await page.waitForFunction((k) => Number(document.body.dataset.renders) > k, n, { timeout: 20000 });
  const title0 = await page.evaluate(() => document.getElementById("slice").layout.title.text);
  check(title0.includes("θi = 0°, φi = 0°") && title0.includes("normal incidence is lit once, from φi = 0°"),
    `at θi = 0 the slice names the plane it shows (${title0})`);
}
runStrictPageTest(main);

// The explorer's colour view (web/colour.js, docs/explorer.md "Colour"), checked in the page the
// browser test opened on make_fixture.py's study: the sRGB shown for known bins equals the value
// computed here from tables.npy; the reference's ΔE00 against itself is 0; the CIEDE2000 function
// reproduces the published test data; the view's widgets redraw it.
"use strict";
const fs = require("fs");
const path = require("path");

// G. Sharma, W. Wu, E. N. Dalal, "The CIEDE2000 color-difference formula: implementation notes,
// supplementary test data, and mathematical observations", Color Res. Appl. 30(1), 21–30 (2005),
// Table 1: L1, a1, b1, L2, a2, b2, ΔE00 (to four decimals).
const SHARMA_2005 = [
  [50.0, 2.6772, -79.7751, 50.0, 0.0, -82.7485, 2.0425],
  [50.0, 3.1571, -77.2803, 50.0, 0.0, -82.7485, 2.8615],
  [50.0, 2.8361, -74.02, 50.0, 0.0, -82.7485, 3.4412],
  [50.0, -1.3802, -84.2814, 50.0, 0.0, -82.7485, 1.0],
  [50.0, -1.1848, -84.8006, 50.0, 0.0, -82.7485, 1.0],
  [50.0, -0.9009, -85.5211, 50.0, 0.0, -82.7485, 1.0],
  [50.0, 0.0, 0.0, 50.0, -1.0, 2.0, 2.3669],
  [50.0, -1.0, 2.0, 50.0, 0.0, 0.0, 2.3669],
  [50.0, 2.49, -0.001, 50.0, -2.49, 0.0009, 7.1792],
  [50.0, 2.49, -0.001, 50.0, -2.49, 0.001, 7.1792],
  [50.0, 2.49, -0.001, 50.0, -2.49, 0.0011, 7.2195],
  [50.0, 2.49, -0.001, 50.0, -2.49, 0.0012, 7.2195],
  [50.0, -0.001, 2.49, 50.0, 0.0009, -2.49, 4.8045],
  [50.0, -0.001, 2.49, 50.0, 0.001, -2.49, 4.8045],
  [50.0, -0.001, 2.49, 50.0, 0.0011, -2.49, 4.7461],
  [50.0, 2.5, 0.0, 50.0, 0.0, -2.5, 4.3065],
  [50.0, 2.5, 0.0, 73.0, 25.0, -18.0, 27.1492],
  [50.0, 2.5, 0.0, 61.0, -5.0, 29.0, 22.8977],
  [50.0, 2.5, 0.0, 56.0, -27.0, -3.0, 31.903],
  [50.0, 2.5, 0.0, 58.0, 24.0, 15.0, 19.4535],
  [50.0, 2.5, 0.0, 50.0, 3.1736, 0.5854, 1.0],
  [50.0, 2.5, 0.0, 50.0, 3.2972, 0.0, 1.0],
  [50.0, 2.5, 0.0, 50.0, 1.8634, 0.5757, 1.0],
  [50.0, 2.5, 0.0, 50.0, 3.2592, 0.335, 1.0],
  [60.2574, -34.0099, 36.2677, 60.4626, -34.1751, 39.4387, 1.2644],
  [63.0109, -31.0961, -5.8663, 62.8187, -29.7946, -4.0864, 1.263],
  [61.2901, 3.7196, -5.3901, 61.4292, 2.248, -4.962, 1.8731],
  [35.0831, -44.1164, 3.7933, 35.0232, -40.0716, 1.5901, 1.8645],
  [22.7233, 20.0904, -46.694, 23.0331, 14.973, -42.5619, 2.0373],
  [36.4612, 47.858, 18.3852, 36.2715, 50.5065, 21.2231, 1.4146],
  [90.8027, -2.0831, 1.441, 91.1528, -1.6435, 0.0447, 1.4441],
  [90.9257, -0.5406, -0.9208, 88.6381, -0.8985, -0.7239, 1.5381],
  [6.7747, -0.2908, -2.4247, 5.8714, -0.0985, -2.2286, 0.6377],
  [2.0776, 0.0795, -1.135, 0.9033, -0.0636, -0.5514, 0.9082],
];

// A float32 .npy file as make_fixture.py writes it (version 1.0, little-endian, C order).
function readNpy(file) {
  const buf = fs.readFileSync(file);
  const len = buf.readUInt16LE(8);
  const header = buf.subarray(10, 10 + len).toString("latin1");
  const shape = header.match(/'shape': \(([^)]*)\)/)[1].split(",").filter((s) => s.trim()).map(Number);
  const data = buf.subarray(10 + len);
  const values = new Float32Array(data.buffer.slice(data.byteOffset, data.byteOffset + data.length));
  return { shape, values };
}

// The sRGB transfer curve of IEC 61966-2-1 and the shown 8-bit colour of a linear value (negative
// channels as 0, a value above 1 scaled down to its largest channel, as docs/explorer.md says).
const encode = (v) => (v <= 0.0031308 ? 12.92 * v : 1.055 * Math.pow(v, 1 / 2.4) - 0.055);
function expectedSrgb(rgb) {
  const c = rgb.map((v) => Math.max(0, v)), m = Math.max(...c), s = m > 1 ? 1 / m : 1;
  return c.map((v) => Math.round(255 * encode(v * s)));
}

async function checkColour(page, studyDir, check) {
  const st = await page.evaluate(() => ({ config: document.body.dataset.config, inc: window.LAMINA_EXPLORER.state.incidence,
    side: window.LAMINA_EXPLORER.state.side }));
  const study = JSON.parse(fs.readFileSync(path.join(studyDir, "study.json"), "utf8"));
  const cfg = JSON.parse(fs.readFileSync(path.join(studyDir, "configs", st.config, "config.json"), "utf8"));
  const tab = readNpy(path.join(studyDir, "configs", st.config, "tables.npy"));
  const [S, I, D, T, P] = tab.shape;
  check(S === cfg.sources.length && T === study.grid.n_theta && P === study.grid.n_phi && st.side === "R",
    `the colour view's test reads ${st.config}'s tables (${tab.shape})`);
  const f = (s, t, p, c) => tab.values[((((s * I + st.inc) * D + 0) * T + t) * P + p) * 3 + c];

  // The exposure, computed here: whole stops below the reference's largest channel over its plane
  // (φ bins 0 and P − 1) and over the merged bins of the hemisphere (θ bins merged by ⌈T/45⌉ with
  // the weights Ω⊥ ∝ sin²θ1 − sin²θ0, φ by ⌈P/45⌉).
  let m = 0;
  for (let t = 0; t < T; ++t) for (let c = 0; c < 3; ++c) m = Math.max(m, f(0, t, 0, c), f(0, t, P - 1, c));
  const kt = Math.floor((T + 44) / 45), kp = Math.floor((P + 44) / 45);
  const rad = Math.PI / 180, w = (t) => Math.sin(((t + 1) * 90 / T) * rad) ** 2 - Math.sin((t * 90 / T) * rad) ** 2;
  const merged = (t2, p2, c) => {
    let num = 0, den = 0;
    for (let t = t2 * kt; t < Math.min(T, (t2 + 1) * kt); ++t)
      for (let p = p2 * kp; p < Math.min(P, (p2 + 1) * kp); ++p) { num += f(0, t, p, c) * w(t); den += w(t); }
    return num / den;
  };
  for (let t2 = 0; t2 * kt < T; ++t2) for (let p2 = 0; p2 * kp < P; ++p2) for (let c = 0; c < 3; ++c) m = Math.max(m, merged(t2, p2, c));
  const stops = Math.log2(m);
  check(Math.abs(stops - Math.round(stops)) > 1e-3, `the reference's maximum ${m.toPrecision(5)} is not at a whole stop (test premise)`);
  const k = Math.pow(2, -Math.ceil(stops));

  const view = await page.evaluate(() => {
    const strip = document.getElementById("colour-strip"), disks = document.getElementById("colour-disks");
    return {
      exposure: Number(document.getElementById("colour-view").dataset.exposure),
      meanDe: JSON.parse(document.getElementById("colour-view").dataset.meanDe),
      rows: strip.layout.yaxis.ticktext, strip: strip.data[0].z, stripType: strip.data[0].type,
      disks: Array.from(disks.children).map((d) => ({ source: d.dataset.source, type: d.data[0] && d.data[0].type,
        z: d.data[0] && d.data[0].z, x0: d.data[0] && d.data[0].x0, dx: d.data[0] && d.data[0].dx })),
    };
  });
  check(view.stripType === "image" && view.rows[0] === "reference" && view.rows.length === 1 + cfg.sources.slice(1)
    .filter((s) => cfg.supported[s].R).length, `the colour strip draws the reference and each supported model (${view.rows})`);
  check(view.disks.length === cfg.sources.length && view.disks[0].source === "reference" && view.disks[0].type === "image",
    `one colour disk per source (${view.disks.map((d) => d.source)})`);
  check(view.exposure === k, `the exposure is 2^${-Math.ceil(stops)} (${view.exposure})`);

  // Bins of the strip (full resolution: x < T the light's side at θ bin T − 1 − x, φ bin 0; x ≥ T
  // the mirror side at θ bin x − T, φ bin P − 1): the reference and the first model.
  for (const [row, s] of [[0, 0], [1, cfg.sources.indexOf(view.rows[1])]])
    for (const x of [10, T + Math.round((2 / 3) * T), 2 * T - 3]) {
      const [t, p] = x < T ? [T - 1 - x, 0] : [x - T, P - 1];
      const want = expectedSrgb([0, 1, 2].map((c) => f(s, t, p, c) * k));
      const got = view.strip[row][x].slice(0, 3);
      check(JSON.stringify(got) === JSON.stringify(want) && want.some((v, c) => v !== want[0]),
        `the strip's ${cfg.sources[s]} at θ bin ${t} (${x < T ? "light's side" : "mirror side"}) is sRGB ${got}, computed here ${want}`);
    }

  // A pixel of the reference's disk: (x, y) = (0.5, −0.2) lies in the merged bin θ = asin(r),
  // φ = atan2(|y|, −x); its colour from the merged value, to one 8-bit step (the page's hemisphere
  // is stored as 16-bit log codes, a relative step of 0.035 %).
  const d0 = view.disks[0], n = d0.z.length, i = Math.round((0.5 - d0.x0) / d0.dx), j = Math.round((-0.2 - d0.x0) / d0.dx);
  const x = d0.x0 + i * d0.dx, y = d0.x0 + j * d0.dx, theta = Math.asin(Math.hypot(x, y)) / rad;
  const phi = Math.atan2(Math.abs(y), -x) / rad;
  const t2 = Math.floor(theta / (90 * kt / T)), p2 = Math.floor(phi / (180 * kp / P));
  const want = expectedSrgb([0, 1, 2].map((c) => merged(t2, p2, c) * k));
  const got = d0.z[j][i].slice(0, 3);
  check(n === 101 && got.every((v, c) => Math.abs(v - want[c]) <= 1),
    `the reference's disk at θ ${theta.toFixed(1)}°, φ ${phi.toFixed(1)}° is sRGB ${got}, computed here ${want}`);
  check(d0.z[0][0][3] === 0, "outside the disk is transparent");

  // ΔE00: the reference against itself is 0 (the page's mean, by the same code as the models');
  // the fixture's ww09 is 1.1 × the reference, openpbr 0.9 ×: both differ.
  check(view.meanDe.reference === 0, `the reference's mean ΔE00 against itself is 0 (${view.meanDe.reference})`);
  check(view.meanDe.ww09 > 0 && view.meanDe.openpbr > 0, `ww09 and openpbr differ (${view.meanDe.ww09}, ${view.meanDe.openpbr})`);
  const de = await page.evaluate((pairs) => pairs.map((q) => [
    window.LAMINA_COLOUR.ciede2000(q.slice(0, 3), q.slice(3, 6)), window.LAMINA_COLOUR.ciede2000(q.slice(3, 6), q.slice(0, 3))]), SHARMA_2005);
  const worst = Math.max(...de.map(([a], q) => Math.abs(a - SHARMA_2005[q][6])));
  check(worst < 5e-5, `CIEDE2000 reproduces the 34 pairs of Sharma, Wu & Dalal (2005), Table 1, to their 4 decimals (worst ${worst.toExponential(2)})`);
  check(de.every(([a, b]) => Math.abs(a - b) < 1e-12), "CIEDE2000 is symmetric on those pairs");
  // CIELAB by hand: linear sRGB (1, 1, 1) is the white, L* = 100, a* = b* = 0; a grey of Y = 0.18
  // has L* = 116 · 0.18^(1/3) − 16 = 49.4961.
  const labs = await page.evaluate(() => [window.LAMINA_COLOUR.labOf([1, 1, 1]), window.LAMINA_COLOUR.labOf([0.18, 0.18, 0.18])]);
  check(Math.abs(labs[0][0] - 100) < 1e-9 && Math.abs(labs[0][1]) < 1e-9 && Math.abs(labs[0][2]) < 1e-9, `white is L*a*b* (100, 0, 0) (${labs[0]})`);
  check(Math.abs(labs[1][0] - 49.4961) < 1e-4 && Math.abs(labs[1][1]) < 1e-9, `a grey of Y = 0.18 has L* 49.4961 (${labs[1][0]})`);

  // The view's widgets: f · cos θo darkens grazing bins (the strip changes); one stop more doubles
  // the exposure; the incidence (the page's widget) redraws the view.
  const strip = () => page.evaluate(() => JSON.stringify(document.getElementById("colour-strip").data[0].z));
  const before = await strip();
  await page.selectOption("#w-colour-mode", "fcos");
  check((await strip()) !== before, "showing f · cos θo changes the colour strip");
  await page.selectOption("#w-colour-mode", "chroma");
  check(await page.evaluate(() => /equal luminance/.test(document.getElementById("colour-note").textContent)), "the chromaticity mode says so");
  await page.selectOption("#w-colour-mode", "f");
  check((await strip()) === before, "back to f, the same strip");
  await page.fill("#w-colour-ev", "1");
  await page.dispatchEvent("#w-colour-ev", "change");
  check(await page.evaluate((k) => Number(document.getElementById("colour-view").dataset.exposure) === 2 * k, k), "one stop more doubles the exposure");
  await page.fill("#w-colour-ev", "0");
  await page.dispatchEvent("#w-colour-ev", "change");
  check((await strip()) === before, "back to 0 stops, the same strip");
}

module.exports = { checkColour, expectedSrgb };

// The explorer's polarization view (docs/explorer.md, view 6) on a small REAL study with the
// polarized reference: every pixel of the degree-of-polarization map is the degree of its bin's
// Stokes vector, computed here from the study's files (reference_stokes.lza and the reference's f
// in tables.lza, docs/formats.md) with the disk's geometry written out independently of the page;
// the angle of linear polarization likewise (the opposite angle on the mirror half of a folded
// disk); both hemispheres of a slab are drawn. Usage: node browser_polarization.js STUDY_DIR SCREENSHOT
"use strict";
const path = require("path");
const { runStrictPageTest } = require("../support/chromium.js");
const { readPacked } = require("../support/packed_reader.js");

const [studyDir, shot] = process.argv.slice(2);

async function main(page, check) {
  for (const [id, side] of [["plastic-P1-a0.05", "R"], ["slab-a0.1-a1.3-clear", "R"], ["slab-a0.1-a1.3-clear", "T"]]) {
    await page.goto("about:blank");  // a new page load: the address's hash is read on loading
    await page.goto("file://" + path.resolve(studyDir, "index.html") + "#config=" + id + "&ti=60&side=" + side);
    await page.waitForFunction((want) => document.body.dataset.config === want && document.body.dataset.polarization,
      id, { timeout: 20000 });
    await page.evaluate(() => { window.LAMINA_EXPLORER.state.polChannel = 1; return window.LAMINA_EXPLORER.render(); });
    const what = `${id} ${side}`;
    check(await page.evaluate(() => document.body.dataset.polarization) === "drawn", `${what}: the polarization view is drawn`);
    check(await page.evaluate(() => document.getElementById("pol-none").hidden), `${what}: no "not polarized" note`);
    // The exact reference follows the microsurfaces' multiple scattering: nothing lost, no
    // microsurface-loss curve and no note about one.
    check(await page.evaluate(() => document.getElementById("albedo-lost-note").hidden &&
      !document.getElementById("albedo").data.some((t) => /lost to microsurfaces/.test(t.name || ""))),
      `${what}: no microsurface-loss curve or note (the exact reference loses nothing there)`);
    const drawn = await page.evaluate(() => {
      const dop = document.getElementById("pol-dop").data[0], aolp = document.getElementById("pol-aolp").data[0];
      return { x: Array.from(dop.x), y: Array.from(dop.y), dop: dop.z, se: dop.customdata, aolp: aolp.z };
    });
    // The study's files: f of the reference (source 0) and S1, S2, S3, at θi = 60° (the only
    // incidence), this side, green.
    const tab = readPacked(path.resolve(studyDir, "configs", id, "tables.lza"));
    const st = readPacked(path.resolve(studyDir, "configs", id, "reference_stokes.lza"));
    const [, , D, T, P] = tab.shape;
    const sd = side === "R" ? 0 : 1, c = 1;
    check(st.shape.join() === [2, 1, D, 3, T, P, 3].join(), `${what}: reference_stokes.lza has shape [2, 1, ${D}, 3, ${T}, ${P}, 3] (${st.shape})`);
    const f = (t, p) => tab.values[((sd * T + t) * P + p) * 3 + c];
    const S = (k, t, p) => st.values[(((sd * 3 + k) * T + t) * P + p) * 3 + c];
    // The grid is 18 × 18 (at most 45 × 45: the page merges no bins). Pixel (x, y) of the disk
    // shows θ = asin r, φ = atan2(|y|, −x) (light on the left); pixels within 0.2° of a bin edge
    // are left out (either bin may be drawn there).
    let compared = 0, worst = 0, worstAngle = 0, maxDop = 0, outside = 0, unlit = 0, angleWithoutDegree = 0;
    for (let j = 0; j < drawn.y.length; ++j)
      for (let i = 0; i < drawn.x.length; ++i) {
        const x = drawn.x[i], y = drawn.y[j], r = Math.hypot(x, y);
        const v = drawn.dop[j][i];
        if (r > 1) { outside += v !== null; continue; }
        const theta = Math.asin(Math.min(1, r)) * 180 / Math.PI, phi = Math.atan2(Math.abs(y), -x) * 180 / Math.PI;
        const ut = theta / (90 / T), up = phi / (180 / P);
        if (Math.abs(ut - Math.round(ut)) * 90 / T < 0.2 || Math.abs(up - Math.round(up)) * 180 / P < 0.2) continue;
        const t = Math.min(T - 1, Math.floor(ut)), p = Math.min(P - 1, Math.floor(up));
        const s1 = S(0, t, p), s2 = S(1, t, p), s3 = S(2, t, p), f0 = f(t, p);
        if (!(f0 > 0)) { unlit += v !== null; continue; }
        const dop = Math.hypot(s1, s2, s3) / f0;
        worst = Math.max(worst, Math.abs(v - Math.min(1, dop)));
        maxDop = Math.max(maxDop, v);
        ++compared;
        const a = drawn.aolp[j][i];
        if (a !== null) {
          const angle = 0.5 * Math.atan2(s2, s1) * 180 / Math.PI * (y > 0 ? -1 : 1);
          worstAngle = Math.max(worstAngle, Math.abs(a - angle));
          angleWithoutDegree += !(v > 2 * drawn.se[j][i] - 1e-4);
        }
      }
    check(compared > 5000, `${what}: ${compared} pixels compared`);
    check(outside === 0, `${what}: nothing is drawn outside the disk`);
    check(unlit === 0, `${what}: bins without light are blank`);
    check(angleWithoutDegree === 0, `${what}: an angle is drawn only where the degree exceeds twice its standard error`);
    // 16-bit codes over [0, 1] (a step of 1.5e-5) of a degree computed from the float16 files.
    check(worst < 1e-4, `${what}: every pixel's degree of polarization is its bin's √(S1² + S2² + S3²)/f from the files (worst difference ${worst})`);
    check(worstAngle < 0.01, `${what}: every drawn angle is its bin's ½ atan2(S2, S1), the opposite on the upper half (worst ${worstAngle}°)`);
    check(maxDop <= 1, `${what}: the degree is at most 1 (${maxDop})`);
    if (id.startsWith("plastic")) {
      // Light reflected by a smooth-ish coat of 1.5 at 60°, near Brewster's angle (56.3°), is
      // mostly s-polarized: R_s = 0.177 against R_p = 0.0017 for one smooth reflection.
      check(maxDop > 0.5, `${what}: the highlight near Brewster's angle is strongly polarized (max degree ${maxDop})`);
    }
    await page.screenshot({ path: shot.replace(/\.png$/, `-${id}-${side}.png`), fullPage: true });
  }
}
runStrictPageTest(main);

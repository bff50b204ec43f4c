// The explorer page of a small REAL study (written by `lamina study`, not a fixture) in headless
// Chromium: it loads from file:// with no console error, page error or network request, and draws
// the reference and the models. Usage: node browser_smoke.js STUDY_DIR SCREENSHOT
"use strict";
const fs = require("fs");
const path = require("path");
const { runStrictPageTest } = require("../support/chromium.js");
const { openExplorer } = require("./explorer_page.js");
const { readPacked } = require("../support/packed_reader.js");

const [studyDir, shot] = process.argv.slice(2);

async function main(page, check) {
  const { shown, cfg } = await openExplorer(page, studyDir);
  const names = await page.evaluate(() => document.getElementById("slice").data.map((t) => t.name));
  check(names.includes("reference"), "the slice draws the reference");
  check(names.some((n) => n !== "reference" && !/reference/.test(n || "")), "the slice draws a model");
  // The albedo view draws the reference's microsurface loss from the study's config.json.
  const lost = await page.evaluate(() => {
    const t = document.getElementById("albedo").data.find((t) => t.name === "reference: lost to microsurfaces");
    return t ? Array.from(t.y) : null;
  });
  const expected = cfg.energy.map((e) => e.lost_microsurface[0]);
  check(expected.some((v) => v > 0), `${shown} loses energy to its rough coat (test premise)`);
  check(lost !== null && lost.length === expected.length && lost.every((v, i) => Math.abs(v - expected[i]) <= 1e-12 * Math.max(1, expected[i])),
    `the albedo view draws the reference's microsurface loss (${lost} against config.json's ${expected})`);
  check(await page.evaluate(() => !document.getElementById("albedo-lost-note").hidden), "… with its note");
  // The slice draws exactly the reference's values of tables.lza (the page inflates the
  // explorer's packed data): the incidence shown, side R, red channel, along the incident plane.
  const tab = readPacked(path.resolve(studyDir, "configs", shown, "tables.lza"));
  const [, , D, T, P] = tab.shape;
  const inc = await page.evaluate(() => window.LAMINA_EXPLORER.state.incidence);
  const at = (t, p) => tab.values[((inc * D + 0) * T * P + t * P + p) * 3];
  const want = [];
  for (let x = 0; x < 2 * T; ++x) want.push(x < T ? at(T - 1 - x, 0) : at(x - T, P - 1));
  const drawn = await page.evaluate(() => Array.from(document.getElementById("slice").data.find((t) => t.name === "reference").y));
  check(drawn.length === want.length && drawn.every((v, x) => v === want[x]) && want.some((v) => v > 0),
    `the slice's reference is tables.lza's, bit for bit (${drawn.slice(0, 4)}… against ${want.slice(0, 4)}…)`);
  const info = await page.evaluate(() => document.getElementById("study-info").textContent);
  check(info.includes("the 2019 reference") && info.includes("single-scattering microsurfaces") && info.includes("unpolarized Fresnel factors"),
    `the header names the reference (${info})`);
  // The 2019 reference is not polarized: the polarization view says so and draws no map.
  const pol = await page.evaluate(() => ({ state: document.body.dataset.polarization,
    note: document.getElementById("pol-none").hidden ? "" : document.getElementById("pol-none").textContent,
    maps: document.getElementById("pol-maps").hidden }));
  check(pol.state === "none" && pol.note.startsWith("Not polarized") && pol.note.includes("--physics bpb19") && pol.maps,
    `the polarization view says the reference is not polarized (${JSON.stringify(pol)})`);
  check(!fs.existsSync(path.resolve(studyDir, "configs", shown, "reference_stokes.lza")),
    "an unpolarized study stores no reference_stokes.lza");
  const cells = await page.evaluate(() => (document.getElementById("leaderboard").data[0] || {}).z);
  check(Array.isArray(cells) && cells.length >= 2, "the leaderboard lists the configurations");
  // The live spheres (docs/explorer.md, "Live spheres"): they start once on screen, offer
  // lamina-1 (the study's states), lamina-coat (a Lambertian plastic) and the tables, and
  // each choice changes the image.
  await page.evaluate(() => document.getElementById("live-canvas").scrollIntoView());
  const liveImage = async (what) => {
    await page.waitForFunction(() => Number(document.body.dataset.liveSpp || 0) >= 16, null, { timeout: 60000 });
    return page.evaluate(() => {
      const c = document.getElementById("live-canvas"), t = document.createElement("canvas");
      t.width = c.width; t.height = c.height;
      const g = t.getContext("2d");
      g.drawImage(c, 0, 0);
      const px = g.getImageData(0, 0, c.width, c.height).data;
      let sum = 0;
      for (let k = 0; k < px.length; k += 4) sum += px[k] + px[k + 1] + px[k + 2];
      const centre = 4 * ((c.height >> 1) * c.width + (c.width >> 1));
      return { mean: sum / (px.length * 0.75), centre: Array.from(px.slice(centre, centre + 3)), corner: Array.from(px.slice(0, 3)) };
    });
  };
  const choose = async (id, value) => {
    await page.evaluate(([id, value]) => {
      document.body.dataset.liveSpp = "0";
      const e = document.getElementById(id);
      e.value = value;
      e.dispatchEvent(new Event("input"));
    }, [id, value]);
  };
  const offered = await page.evaluate(() => Array.from(document.getElementById("w-live-model").options).map((o) => o.value));
  check(["lamina-1", "lamina-coat", "table:reference", "table:lamina-1"].every((m) => offered.includes(m)), `the live view offers lamina-1, lamina-coat and the tables (${offered})`);
  const l1 = await liveImage();
  check(l1.centre.join() !== l1.corner.join() && l1.mean > 0, `lamina-1 draws a sphere (${JSON.stringify(l1)})`);
  const variant = await page.evaluate(() => Array.from(document.getElementById("w-live-l1").options).find((o) => /coat α = 0.5/.test(o.textContent)).value);
  await choose("w-live-l1", variant);
  const rough = await liveImage();
  check(Math.abs(rough.mean - l1.mean) > 0.5, `a rougher coat (α0 = 0.5, the study's state) changes the image (${l1.mean.toFixed(2)} → ${rough.mean.toFixed(2)})`);
  // A smooth coat (α0 = 0: a delta lobe, lamina1_delta) renders with its mirror reflection.
  const smoothVariant = await page.evaluate(() => {
    const o = Array.from(document.getElementById("w-live-l1").options).find((x) => x.textContent === "coat α = 0");
    return o ? o.value : null;
  });
  check(smoothVariant !== null, "lamina-1 offers a smooth coat (coat α = 0)");
  if (smoothVariant !== null) {
    await choose("w-live-l1", smoothVariant);
    const smooth = await liveImage();
    check(smooth.centre.join() !== smooth.corner.join() && Math.abs(smooth.mean - rough.mean) > 0.5,
      `a smooth coat (α0 = 0) draws a sphere unlike α0 = 0.5's (${rough.mean.toFixed(2)} → ${smooth.mean.toFixed(2)})`);
  }
  await choose("w-live-model", "lamina-coat");
  const coat = await liveImage();
  await choose("w-live-tau", "3");
  const dark = await liveImage();
  check(dark.mean < coat.mean - 0.5, `lamina-coat: an absorbing coat darkens the sphere (${coat.mean.toFixed(2)} → ${dark.mean.toFixed(2)})`);
  await choose("w-live-model", "table:reference");
  const ref = await liveImage();
  check(ref.centre.join() !== ref.corner.join(), `the reference's table draws a sphere (${JSON.stringify(ref)})`);
  await page.screenshot({ path: shot.replace(/\.png$/, "-live.png") });
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: shot, fullPage: true });
  // Without WebGL2 the view says so in place of the canvas, with no error.
  await page.addInitScript(() => {
    const get = HTMLCanvasElement.prototype.getContext;
    HTMLCanvasElement.prototype.getContext = function (kind, ...rest) {
      return kind === "webgl2" ? null : get.call(this, kind, ...rest);
    };
  });
  await page.reload();
  await page.waitForFunction(() => document.body.dataset.live === "unavailable", null, { timeout: 20000 });
  const note = await page.evaluate(() => ({ text: document.getElementById("live-note").textContent, hidden: document.getElementById("live-canvas").hidden }));
  check(/no WebGL2/.test(note.text) && note.hidden, `without WebGL2 the live view says so (${note.text})`);
}
runStrictPageTest(main);

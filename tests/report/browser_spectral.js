// The explorer's colour view on a small REAL spectral study (an iridescent configuration: the
// reference traced over 360–830 nm, its tables linear sRGB under D65) in headless Chromium: no
// console error, page error or network request; the reference's colours along the plane of
// incidence equal, to the 8 bits, those computed here from tables.lza; the reference's mean ΔE00
// against itself is 0 and the model's is not. Usage: node browser_spectral.js STUDY_DIR SCREENSHOT
"use strict";
const path = require("path");
const { runStrictPageTest } = require("../support/chromium.js");
const { openExplorer } = require("./explorer_page.js");
const { readPacked } = require("../support/packed_reader.js");
const { expectedSrgb } = require("./browser_colour.js");

const [studyDir, shot] = process.argv.slice(2);

async function main(page, check) {
  const { shown, cfg } = await openExplorer(page, studyDir);
  const inc = await page.evaluate(() => window.LAMINA_EXPLORER.state.incidence);
  check(cfg.category === "iridescent", `${shown} is of the iridescent category, whose reference is spectral (test premise)`);
  const tab = readPacked(path.resolve(studyDir, "configs", shown, "tables.lza"));
  const [, I, D, T, P] = tab.shape;
  check(T <= 45 && P <= 45, `the grid is not merged (${T} × ${P}: the test's premise)`);
  const f = (t, p, c) => tab.values[((inc * D + 0) * T * P + t * P + p) * 3 + c];
  let m = 0;
  for (let t = 0; t < T; ++t) for (let p = 0; p < P; ++p) for (let c = 0; c < 3; ++c) m = Math.max(m, f(t, p, c));
  const k = Math.pow(2, -Math.ceil(Math.log2(m)));
  const view = await page.evaluate(() => ({
    k: Number(document.getElementById("colour-view").dataset.exposure),
    meanDe: JSON.parse(document.getElementById("colour-view").dataset.meanDe),
    rows: document.getElementById("colour-strip").layout.yaxis.ticktext,
    z: document.getElementById("colour-strip").data[0].z,
  }));
  check(view.k === k, `the exposure is whole stops below the reference's largest channel (${view.k}, computed here ${k})`);
  let worst = 0, coloured = 0;
  for (let x = 0; x < 2 * T; ++x) {
    const [t, p] = x < T ? [T - 1 - x, 0] : [x - T, P - 1];
    const want = expectedSrgb([0, 1, 2].map((c) => f(t, p, c) * k));
    worst = Math.max(worst, ...want.map((w, c) => Math.abs(w - view.z[0][x][c])));
    if (Math.max(...want) - Math.min(...want) > 20) ++coloured;
  }
  check(worst === 0 && coloured > 0, `the strip's reference is tables.lza's plane in sRGB, every bin (${coloured} of ${2 * T} bins coloured; worst ${worst} steps)`);
  const models = view.rows.slice(1);
  check(view.meanDe.reference === 0 && models.length > 0 && models.every((s) => view.meanDe[s] > 0),
    `mean ΔE00: the reference against itself 0, the models above (${JSON.stringify(view.meanDe)})`);
  // The incident-plane view says its channels are colour, over config.json's range.
  const title = await page.evaluate(() => document.getElementById("slice").layout.title.text);
  check(cfg.spectral && title.includes("linear sRGB (D65) of a spectral reference, " + cfg.spectral.min_nm + "–" + cfg.spectral.max_nm + " nm"),
    `the slice's title names the spectral reference's channels (${title})`);
  await (await page.$("#colour-view")).screenshot({ path: shot });
}
runStrictPageTest(main);

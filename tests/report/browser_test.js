// The explorer page in a real browser (Debian's chromium driven by playwright-core; no browser is
// ever downloaded). Usage: node browser_test.js STUDY_DIR SCREENSHOT_DIR
//
// Opens STUDY_DIR/index.html from file:// (a study made by make_fixture.py), then checks: no
// console error or page error; each widget changes the data drawn (read back from Plotly's `data`
// on the plot elements); a click on a leaderboard cell opens that configuration. Screenshots go to
// SCREENSHOT_DIR. Exit code 0 when every check passes.
"use strict";
const fs = require("fs");
const path = require("path");
const { CHROMIUM, launchChromium } = require("../support/chromium.js");

const [studyDir, shotDir] = process.argv.slice(2);
let failures = 0, passes = 0;
const check = (ok, what) => {
  if (ok) { passes++; console.log("ok   " + what); } else { failures++; console.log("FAIL " + what); }
};

async function main() {
  if (!fs.existsSync(CHROMIUM)) {
    console.log(`FAIL ${CHROMIUM} is missing: run \`make deps\` (Debian's chromium)`);
    process.exit(1);
  }
  fs.mkdirSync(shotDir, { recursive: true });
  const browser = await launchChromium();
  const errors = [];
  try {
    const page = browser.page;
    page.on("console", (m) => { if (m.type() === "error") errors.push("console: " + m.text()); });
    page.on("pageerror", (e) => errors.push("page error: " + e.message));
    // Nothing may leave the machine: the page must work from file:// alone.
    await page.route(/^(https?|wss?):/, (route) => { errors.push("network request: " + route.request().url()); route.abort(); });

    const renders = () => page.evaluate(() => Number(document.body.dataset.renders || 0));
    const waitRender = async (before) => {
      await page.waitForFunction((n) => Number(document.body.dataset.renders || 0) > n, before, { timeout: 10000 });
    };
    // A digest of what a plot draws: its traces' names, x, y and z, and its axis types.
    const digest = (id) => page.evaluate((id) => {
      const gd = document.getElementById(id);
      const data = (gd.data || []).map((t) => [t.name, t.type, t.x && Array.from(t.x), t.y && Array.from(t.y), t.z, t.text]);
      const lay = gd.layout ? [gd.layout.yaxis && gd.layout.yaxis.type, gd.layout.title && gd.layout.title.text] : [];
      return JSON.stringify([data, lay]);
    }, id);
    const digests = async () => {
      const out = {};
      for (const id of ["slice", "iso-ref", "iso-model", "iso-diff", "albedo", "leaderboard"]) out[id] = await digest(id);
      return out;
    };
    // Runs `action`, waits for the page to redraw, and checks that the named plots changed.
    const changes = async (what, action, plots) => {
      const before = await digests();
      const n = await renders();
      await action();
      await waitRender(n);
      const after = await digests();
      for (const p of plots) check(before[p] !== after[p], `${what} changes the ${p} plot`);
    };

    const url = "file://" + path.resolve(studyDir, "index.html");
    const t0 = Date.now();
    await page.goto(url);
    await page.waitForFunction(() => Number(document.body.dataset.renders || 0) >= 1, null, { timeout: 15000 });
    console.log(`first draw ${Date.now() - t0} ms after navigation (draw ${await page.evaluate(() => document.body.dataset.drawMs)} ms: ${await page.evaluate(() => document.body.dataset.viewMs)})`);
    check(await page.evaluate(() => typeof Plotly === "object" && !!window.LAMINA_INDEX), "the page loads Plotly and the study index");
    check((await page.evaluate(() => document.getElementById("slice").data.length)) > 3, "the slice shows the reference, its band and models");
    await page.screenshot({ path: path.join(shotDir, "explorer-initial.png"), fullPage: true });

    const cfg0 = await page.evaluate(() => document.body.dataset.config);
    await changes("the incidence", () => page.selectOption("#w-incidence", "0"), ["slice", "iso-ref", "iso-model", "iso-diff"]);
    await changes("the G channel", () => page.uncheck("#w-ch-g"), ["slice", "albedo", "leaderboard"]);
    check(await page.evaluate(() => !document.getElementById("slice").data.some((t) => t.xaxis === "x3")), "two channels: two subplots");
    await changes("the log scale", () => page.uncheck("#w-log"), ["slice"]);
    await changes("a model", () => page.uncheck("#w-model-ww09"), ["slice", "albedo"]);
    check(await page.evaluate(() => !document.getElementById("slice").data.some((t) => t.name === "ww09")), "an unticked model is not drawn");
    // The model groups (study.json model_groups): a heading per family, a button that shows one.
    check(await page.evaluate(() => ["2019", "production", "ablations"].every((g) => document.getElementById("w-group-head-" + g))),
      "the models are grouped: 2019 study, production coats, their ablations");
    check(await page.evaluate(() => document.querySelector('#w-models label[data-group="production"]').textContent.includes("openpbr")),
      "openpbr is listed under the production coats");
    await changes("the production group", () => page.click("#w-group-production"), ["slice", "albedo"]);
    check(await page.evaluate(() => {
      const names = document.getElementById("slice").data.map((t) => t.name).filter((n) => window.LAMINA_EXPLORER.models.includes(n));
      return names.length > 0 && names.every((n) => n === "openpbr");
    }), "the production group alone: only openpbr is drawn");
    check(await page.evaluate(() => {
      const boxes = Array.from(document.querySelectorAll("#w-models input[type=checkbox]"));
      return boxes.filter((b) => b.checked).map((b) => b.id).join() === "w-model-openpbr";
    }), "its checkbox alone is ticked");
    await changes("every group", () => page.click("#w-group-all"), ["slice", "albedo"]);
    check(await page.evaluate(() => window.LAMINA_EXPLORER.state.shown.size === window.LAMINA_EXPLORER.models.length), "all: every model shown again");
    await changes("the iso model", () => page.selectOption("#w-iso-model", "ww-prime"), ["iso-model", "iso-diff"]);
    await changes("the iso channel", () => page.selectOption("#w-iso-channel", "2"), ["iso-ref", "iso-model"]);
    await changes("the difference mode", () => page.selectOption("#w-diff", "sigma"), ["iso-diff"]);
    await changes("the contour levels", async () => { await page.fill("#w-levels", "0.05, 0.2, 1"); await page.press("#w-levels", "Enter"); }, ["iso-ref"]);
    check(await page.evaluate(() => document.getElementById("iso-ref").data.length === 4), "three chosen levels: three contour traces");
    await changes("the leaderboard metric", () => page.selectOption("#w-lb-metric", "ae"), ["leaderboard"]);
    await changes("the leaderboard incidence", () => page.selectOption("#w-lb-incidence", "1"), ["leaderboard"]);
    await changes("the leaderboard aggregate", () => page.selectOption("#w-lb-agg", "max"), ["leaderboard"]);
    await page.check("#w-log");
    await page.check("#w-ch-g");
    await page.check("#w-model-ww09");
    await changes("a top-layer parameter (α0)", () => page.selectOption("#w-param-alpha0", "0.3"), ["slice", "iso-ref", "albedo"]);
    check((await page.evaluate(() => document.body.dataset.config)) === "plastic-P2-a0.3", "α0 = 0.3 opens plastic-P2-a0.3");
    // The colour view on this coloured plastic: known bins against tables.npy, ΔE00 against
    // published data.
    await require("./browser_colour.js").checkColour(page, studyDir, check);
    check(await page.evaluate(() => /bel18-forward/.test(document.getElementById("unsupported").textContent)), "an unsupported model is named as such");
    await changes("the category", () => page.selectOption("#w-category", "slab"), ["slice", "albedo"]);
    check((await page.evaluate(() => document.body.dataset.config)) === "slab-a0.1-a1.3-clear", "the slab category opens the slab");
    check(await page.evaluate(() => !document.getElementById("w-side-T").disabled), "a slab enables the BTDF");
    await changes("the hemisphere", () => page.check("#w-side-T"), ["slice", "iso-ref", "albedo"]);
    await page.screenshot({ path: path.join(shotDir, "explorer-slab-btdf.png"), fullPage: true });
    await changes("the configuration list", () => page.selectOption("#w-config", "slab-a0.1-a1.3-clear"), []);  // same: still redraws
    await page.check("#w-side-R");

    // Click the leaderboard cell (paint-a0.05-a1.3, ww-prime): the page opens that configuration.
    const target = "paint-a0.05-a1.3";
    await page.selectOption("#w-lb-metric", "me");
    await page.waitForTimeout(200);
    const pos = await page.evaluate((id) => {
      const gd = document.getElementById("leaderboard");
      const xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
      const r = gd.getBoundingClientRect();
      return { x: r.left + xa._offset + xa.d2p("ww-prime"), y: r.top + ya._offset + ya.d2p(id) };
    }, target);
    await page.evaluate(() => document.getElementById("leaderboard").scrollIntoView());
    const pos2 = await page.evaluate((id) => {
      const gd = document.getElementById("leaderboard");
      const xa = gd._fullLayout.xaxis, ya = gd._fullLayout.yaxis;
      const r = gd.getBoundingClientRect();
      return { x: r.left + xa._offset + xa.d2p("ww-prime"), y: r.top + ya._offset + ya.d2p(id) };
    }, target);
    await page.screenshot({ path: path.join(shotDir, "explorer-leaderboard.png") });
    const n = await renders();
    await page.mouse.click(pos2.x, pos2.y);
    await waitRender(n);
    check((await page.evaluate(() => document.body.dataset.config)) === target, `a leaderboard click opens ${target}`);
    check((await page.evaluate(() => window.LAMINA_EXPLORER.state.isoModel)) === "ww-prime", "… with the clicked model in the iso view");
    await page.waitForFunction(() => Array.from(document.querySelectorAll("#renders img")).every((i) => i.complete));
    check((await page.evaluate(() => Array.from(document.querySelectorAll("#renders img")).filter((i) => i.naturalWidth > 0).length)) === 4,
      "its four sphere renderings are shown");
    check(await page.evaluate(() => /rel\. RMSE 0\.13/.test(document.getElementById("renders").textContent) &&
      /not supported/.test(document.getElementById("renders").textContent)), "… with their errors, and the one that could not be drawn named");
    check(pos.y !== undefined && cfg0 !== target, "the click target differs from the first configuration");
    await page.screenshot({ path: path.join(shotDir, "explorer-after-click.png"), fullPage: true });

    // The state is in the address: reloading keeps the configuration.
    await page.reload();
    await page.waitForFunction(() => Number(document.body.dataset.renders || 0) >= 1);
    check((await page.evaluate(() => document.body.dataset.config)) === target, "a reload keeps the configuration (#config=…)");

    // The live lamina-coat sphere takes the configuration's RGB parameters as the study writes
    // them ("(0.8, 0.2, 0.1)"), not only grey ones: base colour, coat τa, the conductor's η and κ.
    const liveMaterial = async (id) => {
      const n = await renders();
      await page.evaluate((id) => window.LAMINA_EXPLORER.selectConfig(id), id);
      await waitRender(n);
      const offered = await page.evaluate(() => Array.from(document.getElementById("w-live-model").options).map((o) => o.value));
      if (!offered.includes("lamina-coat")) return { offered };
      await page.evaluate(() => {
        const e = document.getElementById("w-live-model");
        e.value = "lamina-coat";
        e.dispatchEvent(new Event("input"));
      });
      return page.evaluate(() => ({ material: JSON.parse(document.body.dataset.liveMaterial || "null"),
        colour: document.getElementById("w-live-colour").value, tau: document.getElementById("w-live-tau").value }));
    };
    const near = (a, b) => Array.isArray(a) && a.length === b.length && a.every((v, k) => Math.abs(v - b[k]) < 2e-3);
    const p2 = await liveMaterial("plastic-P2-a0.3");
    check(p2.material && p2.colour === "#cc331a" && near(p2.material.albedo, [0.8, 0.2, 0.102]),
      `lamina-coat's base colour is the configuration's ρ = (0.8, 0.2, 0.1) (${JSON.stringify(p2)})`);
    const paint = await liveMaterial("paint-a0.05-a1.3");
    check(paint.material && near(paint.material.base_k, [1 / 1.5, 0.01 / 1.5, 0.01 / 1.5]) &&
      near(paint.material.base_eta, [1.45 / 1.5, 1.45 / 1.5, 1.45 / 1.5]) && near(paint.material.tau, [0.1, 0.1, 0.1]) && paint.tau === "0.1",
      `lamina-coat's conductor takes κ1 = (1, 0.01, 0.01) per channel and τa 0.1 (${JSON.stringify(paint)})`);
    await page.evaluate(() => {
      const e = document.getElementById("w-live-tau");
      e.value = "0.2, 0, 1";
      e.dispatchEvent(new Event("input"));
    });
    check(near(await page.evaluate(() => JSON.parse(document.body.dataset.liveMaterial).tau), [0.2, 0, 1]),
      "the τa widget takes three values, r, g, b");
    // A stack of more than a coat over a base (its parameters count the layers) is not one
    // lamina-coat can draw: not offered.
    await page.evaluate(() => { window.LAMINA_EXPLORER.configs.find((c) => c.id === "plastic-P2-a0.3").parameters.layers = "3"; });
    const longer = await liveMaterial("plastic-P2-a0.3");
    check(Array.isArray(longer.offered) && !longer.offered.includes("lamina-coat"),
      `a stack of three layers is not offered to lamina-coat (${JSON.stringify(longer)})`);

    // A configuration whose data file is missing: its views are hidden and the page says which
    // file (the views of the configuration shown before must not stay up under the new name);
    // choosing another configuration shows the views again. (The browser reports the missing
    // file on its console; those messages are the point here, not failures.)
    const damaged = fs.mkdtempSync(path.join(require("os").tmpdir(), "lamina-explorer-"));
    fs.cpSync(studyDir, damaged, { recursive: true });
    const missing = "slab-a0.1-a1.3-clear";
    fs.rmSync(path.join(damaged, "explorer", "data", missing + ".js"));
    const errorsBefore = errors.length;
    await page.goto("file://" + path.resolve(damaged, "index.html") + "#config=plastic-P1-a0.05");
    await page.waitForFunction(() => Number(document.body.dataset.renders || 0) >= 1, null, { timeout: 15000 });
    await page.evaluate((id) => window.LAMINA_EXPLORER.selectConfig(id), missing);
    await page.waitForFunction((id) => document.body.dataset.loadError === id, missing, { timeout: 10000 });
    const shown = await page.evaluate(() => ({ text: document.getElementById("load-error").textContent,
      views: Array.from(document.querySelectorAll("main .view")).map((v) => getComputedStyle(v).display) }));
    check(shown.text.includes("explorer/data/" + missing + ".js") && shown.views.every((d) => d === "none"),
      `a missing data file is named and the views are hidden (${JSON.stringify(shown)})`);
    const n2 = await renders();
    await page.evaluate(() => window.LAMINA_EXPLORER.selectConfig("plastic-P1-a0.05"));
    await waitRender(n2);
    check(await page.evaluate(() => !document.body.dataset.loadError && document.getElementById("load-error").textContent === "" &&
      Array.from(document.querySelectorAll("main .view")).every((v) => getComputedStyle(v).display !== "none")),
      "another configuration shows its views again");
    const expected = errors.splice(errorsBefore);
    check(expected.every((e) => /ERR_FILE_NOT_FOUND|Failed to load resource/.test(e)),
      `only the missing file was reported on the console (${expected})`);
    fs.rmSync(damaged, { recursive: true, force: true });
  } finally {
    await browser.close();
  }
  for (const e of errors) console.log("FAIL " + e);
  check(errors.length === 0, "no console errors, page errors or network requests");
  console.log(`${passes} passed, ${failures} failed`);
  process.exit(failures ? 1 : 0);
}

main().catch((e) => { console.log("FAIL " + (e && e.stack || e)); process.exit(1); });

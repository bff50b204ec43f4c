// The explorer page of a small REAL study (written by `lamina study`, not a fixture) in headless
// Chromium: it loads from file:// with no console error, page error or network request, and draws
// the reference and the models. Usage: node browser_smoke.js STUDY_DIR SCREENSHOT
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const { chromium } = require("playwright-core");

const [studyDir, shot] = process.argv.slice(2);
const CHROMIUM = process.env.LAMINA_CHROMIUM || "/usr/bin/chromium";

async function main() {
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), "lamina-chromium-"));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: CHROMIUM,
    headless: true,
    args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync"],
    viewport: { width: 1400, height: 1000 },
  });
  const errors = [];
  let failures = 0;
  const check = (ok, what) => { console.log((ok ? "ok   " : "FAIL ") + what); if (!ok) failures++; };
  try {
    const page = context.pages()[0] || (await context.newPage());
    page.on("console", (m) => { if (m.type() === "error") errors.push("console: " + m.text()); });
    page.on("pageerror", (e) => errors.push("page error: " + e.message));
    await page.route(/^(https?|wss?):/, (route) => { errors.push("network: " + route.request().url()); route.abort(); });
    await page.goto("file://" + path.resolve(studyDir, "index.html"));
    await page.waitForFunction(() => Number(document.body.dataset.renders || 0) > 0, null, { timeout: 20000 });
    const names = await page.evaluate(() => document.getElementById("slice").data.map((t) => t.name));
    check(names.includes("reference"), "the slice draws the reference");
    check(names.some((n) => n !== "reference" && !/reference/.test(n || "")), "the slice draws a model");
    // The albedo view draws the reference's microsurface loss from the study's config.json.
    const shown = await page.evaluate(() => document.body.dataset.config);
    const cfg = JSON.parse(fs.readFileSync(path.resolve(studyDir, "configs", shown, "config.json"), "utf8"));
    const lost = await page.evaluate(() => {
      const t = document.getElementById("albedo").data.find((t) => t.name === "reference: lost to microsurfaces");
      return t ? Array.from(t.y) : null;
    });
    const expected = cfg.energy.map((e) => e.lost_microsurface[0]);
    check(expected.some((v) => v > 0), `${shown} loses energy to its rough coat (test premise)`);
    check(lost !== null && lost.length === expected.length && lost.every((v, i) => Math.abs(v - expected[i]) <= 1e-12 * Math.max(1, expected[i])),
      `the albedo view draws the reference's microsurface loss (${lost} against config.json's ${expected})`);
    const info = await page.evaluate(() => document.getElementById("study-info").textContent);
    check(info.includes("single-scattering microsurfaces"), `the header names the reference's microsurface model (${info})`);
    const cells = await page.evaluate(() => (document.getElementById("leaderboard").data[0] || {}).z);
    check(Array.isArray(cells) && cells.length >= 2, "the leaderboard lists the configurations");
    await page.screenshot({ path: shot, fullPage: true });
  } finally {
    await context.close();
    fs.rmSync(userDataDir, { recursive: true, force: true });
  }
  for (const e of errors) console.log("FAIL " + e);
  failures += errors.length;
  console.log(failures ? `${failures} failed` : "0 failed");
  process.exit(failures ? 1 : 0);
}
main().catch((e) => { console.log("FAIL " + e); process.exit(1); });

// Debian's chromium, headless, for the browser tests (driven by playwright-core; no browser is ever
// downloaded). The flags keep it from reaching the network: the pages under test must work from
// file:// alone. LAMINA_CHROMIUM names another binary.
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const { chromium } = require("playwright-core");

const CHROMIUM = process.env.LAMINA_CHROMIUM || "/usr/bin/chromium";

// A persistent context in a fresh profile; close() ends the browser and removes the profile.
async function launchChromium(viewport = { width: 1400, height: 1000 }) {
  const userDataDir = fs.mkdtempSync(path.join(os.tmpdir(), "lamina-chromium-"));
  const context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: CHROMIUM,
    headless: true,
    args: ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
      "--disable-background-networking", "--disable-component-update", "--disable-sync"],
    viewport,
  });
  const page = context.pages()[0] || (await context.newPage());
  const close = async () => {
    await context.close();
    fs.rmSync(userDataDir, { recursive: true, force: true });
  };
  return { context, page, close };
}

// A test of a page that must work from file:// alone: run(page, check) drives the page, check(ok,
// what) prints "ok" or "FAIL" with what; any console error, page error or network request fails
// the test too. Prints the count and exits 1 on any failure.
async function strictPageTest(run) {
  const browser = await launchChromium();
  const errors = [];
  let failures = 0;
  const check = (ok, what) => { console.log((ok ? "ok   " : "FAIL ") + what); if (!ok) failures++; };
  try {
    const page = browser.page;
    page.on("console", (m) => { if (m.type() === "error") errors.push("console: " + m.text()); });
    page.on("pageerror", (e) => errors.push("page error: " + e.message));
    await page.route(/^(https?|wss?):/, (route) => { errors.push("network: " + route.request().url()); route.abort(); });
    await run(page, check);
  } finally {
    await browser.close();
  }
  for (const e of errors) console.log("FAIL " + e);
  failures += errors.length;
  console.log(failures ? `${failures} failed` : "0 failed");
  process.exit(failures ? 1 : 0);
}

function runStrictPageTest(run) {
  strictPageTest(run).catch((e) => { console.log("FAIL " + e); process.exit(1); });
}

module.exports = { CHROMIUM, launchChromium, runStrictPageTest };

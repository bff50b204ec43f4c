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

module.exports = { CHROMIUM, launchChromium };

// Opening a study's explorer page in a browser test: load STUDY_DIR/index.html from file://, wait
// until it has drawn, and return the configuration it shows with that configuration's config.json.
"use strict";
const fs = require("fs");
const path = require("path");

async function openExplorer(page, studyDir) {
  await page.goto("file://" + path.resolve(studyDir, "index.html"));
  await page.waitForFunction(() => Number(document.body.dataset.renders || 0) > 0, null, { timeout: 20000 });
  const shown = await page.evaluate(() => document.body.dataset.config);
  const cfg = JSON.parse(fs.readFileSync(path.resolve(studyDir, "configs", shown, "config.json"), "utf8"));
  return { shown, cfg };
}

module.exports = { openExplorer };

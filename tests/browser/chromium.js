// Debian's headless chromium, driven by puppeteer-core, as the browser checks start it: with
// software GL (SwiftShader), so a 3D view draws on a machine without a GPU. A check on a
// machine without chromium or puppeteer-core says so and exits 77 (ctest: skipped).
"use strict";
const fs = require("fs");

const executablePath = process.env.CHROMIUM || "/usr/bin/chromium";

// puppeteer-core, or the exit that says why the check is skipped.
function puppeteerOrSkip() {
  let puppeteer;
  try {
    puppeteer = require("puppeteer-core");
  } catch (e) {
    console.log("skipped: npm ci --prefix tests/browser has not run (" + e.message + ")");
    process.exit(77);
  }
  if (!fs.existsSync(executablePath)) {
    console.log("skipped: no chromium at " + executablePath);
    process.exit(77);
  }
  return puppeteer;
}

function launch(puppeteer) {
  return puppeteer.launch({
    executablePath,
    headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--disable-gpu-sandbox"],
  });
}

module.exports = { puppeteerOrSkip, launch };

// Opens each report in Debian's headless chromium, as a designer would from disk, and checks
// what a person would see: no console error, no request past the file itself, a 3D view that
// is not blank, and a click on a finding that changes it. Exit 0: all good; 1: a check failed;
// 77: no chromium or puppeteer-core here (ctest shows the test as skipped).
"use strict";
const path = require("path");

const { puppeteerOrSkip, launch } = require("./chromium");
const puppeteer = puppeteerOrSkip();
let PNG;
try {
  PNG = require("pngjs").PNG;
} catch (e) {
  console.log("skipped: npm ci --prefix tests/browser has not run (" + e.message + ")");
  process.exit(77);
}

// Pixels of the canvas that differ from its background, and from another shot.
function pixels(png) { return PNG.sync.read(png); }
function notBackground(image) {
  // The background: the commonest colour.
  const counts = new Map();
  for (let i = 0; i < image.data.length; i += 4) {
    const key = (image.data[i] << 16) | (image.data[i + 1] << 8) | image.data[i + 2];
    counts.set(key, (counts.get(key) || 0) + 1);
  }
  const mode = [...counts.entries()].reduce((a, b) => (b[1] > a[1] ? b : a))[0];
  const [r0, g0, b0] = [mode >> 16, (mode >> 8) & 255, mode & 255];
  let count = 0;
  for (let i = 0; i < image.data.length; i += 4) {
    if (Math.abs(image.data[i] - r0) + Math.abs(image.data[i + 1] - g0) + Math.abs(image.data[i + 2] - b0) > 24) ++count;
  }
  return count / (image.width * image.height);
}
function changed(a, b) {
  let count = 0;
  for (let i = 0; i < a.data.length; i += 4) {
    if (Math.abs(a.data[i] - b.data[i]) + Math.abs(a.data[i + 1] - b.data[i + 1]) + Math.abs(a.data[i + 2] - b.data[i + 2]) > 24) ++count;
  }
  return count / (a.width * a.height);
}

async function check(browser, file) {
  const problems = [];
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 900 });
  page.on("console", (m) => { if (m.type() === "error") problems.push("console error: " + m.text()); });
  page.on("pageerror", (e) => problems.push("page error: " + e.message));
  page.on("request", (r) => {
    const url = r.url();
    if (!url.startsWith("file:") && !url.startsWith("data:")) problems.push("fetched " + url);
  });
  await page.goto("file://" + path.resolve(file), { waitUntil: "load" });
  try {
    await page.waitForFunction(() => document.body.dataset.viewer, { timeout: 45000 });
  } catch (e) {
    problems.push("the page never said whether its 3D view started (45 s)");
    return problems;
  }
  const state = await page.evaluate(() => document.body.dataset.viewer);
  if (state !== "ready") {
    problems.push("the 3D view did not start: " + (await page.$eval("#viewer-error", (e) => e.textContent)));
    return problems;
  }
  const view = await page.$("#view");
  const before = pixels(await view.screenshot());
  const drawn = notBackground(before);
  if (drawn < 0.02) problems.push("the 3D view is blank: " + (100 * drawn).toFixed(2) + "% of it drawn");
  // The first finding that names a part shown in the view.
  const index = await page.evaluate(() => {
    const data = JSON.parse(document.getElementById("report-data").textContent);
    const shown = new Set(data.steps.flatMap((s) => s.parts));
    return data.findings.findIndex((f) => f.parts.some((p) => shown.has(p)));
  });
  if (index < 0) {
    problems.push("no finding names a part");
  } else {
    await page.click('li.finding[data-finding="' + index + '"]');
    const after = pixels(await view.screenshot());
    const moved = changed(before, after);
    if (moved < 0.01) problems.push("a click on finding " + (index + 1) + " changed " + (100 * moved).toFixed(2) + "% of the view");
    const selected = await page.$eval('li.finding[data-finding="' + index + '"]', (li) => li.classList.contains("selected"));
    if (!selected) problems.push("the clicked finding is not marked");
    console.log(file + ": " + (100 * drawn).toFixed(1) + "% of the view drawn; finding " + (index + 1) +
                " clicked: " + (100 * moved).toFixed(1) + "% of it changed");
  }
  await page.close();
  return problems;
}

(async () => {
  const browser = await launch(puppeteer);
  let failed = 0;
  try {
    for (const file of process.argv.slice(2)) {
      const problems = await check(browser, file);
      problems.forEach((p) => console.log(file + ": " + p));
      failed += problems.length ? 1 : 0;
    }
  } finally {
    await browser.close();
  }
  console.log(failed ? failed + " report(s) failed" : "all reports passed");
  process.exit(failed ? 1 : 0);
})().catch((e) => {
  console.log("error: " + e.stack);
  process.exit(1);
});

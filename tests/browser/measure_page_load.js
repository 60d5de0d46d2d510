// Times fresh loads of the dashboard's page, as an operator opening it: to the load event, to
// the resources table filled (the first state drawn) and to the 3D view's canvas. Each run is a
// new browser, as the first page of an operator's browser (a GPU process still to start).
//   node tests/browser/measure_page_load.js URL [RUNS]
// URL: the one `cellctl up --dashboard` prints (with its token).
"use strict";
const { puppeteerOrSkip, launch } = require("./chromium");

(async () => {
  const puppeteer = puppeteerOrSkip();
  const url = process.argv[2], runs = Number(process.argv[3] || 1);
  for (let i = 0; i < runs; ++i) {
    const browser = await launch(puppeteer);
    const page = await browser.newPage();
    await page.setViewport({ width: 1400, height: 1100 });
    const t0 = Date.now();
    await page.goto(url, { waitUntil: "load", timeout: 120000 });
    const load = Date.now() - t0;
    await page.waitForFunction(() => document.querySelectorAll("#resources tr").length > 2, { timeout: 120000 });
    const tables = Date.now() - t0;
    await page.waitForFunction(() => document.querySelector("#scene canvas") !== null, { timeout: 120000 }).catch(() => {});
    console.log(`load ${load} ms, tables ${tables} ms, 3D canvas ${Date.now() - t0} ms`);
    await browser.close();
  }
})().catch((e) => { console.error(e.message); process.exit(1); });

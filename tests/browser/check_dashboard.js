// The cell's dashboard in Debian's headless chromium, as an operator would use it: starts
// `cellctl up --dashboard` on a domain of its own, opens the address it printed, and checks
// what a person would see: every resource of the cell; a file that is not a product's zip
// refused with the reason; an order submitted through the page's form (the product's zip)
// advancing to DONE, its report opening from the page's link; one cancelled from its row; a
// killed buffer turning gone, then back; the robot taken out of service from its row, with the
// reason shown, and back; no console error; no request to anything but the dashboard. Prints the page's update latency (a DDS event heard by
// cellctl up to the page's state drawn, p50 and p99) and can keep a screenshot of the page at
// work. DASHBOARD_ORDERS=N submits N orders more (the latency of a busy cell).
//   node check_dashboard.js CELLCTL CELL.yaml DOMAIN PRODUCT.aml PRODUCT.zip [SCREENSHOT.png]
// Exit 0: all good; 1: a check failed; 77: no chromium or puppeteer-core here (skipped).
"use strict";
const fs = require("fs");
const os = require("os");
const path = require("path");
const { spawn, spawnSync } = require("child_process");

const { puppeteerOrSkip, launch } = require("./chromium");
const puppeteer = puppeteerOrSkip();
const [cellctl, cellFile, domain, product, productZip, screenshot] = process.argv.slice(2);
const scratch = fs.mkdtempSync(path.join(os.tmpdir(), "dashboard-"));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Waits until `text` is in the file; what matched `pattern` in it.
async function appears(file, pattern, seconds) {
  for (let waited = 0; waited < seconds * 10; ++waited) {
    const text = fs.existsSync(file) ? fs.readFileSync(file, "utf8") : "";
    const m = text.match(pattern);
    if (m) return m;
    await sleep(100);
  }
  throw new Error(path.basename(file) + " never said " + pattern + " (" + seconds + " s)");
}

// The pid of the cell's process whose command line has `--id ID` on our domain.
function processOf(id) {
  for (const name of fs.readdirSync("/proc")) {
    if (!/^\d+$/.test(name)) continue;
    let args;
    try {
      args = fs.readFileSync("/proc/" + name + "/cmdline", "utf8").split("\0");
    } catch (e) {
      continue;
    }
    const at = (flag) => args.indexOf(flag);
    if (at("--id") >= 0 && args[at("--id") + 1] === id && args[at("--domain") + 1] === domain) return Number(name);
  }
  return 0;
}

// Clicks the button `selector` (whose text is `text`, if given) in the row of `id` in table
// `table`, and answers the question the click asks (`answer`: true to accept, the text to
// type, or null when it asks none); false if there is no such button or the click asked nothing. The click is the page's
// own: a mouse click at a button's place can miss it, as its row shifts whenever a cell's text
// changes width ("restarted 9 s ago", then "10 s").
async function clickInRow(page, table, id, selector, answer, text = null) {
  let answered;
  const asked = new Promise((resolve) => { answered = resolve; });
  const onDialog = (d) => (answer === true ? d.accept() : d.accept(answer)).then(() => answered(true), () => answered(true));
  page.once("dialog", onDialog);
  const clicked = await page.waitForFunction((table, id, selector, text) => {
    const row = [...document.querySelectorAll("#" + table + " tbody tr")].find((tr) => tr.cells[0].textContent === id);
    const button = row && [...row.querySelectorAll(selector)].find((b) => text === null || b.textContent === text);
    if (!button) return false;
    setTimeout(() => button.click(), 0);  // after this check returns: the question stops the page's script
    return true;
  }, { timeout: 20000 }, table, id, selector, text).then(() => true, () => false);
  let ok = clicked;
  if (clicked && answer !== null) {
    const timer = setTimeout(() => answered(false), 20000);
    ok = await asked;
    clearTimeout(timer);
  }
  page.off("dialog", onDialog);
  return ok;
}

function percentile(values, p) {
  const sorted = [...values].sort((a, b) => a - b);
  return sorted[Math.min(sorted.length - 1, Math.floor(p * sorted.length))];
}

(async () => {
  const problems = [];
  const upLog = path.join(scratch, "up.log");
  // Sim time at 5 times real time, not the cell file's 20: a browser starved beside the other
  // tests drew the 3D view 11 times in a minute, and at 20 the order's moves were all over
  // between two draws ("the 3D view never showed anything moving").
  const up = spawn(cellctl, ["up", cellFile, "--domain", domain, "--state-dir", path.join(scratch, "state"),
                             "--dashboard", "127.0.0.1:0", "--real-time-factor", process.env.DASHBOARD_RTF || "5"],
                   { stdio: ["ignore", fs.openSync(upLog, "w"), fs.openSync(upLog, "a")] });
  let browser;
  let step = "starting the cell";
  // ctest ends the test at 300 s, silently: at 280 it says where it stands, and ends the cell.
  const deadline = new Promise((_, reject) => setTimeout(() => reject(new Error("still " + step + " after 280 s")), 280000).unref());
  try {
    await Promise.race([deadline, (async () => {
      const url = (await appears(upLog, /dashboard: (http:\/\/127\.0\.0\.1:\d+\/\?token=[0-9a-f]+)/, 30))[1];
      await appears(upLog, /cell up on domain/, 90);
      const origin = new URL(url).origin;

      step = "opening the page";
      browser = await launch(puppeteer);
      const page = await browser.newPage();
      await page.setViewport({ width: 1400, height: 1100 });
      // The browser logs an answer 400 as an error: the one to the upload refused on purpose is not.
      let refusing = false;
      page.on("console", (m) => {
        if (m.type() === "error" && !(refusing && /status of 400/.test(m.text()))) problems.push("console error: " + m.text());
      });
      page.on("pageerror", (e) => problems.push("page error: " + e.message));
      page.on("request", (r) => {
        if (!r.url().startsWith(origin + "/") && !r.url().startsWith("data:")) problems.push("requested " + r.url());
      });
      await page.goto(url, { waitUntil: "load" });
      if (page.url() !== origin + "/") problems.push("the token stayed in the address: " + page.url());

      step = "looking for every resource";
      // Every resource of the cell, as cellctl status lists them.
      const status = JSON.parse(spawnSync(cellctl, ["status", "--cell", cellFile, "--domain", domain, "--json"],
                                          { encoding: "utf8", timeout: 30000 }).stdout);
      const ids = status.resources.map((r) => r.id);
      await page.waitForFunction((ids) => {
        const shown = [...document.querySelectorAll("#resources tbody tr")].map((tr) => tr.cells[0].textContent);
        return ids.every((id) => shown.includes(id));
      }, { timeout: 20000 }, ids).catch(() => problems.push("the page does not show every resource: " + ids.join(", ")));

      step = "uploading";
      // The page's form: a file that is not a zip is refused, with the reason shown; the
      // product's zip becomes order dash-1.
      const upload = async (file, id) => {
        await page.evaluate(() => { document.getElementById("submit-answer").textContent = ""; });
        await (await page.$("#submit-file")).uploadFile(file);
        await page.$eval("#submit-id", (input, id) => { input.value = id; }, id);
        await page.click("#submit-button");
        await page.waitForFunction(() => /order|zip|archive|refused|larger|cell/.test(document.getElementById("submit-answer").textContent)
          && !document.getElementById("submit-button").disabled, { timeout: 30000 });
        return page.$eval("#submit-answer", (o) => ({ text: o.textContent, cls: o.className }));
      };
      refusing = true;
      const refused = await upload(product, "dash-0");
      refusing = false;
      if (refused.cls !== "answer-refused" || !refused.text.includes("not a zip archive")) {
        problems.push("an .aml sent as the product's zip was not refused with the reason: " + JSON.stringify(refused));
      }
      const taken = await upload(productZip, "dash-1");
      if (taken.cls !== "answer-ok" || !taken.text.includes("dash-1")) problems.push("the product's zip was not taken: " + JSON.stringify(taken));
      // DASHBOARD_ORDERS more, by cellctl, for a measurement of the latency while the cell is busy.
      const extra = Number(process.env.DASHBOARD_ORDERS || 0);
      const submits = [];
      for (let i = 2; i <= 1 + extra; ++i) {
        submits.push(spawn(cellctl, ["submit", product, "--domain", domain, "--order", "dash-" + i, "--out",
                                     path.join(scratch, "dash-" + i), "--detach"], { stdio: "ignore" }));
      }
      const shows = (order, state) => page.waitForFunction((order, state) => [...document.querySelectorAll("#orders tbody tr")].some(
        (tr) => tr.cells[0].textContent === order && tr.cells[1].textContent === state), { timeout: 150000 + 20000 * extra }, order, state);
      if (screenshot) {  // the page at work
        await shows("dash-1", "PHYSICAL_ASSEMBLY").then(() => sleep(800)).then(() => page.screenshot({ path: screenshot, fullPage: true }))
          .catch(() => console.log("no screenshot: dash-1 was not seen in PHYSICAL_ASSEMBLY"));
      }
      step = "waiting for the orders to be done";
      for (let i = 1; i <= 1 + extra; ++i) {
        await shows("dash-" + i, "DONE").catch(() => problems.push("order dash-" + i + " never showed DONE"));
      }
      submits.forEach((s) => s.kill("SIGTERM"));
      step = "opening dash-1's results";
      // Its results, from the page's links: the report opens (sandboxed) with no error, the plan
      // and the animation come as files.
      const links = await page.$$eval("#orders tbody tr", (rows) => rows.filter((tr) => tr.cells[0].textContent === "dash-1")
        .flatMap((tr) => [...tr.querySelectorAll("a")].map((a) => a.href)));
      if (links.length !== 3) problems.push("dash-1 links to " + links.length + " results, not 3");
      for (const link of links.filter((l) => !l.endsWith(".html"))) {
        const status = await page.evaluate(async (l) => (await fetch(l)).status, link);
        if (status !== 200) problems.push(link + ": HTTP " + status);
      }
      const report = await browser.newPage();
      report.on("console", (m) => { if (m.type() === "error") problems.push("report: console error: " + m.text()); });
      report.on("pageerror", (e) => problems.push("report: page error: " + e.message));
      const opened = await report.goto(links.find((l) => l.endsWith("report.html")) || origin + "/none", { waitUntil: "load" });
      if (!opened || opened.status() !== 200) problems.push("the report did not open: HTTP " + (opened && opened.status()));
      await report.waitForFunction(() => document.body.dataset.viewer, { timeout: 45000 })
        .then(async () => {
          const viewer = await report.evaluate(() => document.body.dataset.viewer);
          if (viewer !== "ready") problems.push("the report's 3D view did not start: " + viewer);
        })
        .catch(() => problems.push("the report's 3D view never said whether it started"));
      await report.close();
      // The 3D view: the robot and the arm seen moving, dash-1's parts in the cell.
      const [frames, parts] = await page.evaluate(() => [window.dashboard.movingFrames, window.dashboard.parts["dash-1"] || 0]);
      console.log("3D view: " + frames + " frames drawn while something moved; at most " + parts + " parts of dash-1 in the cell at once");
      if (!frames) problems.push("the 3D view never showed anything moving");
      if (parts < 2) problems.push("the 3D view showed " + parts + " parts of dash-1");
      const bars = await page.evaluate(() => window.dashboard.bars.filter((b) => b.order === "dash-1").length);
      if (bars < 5) problems.push("the Gantt chart holds " + bars + " bars of dash-1's work");

      step = "killing a buffer";
      // A killed buffer: gone, then back.
      const buffer = ids.find((id) => id.startsWith("buffer"));
      const pid = processOf(buffer);
      if (!pid) {
        problems.push("no process of " + buffer + " found");
      } else {
        process.kill(pid, "SIGKILL");
        await page.waitForFunction((id) => {
          const seen = window.dashboard.seen[id] || [];
          const gone = seen.lastIndexOf("gone");
          return gone >= 0 && seen.slice(gone + 1).some((s) => s !== "gone");
        }, { timeout: 60000 }, buffer).catch(async () => problems.push(
          buffer + " did not turn gone and back: it went " + JSON.stringify(await page.evaluate((id) => window.dashboard.seen[id], buffer))));
        const alarms = await page.$$eval("#alarms li", (lis) => lis.map((li) => li.textContent));
        if (!alarms.some((a) => a.includes(buffer) && a.includes("restarted"))) problems.push("no alarm says " + buffer + " restarted");
      }
      step = "cancelling dash-c";
      // The operator cancels an order from its row (the page asks first): it fails with the reason.
      const again = await upload(productZip, "dash-c");
      if (again.cls !== "answer-ok") problems.push("the product's zip was not taken again: " + JSON.stringify(again));
      if (!(await clickInRow(page, "orders", "dash-c", "button.cancel", true))) {
        problems.push("dash-c has no cancel button, or its click asked nothing");
      } else {
        await shows("dash-c", "FAILED").catch((e) => problems.push("dash-c, cancelled, never showed FAILED: " + e.message));
        const reason = await page.$$eval("#orders tbody tr", (rows) => rows.filter((tr) => tr.cells[0].textContent === "dash-c")
          .map((tr) => tr.cells[5].textContent).join(""));
        if (!reason.startsWith("cancelled by the operator (dashboard)")) problems.push("dash-c failed for another reason: " + reason);
      }
      // The operator takes the robot out of service from its row (the page asks why), and back.
      const robot = ids.find((id) => id.startsWith("mobile-robot"));
      step = "taking " + robot + " out of service";
      if (!(await clickInRow(page, "resources", robot, "button.service", "wheel check", "out of service"))) {
        problems.push(robot + " has no out-of-service button, or its click asked nothing");
      } else {
        await page.waitForFunction((id) => (window.dashboard.seen[id] || []).slice(-1)[0] === "out of service", { timeout: 20000 }, robot)
          .catch(() => {});
        const state = await page.$$eval("#resources tbody tr", (rows, id) => rows.filter((tr) => tr.cells[0].textContent === id)
          .map((tr) => tr.cells[2].textContent + " | " + tr.cells[2].firstChild.title).join(""), robot);
        if (!state.startsWith("out of service | wheel check (the operator (dashboard))")) {
          problems.push(robot + " did not show out of service with the reason: " + state);
        }
        step = "bringing " + robot + " back into service";
        if (!(await clickInRow(page, "resources", robot, "button.service", null, "back into service"))) {
          problems.push(robot + " has no back-into-service button");
        } else {
          await page.waitForFunction((id) => (window.dashboard.seen[id] || []).slice(-1)[0] !== "out of service", { timeout: 20000 }, robot)
            .catch(async () => problems.push(robot + " did not come back into service: it went " +
                                             JSON.stringify(await page.evaluate((id) => window.dashboard.seen[id], robot))));
        }
      }
      const drawn = await page.evaluate(() => document.body.dataset.scene);
      if (drawn !== "drawn") problems.push("the 3D view was not drawn");

      const [latencies, built, received] = await page.evaluate(
        () => [window.dashboard.latencies, window.dashboard.built, window.dashboard.received]);
      const ms = (values, p) => (1000 * percentile(values, p)).toFixed(1);
      if (latencies.length) {
        console.log("update latency, DDS event heard to page drawn: p50 " + ms(latencies, 0.5) + " ms, p99 " + ms(latencies, 0.99) +
                    " ms over " + latencies.length + " updates; to the state built: p50 " + ms(built, 0.5) +
                    " ms, p99 " + ms(built, 0.99) + " ms; to the page's script: p50 " + ms(received, 0.5) + " ms, p99 " +
                    ms(received, 0.99) + " ms");
        const drawMs = await page.evaluate(() => window.dashboard.drawMs);
        console.log("drawing, p50 / p99 / max ms: " + Object.entries(drawMs).map(([part, times]) =>
          part + " " + [0.5, 0.99].map((p) => percentile(times, p).toFixed(1)).join(" / ") + " / " +
          Math.max(...times).toFixed(1) + " (" + times.length + ")").join(", "));
      } else {
        problems.push("no update reached the page");
      }
    })()]);
  } catch (e) {
    problems.push(e.message);
  } finally {
    if (browser) await browser.close();
    spawnSync(cellctl, ["down", "--domain", domain], { timeout: 30000 });
    for (let i = 0; i < 100 && up.exitCode === null; ++i) await sleep(100);
    if (up.exitCode === null) up.kill("SIGKILL");
  }
  problems.forEach((p) => console.log("dashboard: " + p));
  if (problems.length) console.log(fs.readFileSync(upLog, "utf8").split("\n").slice(-30).join("\n"));
  fs.rmSync(scratch, { recursive: true, force: true });
  console.log(problems.length ? "the dashboard failed" : "the dashboard passed");
  process.exit(problems.length ? 1 : 0);
})();

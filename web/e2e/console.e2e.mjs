// The console in a real browser (Debian's chromium, headless, driven over the DevTools protocol
// by playwright-core) against a running laminad and lamina-sim, started by the C++ harness
// (tests/console/test_console.cpp), which passes everything in the environment:
//   LAMINA_URL        http://127.0.0.1:PORT
//   LAMINA_MODEL      the STL to upload
//   LAMINA_STOCK_FILE the rack's file (on the cell PC, within laminad's roots); its sheet's slot is "B2 top"
//   LAMINA_SHOTS      folder for the screenshots (test artefacts)
//   LAMINA_USERS      JSON: {"engineer": [name, password], "operator": […], "viewer": […]}
// Prints one JSON line per finding ("step") and a last line {"ok": true, metrics…}; exits 1 on
// the first failed check, naming it.
import { chromium } from "playwright-core";
import http from "node:http";
import { mkdirSync, rmSync } from "node:fs";
import { join } from "node:path";

const url = process.env.LAMINA_URL;
const model = process.env.LAMINA_MODEL;
const stockFile = process.env.LAMINA_STOCK_FILE;
const shots = process.env.LAMINA_SHOTS;
const users = JSON.parse(process.env.LAMINA_USERS ?? "{}");
const limit = (s) => s * 1000;
rmSync(shots, { recursive: true, force: true });  // this run's screenshots only
mkdirSync(shots, { recursive: true });

const say = (step, extra = {}) => console.log(JSON.stringify({ step, ...extra }));
function check(condition, what) {
  if (!condition) throw new Error(`check failed: ${what}`);
  say(what);
}

// A request sent as written (a browser would normalise "../" away before sending it).
function rawGet(path, headers = {}) {
  return new Promise((resolve, reject) => {
    const req = http.request(url + "/", { method: "GET", path, headers }, (res) => {
      let body = "";
      res.on("data", (d) => (body += d));
      res.on("end", () => resolve({ status: res.statusCode, body }));
    });
    req.on("error", reject);
    req.end();
  });
}

const openPages = [];

async function login(browser, role) {
  const context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  const page = await context.newPage();
  openPages.push([role, page]);
  page.on("pageerror", (e) => say("page error", { role, message: e.message }));
  page.on("console", (m) => m.type() === "error" && say("page console error", { role, message: m.text() }));
  page.on("websocket", (ws) => ws.on("close", () => say("the page's WebSocket closed", { role })));
  await page.goto(url + "/", { waitUntil: "load" });
  await page.waitForSelector("#login", { timeout: limit(10) });
  const [name, password] = users[role];
  await page.fill("input[name=user]", name);
  await page.fill("input[name=password]", password);
  await page.click("#login button[type=submit]");
  await page.waitForFunction(() => document.getElementById("link-state")?.textContent === "connected", null, { timeout: limit(10) });
  return { context, page };
}

async function jobState(page) {
  return page.$eval("#job-state", (el) => el.textContent.trim()).catch(() => "");
}

async function waitJobState(page, wanted, seconds) {
  await page.waitForFunction((w) => w.includes(document.getElementById("job-state")?.textContent.trim()), wanted, {
    timeout: limit(seconds),
    polling: 100,
  });
  return jobState(page);
}

// How many distinct colours a 3D view drew (a blank canvas has one).
async function canvasColours(page, selector = ".stack3d canvas") {
  return page.evaluate((selector) => {
    const gl = document.querySelector(selector);
    if (!gl) return 0;
    const copy = document.createElement("canvas");
    copy.width = gl.width;
    copy.height = gl.height;
    const ctx = copy.getContext("2d");
    ctx.drawImage(gl, 0, 0);
    const data = ctx.getImageData(0, 0, copy.width, copy.height).data;
    const seen = new Set();
    for (let i = 0; i < data.length; i += 4 * 37) seen.add((data[i] << 16) | (data[i + 1] << 8) | data[i + 2]);
    return seen.size;
  }, selector);
}

// The first sheet's program in 3D: drawn, with tool-axis lines on its 5-axis moves, and every
// cut's tip where the jet meets the sheet (its top face, inside it). A pivot program read as if
// it carried the tip would put the tilted cuts' tips up to 75 mm below the top face.
async function toolpathIn3d(page, jobId) {
  await page.click("article.sheet[data-sheet='1'] .toolpath-open");
  await page.waitForSelector(".toolpath3d[data-moves]", { timeout: limit(20) });
  const view = await page.$eval(".toolpath3d", (el) => ({ ...el.dataset }));
  const report = await page.evaluate(async (id) => (await fetch(`/api/jobs/${id}/report.json`)).json(), jobId);
  const sheet = report.sheets[0];
  say("toolpath", { moves: +view.moves, cuts: +view.cuts, tilted: +view.tilted, axis_lines: +view.axisLines, bounds: view.cutBounds });
  check(+view.tilted > 0 && +view.axisLines > 0, `the 5-axis moves carry tool-axis lines (${view.axisLines} drawn for ${view.tilted} tilted moves)`);
  check(+view.arcs === 0, "the program has no arcs the view would draw as chords");
  const { min, max } = JSON.parse(view.cutBounds);
  const eps = 0.01;
  check(Math.abs(min[2]) < eps && Math.abs(max[2]) < eps, `every cut's tip is on the sheet's top face (z ${min[2].toFixed(4)} … ${max[2].toFixed(4)} mm)`);
  check(min[0] >= 0 && min[1] >= 0 && max[0] <= sheet.length_mm && max[1] <= sheet.width_mm,
    `every cut's tip is on the ${sheet.length_mm} x ${sheet.width_mm} mm sheet (x ${min[0].toFixed(1)} … ${max[0].toFixed(1)}, y ${min[1].toFixed(1)} … ${max[1].toFixed(1)})`);
  let colours = 0;
  for (let i = 0; i < 100 && colours < 4; ++i) {
    await page.waitForTimeout(100);
    colours = await canvasColours(page, ".toolpath3d canvas");
  }
  check(colours >= 4, `the 3D toolpath is drawn (${colours} colours sampled)`);
  await page.locator(".toolpath3d").screenshot({ path: join(shots, "toolpath-3d.png") });
}

async function refusals(browser, jobId) {
  const wrong = await fetch(url + "/api/login", { method: "POST", body: JSON.stringify({ user: users.operator[0], password: "not it" }) });
  check(wrong.status === 401, "a wrong password is refused (401)");
  const bare = await browser.newContext();
  const page = await bare.newPage();
  await page.goto(url + "/");
  const noCookie = await page.evaluate(async (id) => (await fetch(`/api/jobs/${id}/report.json`)).status, jobId);
  check(noCookie === 401, "an artefact without a session cookie is refused (401)");
  const ws = await page.evaluate(() => new Promise((resolve) => {
    const s = new WebSocket(`ws://${location.host}/ws`);
    s.onopen = () => resolve("open");
    s.onclose = () => resolve("closed");
  }));
  check(ws === "closed", "the WebSocket without a session cookie is refused");
  await bare.close();
  const dots = await rawGet(`/api/jobs/${jobId}/../../jobs.db`);
  check(dots.status === 400 && !dots.body.includes("SQLite"), "'../' in an artefact path is refused (400)");
}

// Another site's page (same host, another port: same site, so the SameSite cookie goes with
// it) opens the console's WebSocket: the Origin check must refuse it.
async function foreignOrigin(context) {
  const server = http.createServer((req, res) => {
    res.setHeader("Content-Type", "text/html");
    res.end("<!doctype html><title>elsewhere</title>");
  });
  await new Promise((r) => server.listen(0, "127.0.0.1", r));
  const page = await context.newPage();
  await page.goto(`http://127.0.0.1:${server.address().port}/`);
  const target = url.replace("http://", "ws://") + "/ws";
  const result = await page.evaluate((t) => new Promise((resolve) => {
    const s = new WebSocket(t);
    s.onopen = () => resolve("open");
    s.onclose = () => resolve("closed");
  }), target);
  check(result === "closed", "a WebSocket opened by another origin's page is refused");
  await page.close();
  server.close();
}

async function engineerSubmits(browser, metrics) {
  const { context, page } = await login(browser, "engineer");
  const load = await page.evaluate(() => {
    const t = performance.getEntriesByType("navigation")[0];
    return t.loadEventEnd - t.startTime;
  });
  metrics.page_load_ms = load;
  await page.screenshot({ path: join(shots, "machine.png"), fullPage: true });
  await page.click("nav a[data-view=queue]");
  await page.setInputFiles("input[name=model]", model);
  await page.fill("input[name=stock_file]", stockFile);
  await page.click("#submit-form button[type=submit]");
  await page.waitForURL(/#\/job\/j-/, { timeout: limit(30) });
  const jobId = page.url().split("/").pop();
  say("submitted", { job: jobId });
  const phases = new Set();
  const t0 = Date.now();
  while (Date.now() - t0 < limit(60)) {
    const state = await jobState(page);
    const text = await page.$eval("#job-progress", (el) => el.textContent).catch(() => "");
    if (state === "planning" && text) phases.add(text.replace(/ \(.*$/, ""));
    if (["waiting sheet", "failed"].includes(state)) break;
    await page.waitForTimeout(50);
  }
  metrics.planning_phases_seen = [...phases];
  check(phases.size >= 2, `planning progress was shown (${[...phases].join(", ")})`);
  check((await jobState(page)) === "waiting sheet", "the job was planned and waits for its first sheet");
  await page.waitForSelector("#layers tr:nth-child(2)", { timeout: limit(20) });
  const layers = await page.$$eval("#layers tr", (rows) => rows.length - 1);
  check(layers > 0, `the layer table lists ${layers} layers`);
  const warnings = await page.$$eval("#plan-warnings li", (items) => items.length);
  check(warnings > 0, `the plan's ${warnings} warnings are listed`);
  await page.waitForFunction(() => !!document.querySelector(".stack3d canvas"), null, { timeout: limit(20) });
  let colours = 0;
  for (let i = 0; i < 100 && colours < 10; ++i) {
    await page.waitForTimeout(100);
    colours = await canvasColours(page);
  }
  check(colours >= 10, `the 3D view drew the stack (${colours} colours sampled)`);
  await page.waitForFunction(() => [...document.querySelectorAll("svg.sheet-drawing")].some((s) => s.getBoundingClientRect().width > 100 && s.querySelector("#sheet")), null, { timeout: limit(20) });
  check(true, "a sheet drawing is shown");
  const sheetTitle = await page.$eval("article.sheet[data-sheet='1'] h3", (el) => el.textContent);
  check(sheetTitle.includes("rack slot B2 top"), `the sheet names its rack slot: "${sheetTitle}"`);
  await toolpathIn3d(page, jobId);
  await page.locator(".stack3d").screenshot({ path: join(shots, "stack-3d.png") });
  await page.screenshot({ path: join(shots, "job.png"), fullPage: true });
  await foreignOrigin(context);
  await context.close();
  return jobId;
}

async function viewerIsRefused(browser, jobId) {
  const { context, page } = await login(browser, "viewer");
  await page.goto(`${url}/#/job/${jobId}`);
  await page.waitForSelector("#prompt button", { timeout: limit(20) });
  await page.click("#prompt button");
  await page.waitForFunction(() => !document.getElementById("notice").hidden, null, { timeout: limit(10) });
  const notice = await page.$eval("#notice", (el) => el.textContent);
  check(notice.includes("is for an operator or above") && notice.includes("is a viewer"), `a viewer's confirm is refused out loud: "${notice}"`);
  await page.screenshot({ path: join(shots, "viewer-refused.png"), fullPage: true });
  await context.close();
}

async function operatorCuts(browser, jobId, metrics) {
  const { context, page } = await login(browser, "operator");
  await page.goto(`${url}/#/job/${jobId}`);
  await page.waitForSelector("#job-state", { timeout: limit(20) });
  let held = false, sheets = 0;
  const t0 = Date.now();
  while (Date.now() - t0 < limit(600)) {
    const state = await waitJobState(page, ["waiting sheet", "completed", "failed", "cancelled", "paused"], 300);
    if (state !== "waiting sheet") break;
    await page.waitForSelector("#prompt button", { timeout: limit(10) });
    if (sheets === 0) {
      const slot = await page.$eval("#prompt-slot", (el) => el.textContent).catch(() => "(no slot shown)");
      check(slot.includes("B2 top"), `the operator's prompt says where the sheet lies: "${slot}"`);
      await page.screenshot({ path: join(shots, "operator-prompt.png"), fullPage: true });
    }
    await page.click("#prompt button");
    ++sheets;
    await waitJobState(page, ["cutting"], 60);
    if (!held) {
      await page.waitForSelector("#motion-bar:not([hidden]) #hold", { timeout: limit(10) });
      // Mid-cut: once the controller has taken lines (a hold before the first line is a stop).
      await page.waitForFunction(() => /line [1-9]\d* of/.test(document.getElementById("job-progress")?.textContent ?? ""), null, {
        timeout: limit(60),
        polling: 50,
      });
      await page.click("#hold");
      await waitJobState(page, ["paused"], 30);
      await page.screenshot({ path: join(shots, "held.png"), fullPage: true });
      await page.click("#resume");
      await waitJobState(page, ["cutting", "sheet done", "waiting sheet", "completed"], 30);
      held = true;
      say("held and resumed once");
      await page.goto(`${url}/#/machine`);
      await page.waitForSelector(".lamps", { timeout: limit(10) });
      // The daemon's own warnings: the wrong password of refusals() above was logged, and shown.
      const warned = await page.waitForFunction(() => /failed login as/.test(document.getElementById("daemon-warnings")?.textContent ?? ""), null, {
        timeout: limit(10),
      }).then(() => true, () => false);
      check(warned, "the machine view lists the daemon's warnings (the failed login)");
      await page.screenshot({ path: join(shots, "machine-cutting.png"), fullPage: true });
      await page.goto(`${url}/#/job/${jobId}`);
      await page.waitForSelector("#job-state", { timeout: limit(20) });
    }
  }
  metrics.sheets_confirmed = sheets;
  check(held, "the operator held and resumed the cut");
  check((await jobState(page)) === "completed", `the job completed after ${sheets} confirmed sheets`);
  await page.screenshot({ path: join(shots, "completed.png"), fullPage: true });
  await context.close();
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? "/usr/bin/chromium",
  args: ["--headless=new", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--disable-quic", "--no-first-run", "--disable-background-networking", "--disable-component-update", "--disable-sync"],
});
const metrics = {};
let failed = null;
try {
  const jobId = await engineerSubmits(browser, metrics);
  await refusals(browser, jobId);
  await viewerIsRefused(browser, jobId);
  await operatorCuts(browser, jobId, metrics);
} catch (e) {
  failed = e;
  // What each page showed when it failed: the first thing to look at.
  for (const [role, page] of openPages)
    if (!page.isClosed()) await page.screenshot({ path: join(shots, `failed-${role}.png`), fullPage: true }).catch(() => undefined);
} finally {
  await browser.close();
}
if (failed) {
  console.log(JSON.stringify({ ok: false, error: failed.message, ...metrics }));
  process.exit(1);
}
console.log(JSON.stringify({ ok: true, ...metrics }));

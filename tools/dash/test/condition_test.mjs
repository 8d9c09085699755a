// Browser test of hoist-dash's "Shaft condition" view (CTest dash_condition,
// label `browser`): a SQLite history database written by the Store
// (tests/dash hoist-test-history-fill: 12 trips, the preload falling from
// 1.0 to 0.6 at trip 9), hoist-dash --history on it (read-only), the page in
// headless Chromium.
//
//   node condition_test.mjs [LCM_PORT] [--screenshot FILE]
//
// Asserts: a server without --history shows no view; with a missing
// database the view says so, naming the file (and the server keeps
// serving); once the database exists the view shows 12 trips, the trend's
// 12 identified points, the heat map's 12 x 40 cells, GUIDE_PRELOAD_LOW
// CRITICAL naming the estimate, the last trip's record (s = value +- sigma
// as stored) and its 40 depth bins; a 13th trip written while the page is
// open appears without a reload; the log names the file and says read-only.
import fs from "node:fs";
import path from "node:path";
import puppeteer from "puppeteer-core";
import { check, fail, lcmUrl, start, startDash, stop, workDir } from "./harness.mjs";

const args = process.argv.slice(2);
const lcmPort = Number(args.find((a) => /^\d+$/.test(a)) || 7960);
const shotIdx = args.indexOf("--screenshot");
const dir = workDir("condition");
const shot = shotIdx >= 0 ? path.resolve(args[shotIdx + 1]) : path.join(dir, "condition.png");
const chromium = process.env.CHROMIUM || ["/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"].find((p) => fs.existsSync(p));
if (!chromium) fail("no Chromium found (scripts/setup.sh installs Debian's chromium)");
const fillExe = process.env.HOIST_HISTORY_FILL;
if (!fillExe) fail("HOIST_HISTORY_FILL (tests/dash: hoist-test-history-fill) is not set");
const lcm = lcmUrl(lcmPort);
const db = path.join(dir, "history.sqlite");
for (const f of [db, `${db}-wal`, `${db}-shm`]) fs.rmSync(f, { force: true });
console.log(`work dir ${dir}, LCM ${lcm}`);

const fill = async (first, last) => {
  const p = start(`fill-${first}-${last}`, fillExe, [db, String(first), String(last), "--preload-step", "9"], dir);
  const r = await p.exited;
  if (r.code !== 0) fail(`hoist-test-history-fill exited ${JSON.stringify(r)}`);
};

const plain = await startDash(dir, lcm, ["--channel-prefix", "north/"], "hoist-dash-plain");
const dash = await startDash(dir, lcm, ["--channel-prefix", "north/", "--history", db, "--history-poll", "0.2"]);
const browser = await puppeteer.launch({
  executablePath: chromium, headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1500,1400"],
  defaultViewport: { width: 1500, height: 1400 },
});
const page = await browser.newPage();
const errors = [];
page.on("pageerror", (e) => errors.push(String(e)));
page.on("console", (m) => { if (m.type() === "error" && !/404/.test(m.text())) errors.push(m.text()); });
process.on("uncaughtException", async (e) => {
  console.error(`FAIL: ${e.message}`);
  try {
    console.error(await page.evaluate(() => document.body.innerText.slice(0, 3000)));
    await page.screenshot({ path: path.join(dir, "failure.png"), fullPage: true });
    console.error(`page at failure: ${path.join(dir, "failure.png")}`);
  } catch { /* browser gone */ }
  process.exit(1);
});

// 1. Without --history: /api/condition says the view is off (naming --history) and the view stays hidden.
const r404 = await fetch(new URL("/api/condition", plain.url));
const off = r404.status === 200 ? await r404.json() : {};
check(off.enabled === false && /--history/.test(off.why || ""), "without --history, /api/condition says the view is off, naming --history");
await page.goto(plain.url, { waitUntil: "load" });
await page.waitForFunction(() => document.querySelector("#conn")?.dataset.state === "connected", { timeout: 10000 });
check(await page.$eval("#condition", (e) => e.hidden), "without --history the Shaft condition view is hidden");

// 2. A missing database: a clear message on the page, naming the file.
await page.goto(dash.url, { waitUntil: "load" });
await page.waitForSelector('#condition[data-state="error"]', { timeout: 10000 });
const errText = await page.$eval("#cond-status", (e) => e.textContent);
check(errText.includes("no such file") && errText.includes(db), `missing database: "${errText}"`);

// 3. The database appears (12 trips): the view follows without a reload.
await fill(1, 12);
await page.waitForSelector('#condition[data-state="ok"][data-trips="12"]', { timeout: 10000 });
check(true, "the view shows 12 trips once the database exists");
const pts = await page.$eval("#cond-trend", (e) => Number(e.dataset.points));
check(pts === 12, `the trend drew 12 identified trips (${pts})`);
const cells = await page.$eval("#cond-heat", (e) => Number(e.dataset.cells));
check(cells === 12 * 40, `the heat map drew 12 x 40 cells (${cells})`);
const gpl = await page.$eval('.cond-alarm[data-kind="GUIDE_PRELOAD_LOW"]', (e) => ({ level: e.dataset.level, text: e.textContent }));
check(gpl.level === "CRITICAL" && /0\.6/.test(gpl.text), `GUIDE_PRELOAD_LOW CRITICAL after the drop to 0.6 ("${gpl.text}")`);
const fp = await page.$eval('.cond-alarm[data-kind="SHAFT_FINGERPRINT"]', (e) => e.dataset.level);
check(fp === "NONE" || fp === "WARNING", `SHAFT_FINGERPRINT row present (${fp})`);
const field = (k) => page.$eval(`#cond-last td[data-field="${k}"]`, (e) => e.textContent);
check((await field("trip")) === "12", "the last trip's record is trip 12");
const s12 = 0.6 + 0.03 * Math.sin(1.7 * 12);
const sText = await field("preload_scale");
check(sText === `${s12.toFixed(3)} ± 0.030`, `its preload scale as stored (${sText})`);
check((await field("alarms")) === "GUIDE_PRELOAD_LOW", "its alarms as stored");
const nb = await page.$$eval("#cond-bins tbody tr", (r) => r.length);
check(nb === 40, `its depth-bin table has 40 rows (${nb})`);

// 4. A new trip written while the page is open appears without a reload.
await fill(13, 13);
await page.waitForSelector('#condition[data-trips="13"][data-last-trip="13"]', { timeout: 10000 });
check(true, "trip 13 appeared without a reload");
await (await page.$("#condition")).screenshot({ path: shot });  // the view itself
console.log(`screenshot ${shot}`);

// 5. The log: the missing file, then the database read-only.
const dashLog = fs.readFileSync(path.join(dir, "hoist-dash.log"), "utf8");
check(/no such file/.test(dashLog) && /reading sqlite .* \(read-only\)/.test(dashLog), "the log names the missing file, then the database it reads read-only");
check(errors.length === 0, `no page errors (${errors.join("; ")})`);

await browser.close();
for (const p of [dash.proc, plain.proc]) {
  const r = await stop(p);
  if (r.code !== 0) fail(`${p.name} exited ${JSON.stringify(r)}`);
}
console.log("PASS");

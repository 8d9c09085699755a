// Browser test of hoist-dash's load-estimate panel (CTest dash_estimate, label
// `browser`): hoist-dash for the shaft "north/" on a private LCM URL and a free
// port, synthetic HOIST_ESTIMATE messages from hoist-test-estimate-pub
// (tests/dash: realistic values, 100 Hz), the page in headless Chromium.
//
//   node estimate_test.mjs [LCM_PORT] [--screenshot FILE]
//
// Asserts: the panel stays hidden until the first estimate; then it shows Fa
// and b with their sigma ("1502 ± 3 N", "0.60 ± 0.01 m"), the sensors in use;
// the theta trend has points of the estimate, of its +-2 sigma band (upper
// above, lower below the estimate, 2 sigma apart) and of the open-loop theta;
// the NIS trend has points of the window's NIS and of its bounds; a mismatch
// raises the MODEL_MISMATCH badge naming the NIS, and the MODEL_MISMATCH alarm
// row shows the NIS against its bound; without the rope load cell
// Fa and b read "n/a"; the panel says STALE when the estimates stop; the
// calibration form sends a calibration (confirmed, with the operator's name)
// that hoist-dash publishes, refuses one outside the daemon's bounds, and
// shows estimate_t.calibrating.
import fs from "node:fs";
import path from "node:path";
import puppeteer from "puppeteer-core";
import { check, fail, lcmUrl, sleep, start, startDash, stats, stop, workDir } from "./harness.mjs";

const args = process.argv.slice(2);
const lcmPort = Number(args.find((a) => /^\d+$/.test(a)) || 7842);
const shotIdx = args.indexOf("--screenshot");
const dir = workDir("estimate");
const shot = shotIdx >= 0 ? path.resolve(args[shotIdx + 1]) : path.join(dir, "estimate.png");
const chromium = process.env.CHROMIUM || ["/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"].find((p) => fs.existsSync(p));
if (!chromium) fail("no Chromium found (scripts/setup.sh installs Debian's chromium)");
const pubExe = process.env.HOIST_ESTIMATE_PUB;
if (!pubExe) fail("HOIST_ESTIMATE_PUB (tests/dash: hoist-test-estimate-pub) is not set");
const lcm = lcmUrl(lcmPort);
console.log(`work dir ${dir}, LCM ${lcm}`);

const dash = await startDash(dir, lcm, ["--channel-prefix", "north/"]);
const browser = await puppeteer.launch({
  executablePath: chromium, headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1500,1180"],
  defaultViewport: { width: 1500, height: 1180 },
});
const page = await browser.newPage();
const errors = [], dialogs = [];
page.on("pageerror", (e) => errors.push(String(e)));
page.on("dialog", async (d) => { dialogs.push(d.message()); await d.accept(); });
page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
process.on("uncaughtException", async (e) => {
  console.error(`FAIL: ${e.message}`);
  try {
    console.error(await page.evaluate(() => document.body.innerText.slice(0, 3000)));
    await page.screenshot({ path: path.join(dir, "failure.png") });
    console.error(`page at failure: ${path.join(dir, "failure.png")}`);
  } catch { /* browser gone */ }
  process.exit(1);
});
await page.goto(dash.url, { waitUntil: "load" });
const box = '[data-shaft="north/"] [data-role=estimate]';
await page.waitForSelector(box, { timeout: 5000 });
check(await page.$eval(box, (e) => e.hidden), "no estimate yet: the load-estimate panel is hidden");

const publish = async (mode, count) => {
  const p = start(`estimate-pub-${mode}`, pubExe, [lcm, "north/", String(count), "10", mode], dir);
  const r = await p.exited;
  if (r.code !== 0) fail(`hoist-test-estimate-pub ${mode} exited ${JSON.stringify(r)}`);
};
const panel = () => page.evaluate((sel) => {
  const b = document.querySelector(sel);
  const f = (k) => b.querySelector(`[data-field="est-${k}"]`).textContent;
  const pts = (role) => ({ ...b.querySelector(`[data-role="${role}"]`).dataset });
  return { hidden: b.hidden, state: b.dataset.state, Fa: f("Fa"), b: f("b"), moment: f("moment"), theta: f("theta"),
           nis: f("nis"), sensors: f("sensors"), badge: f("mismatch"), detect: f("detect"),
           badgeState: b.querySelector('[data-field="est-mismatch"]').dataset.state,
           badgeVisible: getComputedStyle(b.querySelector('[data-field="est-mismatch"]')).display !== "none",
           theta_pts: pts("estimate-theta"), nis_pts: pts("estimate-nis") };
}, box);

// 1. Estimates of a shaft whose model matches: Fa and b with their sigma.
const pub = publish("normal", 250);  // 2.5 s at 100 Hz
await page.waitForFunction((sel) => {
  const b = document.querySelector(sel);
  return !b.hidden && Number(b.querySelector('[data-role="estimate-theta"]').dataset.points_hi || 0) >= 20 &&
         Number(b.querySelector('[data-role="estimate-nis"]').dataset.points_nis || 0) >= 20;
}, { timeout: 8000 }, box);
let p = await panel();
console.log("panel:", JSON.stringify(p));
check(p.Fa === "1502 ± 3 N", `payload shown with its sigma: "${p.Fa}"`);
check(p.b === "0.60 ± 0.01 m", `offset shown with its sigma: "${p.b}"`);
check(/^90\d ± 16 N·m$/.test(p.moment), `moment shown with its sigma: "${p.moment}"`);
check(/^0\.6[4-6] ± 0\.01 mrad \(open loop 0\.830 mrad\)$/.test(p.theta), `theta with sigma and open loop: "${p.theta}"`);
check(/^IMU, \d+ ms ago; rope load, \d+ ms ago$/.test(p.sensors), `sensors in use with their ages: "${p.sensors}"`);
check(/^3\d\d\.\d \/ 372\.0 \(300 dof; 95 %: 253\.9 … 349\.9\)$/.test(p.nis), `NIS against its bound: "${p.nis}"`);
check(p.badgeState === "ok" && !p.badgeVisible, "no MODEL_MISMATCH badge while the model matches");
check(p.detect === "this IMU can see a 30 % preload loss (trip 12: 5.2 σ)", `the last trip's detectability: "${p.detect}"`);
const tp = p.theta_pts, np = p.nis_pts;
check(Number(tp.points_th) >= 20 && Number(tp.points_hi) >= 20 && Number(tp.points_lo) >= 20 && Number(tp.points_open) >= 20,
      `theta trend has points: estimate ${tp.points_th}, +2 sigma ${tp.points_hi}, -2 sigma ${tp.points_lo}, open loop ${tp.points_open}`);
check(Number(np.points_nis) >= 20 && Number(np.points_bound) >= 20 && Number(np.points_nlo) >= 20 && Number(np.points_nup) >= 20,
      `NIS trend has points: NIS ${np.points_nis}, bound ${np.points_bound}, 95 % bounds ${np.points_nlo}/${np.points_nup}`);
// The band is the estimate +-2 sigma (sigma_theta 1e-5 rad = 0.01 mrad) and the
// trend's values are the published ones (6.5e-4 +- 1e-5 rad).
const band = await page.evaluate(() => {
  const D = window.hoistDash.shafts.get("north/").estData;
  let n = 0, bad = 0, lo = Infinity, hi = -Infinity;
  for (let i = 0; i < D.x.length; i++) {
    if (D.th[i] === null) continue;
    n++;
    if (Math.abs(D.hi[i] - D.th[i] - 0.02) > 1e-9 || Math.abs(D.th[i] - D.lo[i] - 0.02) > 1e-9) bad++;
    lo = Math.min(lo, D.th[i]); hi = Math.max(hi, D.th[i]);
  }
  return { n, bad, lo, hi, open: D.open[D.open.length - 1] };
});
check(band.n >= 20 && band.bad === 0, `the band is theta +-2 sigma at every point (${band.n} points, ${band.bad} off)`);
check(band.lo >= 0.64 - 1e-9 && band.hi <= 0.66 + 1e-9 && Math.abs(band.open - 0.83) < 1e-9,
      `theta trend within 0.65 +- 0.01 mrad (${band.lo.toFixed(4)} .. ${band.hi.toFixed(4)}), open loop ${band.open}`);
await pub;
await page.screenshot({ path: shot });
console.log(`screenshot: ${shot}`);

// 2. The model check fails: the MODEL_MISMATCH badge, naming the NIS.
await publish("mismatch", 60);
await page.waitForFunction((sel) => document.querySelector(`${sel} [data-field="est-mismatch"]`).dataset.state === "mismatch",
                           { timeout: 3000 }, box);
p = await panel();
check(p.badgeVisible && p.badge === "MODEL_MISMATCH (NIS)", `MODEL_MISMATCH badge shown: "${p.badge}"`);
check(p.nis.startsWith("450.0 / 372.0"), `NIS above its bound shown: "${p.nis}"`);
// The daemon's MODEL_MISMATCH alarm: its value is a statistic (NIS) against the bound, not millimetres.
const row = '[data-shaft="north/"] tr.alarm[data-kind="MODEL_MISMATCH"][data-active="true"]';
await page.waitForSelector(row, { timeout: 3000 });
const val = await page.$eval(`${row} [data-field="value"]`, (e) => e.textContent);
check(val === "450.0 / 372.0", `MODEL_MISMATCH alarm row shows the NIS against its bound: "${val}"`);

// 3. The rope load cell is gone: Fa and b are not observed.
await publish("norope", 60);
await page.waitForFunction((sel) => document.querySelector(`${sel} [data-field="est-Fa"]`).textContent === "n/a" &&
                           document.querySelector(`${sel} [data-field="est-mismatch"]`).dataset.state === "ok",
                           { timeout: 3000 }, box);
p = await panel();
check(p.Fa === "n/a" && p.b === "n/a", `not observed: Fa "${p.Fa}", b "${p.b}"`);
check(/^IMU, \d+ ms ago$/.test(p.sensors), `only the IMU in use: "${p.sensors}"`);
check(p.badgeState === "ok", "the badge clears with the mismatch");
check(p.detect === "this IMU cannot see a 30 % preload loss (trip 13: 1.6 σ)", `a trip that could not tell: "${p.detect}"`);

// 4. The headline tilt shows what the alarms judge: while the estimate is in
// use, the estimate's theta (0.65 mrad) with the open-loop twin's (0.830) beside it.
await publish("inuse", 150);
const tilt = await page.waitForFunction(() => {
  const c = document.querySelector('[data-shaft="north/"] [data-role=readouts] [data-field="theta"]');
  return c && c.dataset.source === "estimate" ? { text: c.firstChild.textContent, sub: c.querySelector(".sub").textContent } : null;
}, { timeout: 3000 }).then((h) => h.jsonValue());
check(/^0\.6[4-6]\d$/.test(tilt.text) && tilt.sub === "estimate; open loop 0.830",
      `headline tilt is the estimate's with the open loop beside it: "${tilt.text}" (${tilt.sub})`);

// 5. STALE when the estimates stop.
await page.waitForFunction((sel) => document.querySelector(sel).dataset.state === "stale", { timeout: 4000 }, box);
p = await panel();
check(p.state === "stale", "the panel says STALE after the estimates stopped");

// 6. The accelerometer's calibration from the panel's form: confirmed by the
// operator, checked by hoist-dash with the daemon's rule, sent (counted) or
// refused with the bounds; estimate_t.calibrating shows while it is in force.
const form = `${box} [data-role=calibrate]`;
check(await page.$eval(form, (f) => getComputedStyle(f).display !== "none"), "the calibration form is shown (commands enabled)");
const toasts = () => page.$$eval("#toast div", (ds) => ds.map((d) => d.textContent));
const published = async () => (await stats(dash.url)).counters.commands_published || 0;
const calibrateWith = async (fa, b, duration) => {
  for (const [f, v] of [["fa", fa], ["b", b], ["duration", duration]]) {
    await page.$eval(`${form} [data-field="cal-${f}"]`, (i, v) => { i.value = v; }, String(v));
  }
  await page.click(`${form} button[data-action=calibrate]`);
};
await calibrateWith(0, 0, 20);
check(dialogs.length === 0 && (await toasts()).some((t) => t.startsWith("Enter your name")),
      "without an operator name nothing is asked or sent");
await page.type("#user", "cal-test");
const pub0 = await published();
await calibrateWith(0, 0, 20);
await page.waitForFunction(() => [...document.querySelectorAll("#toast div")].some((d) => d.textContent.startsWith("sent calibrate")),
                           { timeout: 3000 });
const sent = (await toasts()).find((t) => t.startsWith("sent calibrate"));
check(sent === "sent calibrate: the load is known, Fa = 0 N at b = 0 m for 20 s, by cal-test on north/HOIST_ALARM_ACK",
      `the calibration went out on the shaft's command channel: "${sent}"`);
check(dialogs.length === 1 && dialogs[0].startsWith("Calibrate the accelerometer of north/: the load is known, Fa = 0 N at b = 0 m, for the next 20 s?"),
      `the confirmation named the shaft and the load: "${dialogs[0]}"`);
check(await published() === pub0 + 1, "hoist-dash published it once");
await calibrateWith(0, 0, 9999);
await page.waitForFunction(() => [...document.querySelectorAll("#toast div.err")].some((d) => d.textContent.startsWith("rejected command: calibrate needs")),
                           { timeout: 3000 });
check(await published() === pub0 + 1, "a calibration outside the daemon's bounds (9999 s) is refused, with the rule, and not published");
await publish("calibrating", 60);
p = await page.$eval(`${box} [data-field="est-calibrating"]`, (n) => ({ state: n.dataset.state, text: n.textContent }));
check(p.state === "calibrating" && p.text.startsWith("CALIBRATING: the declared load is in force"),
      `estimate_t.calibrating is shown: "${p.text}"`);

await browser.close();
await stop(dash.proc);
check(errors.length === 0, `no errors in the page's console (${errors.join(" | ")})`);
console.log("PASS");
process.exit(0);

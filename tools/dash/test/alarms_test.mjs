// The alarm list and trends an operator can trust (CTest label `browser`):
// the real daemon (demo config: tight gaps, re-announce every 2 s),
// hoist-replay and hoist-dash; the page in headless Chromium; assertions on
// the page's DOM over the live twin.
//
//   node alarms_test.mjs [LCM_PORT]
//
// 1. A page opened late has trend points from before it opened (hoist-dash's
//    history), and its axes have at least 3 distinct tick labels each, the
//    speed axis from 0 to about the trip's speed (not 0..100).
// 2. The replay stops: INPUT_STALE joins the active alarms.  In every
//    animation frame over 3 s each active unacknowledged alarm's state text
//    is visible (not hidden, not transparent, not blank).
// 3. The order and the activation times are unchanged across a re-announce,
//    and the re-announce is shown apart.
// 4. Acknowledge on the last row acknowledges that row's alarm (and only it);
//    the confirmation names it.
// 5. A command whose activation is not the alarm's is refused with a clear
//    message (nothing published); a command without utime and
//    shelve_duration (a Foxglove client) is accepted.
// 6. Each side's gap is shown; no negative zero anywhere on the page.
// 7. 40 forged shafts: the full table is a notice on the page while it
//    lasts; the forged tabs leave once they age out.
import fs from "node:fs";
import path from "node:path";
import WebSocket from "ws";
import { binDir, check, openBrowser, demoConfig, fail, lcmUrl, sleep, start, startDash, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7983);
const dir = workDir("alarms");
const lcm = lcmUrl(lcmPort);
// The demo configuration, re-announcing every 2 s.
const config = path.join(dir, "demo-reannounce.toml");
fs.writeFileSync(config, fs.readFileSync(demoConfig, "utf8").replace(/^reannounce\s*=.*$/m, "reannounce = 2.0"));
if (!/reannounce = 2\.0/.test(fs.readFileSync(config, "utf8"))) fail("could not set [alarms] reannounce in the test config");

const dash = await startDash(dir, lcm, []);
const twind = start("hoist-twind", path.join(binDir, "hoist-twind"), ["--config", config, "--lcm-url", lcm], dir);
await sleep(500);
if (twind.exitCode !== null) fail(`hoist-twind exited: ${fs.readFileSync(path.join(dir, "hoist-twind.log"), "utf8")}`);
const replay = start("hoist-replay", path.join(binDir, "hoist-replay"), ["--lcm-url", lcm, "--profile", "paper", "-q"], dir);
const tReplay = Date.now();
await sleep(6000);  // history accumulates before any page is open

const { browser, page, errors, dialogs } = await openBrowser(dir);
const tOpen = Date.now();
await page.goto(dash.url, { waitUntil: "load" });

// ---- 1. history, axes --------------------------------------------------------------------
const hist = await page.waitForFunction(() => {
  const s = window.hoistDash.shafts.get("");
  return s && s.historyPoints > 0 && s.data.x.length > 0 ? { first: s.data.x[0], n: s.historyPoints } : null;
}, { timeout: 5000 }).then((h) => h.jsonValue());
const before = tOpen / 1000 - hist.first;
check(before > 3 && hist.first * 1000 >= tReplay - 2000,
      `a page opened ${((tOpen - tReplay) / 1000).toFixed(1)} s into the trip has trend points from ${before.toFixed(1)} s before it opened (${hist.n} history buckets)`);
await page.select("#window", "30");
await page.waitForFunction(() => window.hoistDash.shafts.get("").charts.every((c) => Math.abs(c.u.scales.x.max - c.u.scales.x.min - 30) < 0.01 &&
                                                                                   (c.u.axes[1]._values || []).length > 0), { timeout: 5000 });
const axes = await page.evaluate(() => {
  const s = window.hoistDash.shafts.get("");
  const vs = s.data.v.filter((v) => isFinite(v));
  return { charts: s.charts.map((c) => ({ title: c.title, labels: (c.u.axes[1]._values || []).map(String) })),
           speed: { min: s.charts[5].u.scales.y.min, max: s.charts[5].u.scales.y.max }, vmax: Math.max(...vs.map(Math.abs)) };
});
for (const c of axes.charts) {
  const distinct = new Set(c.labels).size;
  check(distinct >= 3 && distinct === c.labels.length, `${c.title}: ${distinct} distinct tick labels (${c.labels.join(" | ")})`);
}
check(axes.speed.min <= 0 && axes.speed.min >= -1.3 * axes.vmax - 1 && axes.speed.max >= axes.vmax && axes.speed.max <= 1.3 * axes.vmax + 1,
      `speed axis ${axes.speed.min.toFixed(2)}..${axes.speed.max.toFixed(2)} m/s for a trip at up to ${axes.vmax.toFixed(2)} m/s`);

// ---- 2. INPUT_STALE; state text visible in every frame ------------------------------------------
await stop(replay);
await page.waitForSelector('tr.alarm[data-kind="INPUT_STALE"][data-active="true"]', { timeout: 5000 });
await page.waitForFunction(() => document.querySelectorAll("tr.alarm.active.unacked").length >= 2, { timeout: 5000 });
const frames = await page.evaluate(() => new Promise((resolve) => {
  const t0 = performance.now();
  const res = { frames: 0, bad: [] };
  const one = () => {
    for (const td of document.querySelectorAll("tr.alarm.active.unacked td.state")) {
      const cs = getComputedStyle(td);
      const r = td.getBoundingClientRect();
      const ok = cs.visibility === "visible" && Number(cs.opacity) === 1 && cs.color !== cs.backgroundColor &&
                 cs.color !== "rgba(0, 0, 0, 0)" && td.textContent.trim().length > 0 && r.width > 0 && r.height > 0;
      if (!ok) res.bad.push(`${td.parentElement.dataset.kind}: "${td.textContent}" ${cs.visibility} ${cs.opacity} ${cs.color}`);
    }
    res.frames++;
    if (performance.now() - t0 < 3000) requestAnimationFrame(one); else resolve(res);
  };
  requestAnimationFrame(one);
}));
check(frames.frames >= 30 && frames.bad.length === 0,
      `active unacknowledged alarms' state text visible in all ${frames.frames} frames over 3 s (${frames.bad.slice(0, 3).join("; ")})`);
const blink = await page.evaluate(() => getComputedStyle(document.querySelector("tr.alarm.active.unacked td")).animationName);
check(/blinkbg/.test(blink), `the row background blinks (animation ${blink})`);

// ---- 3. order across a re-announce ---------------------------------------------------------------
const rows = () => page.evaluate(() => [...document.querySelectorAll("tr.alarm")].map((tr) => ({
  id: `${tr.dataset.kind}/${tr.dataset.level}`, activation: tr.dataset.activation,
  time: tr.querySelector('[data-field="activation"]').firstChild.textContent,
  re: tr.querySelector('[data-field="reannounce"]')?.textContent || "" })));
const r0 = await rows();
console.log("rows:", JSON.stringify(r0));
check(r0.length >= 2, `${r0.length} alarms in the list`);
const stale = r0.find((r) => r.id.startsWith("INPUT_STALE"));
const r1 = await waitFor(async () => {
  const r = await rows();
  const s1 = r.find((x) => x.id === stale.id);
  return s1 && s1.re && s1.re !== stale.re ? r : null;
}, 6000, "a re-announce of INPUT_STALE");
check(JSON.stringify(r1.map((r) => r.id)) === JSON.stringify(r0.map((r) => r.id)),
      `order unchanged across the re-announce (${r1.map((r) => r.id).join(", ")})`);
check(r1.every((r, i) => r.activation === r0[i].activation && r.time === r0[i].time),
      "each row's activation time unchanged across the re-announce");
check(r1.find((x) => x.id === stale.id).re.includes("re-announced"), `the re-announce is shown apart ("${r1.find((x) => x.id === stale.id).re.trim()}")`);

// ---- 4. Acknowledge acknowledges that row's alarm ----------------------------------------------------
await page.type("#user", "row-test");
const lastRow = r1[r1.length - 1];
const [kind, level] = lastRow.id.split("/");
const ackedBefore = await page.evaluate(() => [...document.querySelectorAll("tr.alarm")].map((tr) => `${tr.dataset.kind}/${tr.dataset.level}=${tr.dataset.acked}`));
// A locator: it waits for a stable, enabled button and retries a detached one.
const ackSel = `tr.alarm[data-kind="${kind}"][data-level="${level}"] button[data-action="acknowledge"]`;
await page.locator(ackSel).setTimeout(5000).click();
const clicked = true;
check(clicked, `clicked Acknowledge on the last row (${lastRow.id})`);
await page.waitForSelector(`tr.alarm[data-kind="${kind}"][data-level="${level}"][data-acked="true"]`, { timeout: 5000 });
const ackedAfter = await page.evaluate(() => [...document.querySelectorAll("tr.alarm")].map((tr) => `${tr.dataset.kind}/${tr.dataset.level}=${tr.dataset.acked}`));
const changed = ackedAfter.filter((x) => !ackedBefore.includes(x));
check(changed.length === 1 && changed[0] === `${lastRow.id}=true`, `Acknowledge on the last row acknowledged ${lastRow.id} and nothing else (${changed.join(", ")})`);
const levelName = ["NONE", "WARNING", "CRITICAL"][Number(level)];
check(dialogs.length === 1 && dialogs[0].startsWith(`Acknowledge ${kind} ${levelName} (active since `), `the confirmation named it: "${dialogs[0]}"`);

// ---- 5. stale and Foxglove-style commands ----------------------------------------------------------------
const w = new WebSocket(dash.url.replace("http", "ws"), ["foxglove.websocket.v1"]);
w.msgs = [];
w.on("message", (d, bin) => { if (!bin) w.msgs.push(JSON.parse(d.toString())); });
await new Promise((r) => w.on("open", r));
await waitFor(() => w.msgs.some((m) => m.op === "advertise"), 3000, "advertise");
w.send(JSON.stringify({ op: "advertise", channels: [{ id: 5, topic: "HOIST_ALARM_ACK", encoding: "json", schemaName: "hoist.alarm_ack_t" }] }));
const sendCmd = (o) => { const p = Buffer.from(JSON.stringify(o)); const h = Buffer.alloc(5); h[0] = 1; h.writeUInt32LE(5, 1); w.send(Buffer.concat([h, p])); };
const first = r1[0];
const [k0, l0] = first.id.split("/");
const pub0 = (await stats(dash.url)).counters.commands_published || 0;
sendCmd({ utime: 0, kind: k0, level: Number(l0), action: 1, shelve_duration: 0, user: "stale-page", activation_utime: Number(first.activation) - 1 });
const refusal = await waitFor(() => w.msgs.find((m) => m.op === "status" && /^refused: /.test(m.message)), 3000, "the stale command's refusal");
check(refusal.level === 2 && refusal.message.includes(`${k0} ${["NONE", "WARNING", "CRITICAL"][Number(l0)]} changed since your page drew it`),
      `a command for another activation is refused: "${refusal.message}"`);
let c = (await stats(dash.url)).counters;
check(c.commands_refused_stale === 1 && (c.commands_published || 0) === pub0, "it was counted and nothing was published");
sendCmd({ kind: "INPUT_STALE", level: 0, action: 1, user: "foxglove-user" });
await waitFor(() => w.msgs.find((m) => m.op === "status" && /^sent acknowledge INPUT_STALE/.test(m.message)), 3000,
              "the command without utime and shelve_duration to be sent");
check(true, "a command without utime and shelve_duration (a Foxglove client) is accepted and sent");
w.close();

// ---- 6. gaps, no negative zero -----------------------------------------------------------------------------
const gaps = await page.evaluate(() => {
  const s = window.hoistDash.shafts.get("");
  return { note: document.querySelector('[data-shaft=""] [data-role=scale]').textContent, pos: s.gap.pos * 1e3, neg: s.gap.neg * 1e3,
           text: document.body.innerText };
});
check(gaps.note.includes(`+y ${gaps.pos.toFixed(1)} mm`) && gaps.note.includes(`−y ${gaps.neg.toFixed(1)} mm`),
      `each side's gap is shown: "${gaps.note}"`);
const negZero = gaps.text.match(/(^|[^\d.])-0(\.0+)?(?![\d.])/gm);
check(!negZero, `no negative zero on the page (${negZero ? negZero.join(",") : "none"})`);
await page.screenshot({ path: path.join(dir, "alarms.png") });

// ---- 7. a full shaft table is visible on the page while it lasts; forged shafts leave ---------------------
if (!process.env.HOIST_HEALTH_FORGE) fail("HOIST_HEALTH_FORGE (tests/dash: hoist-test-health-forge) is not set");
const { spawnSync } = await import("node:child_process");
spawnSync(process.env.HOIST_HEALTH_FORGE, [lcm, "forged%d/", "40", "1", "0", "99"]);
await page.waitForSelector('#notices .notice[data-status-id="discovery-full"]', { visible: true, timeout: 3000 });
const notice = await page.$eval('#notices .notice[data-status-id="discovery-full"]', (e) => e.textContent);
const tabs = await page.evaluate(() => document.querySelectorAll("#tabs button").length);
check(/shaft table full/.test(notice) && tabs === 16, `the page shows "${notice}" (${tabs} tabs)`);
await page.waitForFunction(() => document.querySelectorAll("#tabs button").length === 1, { timeout: 8000 });
check(await page.evaluate(() => document.querySelector('[data-shaft=""]') !== null && !document.querySelector('[data-shaft=""]').hidden),
      "the forged shafts aged out and left the page; the real shaft stays selected");
check(errors.length === 0, `no errors in the page's console (${errors.join(" | ")})`);
await browser.close();
await stop(twind);
await stop(dash.proc);
console.log("PASS");
process.exit(0);

// hoist-dash's CPU with N browser clients on a 100 Hz twin (figures for
// docs/dashboard.md).  Not a CTest test: a measurement.
//
//   node load.mjs [LCM_PORT] [SECONDS] [N...]     e.g. node load.mjs 7875 20 0 1 10
import fs from "node:fs";
import puppeteer from "puppeteer-core";
import { cpuTicks, lcmUrl, rssKiB, sleep, startDash, startTwin, stats, stop, workDir } from "./harness.mjs";

const [portArg, secArg, ...ns] = process.argv.slice(2);
const lcm = lcmUrl(Number(portArg || 7875));
const seconds = Number(secArg || 20);
const counts = (ns.length ? ns : ["0", "1", "10"]).map(Number);
const dir = workDir("load");
const hz = 100;  // clock ticks per second (getconf CLK_TCK)
const dash = await startDash(dir, lcm, []);
const twin = await startTwin(dir, lcm, { logger: false, profile: "trapezoid:vmax=5,amax=1,travel=300,t_end=400" });
const browser = await puppeteer.launch({
  executablePath: "/usr/bin/chromium", headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--disable-background-timer-throttling",
         "--disable-renderer-backgrounding", "--disable-backgrounding-occluded-windows"],
  defaultViewport: { width: 1500, height: 1000 },
});
const pages = [];
const rows = [];
await sleep(3000);
for (const n of counts) {
  while (pages.length < n) {
    const p = await browser.newPage();
    await p.goto(dash.url);
    pages.push(p);
  }
  while (pages.length > n) await pages.pop().close();
  await sleep(3000);
  const c0 = cpuTicks(dash.proc.pid), s0 = (await stats(dash.url)).counters, t0 = Date.now();
  await sleep(seconds * 1000);
  const c1 = cpuTicks(dash.proc.pid), s1 = (await stats(dash.url)).counters, t1 = Date.now();
  const cpu = (100 * (c1 - c0) / hz) / ((t1 - t0) / 1000);
  const lcmRate = ((s1.lcm_messages || 0) - (s0.lcm_messages || 0)) / ((t1 - t0) / 1000);
  const dropped = (s1.data_frames_dropped_slow_client || 0) - (s0.data_frames_dropped_slow_client || 0);
  rows.push({ clients: n, cpu_percent: Number(cpu.toFixed(1)), lcm_msgs_per_s: Math.round(lcmRate), rss_kib: rssKiB(dash.proc.pid), dropped });
  console.log(JSON.stringify(rows[rows.length - 1]));
}
await browser.close();
await stop(twin.replay);
await stop(twin.twind);
await stop(dash.proc);
fs.writeFileSync(`${dir}/load.json`, JSON.stringify(rows, null, 1));
process.exit(0);

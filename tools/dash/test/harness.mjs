// Shared helpers of hoist-dash's Node tests: start the real programs
// (hoist-twind, hoist-replay, hoist-dash, lcm-logger) on a private LCM URL
// and a free TCP port, stop them, read lcm-logger's log through hoist-log2csv.
import { spawn, spawnSync } from "node:child_process";
import fs from "node:fs";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import { fileURLToPath } from "node:url";

export const here = path.dirname(fileURLToPath(import.meta.url));
export const srcRoot = path.resolve(here, "../../..");
export const binDir = process.env.HOIST_BIN_DIR || path.join(srcRoot, "build/bin");
export const demoConfig = path.join(srcRoot, "service/config/demo.toml");

export function lcmUrl(port) { return `udpm://239.255.76.67:${port}?ttl=0`; }

export function fail(msg) {
  console.error(`FAIL: ${msg}`);
  cleanupAll();
  process.exit(1);
}
export function check(cond, msg) {
  if (!cond) fail(msg);
  console.log(`ok: ${msg}`);
}

export function workDir(name) {
  const d = fs.mkdtempSync(path.join(os.tmpdir(), `hoist-dash-${name}-`));
  return d;
}

export async function freePort() {
  return new Promise((resolve, reject) => {
    const s = net.createServer();
    s.listen(0, "127.0.0.1", () => {
      const p = s.address().port;
      s.close(() => resolve(p));
    });
    s.on("error", reject);
  });
}

const procs = new Set();
export function cleanupAll() {
  for (const p of procs) { try { p.kill("SIGKILL"); } catch { /* gone */ } }
  procs.clear();
}
process.on("exit", cleanupAll);
process.on("SIGINT", () => { cleanupAll(); process.exit(130); });
process.on("SIGTERM", () => { cleanupAll(); process.exit(143); });

/// Starts a program; its stderr goes to dir/<name>.log, stdout is collected.
export function start(name, exe, args, dir) {
  const log = fs.openSync(path.join(dir, `${name}.log`), "w");
  const p = spawn(exe, args, { stdio: ["ignore", "pipe", log] });
  p.out = "";
  p.stdout.on("data", (d) => { p.out += d.toString(); });
  p.exited = new Promise((resolve) => p.on("exit", (code, sig) => { procs.delete(p); resolve({ code, sig }); }));
  p.name = name;
  procs.add(p);
  return p;
}

export async function stop(p, sig = "SIGTERM", timeoutMs = 5000) {
  if (p.exitCode !== null || p.signalCode !== null) return p.exited;
  p.kill(sig);
  const t = setTimeout(() => p.kill("SIGKILL"), timeoutMs);
  const r = await p.exited;
  clearTimeout(t);
  return r;
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

export async function waitFor(fn, timeoutMs, what) {
  const t0 = Date.now();
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() - t0 > timeoutMs) fail(`timed out after ${timeoutMs} ms waiting for ${what}`);
    await sleep(50);
  }
}

/// hoist-dash on a free port; resolves with { proc, port, url } once it serves.
export async function startDash(dir, lcm, extra = [], name = "hoist-dash") {
  const port = extra.includes("--port") ? [] : ["--port", "0"];  // a given --port wins
  const p = start(name, path.join(binDir, "hoist-dash"), [...port, "--lcm-url", lcm, ...extra], dir);
  const line = await waitFor(() => {
    if (p.exitCode !== null) fail(`${name} exited: ${fs.readFileSync(path.join(dir, name + ".log"), "utf8")}`);
    return /serving (http:\/\/[^ ]+)/.exec(p.out);
  }, 5000, `${name} to print its URL`);
  const url = line[1];
  return { proc: p, url, port: Number(new URL(url).port) };
}

export async function stats(url) {
  const r = await fetch(new URL("/api/stats", url));
  return r.json();
}

export function rssKiB(pid) {
  const s = fs.readFileSync(`/proc/${pid}/status`, "utf8");
  return Number(/VmRSS:\s+(\d+)/.exec(s)[1]);
}
export function cpuTicks(pid) {
  const f = fs.readFileSync(`/proc/${pid}/stat`, "utf8").split(") ")[1].split(" ");
  return Number(f[11]) + Number(f[12]);  // utime + stime
}

/// lcm-logger's log -> { CHANNEL: [ {column: string} ] } through hoist-log2csv.
/// `undecodable`: the number of events the test itself sent that must fail
/// the checked decoder (hoist-log2csv then exits 1 unless --lenient): exactly
/// that many, no more.
export function readLog(logFile, dir, { undecodable = 0 } = {}) {
  const out = path.join(dir, "csv");
  const args = [logFile, "--out-dir", out, ...(undecodable ? ["--lenient"] : [])];
  const r = spawnSync(path.join(binDir, "hoist-log2csv"), args, { encoding: "utf8" });
  if (r.status !== 0) fail(`hoist-log2csv failed: ${r.stderr}`);
  if (undecodable && !r.stderr.includes(`${undecodable} undecodable)`))
    fail(`expected exactly ${undecodable} undecodable event(s) in the log: ${r.stderr}`);
  const res = {};
  for (const f of fs.readdirSync(out)) {
    if (!f.endsWith(".csv")) continue;
    const lines = fs.readFileSync(path.join(out, f), "utf8").split("\n").filter((l) => l && !l.startsWith("#"));
    const head = lines[0].split(",");
    res[f.slice(0, -4)] = lines.slice(1).map((l) => {
      const v = splitCsv(l);
      return Object.fromEntries(head.map((h, i) => [h, v[i]]));
    });
  }
  return res;
}

function splitCsv(line) {
  const out = [];
  let cur = "", q = false;
  for (let i = 0; i < line.length; i++) {
    const c = line[i];
    if (q) {
      if (c === '"' && line[i + 1] === '"') { cur += '"'; i++; } else if (c === '"') q = false; else cur += c;
    } else if (c === '"') q = true;
    else if (c === ",") { out.push(cur); cur = ""; } else cur += c;
  }
  out.push(cur);
  return out;
}

/// The twin: daemon (demo config: tight gaps, alarms at once), lcm-logger, replay.
export async function startTwin(dir, lcm, { profile = "paper", config = demoConfig, logger = true, replay = true } = {}) {
  const r = {};
  if (logger) r.logger = start("lcm-logger", "lcm-logger", [`--lcm-url=${lcm}`, "-f", path.join(dir, "run.lcm")], dir);
  r.twind = start("hoist-twind", path.join(binDir, "hoist-twind"), ["--config", config, "--lcm-url", lcm], dir);
  await sleep(500);
  if (r.twind.exitCode !== null) fail(`hoist-twind exited: ${fs.readFileSync(path.join(dir, "hoist-twind.log"), "utf8")}`);
  if (replay) r.replay = start("hoist-replay", path.join(binDir, "hoist-replay"), ["--lcm-url", lcm, "--profile", profile, "-q"], dir);
  return r;
}

/// Debian's headless Chromium (puppeteer-core) with one 1500x1180 page:
/// page errors and console errors collected in `errors`, dialogs accepted
/// and their texts in `dialogs`; on an uncaught exception the test fails
/// with the page's screenshot in dir/failure.png.
export async function openBrowser(dir) {
  const chromium = process.env.CHROMIUM || ["/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"].find((p) => fs.existsSync(p));
  if (!chromium) fail("no Chromium found (scripts/setup.sh installs Debian's chromium)");
  const { default: puppeteer } = await import("puppeteer-core");
  const browser = await puppeteer.launch({
    executablePath: chromium, headless: true,
    args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1500,1180"],
    defaultViewport: { width: 1500, height: 1180 },
  });
  const page = await browser.newPage();
  const errors = [], dialogs = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  page.on("console", (m) => { if (m.type() === "error") errors.push(m.text()); });
  page.on("dialog", async (d) => { dialogs.push(d.message()); await d.accept(); });
  process.on("uncaughtException", async (e) => {
    console.error(`FAIL: ${e.message}`);
    try { await page.screenshot({ path: path.join(dir, "failure.png") }); console.error(`page: ${path.join(dir, "failure.png")}`); } catch { /* gone */ }
    process.exit(1);
  });
  return { browser, page, errors, dialogs };
}

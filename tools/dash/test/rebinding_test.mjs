// DNS rebinding against hoist-dash (CTest label `browser`): the Host
// allow-list and the Origin check, with raw requests and with a real headless
// Chromium whose resolver maps evil.example to 127.0.0.1
// (--host-resolver-rules), the way a rebinding DNS server would.
//
//   node rebinding_test.mjs [LCM_PORT]
//
// Raw: a request whose Host is not a name of the dashboard gets 403, HTTP and
// WebSocket alike, even with a matching Origin; the dashboard's own names
// (127.0.0.1, localhost, [::1], any port) get 200/101; an Origin that is not
// the Host's own page (another port, another name) gets 403; --allow-host and
// --allow-origin widen this; a bad --allow-host is exit 2 naming it.
// Chromium: a page loaded from evil.example:P whose server then goes away and
// hoist-dash starts on P (the rebinding) cannot open the WebSocket nor read
// /api/stats; with --allow-host evil.example the same page does open it (the
// test can fail).
import crypto from "node:crypto";
import fs from "node:fs";
import http from "node:http";
import net from "node:net";
import path from "node:path";
import { spawnSync } from "node:child_process";
import puppeteer from "puppeteer-core";
import { binDir, check, fail, freePort, lcmUrl, sleep, startDash, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7980);
const dir = workDir("rebinding");
const lcm = lcmUrl(lcmPort);
const SUB = "foxglove.websocket.v1";

function raw(port, bytes, waitMs = 2000) {
  return new Promise((resolve) => {
    const s = net.connect(port, "127.0.0.1");
    let got = Buffer.alloc(0);
    const t = setTimeout(() => { s.destroy(); resolve(got.toString("latin1")); }, waitMs);
    s.on("data", (d) => {
      got = Buffer.concat([got, d]);
      if (/^HTTP\/1\.1 101/.test(got.toString("latin1")) && got.includes("\r\n\r\n")) { clearTimeout(t); s.destroy(); resolve(got.toString("latin1")); }
    });
    s.on("close", () => { clearTimeout(t); resolve(got.toString("latin1")); });
    s.on("error", () => {});
    s.write(bytes);
  });
}
const status = (r) => Number((/^HTTP\/1\.[01] (\d+)/.exec(r) || [0, 0])[1]);
const get = async (port, host, target = "/") =>
  status(await raw(port, `GET ${target} HTTP/1.1\r\n${host === null ? "" : `Host: ${host}\r\n`}Connection: close\r\n\r\n`));
const upgrade = async (port, host, origin) => {
  const key = crypto.randomBytes(16).toString("base64");
  return status(await raw(port, `GET / HTTP/1.1\r\nHost: ${host}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
    `Sec-WebSocket-Key: ${key}\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: ${SUB}\r\n` +
    (origin ? `Origin: ${origin}\r\n` : "") + "\r\n"));
};

// ---- 1. raw requests ---------------------------------------------------------------
const dash = await startDash(dir, lcm, ["--channel-prefix", ""]);
const P = dash.port;
for (const h of [`evil.example:${P}`, "evil.example", `127.0.0.1.evil.example:${P}`, `localhost.evil.example`, `127.0.0.2:${P}`,
                 `127.0.0.1:${P}:1`, `127.0.0.1@evil.example`, `[::1`, `::1`, ""]) {
  check(await get(P, h) === 403, `GET / with Host '${h}' -> 403`);
}
check(await get(P, null) === 403, "GET / without a Host header -> 403");
check(await get(P, `evil.example:${P}`, "/api/stats") === 403, "GET /api/stats with Host evil.example -> 403");
for (const h of [`127.0.0.1:${P}`, "127.0.0.1", `localhost:${P}`, "LOCALHOST.", `[::1]:${P}`, "localhost:9000"])
  check(await get(P, h) === 200, `GET / with Host '${h}' (a name of this dashboard; the port is not compared) -> 200`);
check(await upgrade(P, `evil.example:${P}`, `http://evil.example:${P}`) === 403,
      "WebSocket with Host evil.example:P and matching Origin http://evil.example:P -> 403");
check(await upgrade(P, `evil.example:${P}`, null) === 403, "WebSocket with Host evil.example:P and no Origin -> 403");
check(await upgrade(P, `127.0.0.1:${P}`, `http://127.0.0.1:${P}`) === 101, "WebSocket from the dashboard's own page -> 101");
check(await upgrade(P, `localhost:${P}`, `http://localhost:${P}`) === 101, "WebSocket from http://localhost:P -> 101");
check(await upgrade(P, `127.0.0.1:${P}`, null) === 101, "WebSocket without Origin (a non-browser client) -> 101");
check(await upgrade(P, `127.0.0.1:${P}`, `http://127.0.0.1:${P + 1}`) === 403,
      "WebSocket from a page on another port of an allowed name -> 403");
check(await upgrade(P, `127.0.0.1:${P}`, `http://evil.example:${P}`) === 403,
      "WebSocket with an allowed Host but Origin http://evil.example:P -> 403");
let c = (await stats(dash.url)).counters;
check(c.http_rejected_host === 12 && c.ws_rejected_host === 2 && c.ws_rejected_origin === 2,
      `refusals counted (http_rejected_host ${c.http_rejected_host}, ws_rejected_host ${c.ws_rejected_host}, ws_rejected_origin ${c.ws_rejected_origin})`);
const log = fs.readFileSync(path.join(dir, "hoist-dash.log"), "utf8");
check(/Host 'evil\.example:\d+' refused/.test(log), "the refusal is logged with the Host");

const wide = await startDash(dir, lcm, ["--channel-prefix", "", "--allow-host", "evil.example", "--allow-host", "[::2]",
                                        "--allow-origin", "http://ops.example:8443"], "hoist-dash-wide");
const W = wide.port;
check(await upgrade(W, `evil.example:${W}`, `http://evil.example:${W}`) === 101, "--allow-host evil.example: that Host -> 101");
check(await get(W, "EVIL.example") === 200 && await get(W, "[::2]:80") === 200, "--allow-host: names compared case-insensitively, IPv6 in brackets");
check(await upgrade(W, `127.0.0.1:${W}`, "http://ops.example:8443") === 101, "--allow-origin http://ops.example:8443 -> 101");
check(await upgrade(W, `other.example:${W}`, "http://ops.example:8443") === 403, "--allow-origin does not widen the Host check -> 403");
await stop(wide.proc);
for (const bad of ["evil.example:80", "bad host", "[::1", "a/b"]) {
  const r = spawnSync(path.join(binDir, "hoist-dash"), ["--allow-host", bad, "--port", "0", "--lcm-url", lcm, "--duration", "1"], { encoding: "utf8" });
  check(r.status === 2 && r.stderr.includes("--allow-host") && r.stderr.includes(bad), `--allow-host '${bad}' -> exit 2 naming it (${r.stderr.trim()})`);
}
await stop(dash.proc);

// ---- 2. Chromium, simulated rebinding ------------------------------------------------
const chromium = process.env.CHROMIUM || ["/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"].find((p) => fs.existsSync(p));
if (!chromium) fail("no Chromium found (scripts/setup.sh installs Debian's chromium)");
// The attacker's page: keeps trying to open the dashboard's WebSocket on its own
// origin and, once open, to shelve everything; also reads /api/stats.
const ATTACK = `<!doctype html><title>evil</title><script>
window.results = { opened: 0, refused: 0, stats: [], sent: 0 };
function tryWs() {
  const ws = new WebSocket("ws://" + location.host + "/", ["${SUB}"]);
  ws.binaryType = "arraybuffer";
  ws.onopen = () => { window.results.opened++; };
  ws.onmessage = (ev) => {
    if (typeof ev.data !== "string") return;
    const m = JSON.parse(ev.data);
    if (m.op !== "advertise") return;
    const ack = m.channels.find((c) => c.topic.endsWith("HOIST_ALARM_ACK"));
    if (!ack) return;
    ws.send(JSON.stringify({ op: "advertise", channels: [{ id: 7, topic: ack.topic, encoding: "json", schemaName: "hoist.alarm_ack_t" }] }));
    const p = new TextEncoder().encode(JSON.stringify({ utime: 0, kind: "*", level: 0, action: 2, shelve_duration: 3600, user: "evil-page" }));
    const b = new Uint8Array(5 + p.length); b[0] = 1; new DataView(b.buffer).setUint32(1, 7, true); b.set(p, 5);
    ws.send(b); window.results.sent++;
  };
  ws.onerror = () => { window.results.refused++; };
  fetch("/api/stats", { cache: "no-store" }).then((r) => window.results.stats.push(r.status)).catch(() => window.results.stats.push(-1));
}
setInterval(tryWs, 300);
</script>`;

async function attack(browser, extraDashArgs, name) {
  const port = await freePort();
  const evil = http.createServer((req, res) => {
    if (req.url !== "/") { res.writeHead(404, { Connection: "close" }); res.end(); return; }
    res.writeHead(200, { "Content-Type": "text/html", Connection: "close" });
    res.end(ATTACK);
  });
  await new Promise((r) => evil.listen(port, "127.0.0.1", r));
  const page = await browser.newPage();
  await page.goto(`http://evil.example:${port}/`, { waitUntil: "load" });
  const before = await page.evaluate(() => document.title);
  if (before !== "evil") fail(`the attacker's page did not load from evil.example (${before})`);
  // The rebinding: evil.example's server is gone, the name now leads to hoist-dash.
  evil.closeAllConnections();
  await new Promise((r) => evil.close(r));
  const d = await startDash(dir, lcm, ["--port", String(port), "--channel-prefix", "", ...extraDashArgs], name);
  await sleep(3000);
  const res = await page.evaluate(() => window.results);
  const st = await stats(d.url);
  await page.close();
  await stop(d.proc);
  return { res, counters: st.counters };
}

const browser = await puppeteer.launch({
  executablePath: chromium, headless: true,
  args: ["--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--host-resolver-rules=MAP evil.example 127.0.0.1"],
});
const a = await attack(browser, [], "hoist-dash-rebound");
console.log("rebinding against the default dashboard:", JSON.stringify(a));
check(a.res.opened === 0 && a.res.sent === 0, `the rebound page could not open the WebSocket (${a.res.opened} opened, ${a.res.refused} refused)`);
check(a.res.stats.includes(403) && !a.res.stats.includes(200), `the rebound page's fetch of /api/stats got 403, never 200 (${[...new Set(a.res.stats)]})`);
check((a.counters.ws_rejected_host || 0) >= 1 && !a.counters.commands_published,
      `hoist-dash refused the WebSocket by Host (ws_rejected_host ${a.counters.ws_rejected_host}) and published no command`);
const b = await attack(browser, ["--allow-host", "evil.example"], "hoist-dash-control");
console.log("control, --allow-host evil.example:", JSON.stringify(b));
check(b.res.opened >= 1 && b.counters.commands_published >= 1,
      `control: with --allow-host evil.example the same page opens the WebSocket and shelves (${b.res.opened} opened, ${b.counters.commands_published} published): the check above can fail`);
await browser.close();
console.log("PASS");
process.exit(0);

// The per-peer connection limits of hoist-dash (CTest label `browser`): one
// peer cannot lock others out, and a peer is what one party controls -- all
// of loopback (any local process can bind the whole of 127.0.0.0/8), an IPv4
// address, an IPv6 /64 (unit test PeerTest).  Peers here: loopback, spread
// over many source addresses (127.0.0.2, 127.0.0.3, ...) as the attacker of
// issue 33 did, and this machine's own non-loopback IPv4 address ("E").
//
//   node peers_test.mjs [LCM_PORT]
//
// 1. 40 idle TCP connections from 40 loopback addresses are one peer: they
//    hold at most --max-per-peer, and E still loads the page and opens the WebSocket.
// 2. Loopback (from many addresses) holding its cap in WebSockets gets no
//    more; E's newcomers are admitted while the WebSocket table is full
//    (loopback's oldest closed), and a peer within its share is never closed.
// 3. The token (LoadCredential: $CREDENTIALS_DIRECTORY/hoist-dash-token):
//    with loopback at its cap and the table full, a local client without the
//    token is refused, one with it (Authorization: Bearer, or the cookie set
//    by opening /?token=...) opens a WebSocket from the reserve; more
//    loopback connections never close it.  A bad credential is exit 2.
// 4. 40 connections at once from 40 loopback addresses with --max-peer-rate 5:
//    one peer's burst, the rest refused and counted; E is not affected.
import { spawnSync } from "node:child_process";
import fs from "node:fs";
import net from "node:net";
import os from "node:os";
import path from "node:path";
import WebSocket from "ws";
import { binDir, check, fail, lcmUrl, sleep, startDash, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7981);
const dir = workDir("peers");
const lcm = lcmUrl(lcmPort);
const SUB = "foxglove.websocket.v1";
const MAXC = 8, PER = 6;  // 8 WebSockets, 16 connections, 6 per peer
const E = Object.values(os.networkInterfaces()).flat().find((i) => i && i.family === "IPv4" && !i.internal)?.address;
if (!E) fail("this test needs a non-loopback IPv4 address on this machine (a second peer besides loopback)");
const lo = (k) => `127.0.${Math.floor(k / 250)}.${2 + (k % 250)}`;  // the k-th loopback source address
let nextLo = 0;
const anyLo = () => lo(nextLo++);
console.log(`work dir ${dir}; peers: loopback (127.0.0.2, ...) and ${E}`);

let P = 0;
// An idle TCP connection from `from`; .gone turns true when the server closes it.
function idle(from) {
  return new Promise((resolve) => {
    const s = net.connect({ port: P, host: "127.0.0.1", localAddress: from });
    s.gone = false;
    s.on("close", () => { s.gone = true; });
    s.on("error", () => {});
    s.on("connect", () => resolve(s));
  });
}
// A WebSocket from `from`: resolves with the socket once open, or null if refused.
function wsFrom(from, headers = {}) {
  return new Promise((resolve) => {
    const w = new WebSocket(`ws://127.0.0.1:${P}/`, [SUB], { localAddress: from, headers });
    w.closedAt = null;
    const t = setTimeout(() => { w.terminate(); resolve(null); }, 4000);
    w.on("open", () => { clearTimeout(t); resolve(w); });
    w.on("close", () => { w.closedAt = Date.now(); });
    w.on("unexpected-response", (req, res) => { clearTimeout(t); w.status = res.statusCode; resolve(null); });
    w.on("error", () => { clearTimeout(t); resolve(null); });
  });
}
// GET `target` from `from`: { status, head } (status 0: closed without an answer).
function getFrom(from, target = "/") {
  return new Promise((resolve) => {
    const s = net.connect({ port: P, host: "127.0.0.1", localAddress: from });
    let got = "";
    const t = setTimeout(() => { s.destroy(); resolve({ status: 0, head: got }); }, 4000);
    s.on("data", (d) => { got += d.toString("latin1"); });
    s.on("close", () => {
      clearTimeout(t);
      const [head, ...body] = got.split("\r\n\r\n");
      resolve({ status: Number((/^HTTP\/1\.1 (\d+)/.exec(got) || [0, 0])[1]), head, body: body.join("\r\n\r\n") });
    });
    s.on("error", () => {});
    s.on("connect", () => s.write(`GET ${target} HTTP/1.1\r\nHost: 127.0.0.1:${P}\r\nConnection: close\r\n\r\n`));
  });
}
// The counters, asked from E (loopback may be at its cap).
const statsE = async () => JSON.parse((await getFrom(E, "/api/stats")).body);
const openCount = (arr) => arr.filter((s) => s && !s.gone && s.readyState !== WebSocket.CLOSED && s.closedAt == null).length;
// Until the server's accounting has settled (closes reach the client).
const settle = (fn, what) => waitFor(fn, 3000, what);

// ---- 1. idle TCP flood from 40 loopback addresses: one peer -------------------------------------
let dash = await startDash(dir, lcm, ["--channel-prefix", "", "--max-clients", String(MAXC), "--max-per-peer", String(PER),
                                      "--max-peer-rate", "1000"]);
P = dash.port;
const flood = [];
for (let i = 0; i < 40; i++) flood.push(await idle(anyLo()));
await settle(() => openCount(flood) <= PER, `the loopback flood to be cut to ${PER}`);
check(openCount(flood) <= PER, `40 idle connections from 40 loopback addresses hold ${openCount(flood)} (<= --max-per-peer ${PER}: one peer)`);
check((await getFrom(E)).status === 200, `meanwhile ${E} loads the page (200)`);
const wE = await wsFrom(E);
check(wE !== null, "and opens the WebSocket");
for (const s of flood) s.destroy();

// ---- 2. WebSockets ------------------------------------------------------------------------------
const hog = [];
for (let i = 0; i < PER + 3; i++) hog.push(await wsFrom(anyLo()));
check(hog.filter(Boolean).length === PER, `loopback (from ${PER + 3} addresses) got ${hog.filter(Boolean).length} WebSockets (its cap ${PER})`);
// loopback holds 6, E holds 1: one slot of 8 left; E's newcomers then take loopback's excess.
const newcomers = [];
for (let i = 0; i < 3; i++) {
  const w = await wsFrom(E);
  newcomers.push(w);
  check(w !== null, `${E} opens WebSocket ${i + 2} with the table full (loopback holds more than its share)`);
}
await settle(() => openCount(hog.filter(Boolean)) <= MAXC / 2, "loopback's excess WebSockets to close");
check(openCount(hog.filter(Boolean)) <= MAXC / 2, `loopback's oldest WebSockets were closed to make room: it holds ${openCount(hog.filter(Boolean))}`);
check(wE.closedAt === null && newcomers.every((w) => w && w.closedAt === null), "no WebSocket of the peer within its share was closed");
let st = await statsE();
check((st.counters.ws_evicted_over_share || 0) >= 2, `evictions counted (ws_evicted_over_share ${st.counters.ws_evicted_over_share})`);
for (const w of [...hog, ...newcomers, wE]) if (w) w.terminate();
await stop(dash.proc);

// ---- 3. the reserve of clients with the token ---------------------------------------------------------
const cred = path.join(dir, "credentials");
fs.mkdirSync(cred, { mode: 0o700 });
const token = "t0ken-" + Math.random().toString(36).slice(2) + "-0123456789";
fs.writeFileSync(path.join(cred, "hoist-dash-token"), `${token}\n`, { mode: 0o600 });
fs.writeFileSync(path.join(cred, "short"), "abc\n", { mode: 0o600 });
const bad = spawnSync(path.join(binDir, "hoist-dash"), ["--port", "0", "--token-credential", "short", "--duration", "1"],
                      { env: { ...process.env, CREDENTIALS_DIRECTORY: cred }, encoding: "utf8" });
check(bad.status === 2 && /--token-credential short: .*16 to 256/.test(bad.stderr), `a bad credential is exit 2 naming it (${bad.stderr.trim()})`);
const missing = spawnSync(path.join(binDir, "hoist-dash"), ["--port", "0", "--token-credential", "nosuch", "--duration", "1"],
                          { env: { ...process.env, CREDENTIALS_DIRECTORY: cred }, encoding: "utf8" });
check(missing.status === 2 && /nosuch: no such credential/.test(missing.stderr), `a missing named credential is exit 2 (${missing.stderr.trim()})`);
process.env.CREDENTIALS_DIRECTORY = cred;
dash = await startDash(dir, lcm, ["--channel-prefix", "", "--max-clients", "4", "--max-per-peer", "4", "--reserved-clients", "2",
                                  "--max-peer-rate", "1000"], "hoist-dash-token");
delete process.env.CREDENTIALS_DIRECTORY;
P = dash.port;
const local = [];
for (let i = 0; i < 4; i++) local.push(await wsFrom(anyLo()));
check(local.every(Boolean), "loopback holds its cap (4) of WebSockets: the table (4) is full");
const refused = await wsFrom(anyLo());
check(refused === null, `a local client without the token is refused (HTTP ${refused === null ? "refused" : "open"})`);
const bearer = await wsFrom(anyLo(), { Authorization: `Bearer ${token}` });
check(bearer !== null, "a local client with the token (Authorization: Bearer) opens a WebSocket from the reserve");
const page = await getFrom(anyLo(), `/?token=${encodeURIComponent(token)}`);
const cookie = /^Set-Cookie: (hoist_dash_token=[^;]+);.*HttpOnly.*SameSite=Strict/mi.exec(page.head);
check(page.status === 200 && cookie, `the page opened once as /?token=... sets the cookie (${page.status}, ${cookie ? "HttpOnly, SameSite=Strict" : "none"})`);
const byCookie = await wsFrom(anyLo(), { Cookie: cookie[1] });
check(byCookie !== null, "and the browser's WebSocket with that cookie opens (the reserve's second slot)");
const more = [];
for (let i = 0; i < 12; i++) more.push(await idle(anyLo()));
for (let i = 0; i < 3; i++) more.push(await wsFrom(anyLo()));
await sleep(300);  // give the server the chance to close the wrong ones
check(bearer.closedAt === null && byCookie.closedAt === null, "more loopback connections never close an authenticated client");
check((await wsFrom(anyLo(), { Authorization: "Bearer wrong-token-0123456789" })) === null, "a wrong token gets nothing");
st = await statsE();
check(st.counters.clients_authenticated >= 2 && (st.counters.http_rejected_probation_unauthenticated || 0) >= 1,
      `counted: ${st.counters.clients_authenticated} authenticated, ${st.counters.http_rejected_probation_unauthenticated} refused on probation`);
for (const w of [...local, ...more, bearer, byCookie]) if (w) (w.terminate || w.destroy).call(w);
await stop(dash.proc);

// ---- 4. connection rate ---------------------------------------------------------------------------
const slow = await startDash(dir, lcm, ["--channel-prefix", "", "--max-peer-rate", "5"], "hoist-dash-rate");
P = slow.port;
const burst = await Promise.all(Array.from({ length: 40 }, () => new Promise((resolve) => {
  const s = net.connect({ port: P, host: "127.0.0.1", localAddress: anyLo() });
  s.gone = false;
  s.on("close", () => { s.gone = true; });
  s.on("error", () => {});
  s.on("connect", () => resolve(s));
})));
await settle(() => burst.filter((s) => s.gone).length >= 40 - 2 * 5 - 8, "the refusals");
const nRefused = burst.filter((s) => s.gone).length;
// (at most 30: the burst of 10 is admitted; a slow machine refills a few tokens meanwhile)
check(nRefused >= 40 - 2 * 5 - 8 && nRefused <= 40 - 2 * 5,
      `40 connections at once from 40 loopback addresses with --max-peer-rate 5: ${nRefused} refused (one peer's burst of ${2 * 5} admitted)`);
check((await getFrom(E)).status === 200, `${E} is not affected (200)`);
st = await statsE();
check(st.counters.http_rejected_peer_rate === nRefused, `refusals counted (http_rejected_peer_rate ${st.counters.http_rejected_peer_rate})`);
for (const s of burst) s.destroy();
await stop(slow.proc);
console.log("PASS");
process.exit(0);

// The per-peer connection limits of hoist-dash (CTest label `browser`): one
// peer (remote address) cannot lock others out.  Loopback gives every test
// peer its own source address (127.0.0.2, 127.0.0.3, ... bound before connect).
//
//   node peers_test.mjs [LCM_PORT]
//
// 1. A peer that opens 40 idle TCP connections holds at most --max-per-peer
//    (its own oldest idle connections make room), and another peer still
//    loads the page and opens the WebSocket.
// 2. A peer holding its cap in WebSockets gets no more; peers arriving while
//    the WebSocket table is full are admitted (the hog's oldest WebSocket is
//    closed), and a peer within its share is never closed.
// 3. The global connection table full of idle connections from three peers:
//    a fourth peer is still admitted.
// 4. A peer opening connections faster than --max-peer-rate is refused
//    beyond the burst and counted; another peer is not affected.
import net from "node:net";
import WebSocket from "ws";
import { check, lcmUrl, sleep, startDash, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7981);
const dir = workDir("peers");
const lcm = lcmUrl(lcmPort);
const SUB = "foxglove.websocket.v1";
const MAXC = 8, PER = 6;  // 8 WebSockets, 16 connections, 6 per peer
const dash = await startDash(dir, lcm, ["--channel-prefix", "", "--max-clients", String(MAXC), "--max-per-peer", String(PER),
                                        "--max-peer-rate", "1000"]);
const P = dash.port;

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
function wsFrom(from, port = P) {
  return new Promise((resolve) => {
    const w = new WebSocket(`ws://127.0.0.1:${port}/`, [SUB], { localAddress: from });
    w.closedAt = null;
    const t = setTimeout(() => { w.terminate(); resolve(null); }, 4000);
    w.on("open", () => { clearTimeout(t); resolve(w); });
    w.on("close", () => { w.closedAt = Date.now(); });
    w.on("unexpected-response", () => { clearTimeout(t); resolve(null); });
    w.on("error", () => { clearTimeout(t); resolve(null); });
  });
}
function getFrom(from, port = P) {
  return new Promise((resolve) => {
    const s = net.connect({ port, host: "127.0.0.1", localAddress: from });
    let got = "";
    const t = setTimeout(() => { s.destroy(); resolve(0); }, 4000);
    s.on("data", (d) => { got += d.toString("latin1"); });
    s.on("close", () => { clearTimeout(t); resolve(Number((/^HTTP\/1\.1 (\d+)/.exec(got) || [0, 0])[1])); });
    s.on("error", () => {});
    s.on("connect", () => s.write(`GET / HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nConnection: close\r\n\r\n`));
  });
}
const openCount = (arr) => arr.filter((s) => s && !s.gone && s.readyState !== WebSocket.CLOSED && s.closedAt == null).length;

// ---- 1. idle TCP flood from one peer ------------------------------------------------------
const flood = [];
for (let i = 0; i < 40; i++) flood.push(await idle("127.0.0.2"));
await sleep(300);
check(openCount(flood) <= PER, `peer 127.0.0.2 opened 40 idle connections and holds ${openCount(flood)} (<= --max-per-peer ${PER})`);
check(await getFrom("127.0.0.3") === 200, "meanwhile peer 127.0.0.3 loads the page (200)");
const w3 = await wsFrom("127.0.0.3");
check(w3 !== null, "and opens the WebSocket");
for (const s of flood) s.destroy();

// ---- 2. WebSockets -----------------------------------------------------------------------
const hog = [];
for (let i = 0; i < PER + 3; i++) hog.push(await wsFrom("127.0.0.2"));
check(hog.filter(Boolean).length === PER, `peer 127.0.0.2 got ${hog.filter(Boolean).length} WebSockets of ${PER + 3} tried (its cap ${PER})`);
// 127.0.0.2 holds 6, 127.0.0.3 holds 1: one WebSocket slot of 8 left.
const newcomers = [];
for (const from of ["127.0.0.4", "127.0.0.5", "127.0.0.6", "127.0.0.7"]) {
  const w = await wsFrom(from);
  newcomers.push(w);
  check(w !== null, `peer ${from} opens a WebSocket with the table full (the hog holds more than its share)`);
}
await sleep(300);
const hogOpen = openCount(hog.filter(Boolean));
check(hogOpen <= 3, `the hog's oldest WebSockets were closed to make room: it holds ${hogOpen}`);
check(w3.closedAt === null && newcomers.every((w) => w && w.closedAt === null), "no peer within its share was closed");
let st = await stats(dash.url);
check((st.counters.ws_evicted_over_share || 0) >= 3, `evictions counted (ws_evicted_over_share ${st.counters.ws_evicted_over_share})`);
for (const w of [...hog, ...newcomers, w3]) if (w) w.terminate();
await sleep(300);

// ---- 3. the connection table full of idle connections from three peers -----------------
const table = [];
for (const [from, n] of [["127.0.0.10", PER], ["127.0.0.11", PER], ["127.0.0.12", 2 * MAXC - 2 * PER]])
  for (let i = 0; i < n; i++) table.push(await idle(from));
await sleep(200);
// (the test's own keep-alive connection for /api/stats, from 127.0.0.1, may hold one slot)
check(openCount(table) >= 2 * MAXC - 1, `three peers hold ${openCount(table)} idle connections: the table (${2 * MAXC}) is full`);
check(await getFrom("127.0.0.14") === 200, "a fourth peer still loads the page with the table full");
const w14 = await wsFrom("127.0.0.14");
check(w14 !== null, "and opens the WebSocket");
st = await stats(dash.url);
check((st.counters.connections_evicted_over_share || 0) >= 1,
      `connections closed to make room were of peers over their share (connections_evicted_over_share ${st.counters.connections_evicted_over_share})`);
for (const s of table) s.destroy();
w14.terminate();
await stop(dash.proc);

// ---- 4. connection rate ---------------------------------------------------------------
const slow = await startDash(dir, lcm, ["--channel-prefix", "", "--max-peer-rate", "5"], "hoist-dash-rate");
const burst = await Promise.all(Array.from({ length: 40 }, () => new Promise((resolve) => {
  const s = net.connect({ port: slow.port, host: "127.0.0.1", localAddress: "127.0.0.20" });
  s.gone = false;
  s.on("close", () => { s.gone = true; });
  s.on("error", () => {});
  s.on("connect", () => resolve(s));
})));
await sleep(500);
const refused = burst.filter((s) => s.gone).length;
// (at most 30: the burst of 10 is admitted; a slow machine refills a few tokens meanwhile)
check(refused >= 40 - 2 * 5 - 8 && refused <= 40 - 2 * 5,
      `40 connections at once from 127.0.0.20 with --max-peer-rate 5: ${refused} refused (the burst of ${2 * 5} admitted)`);
check(await getFrom("127.0.0.21", slow.port) === 200, "another peer is not affected (200)");
st = await stats(slow.url);
check(st.counters.http_rejected_peer_rate === refused, `refusals counted (http_rejected_peer_rate ${st.counters.http_rejected_peer_rate})`);
for (const s of burst) s.destroy();
await stop(slow.proc);
console.log("PASS");
process.exit(0);

// Bad input against hoist-dash (CTest label `browser`): path traversal and
// its encoded variants, malformed HTTP, a missing subprotocol, a foreign
// Origin, malformed WebSocket frames, bad JSON, unknown ops, oversized
// messages, and commands sent to a --read-only server.  Each is rejected with
// a clear answer, counted in /api/stats, and the server keeps serving.
//
//   node badinput_test.mjs [LCM_PORT]
import crypto from "node:crypto";
import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import WebSocket from "ws";
import { check, lcmUrl, sleep, startDash, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7873);
const dir = workDir("badinput");
const lcm = lcmUrl(lcmPort);
const dash = await startDash(dir, lcm, ["--channel-prefix", "", "--max-message", "4096"]);
const ro = await startDash(dir, lcm, ["--channel-prefix", "", "--read-only"], "hoist-dash-ro");
const SUB = "foxglove.websocket.v1";

// Raw bytes to the port; resolves with everything the server sent before closing (or 2 s).
function raw(port, bytes, { waitMs = 2000 } = {}) {
  return new Promise((resolve) => {
    const s = net.connect(port, "127.0.0.1");
    let got = Buffer.alloc(0);
    const t = setTimeout(() => { s.destroy(); resolve(got); }, waitMs);
    s.on("data", (d) => { got = Buffer.concat([got, d]); });
    s.on("close", () => { clearTimeout(t); resolve(got); });
    s.on("error", () => {});
    s.write(bytes);
  });
}
const get = async (port, target) => {
  const r = (await raw(port, `GET ${target} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n`)).toString("latin1");
  return { status: Number((/^HTTP\/1\.1 (\d+)/.exec(r) || [0, 0])[1]), body: r };
};

// 1. Path traversal, plain and encoded.
const before = (await stats(dash.url)).counters;
const targets = ["/../../etc/passwd", "/%2e%2e/%2e%2e/etc/passwd", "/..%2f..%2fetc%2fpasswd", "/%252e%252e/%252e%252e/etc/passwd",
                 "/vendor/../../../../etc/passwd", "/..\\..\\etc\\passwd", "/%2e%2e%5c%2e%2e%5cetc%5cpasswd", "/.%2e/.%2e/etc/passwd",
                 "/index.html%00.png"];
for (const t of targets) {
  const r = await get(dash.port, t);
  check(r.status === 403 && !/root:/.test(r.body), `GET ${t} -> ${r.status}, no file content`);
}
let c = (await stats(dash.url)).counters;
check((c.http_rejected_traversal || 0) - (before.http_rejected_traversal || 0) === targets.length,
      `${targets.length} traversal attempts counted (http_rejected_traversal = ${c.http_rejected_traversal})`);
check((await get(dash.port, "/nonexistent.js")).status === 404, "unknown file -> 404");
check((await get(dash.port, "/%zz")).status === 400, "malformed percent escape -> 400");

// 1b. Network strings in the log: a traversal whose path carries C1 controls
// (CSI U+009B, raw and percent-encoded) and bidi controls (RLO U+202E, LRI
// U+2066) is logged escaped, never as the raw bytes that reorder or hide
// what an operator reads in the journal.
{
  const evil = Buffer.concat([Buffer.from("GET /../\u202eetc/\u2066passwd"), Buffer.from([0xc2, 0x9b]),
                              Buffer.from("31m%C2%9B%E2%80%AE HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n")]);
  const r = (await raw(dash.port, evil)).toString("latin1");
  check(/^HTTP\/1\.1 403/.test(r), "a traversal with C1 and bidi characters in its path -> 403");
  const log = await waitFor(() => {
    const l = fs.readFileSync(path.join(dir, "hoist-dash.log"), "utf8").split("\n").filter((x) => x.includes("refused path traversal: /../"));
    return l.find((x) => x.includes("31m")) || null;
  }, 3000, "the traversal's log line");
  check(!/[\u0080-\u009f\u061c\u200e\u200f\u202a-\u202e\u2066-\u2069]/.test(log) && log.includes("\\u202e") &&
        log.includes("\\u2066") && log.includes("\\u009b"), `logged with C1 and bidi escaped: ${log.slice(log.indexOf("refused"))}`);
}

// 2. Malformed HTTP and an oversized header.
let r = (await raw(dash.port, "GARBAGE\r\n\r\n")).toString();
check(/^HTTP\/1\.1 400/.test(r), "malformed request line -> 400");
r = (await raw(dash.port, `GET / HTTP/1.1\r\nHost: x\r\nX-Big: ${"a".repeat(20000)}\r\n\r\n`)).toString();
check(/^HTTP\/1\.1 (413|400|431)/.test(r), `oversized header -> ${r.slice(9, 12)}`);
r = (await raw(dash.port, "POST / HTTP/1.1\r\nHost: x\r\nContent-Length: 5\r\n\r\nhello")).toString();
check(/^HTTP\/1\.1 (413|405)/.test(r), `request body -> ${r.slice(9, 12)}`);

// 3. WebSocket without the subprotocol, from a foreign origin.
const wsFail = (opts, protos = [SUB]) => new Promise((resolve) => {
  const w = new WebSocket(dash.url.replace("http", "ws"), protos, opts);
  w.on("unexpected-response", (_req, res) => resolve(res.statusCode));
  w.on("open", () => { w.close(); resolve(101); });
  w.on("error", () => resolve(-1));
});
check(await wsFail({}, []) === 400, "WebSocket without subprotocol foxglove.websocket.v1 -> 400");
check(await wsFail({ origin: "http://evil.example" }) === 403, "WebSocket from a foreign Origin -> 403");

// 4. Malformed frames over a raw handshake.
// The frame goes out after the 101 (a client must wait for it, RFC 6455 4.1).
function rawWs(frame) {
  const key = crypto.randomBytes(16).toString("base64");
  const hs = `GET / HTTP/1.1\r\nHost: 127.0.0.1:${dash.port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
             `Sec-WebSocket-Key: ${key}\r\nSec-WebSocket-Version: 13\r\nSec-WebSocket-Protocol: ${SUB}\r\n\r\n`;
  return new Promise((resolve) => {
    const s = net.connect(dash.port, "127.0.0.1");
    let got = Buffer.alloc(0), sent = false;
    const t = setTimeout(() => { s.destroy(); resolve({ got, closed: false }); }, 3000);
    s.on("data", (d) => {
      got = Buffer.concat([got, d]);
      if (!sent && got.includes("\r\n\r\n")) { sent = true; s.write(frame); }
    });
    s.on("close", () => { clearTimeout(t); resolve({ got, closed: true }); });
    s.on("error", () => {});
    s.write(hs);
  });
}
const masked = (op, payload, fin = true, rsv = 0) => {
  const m = crypto.randomBytes(4);
  const p = Buffer.from(payload);
  const x = Buffer.from(p.map((b, i) => b ^ m[i % 4]));
  return Buffer.concat([Buffer.from([(fin ? 0x80 : 0) | rsv | op, 0x80 | p.length]), m, x]);
};
const frames = {
  "reserved opcode 0x3": masked(0x3, "x"),
  "unmasked client frame": Buffer.from([0x81, 0x02, 0x68, 0x69]),
  "RSV bits without extension": masked(0x1, "hi", true, 0x40),
  "fragmented control frame": masked(0x9, "p", false),
  "invalid UTF-8 text": masked(0x1, Buffer.from([0xc3, 0x28])),
};
const b4 = (await stats(dash.url)).counters.ws_rejected_malformed_frame || 0;
for (const [name, f] of Object.entries(frames)) {
  const { got, closed } = await rawWs(f);
  const text = got.toString("latin1");
  const close = got.indexOf(Buffer.from([0x88]), text.indexOf("\r\n\r\n"));
  check(/^HTTP\/1\.1 101/.test(text) && close > 0, `handshake, then ${name}: the server sends close (code ${close > 0 && got.length >= close + 4 ? got.readUInt16BE(close + 2) : "?"})${closed ? " and closes" : ""}`);
}
// (Beast first completes the closing handshake or its timeout, then reports.)
await waitFor(async () => ((await stats(dash.url)).counters.ws_rejected_malformed_frame || 0) - b4 >= Object.keys(frames).length,
              12000, "the malformed frames to be counted");
c = (await stats(dash.url)).counters;
check((c.ws_rejected_malformed_frame || 0) - b4 === Object.keys(frames).length,
      `malformed frames counted (ws_rejected_malformed_frame = ${c.ws_rejected_malformed_frame})`);

// 5. Bad JSON, unknown ops, bad subscribe, oversized message on a real client.
function client(url) {
  return new Promise((resolve) => {
    const w = new WebSocket(url.replace("http", "ws"), [SUB]);
    w.msgs = [];
    w.closed = null;
    w.on("message", (d, isBin) => { if (!isBin) w.msgs.push(JSON.parse(d.toString())); });
    w.on("close", (code) => { w.closed = code; });
    w.on("open", () => resolve(w));
  });
}
const w = await client(dash.url);
await waitFor(() => w.msgs.some((m) => m.op === "advertise"), 3000, "advertise");
const statusCount = () => w.msgs.filter((m) => m.op === "status" && m.level === 2).length;
const sends = ["not json", "[1,2]", JSON.stringify({ op: "frobnicate" }), JSON.stringify({ op: "getParameters", parameterNames: [] }),
               JSON.stringify({ op: "subscribe", subscriptions: [{ id: -1, channelId: "x" }] }),
               JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: 999999 }] })];
for (const s of sends) w.send(s);
w.send(Buffer.from([0x07, 1, 2, 3]));
await waitFor(() => statusCount() >= sends.length + 1, 3000, "one error status per bad message");
check(true, `each bad message answered with an error status (${statusCount()})`);
c = (await stats(dash.url)).counters;
check(c.ws_rejected_bad_json === 2 && c.ws_rejected_unknown_op === 1 && c.ws_rejected_unsupported_op === 1 &&
      c.ws_rejected_bad_request === 2 && c.ws_rejected_unknown_binary_op === 1, `counted: ${JSON.stringify(c)}`);
w.send("x".repeat(10000));  // over --max-message 4096
await waitFor(() => w.closed !== null, 3000, "close after an oversized message");
check(w.closed === 1009, `oversized message -> close code ${w.closed} (1009: message too big)`);
check(((await stats(dash.url)).counters.ws_rejected_oversized || 0) === 1, "oversized message counted");

// 6. Commands to a --read-only server.
const rw = await client(ro.url);
await waitFor(() => rw.msgs.some((m) => m.op === "serverInfo"), 3000, "serverInfo");
const si = rw.msgs.find((m) => m.op === "serverInfo");
check(!si.capabilities.includes("clientPublish"), `--read-only serverInfo announces no clientPublish (${JSON.stringify(si.capabilities)})`);
rw.send(JSON.stringify({ op: "advertise", channels: [{ id: 1, topic: "HOIST_ALARM_ACK", encoding: "json", schemaName: "hoist.alarm_ack_t" }] }));
const payload = Buffer.from(JSON.stringify({ kind: "CAGE_POS_Y", level: 0, action: 1, shelve_duration: 0, user: "intruder" }));
const hdr = Buffer.alloc(5); hdr[0] = 1; hdr.writeUInt32LE(1, 1);
rw.send(Buffer.concat([hdr, payload]));
await waitFor(() => rw.msgs.filter((m) => m.op === "status" && /read-only/.test(m.message)).length >= 2, 3000, "read-only rejections");
const rc = (await stats(ro.url)).counters;
check(rc.commands_rejected_read_only === 2 && !rc.commands_published, `--read-only: advertise and message refused and counted (${JSON.stringify(rc)})`);
rw.close();

// 7. Still alive and serving.
check((await get(dash.port, "/")).status === 200 && (await get(ro.port, "/app.js")).status === 200, "both servers still serve the page");
const e1 = await stop(dash.proc), e2 = await stop(ro.proc);
check(e1.code === 0 && e2.code === 0, `clean exit on SIGTERM (${JSON.stringify([e1, e2])})`);
console.log("PASS");
process.exit(0);

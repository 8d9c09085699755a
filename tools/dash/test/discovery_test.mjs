// Shaft discovery poisoning against hoist-dash (CTest label `browser`), with
// forged HOIST_HEALTH datagrams (tests/dash/health_forge.cpp) on the real
// LCM group and the real daemon.
//
//   node discovery_test.mjs [LCM_PORT]
//
// 1. 300 forged prefixes, one datagram each (with a forged instance id): the
//    16-slot table fills, the refusals are a log line and a status a client
//    sees (Foxglove `status` with id "discovery-full") and /api/stats shows,
//    while it lasts.
// 2. The forged slots age out; the real daemon (hoist-twind, prefix north/)
//    started afterwards appears and is confirmed (instance id, health rate).
// 3. A forger that keeps sending north_HOIST_HEALTH at the health rate: both
//    north/ and north_ are listed, and the clash of their shaft name "north"
//    is a log line and a status.
import fs from "node:fs";
import path from "node:path";
import { spawnSync } from "node:child_process";
import WebSocket from "ws";
import { binDir, check, demoConfig, fail, lcmUrl, sleep, start, startDash, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7982);
const dir = workDir("discovery");
const lcm = lcmUrl(lcmPort);
const forge = process.env.HOIST_HEALTH_FORGE;
if (!forge) fail("HOIST_HEALTH_FORGE (tests/dash: hoist-test-health-forge) is not set");
const dash = await startDash(dir, lcm, []);  // discovery (the default)

// A protocol client that records every status.
const w = new WebSocket(dash.url.replace("http", "ws"), ["foxglove.websocket.v1"]);
w.msgs = [];
w.on("message", (d, bin) => { if (!bin) w.msgs.push(JSON.parse(d.toString())); });
await new Promise((r) => w.on("open", r));

// ---- 1. 300 forged prefixes ---------------------------------------------------------
let r = spawnSync(forge, [lcm, "forged%d/", "300", "1", "0", "424242"], { encoding: "utf8" });
if (r.status !== 0) fail(`forger failed: ${r.stderr}`);
let st = await waitFor(async () => { const s = await stats(dash.url); return s.discovery.refused_total >= 200 ? s : null; },
                       5000, "the forged prefixes to be refused");
check(st.discovery.table_full && st.discovery.slots === 16 && st.discovery.max === 16,
      `the table is full of forged candidates (${st.discovery.slots}/${st.discovery.max}; ${st.discovery.refused_total} refused)`);
check(st.discovery.status.some((s) => s.id === "discovery-full" && /table full/.test(s.message)),
      `/api/stats shows the table-full status (${JSON.stringify(st.discovery.status.map((s) => s.message))})`);
await waitFor(() => w.msgs.some((m) => m.op === "status" && m.id === "discovery-full"), 2000, "the status to reach the client");
check(true, "a connected client got the table-full status (Foxglove status id discovery-full)");
check(/shaft discovery: shaft table full/.test(fs.readFileSync(path.join(dir, "hoist-dash.log"), "utf8")), "a log line says the table is full");

// ---- 2. they age out; the real daemon appears ----------------------------------------
st = await waitFor(async () => { const s = await stats(dash.url); return s.discovery.slots === 0 ? s : null; },
                   8000, "the forged single-datagram prefixes to age out");
check(st.counters.prefix_aged_out === 16, `the 16 forged slots aged out (prefix_aged_out ${st.counters.prefix_aged_out})`);
await waitFor(() => w.msgs.filter((m) => m.op === "unadvertise").length >= 16, 3000, "the forged channels to be unadvertised");
check(true, "clients were told (16 unadvertise messages)");
const twind = start("hoist-twind", path.join(binDir, "hoist-twind"), ["--config", demoConfig, "--lcm-url", lcm, "--channel-prefix", "north/"], dir);
// Meanwhile another burst of forgeries: they must not keep the real daemon out.
spawnSync(forge, [lcm, "again%d/", "300", "1", "0", "424242"]);
st = await waitFor(async () => { const s = await stats(dash.url); return s.discovery.confirmed.includes("north/") ? s : null; },
                   12000, "the real daemon north/ to be discovered and confirmed");
check(st.prefixes.includes("north/"), `the real daemon appears after 600 forged prefixes (prefixes ${JSON.stringify(st.prefixes)})`);
await waitFor(() => w.msgs.some((m) => m.op === "advertise" && m.channels.some((c) => c.topic === "north/HOIST_CAGE")), 2000,
              "north/ to be advertised to the client");
check(true, "north/HOIST_CAGE advertised to the connected client");

// ---- 3. a name clash -------------------------------------------------------------------
const forger = start("forger", forge, [lcm, "north_", "1", "8", "1000", "777"], dir);
st = await waitFor(async () => { const s = await stats(dash.url); return s.prefixes.includes("north_") && s.discovery.status.some((x) => x.id === "discovery-clash:north") ? s : null; },
                   6000, "the clash north/ vs north_ to be reported");
check(st.prefixes.includes("north/") && st.prefixes.includes("north_"), `both prefixes are listed (${JSON.stringify(st.prefixes)})`);
const clash = st.discovery.status.find((x) => x.id === "discovery-clash:north");
check(/'north\/'/.test(clash.message) && /'north_'/.test(clash.message), `the status names both: ${clash.message}`);
check(w.msgs.some((m) => m.op === "status" && m.id === "discovery-clash:north"), "a connected client got the clash status");
check(/shaft discovery: prefixes .*north.*give the shaft name 'north'/.test(fs.readFileSync(path.join(dir, "hoist-dash.log"), "utf8")),
      "a log line reports the clash");
await stop(forger);
await stop(twind);
w.close();
await stop(dash.proc);
console.log("PASS");
process.exit(0);

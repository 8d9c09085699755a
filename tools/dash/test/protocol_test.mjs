// Protocol test of hoist-dash (CTest label `browser`): the official
// @foxglove/ws-protocol client in Node against the real twin.
//
//   node protocol_test.mjs [LCM_PORT]
//
// Connects, receives serverInfo and advertise (every hoist channel with a
// parseable JSON Schema naming the msgs/*.lcm fields), subscribes to
// HOIST_CAGE, decodes >= 50 messages, and checks that their fields equal what
// lcm-logger recorded in the same run (through hoist-log2csv, round-trip
// exact doubles).  Also publishes one HOIST_ALARM_ACK as a client channel, and
// checks HOIST_FORECAST (nested forecast_scenario_t) end to end.
import foxglove from "@foxglove/ws-protocol";
import path from "node:path";
import WebSocket from "ws";
import { check, fail, lcmUrl, readLog, sleep, start, startDash, startTwin, stop, waitFor, workDir } from "./harness.mjs";

const { FoxgloveClient } = foxglove;
const lcmPort = Number(process.argv[2] || 7872);
const dir = workDir("protocol");
const lcm = lcmUrl(lcmPort);
console.log(`work dir ${dir}, LCM ${lcm}`);
const dash = await startDash(dir, lcm, []);
const twin = await startTwin(dir, lcm);

const ws = new WebSocket(dash.url.replace("http", "ws"), [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
const client = new FoxgloveClient({ ws });
let info = null;
const channels = new Map();
const decoded = [];
const statuses = [];
let cageSub = null;
let fcSub = null;
const forecasts = [];
client.on("serverInfo", (i) => { info = i; });
client.on("status", (s) => statuses.push(s));
client.on("error", (e) => fail(`client error: ${e}`));
client.on("advertise", (chs) => {
  for (const ch of chs) channels.set(ch.topic, ch);
  const cage = channels.get("HOIST_CAGE");
  if (cage && cageSub === null) cageSub = client.subscribe(cage.id);
  const fc = channels.get("HOIST_FORECAST");
  if (fc && fcSub === null) fcSub = client.subscribe(fc.id);
});
client.on("message", ({ subscriptionId, data }) => {
  if (subscriptionId === fcSub) forecasts.push(JSON.parse(new TextDecoder().decode(data)));
  if (subscriptionId !== cageSub) return;
  decoded.push(JSON.parse(new TextDecoder().decode(data)));
});

await waitFor(() => info, 5000, "serverInfo");
check(info.name === "hoist-dash" && info.capabilities.includes("clientPublish"), `serverInfo ${JSON.stringify(info.capabilities)}`);
await waitFor(() => channels.has("HOIST_CAGE"), 5000, "advertise of HOIST_CAGE (discovered from HOIST_HEALTH)");
const expect = {
  HOIST_WINDER: ["utime", "seq", "v", "a", "has_length", "length"],
  HOIST_CAGE: ["utime", "t", "l", "v", "a", "x_c", "y_c", "theta", "lambdas", "y_top", "y_bottom", "min_clearance", "alarm_level", "degraded"],
  HOIST_GUIDE_SHAPE: ["utime", "t", "l", "h", "n", "x", "y1", "y2"],
  HOIST_ALARM: ["utime", "kind", "level", "event_type", "active", "acked", "shelved", "latched", "value", "threshold", "message", "user"],
  HOIST_ALARM_ACK: ["utime", "kind", "level", "action", "shelve_duration", "user"],
  HOIST_HEALTH: ["utime", "step_p50_us", "deadline_misses", "input_age", "rejected_total", "reject_reason", "rejected", "degraded"],
  HOIST_FORECAST: ["utime", "seq", "instance_id", "t_start", "l", "v", "a", "plan_seq", "compute_time", "num_scenarios", "scenarios"],
  HOIST_TRIP_PLAN: ["utime", "seq", "target_length", "vmax", "amax", "jerk", "sender_id"],
};
for (const [topic, fields] of Object.entries(expect)) {
  const ch = channels.get(topic);
  if (!ch) fail(`channel ${topic} not advertised (have ${[...channels.keys()].join(", ")})`);
  const schema = JSON.parse(ch.schema);
  const props = Object.keys(schema.properties || {});
  const missing = fields.filter((f) => !props.includes(f));
  check(ch.encoding === "json" && missing.length === 0,
        `${topic}: encoding json, schema ${ch.schemaName} names the msgs/*.lcm fields (missing: ${missing.join(",") || "none"})`);
}

// HOIST_FORECAST: the nested scenario schema, then synthetic forecasts
// (tests/dash/forecast_pub.cpp) decoded as JSON with their nested values.
{
  const item = JSON.parse(channels.get("HOIST_FORECAST").schema).properties.scenarios.items;
  const want = ["name", "status", "horizon", "t_reached", "min_clearance", "t_min_clearance", "t_warning", "t_critical",
                "peak_y_c", "peak_theta", "peak_lambdas", "lambda0_min", "lambda0_max", "num_points", "series_t",
                "series_min_clearance", "series_lambda0_min", "series_lambda0_max"];
  check(item.title === "hoist.forecast_scenario_t" && want.every((k) => item.properties[k]) && item.additionalProperties === false,
        "HOIST_FORECAST schema inlines forecast_scenario_t with every field");
  if (!process.env.HOIST_FORECAST_PUB) fail("HOIST_FORECAST_PUB (tests/dash: hoist-test-forecast-pub) is not set");
  // Not spawnSync: the event loop must keep reading the WebSocket meanwhile.
  const pub = start("forecast-pub", process.env.HOIST_FORECAST_PUB, [lcm, "", "3", "100"], dir);
  const res = await pub.exited;
  check(res.code === 0, `synthetic forecasts published (${pub.out.trim().split("\n").length} lines)`);
  // (the test's daemon forecasts too -- on by default; the synthetic ones carry
  // its instance id as well, so they are told apart by their scenarios)
  const synthetic = () => forecasts.filter((x) => x.num_scenarios === 2 && x.scenarios[0].name === "estop" &&
                                                  x.scenarios[0].series_t.length === 50 && x.plan_seq === -1 &&
                                                  x.compute_time === 0.02);
  await waitFor(() => synthetic().length >= 3, 5000, "3 HOIST_FORECAST messages");
  const f = synthetic()[0];
  const [e, o] = f.scenarios;
  check(synthetic().length === 3 && f.seq === 0 && f.num_scenarios === 2 && e.name === "estop" && e.t_critical === 2.5 &&
        e.t_warning === 1.5 && e.min_clearance === 0.0125 && e.series_t.length === 50 && e.series_lambda0_max.length === 50 &&
        o.name === "<img src=x onerror=alert(1)>\u001b[2J" && o.t_critical === -1 && o.series_t.length === 20,
        "forecasts arrive whole, nested scenarios and series intact; the lying one (num_points 30000) was dropped");
  const st = await (await fetch(new URL("/api/stats", dash.url))).json();
  check(st.counters.lcm_rejected_decode_bad_count === 1, `hoist-dash counted it (${JSON.stringify(st.counters)})`);
}

await waitFor(() => decoded.length >= 60, 10000, "60 HOIST_CAGE messages");
client.unsubscribe(cageSub);
// What the server sent before it read the unsubscribe may still arrive (a
// loaded machine: 3 messages 300 ms later); after that settling nothing more.
const n = decoded.length;
await sleep(300);
const settled = decoded.length;
await sleep(700);
const after = decoded.length;
check(after === settled, `unsubscribe stops the stream (${settled - n} in flight, then ${after - settled} in 700 ms)`);

// A command through clientPublish, as Foxglove's Publish panel would send it.
const cid = client.advertise({ topic: "HOIST_ALARM_ACK", encoding: "json", schemaName: "hoist.alarm_ack_t" });
client.sendMessage(cid, new TextEncoder().encode(JSON.stringify({ utime: 0, kind: "CAGE_NEG_Y", level: 0, action: 1, shelve_duration: 0, user: "protocol-test" })));
await waitFor(() => statuses.some((s) => /sent acknowledge CAGE_NEG_Y/.test(s.message)), 3000, "the server's confirmation");
client.sendMessage(cid, new TextEncoder().encode(JSON.stringify({ utime: 0, kind: "../etc", level: 9, action: 7, shelve_duration: 0, user: "" })));
await waitFor(() => statuses.some((s) => s.level === 2 && /rejected command/.test(s.message)), 3000, "rejection of a bad command");
check(true, "client publish: a valid HOIST_ALARM_ACK is confirmed, an invalid one rejected");
await sleep(300);
client.close();

await stop(twin.replay);
await stop(twin.twind);
await sleep(300);
await stop(twin.logger, "SIGINT");
await stop(dash.proc);

// Every decoded message equals the one lcm-logger recorded (same utime).
const log = readLog(path.join(dir, "run.lcm"), dir, { undecodable: 1 });  // the lying forecast
const rows = new Map((log.HOIST_CAGE || []).map((r) => [r.utime, r]));
let compared = 0;
for (const m of decoded) {
  const r = rows.get(String(m.utime));
  if (!r) fail(`HOIST_CAGE utime ${m.utime} not in lcm-logger's log`);
  const want = {
    t: m.t, l: m.l, v: m.v, a: m.a, x_c: m.x_c, y_c: m.y_c, theta: m.theta,
    lambda_0: m.lambdas[0], lambda_1: m.lambdas[1], lambda_2: m.lambdas[2], lambda_3: m.lambdas[3], lambda_4: m.lambdas[4],
    seq: m.seq, input_seq: m.input_seq, y_top: m.y_top, y_bottom: m.y_bottom, guide_deflection: m.guide_deflection,
    clearance_pos_y: m.clearance_pos_y, clearance_neg_y: m.clearance_neg_y, clearance_guide: m.clearance_guide,
    min_clearance: m.min_clearance, alarm_level: m.alarm_level, degraded: m.degraded ? 1 : 0,
  };
  for (const [k, v] of Object.entries(want)) {
    if (r[k] === undefined) fail(`log2csv has no column ${k}`);
    if (Number(r[k]) !== Number(v)) fail(`utime ${m.utime}: ${k} = ${v} over WebSocket, ${r[k]} in the log`);
  }
  compared++;
}
check(compared >= 50, `${compared} HOIST_CAGE messages decoded from the WebSocket equal lcm-logger's record field by field`);
// Besides the commands: hoist-dash asks the daemon once for its alarm states
// (ACTION_REANNOUNCE = 4) when it confirms the shaft (its third health,
// which this short run may end before): at most one.
const all = log.HOIST_ALARM_ACK || [];
const acks = all.filter((a) => Number(a.action) !== 4);
check(acks.length === 1 && acks[0].user === "protocol-test", `exactly the valid command reached LCM (${acks.length})`);
check(all.length - acks.length <= 1, `at most one alarm-state request, when the shaft was confirmed (${all.length - acks.length})`);
console.log("PASS");
process.exit(0);

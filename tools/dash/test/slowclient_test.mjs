// Slow-client test of hoist-dash (CTest label `browser`): a client that
// subscribes to every channel (the full-rate HOIST_CAGE included) and then
// stops reading for 30 s must not make hoist-dash buffer without bound: its
// RSS stays flat, the data beyond the per-client queue is dropped (counted),
// and a second, healthy client keeps getting the decimated stream meanwhile.
//
//   node slowclient_test.mjs [LCM_PORT] [SECONDS]
import WebSocket from "ws";
import { check, fail, lcmUrl, rssKiB, sleep, startDash, startTwin, stats, stop, waitFor, workDir } from "./harness.mjs";

const lcmPort = Number(process.argv[2] || 7874);
const seconds = Number(process.argv[3] || 30);
const dir = workDir("slow");
const lcm = lcmUrl(lcmPort);
// A small queue (256 KiB) so that it fills within seconds.
const dash = await startDash(dir, lcm, ["--max-queue-kb", "256"]);
const twin = await startTwin(dir, lcm, { logger: false });

function client(onData) {
  return new Promise((resolve) => {
    const w = new WebSocket(dash.url.replace("http", "ws"), ["foxglove.websocket.v1"]);
    w.channels = [];
    w.on("message", (d, isBin) => {
      if (isBin) { onData(d); return; }
      const m = JSON.parse(d.toString());
      if (m.op === "advertise") w.channels.push(...m.channels);
    });
    w.on("open", () => resolve(w));
  });
}
let slowBytes = 0;
const slow = await client((d) => { slowBytes += d.length; });
await waitFor(() => slow.channels.some((c) => c.topic === "HOIST_CAGE"), 5000, "HOIST_CAGE advertised");
slow.send(JSON.stringify({ op: "subscribe", subscriptions: slow.channels.map((c, i) => ({ id: i + 1, channelId: c.id })) }));
let fastMsgs = 0;
const fast = await client(() => { fastMsgs++; });
await waitFor(() => fast.channels.length > 0, 3000, "advertise");
const dec = fast.channels.find((c) => c.topic === "HOIST_CAGE/decimated");
fast.send(JSON.stringify({ op: "subscribe", subscriptions: [{ id: 1, channelId: dec.id }] }));
await sleep(2000);
check(slowBytes > 0 && fastMsgs > 20, `both clients receive (${slowBytes} bytes, ${fastMsgs} messages)`);

// The slow client stops reading: its socket is paused (the kernel buffers
// fill, then hoist-dash's bounded queue).
slow._socket.pause();
const rss = [];
const fastStart = fastMsgs;
for (let i = 0; i < seconds; i++) {
  await sleep(1000);
  rss.push(rssKiB(dash.proc.pid));
}
const fastRate = (fastMsgs - fastStart) / seconds;
const st = (await stats(dash.url)).counters;
const settled = rss[Math.min(4, rss.length - 1)];
const peak = Math.max(...rss);
console.log(`RSS [KiB] over ${seconds} s: ${rss.join(" ")}`);
check(peak - settled < 3 * 1024, `RSS flat while the client does not read: ${settled} KiB after 5 s, peak ${peak} KiB (growth ${peak - settled} KiB < 3 MiB)`);
check((st.data_frames_dropped_slow_client || 0) > 0 || (st.clients_closed_slow || 0) > 0,
      `the slow client's data was dropped (${st.data_frames_dropped_slow_client || 0} frames) or it was disconnected (${st.clients_closed_slow || 0})`);
check(fastRate > 15, `the healthy client kept its decimated stream meanwhile (${fastRate.toFixed(1)} messages/s)`);
slow._socket.resume();
await sleep(500);
check(dash.proc.exitCode === null, "hoist-dash still running");
slow.terminate();
fast.close();
await stop(twin.replay);
await stop(twin.twind);
const e = await stop(dash.proc);
if (e.code !== 0) fail(`hoist-dash exit ${JSON.stringify(e)}`);
console.log("PASS");
process.exit(0);

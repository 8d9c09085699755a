// hoist-dash page: a Foxglove WebSocket protocol client (foxglove.websocket.v1)
// of the hoist-dash server it was loaded from.  Per shaft (channel prefix): the
// shaft view, the trends (uPlot), the ISA-18.2 alarm list with operator
// commands, the health panel, the load estimate (when the daemon's estimator
// publishes HOIST_ESTIMATE) and the STALE / NO DATA state.
//
// The entry of the page's ES modules (tools/dash/page/*.js), bundled by
// esbuild into app.js (tools/dash/CMakeLists.txt); three imports stay
// beside app.js, nothing comes from elsewhere: the protocol client is
// @foxglove/ws-protocol's FoxgloveClient (vendor/foxglove-client.js, bundled
// by esbuild too); the channel names and the alarm level and event names are
// hoist_msgs.js, generated from msgs/*.lcm by msgs/codec (the same tables as
// the daemon's); the alarm kinds' units are alarm_units.js, generated from
// msgs/contract/alarm_units.json.  This file: the connection, the shafts
// (tabs, layout) and the drawing loop.
import { FoxgloveClient } from "./vendor/foxglove-client.js";
import { CH, SUFFIXES, SUBSCRIBE, STALE_AFTER_MS, state, userInput } from "./state.js";
import { $, el, fix, clock, toast } from "./util.js";
import { chartSize, makeCharts, onHistory, onCage } from "./trends.js";
import { onAlarm, onInstance, renderAlarms } from "./alarms.js";
import { makeEstimateCard, onEstimate, drawEstimate } from "./estimate.js";
import { renderHealth, renderForecast, drawShaft } from "./panels.js";
import "./condition.js";  // the Shaft condition view (its own polling of /api/condition)

// Subscribe the next queued history once the previous one has arrived.
export function nextHistory() {
  if (state.historyPending) return;
  while (state.historyQueue.length) {
    const h = state.historyQueue.shift();
    if (!state.channels.has(h.channelId)) continue;  // withdrawn meanwhile
    if (!subscribe(h.shaft, h.suffix, h.channelId)) return;
    state.historyPending = true;
    // (a history dropped by the server, or a shaft withdrawn: go on after 3 s)
    clearTimeout(state.historyTimer);
    state.historyTimer = setTimeout(() => { state.historyPending = false; nextHistory(); }, 3000);
    return;
  }
}

// Persistent server statuses (Foxglove status with an id, until removeStatus):
// a full shaft table, two prefixes with one shaft name.
export function setNotice(id, text, level) {
  let d = state.notices.get(id);
  if (!d) {
    d = el("div", { class: "notice", "data-status-id": id });
    state.notices.set(id, d);
    $("#notices").append(d);
  }
  d.className = `notice lvl-${level}`;
  d.textContent = text;
}

// Channels withdrawn by the server (a discovered prefix that aged out): a
// shaft with none left leaves the page.
export function onUnadvertise(ids) {
  for (const id of ids) {
    state.channels.delete(id);
    for (const [sid, sub] of state.subs) if (sub.channelId === id) state.subs.delete(sid);
  }
  const live = new Set([...state.channels.values()].map((c) => splitTopic(c.topic)[0]));
  for (const [prefix, s] of state.shafts) {
    if (live.has(prefix)) continue;
    s.root.remove(); s.tab.remove();
    state.shafts.delete(prefix);
    state.ackChannels.delete(prefix);
    if (state.selected === prefix) { state.selected = null; const first = state.shafts.keys().next(); if (!first.done) select(first.value); }
  }
}
// (the operator name field: state.js userInput)
userInput.value = localStorage.getItem("hoist-dash-user") || "";
userInput.addEventListener("change", () => localStorage.setItem("hoist-dash-user", userInput.value.trim()));
$("#window").addEventListener("change", (e) => {
  state.windowS = Number(e.target.value);
  for (const s of state.shafts.values()) s.dirty = s.estDirty = true;
});

export function splitTopic(topic) {
  for (const suf of SUFFIXES) if (topic.endsWith(suf)) return [topic.slice(0, topic.length - suf.length), suf];
  return [null, null];
}

// ---- connection -------------------------------------------------------------
export function setConn(text, cls, st) {
  const c = $("#conn");
  c.textContent = text;
  c.className = "conn " + cls;
  c.dataset.state = st;
}

// One FoxgloveClient per WebSocket; a closed one is replaced after 2 s.
export function connect() {
  const ws = new WebSocket(`ws://${location.host}/`, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  state.ws = ws;
  state.client = client;
  state.channels.clear(); state.subs.clear(); state.ackChannels.clear();
  state.historyQueue = []; state.historyPending = false;
  setConn("connecting…", "conn-wait", "connecting");
  client.on("open", () => setConn("connected", "conn-ok", "connected"));
  client.on("close", () => {
    setConn("DISCONNECTED: retrying", "conn-bad", "disconnected");
    for (const s of state.shafts.values()) s.lastMsg = -1e12;
    setTimeout(connect, 2000);
  });
  client.on("serverInfo", onServerInfo);
  client.on("advertise", onAdvertise);
  client.on("unadvertise", (ids) => onUnadvertise(ids || []));
  client.on("status", (m) => {
    if (typeof m.id === "string" && m.id) setNotice(m.id, m.message, m.level);
    else toast(m.message, m.level >= 2);
  });
  client.on("removeStatus", (m) => {
    for (const id of m.statusIds || []) state.notices.get(id)?.remove(), state.notices.delete(id);
  });
  client.on("message", onMessage);
  // A frame the client cannot parse (or an opcode it does not know) is dropped.
  client.on("error", (e) => console.warn("hoist-dash:", e));
}

// The client's calls send at once: only on the open socket of this page's client.
export const isOpen = () => state.ws !== null && state.ws.readyState === WebSocket.OPEN;

// Subscribe one channel of a shaft; false when the socket is not open.
export function subscribe(shaft, suffix, channelId) {
  if (!isOpen()) return false;
  const id = state.client.subscribe(channelId);
  state.subs.set(id, { shaft, suffix, channelId });
  return true;
}

export function onServerInfo(m) {
  state.readOnly = !(m.capabilities || []).includes("clientPublish");
  document.body.classList.toggle("read-only", state.readOnly);
  document.body.dataset.readOnly = String(state.readOnly);
  $("#mode").textContent = state.readOnly ? "read-only: operator commands disabled" : "";
  try { state.meta = JSON.parse((m.metadata || {}).shafts || "{}"); } catch { state.meta = {}; }
  for (const s of state.shafts.values()) renderAlarms(s);
}

export function onAdvertise(channels) {
  for (const ch of channels || []) {
    state.channels.set(ch.id, ch);
    const [prefix, suffix] = splitTopic(ch.topic);
    if (prefix === null) continue;
    const shaft = getShaft(prefix);
    if (SUBSCRIBE.has(suffix)) {
      // Histories one shaft at a time (each up to ~0.5 MB): all at once
      // would overflow the server's send queue with many shafts.
      if (suffix === CH.history) state.historyQueue.push({ shaft, suffix, channelId: ch.id });
      else subscribe(shaft, suffix, ch.id);
    }
    if (suffix === CH.ack && !state.readOnly && isOpen()) {
      state.ackChannels.set(prefix, state.client.advertise({ topic: ch.topic, encoding: "json", schemaName: "hoist.alarm_ack_t" }));
    }
  }
  nextHistory();
}

export const decoder = new TextDecoder();
export function onMessage({ subscriptionId, data }) {
  const sub = state.subs.get(subscriptionId);
  if (!sub) return;
  const msg = JSON.parse(decoder.decode(data));
  const s = sub.shaft;
  s.lastMsg = performance.now();
  switch (sub.suffix) {
    case CH.history: onHistory(s, msg); clearTimeout(state.historyTimer); state.historyPending = false; nextHistory(); break;
    case CH.cageDecimated: onCage(s, msg); break;
    case CH.plan: s.plan = msg; s.dirty = true; break;
    case CH.shape: s.shape = msg; s.dirty = true; break;
    case CH.alarm: onAlarm(s, msg); break;
    case CH.health: s.health = msg; onInstance(s, msg); renderHealth(s); break;
    case CH.forecast: s.forecast = msg; renderForecast(s); break;
    case CH.estimateDecimated: onEstimate(s, msg); break;
  }
}

// ---- shafts -------------------------------------------------------------------
export function getShaft(prefix) {
  let s = state.shafts.get(prefix);
  if (s) return s;
  $("#noshaft")?.remove();
  const label = prefix === "" ? "default shaft" : prefix;
  const root = el("section", { class: "shaft", "data-shaft": prefix });
  const banner = el("div", { class: "banner", "data-role": "stale", "data-state": "nodata" }, "NO DATA");
  const canvas = el("canvas", { class: "shaftview", width: "560", height: "1280" });
  const ro = el("div", { class: "readouts", "data-role": "readouts" });
  const fields = [["t", "model time", "s"], ["l", "depth l", "m"], ["y_c", "sway y_c", "mm"], ["theta", "tilt θ", "mrad"],
                  ["v", "speed v", "m/s"], ["min_clearance", "min clearance", "mm"], ["alarm_level", "alarm level", ""],
                  ["degraded", "degraded", ""]];
  for (const [f, k, u] of fields) {
    ro.append(el("span", { class: "k" }, `${k}${u ? " [" + u + "]" : ""}`), el("span", { class: "v", "data-field": f }, "–"));
  }
  const left = el("div", { class: "card" }, el("h2", {}, "Shaft view"), canvas,
                  el("div", { class: "scale-note", "data-role": "scale" }, ""), ro);
  const trends = el("div", { class: "card trends" }, el("h2", {}, "Trends"));
  const alarmsBody = el("tbody");
  const alarms = el("div", { class: "card alarms" }, el("h2", {}, "Alarms"),
    el("table", {}, el("thead", {}, el("tr", {}, ...["Level", "Alarm", "State", "Time", "Value / threshold", "By", ""].map((h) => el("th", {}, h)))), alarmsBody),
    el("p", { class: "empty", "data-role": "no-alarms" }, "no alarms"),
    el("label", { class: "cmd" }, "Shelve for ", el("select", { "data-role": "shelve-s" },
      el("option", { value: "600" }, "10 min"), el("option", { value: "1800" }, "30 min"), el("option", { value: "3600" }, "60 min"))));
  const health = el("div", { class: "card health" }, el("h2", {}, "Health"), el("dl", { "data-role": "health" }, el("dt", {}, "–"), el("dd", {}, "no HOIST_HEALTH yet")));
  const forecast = el("div", { class: "card forecast", "data-role": "forecast", hidden: "" }, el("h2", {}, "Forecasts"), el("div", { "data-role": "forecast-body" }));
  const estimate = makeEstimateCard(prefix);
  const right = el("div", { class: "side" }, alarms, estimate, health, forecast);
  root.append(banner, left, trends, right);
  $("#shafts").append(root);
  const tab = el("button", { "data-shaft": prefix, onclick: () => select(prefix) }, el("span", { class: "dot" }), label);
  $("#tabs").append(tab);
  s = { prefix, root, banner, canvas, ro, alarmsBody, tab, lastMsg: -1e12, everData: false, cage: null, shape: null,
        health: null, alarms: new Map(), rows: new Map(), instance: undefined, thr: {}, dirty: true, charts: [], data: null, gap: null,
        estBox: estimate, est: null, estCharts: [], estDirty: false, lastEst: -1e12 };
  s.estData = { x: [], th: [], hi: [], lo: [], open: [], nis: [], bound: [], nlo: [], nup: [] };
  s.data = { x: [], y_c: [], theta: [], l1: [], l2: [], l3: [], l4: [], l0: [], slk: [], ovl: [], clr: [], warn: [], crit: [], v: [], l: [] };
  makeCharts(s, trends);
  state.shafts.set(prefix, s);
  if (state.selected === null) select(prefix);
  else root.hidden = true;
  return s;
}

export function select(prefix) {
  state.selected = prefix;
  for (const s of state.shafts.values()) {
    s.root.hidden = s.prefix !== prefix;
    s.tab.classList.toggle("sel", s.prefix === prefix);
    if (s.prefix === prefix) { s.dirty = true; for (const c of s.charts) c.u.setSize(chartSize(c.el)); }
  }
}


// ---- loop ---------------------------------------------------------------------
export function updateStale() {
  const now = performance.now();
  for (const s of state.shafts.values()) {
    const age = now - s.lastMsg;
    // No cage state since the page opened, but hoist-dash's history has
    // some (e.g. opened after an input-clock trip): STALE since its last point, not NO DATA.
    const histOnly = !s.everData && s.lastHistUs > 0;
    const st = !s.everData && !histOnly ? "nodata" : histOnly || age > STALE_AFTER_MS ? "stale" : "ok";
    s.banner.dataset.state = st;
    const waiting = s.health && age <= STALE_AFTER_MS ? " (the daemon is up, waiting for winder input)" : "";
    s.banner.textContent = st === "nodata"
      ? `NO DATA: no cage state from ${s.prefix || "the default shaft"}${waiting}`
      : histOnly ? `STALE: no cage state since ${clock(s.lastHistUs)}${waiting}; the trends show hoist-dash's history`
      : st === "stale" ? `STALE: no data for ${s.lastMsg < 0 ? "—" : fix(age / 1000, 1) + " s"}; values below are old` : "";
    const was = s.root.classList.contains("stale");
    s.root.classList.toggle("stale", st !== "ok");
    if (was !== (st !== "ok")) s.dirty = true;
    if (st !== "ok") s.tab.querySelector(".dot").style.background = "#6b7280";
    if (s.est) {
      const ea = now - s.lastEst;
      const old = ea > STALE_AFTER_MS;
      s.estBox.dataset.state = old ? "stale" : "ok";
      $('[data-field="est-stale"]', s.estBox).textContent = old ? `STALE: no HOIST_ESTIMATE for ${fix(ea / 1000, 1)} s; values are old` : "";
    }
  }
}

export function frame() {
  updateStale();
  for (const s of state.shafts.values()) {
    if (s.estDirty && !s.root.hidden) { s.estDirty = false; drawEstimate(s); }
    if (!s.dirty || s.root.hidden) continue;
    s.dirty = false;
    drawShaft(s);
    const D = s.data;
    const xmax = D.x.length ? D.x[D.x.length - 1] : Date.now() / 1000;
    for (const c of s.charts) {
      c.u.setData([D.x, ...c.keys.map((k) => D[k])], false);
      c.u.setScale("x", { min: xmax - state.windowS, max: xmax });
    }
  }
  requestAnimationFrame(frame);
}
setInterval(updateStale, 250);  // also when the tab is in the background
window.addEventListener("resize", () => { for (const s of state.shafts.values()) for (const c of s.charts) c.u.setSize(chartSize(c.el)); });
window.hoistDash = state;  // for tests and debugging
connect();
requestAnimationFrame(frame);

// hoist-dash page: a Foxglove WebSocket protocol client (foxglove.websocket.v1)
// of the hoist-dash server it was loaded from.  Per shaft (channel prefix): the
// shaft view, the trends (uPlot), the ISA-18.2 alarm list with operator
// commands, the health panel, the load estimate (when the daemon's estimator
// publishes HOIST_ESTIMATE) and the STALE / NO DATA state.
//
// An ES module.  Both imports are put beside this file by the build
// (tools/dash/CMakeLists.txt), nothing comes from elsewhere: the protocol
// client is @foxglove/ws-protocol's FoxgloveClient (frame parsing, subscribe,
// advertise, client message data), bundled by esbuild; the channel names and
// the alarm level and event names are hoist_msgs.js, generated from msgs/*.lcm
// by msgs/codec (the same tables as the daemon's).
import { FoxgloveClient } from "./vendor/foxglove-client.js";
import { CHANNELS, alarm_t } from "./hoist_msgs.js";
import { ALARM_UNITS } from "./alarm_units.js";

(() => {
  // Channel suffixes (what follows a shaft's prefix): the wire channels of
  // msgs/*.lcm, and the ones hoist-dash derives from them (the decimated cage
  // state and load estimate, the cage history).
  const channelOf = (type) => {
    const c = CHANNELS[type];
    if (typeof c !== "string") throw new Error(`hoist_msgs.js names no channel for ${type}`);
    return c;
  };
  const CH = {
    cage: channelOf("hoist.cage_state_t"), shape: channelOf("hoist.guide_shape_t"), alarm: channelOf("hoist.alarm_t"),
    ack: channelOf("hoist.alarm_ack_t"), health: channelOf("hoist.health_t"), forecast: channelOf("hoist.forecast_t"),
    plan: channelOf("hoist.trip_plan_t"), estimate: channelOf("hoist.estimate_t"),
  };
  CH.history = `${CH.cage}/history`;
  CH.cageDecimated = `${CH.cage}/decimated`;
  CH.estimateDecimated = `${CH.estimate}/decimated`;
  // Longest first: a topic belongs to the longest suffix it ends with.
  const SUFFIXES = [...Object.values(CHANNELS), CH.history, CH.cageDecimated, CH.estimateDecimated]
    .sort((a, b) => b.length - a.length);
  const SUBSCRIBE = new Set([CH.history, CH.cageDecimated, CH.shape, CH.alarm, CH.health, CH.forecast, CH.plan,
                             CH.estimateDecimated]);
  const STALE_AFTER_MS = 1500;     // STALE shown within 2 s of silence
  const KEEP_S = 300;              // longest trend window
  // alarm_t.level's name (NONE, WARNING, CRITICAL), the number for a value without one.
  const levelName = (v) => alarm_t.LEVEL_NAMES[v - alarm_t.LEVEL_FIRST] ?? String(v);
  const EVENT_RAISE = alarm_t.EVENT_FIRST + alarm_t.EVENT_NAMES.indexOf("RAISE");

  const $ = (sel, root = document) => root.querySelector(sel);
  const el = (tag, attrs = {}, ...kids) => {
    const e = document.createElement(tag);
    for (const [k, v] of Object.entries(attrs)) {
      if (k === "class") e.className = v;
      else if (k.startsWith("on")) e.addEventListener(k.slice(2), v);
      else e.setAttribute(k, v);
    }
    for (const k of kids) e.append(k);
    return e;
  };
  // A number with d decimals, never "-0.0" (a value that rounds to zero is zero).
  const fix = (x, d) => {
    const t = Number(x).toFixed(d);
    return /^-0\.?0*$/.test(t) ? t.slice(1) : t;
  };
  const num = (x) => typeof x === "number" && isFinite(x);
  // Text and attributes are written only when they change (no DOM mutation
  // without a change: the alarm rows' MutationObserver test counts them).
  const setText = (e, t) => { if (e.textContent !== t) e.textContent = t; };
  const setAttr = (e, k, v) => { if (e.getAttribute(k) !== v) e.setAttribute(k, v); };
  const clock = (utime) => new Date(utime / 1000).toLocaleTimeString([], { hour12: false });
  const toast = (msg, err = false) => {
    const d = el("div", { class: err ? "err" : "" }, msg);
    $("#toast").append(d);
    setTimeout(() => d.remove(), err ? 8000 : 4000);
    while ($("#toast").children.length > 5) $("#toast").firstChild.remove();
  };

  const state = {
    ws: null, client: null, readOnly: true, meta: {}, channels: new Map(), subs: new Map(),
    shafts: new Map(), selected: null, ackChannels: new Map(),
    windowS: 60, notices: new Map(), alarmEvents: 0, historyQueue: [], historyPending: false,
  };

  // Subscribe the next queued history once the previous one has arrived.
  function nextHistory() {
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
  function setNotice(id, text, level) {
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
  function onUnadvertise(ids) {
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
  const userInput = $("#user");
  userInput.value = localStorage.getItem("hoist-dash-user") || "";
  userInput.addEventListener("change", () => localStorage.setItem("hoist-dash-user", userInput.value.trim()));
  $("#window").addEventListener("change", (e) => {
    state.windowS = Number(e.target.value);
    for (const s of state.shafts.values()) s.dirty = s.estDirty = true;
  });

  function splitTopic(topic) {
    for (const suf of SUFFIXES) if (topic.endsWith(suf)) return [topic.slice(0, topic.length - suf.length), suf];
    return [null, null];
  }

  // ---- connection -------------------------------------------------------------
  function setConn(text, cls, st) {
    const c = $("#conn");
    c.textContent = text;
    c.className = "conn " + cls;
    c.dataset.state = st;
  }

  // One FoxgloveClient per WebSocket; a closed one is replaced after 2 s.
  function connect() {
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
  const isOpen = () => state.ws !== null && state.ws.readyState === WebSocket.OPEN;

  // Subscribe one channel of a shaft; false when the socket is not open.
  function subscribe(shaft, suffix, channelId) {
    if (!isOpen()) return false;
    const id = state.client.subscribe(channelId);
    state.subs.set(id, { shaft, suffix, channelId });
    return true;
  }

  function onServerInfo(m) {
    state.readOnly = !(m.capabilities || []).includes("clientPublish");
    document.body.classList.toggle("read-only", state.readOnly);
    document.body.dataset.readOnly = String(state.readOnly);
    $("#mode").textContent = state.readOnly ? "read-only: operator commands disabled" : "";
    try { state.meta = JSON.parse((m.metadata || {}).shafts || "{}"); } catch { state.meta = {}; }
    for (const s of state.shafts.values()) renderAlarms(s);
  }

  function onAdvertise(channels) {
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

  const decoder = new TextDecoder();
  function onMessage({ subscriptionId, data }) {
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
  function getShaft(prefix) {
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
    const estimate = makeEstimateCard();
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

  function select(prefix) {
    state.selected = prefix;
    for (const s of state.shafts.values()) {
      s.root.hidden = s.prefix !== prefix;
      s.tab.classList.toggle("sel", s.prefix === prefix);
      if (s.prefix === prefix) { s.dirty = true; for (const c of s.charts) c.u.setSize(chartSize(c.el)); }
    }
  }

  // ---- trends -------------------------------------------------------------------
  function chartSize(host) { return { width: Math.max(300, host.clientWidth || 600), height: 132 }; }

  // Y ranges that suit the data: a minimum span around a flat signal (so the
  // axis has at least three distinct labels), forces from 0, the speed from 0
  // (or -vmax) to the trip's vmax.
  const spanAtLeast = (min, max, span) => {
    if (!isFinite(min) || !isFinite(max)) return [-span / 2, span / 2];
    if (max - min >= span) { const pad = 0.05 * (max - min); return [min - pad, max + pad]; }
    const c = (min + max) / 2;
    return [c - span / 2, c + span / 2];
  };
  // Ticks: the smallest "nice" step (1, 2, 2.5, 5 x 10^k) of at least a
  // fifth of the range -- 3 to 6 ticks on every axis -- labelled with as
  // many decimals as they need to be exact, hence distinct.
  const niceStep = (span) => {
    const raw = span / 5, p = Math.pow(10, Math.floor(Math.log10(raw)));
    for (const m of [1, 2, 2.5, 5, 10]) if (m * p >= raw * (1 - 1e-9)) return m * p;
    return 10 * p;
  };
  const splits = (u, axisIdx, min, max) => {
    if (!(max > min) || !isFinite(min) || !isFinite(max)) return [min];
    const step = niceStep(max - min);
    const out = [];
    for (let k = Math.ceil(min / step - 1e-9); k * step <= max + 1e-9 * step; k++) out.push(k === 0 ? 0 : k * step);
    return out;
  };
  const ticks = (u, vals) => {
    let d = 0;
    while (d < 8 && vals.some((v) => Math.abs(v * 10 ** d - Math.round(v * 10 ** d)) > 1e-6 * Math.max(1, Math.abs(v * 10 ** d)))) d++;
    return vals.map((v) => fix(v, d));
  };
  function speedRange(s, min, max) {
    const seen = Math.max(Math.abs(isFinite(min) ? min : 0), Math.abs(isFinite(max) ? max : 0));
    const vmax = s.plan && s.plan.vmax > 0 ? Math.max(s.plan.vmax, seen) : Math.max(1, seen * 1.1);
    return [isFinite(min) && min < -0.05 * vmax ? -vmax : 0, vmax];
  }

  function makeCharts(s, host) {
    const D = s.data;
    const defs = [
      ["sway y_c [mm]", [["y_c", "#60a5fa"]], (u, lo, hi) => spanAtLeast(lo, hi, 2)],
      ["tilt θ [mrad]", [["theta", "#a78bfa"]], (u, lo, hi) => spanAtLeast(lo, hi, 0.02)],
      ["guide-sleeve forces λ1..λ4 [N]", [["l1", "#f87171", "λ1"], ["l2", "#fbbf24", "λ2"], ["l3", "#34d399", "λ3"], ["l4", "#60a5fa", "λ4"]],
       (u, lo, hi) => [Math.min(0, isFinite(lo) ? lo : 0), Math.max(10, isFinite(hi) ? hi * 1.1 : 10)]],
      ["hoisting-rope force λ0 [kN]", [["l0", "#e5e7eb", "λ0"], ["slk", "#ef4444", "ROPE_SLACK", [6, 4]], ["ovl", "#ef4444", "ROPE_OVERLOAD", [2, 4]]],
       (u, lo, hi) => spanAtLeast(lo, hi, 1)],
      ["min clearance [mm]", [["clr", "#2fbf71", "min clearance"], ["warn", "#f0b429", "WARNING", [6, 4]], ["crit", "#ef4444", "CRITICAL", [6, 4]]],
       (u, lo, hi) => spanAtLeast(lo, hi, 2)],
      ["speed v [m/s] and depth l [m]", [["v", "#93c5fd", "v"], ["l", "#fca5a5", "l", null, "l"]], (u, lo, hi) => speedRange(s, lo, hi)],
    ];
    for (const [title, series, yrange] of defs) {
      const box = el("div", { class: "trend" }, el("h3", {}, title));
      const plotEl = el("div");
      box.append(plotEl);
      host.append(box);
      const scales = { x: { time: true }, y: { range: yrange } };
      const hms = (u, vals) => vals.map((v) => new Date(v * 1000).toLocaleTimeString([], { hour12: false }));
      const axes = [{ stroke: "#8a96a3", grid: { stroke: "#252c34" }, values: hms, size: 24, space: 90 },
                    { stroke: "#8a96a3", grid: { stroke: "#252c34" }, size: 60, splits, values: ticks }];
      if (series.some((sr) => sr[4] === "l")) {
        scales.l = { range: (u, lo, hi) => spanAtLeast(lo, hi, 2) };
        axes.push({ scale: "l", side: 1, stroke: "#fca5a5", grid: { show: false }, size: 50, splits, values: ticks });
      }
      const opts = {
        ...chartSize(plotEl), scales, axes, legend: { show: true, live: false },
        cursor: { drag: { x: false, y: false } },
        series: [{}, ...series.map(([k, c, label, dash, scale]) => ({ label: label || k, stroke: c, width: 1.2, dash: dash || undefined, scale: scale || "y", points: { show: false } }))],
      };
      const u = new uPlot(opts, [D.x, ...series.map(([k]) => D[k])], plotEl);
      s.charts.push({ u, keys: series.map(([k]) => k), el: plotEl, title });
    }
  }

  // The server's history (HOIST_CAGE/history, sent once on subscribe): the
  // trends start with what happened before the page opened.
  function onHistory(s, h) {
    const F = h.fields || [];
    const obj = (row) => {
      const o = { lambdas: [NaN, NaN, NaN, NaN, NaN] };
      F.forEach((f, i) => {
        const v = row[i] === null || row[i] === undefined ? NaN : row[i];
        if (f.startsWith("lambdas.")) o.lambdas[Number(f.slice(8))] = v; else o[f] = v;
      });
      return o;
    };
    const old = s.data;
    const fresh = Object.fromEntries(Object.keys(old).map((k) => [k, []]));
    const n = (h.first_utime || []).length;
    for (let i = 0; i < n; i++) {
      const t0 = h.first_utime[i] / 1e6, t1 = h.last_utime[i] / 1e6;
      const add = (x, v) => { fresh.x.push(x); for (const k of Object.keys(v)) fresh[k].push(v[k]); };
      if (t1 > t0) { add(t0, cageVals(obj(h.min[i]), s)); add(t1, cageVals(obj(h.max[i]), s)); }
      else add(t1, cageVals(obj(h.max[i]), s));
    }
    const last = fresh.x.length ? fresh.x[fresh.x.length - 1] : -Infinity;
    for (let i = 0; i < old.x.length; i++) {
      if (old.x[i] <= last) continue;
      for (const k of Object.keys(old)) fresh[k].push(old[k][i]);
    }
    for (const k of Object.keys(old)) { old[k].length = 0; old[k].push(...fresh[k]); }
    s.historyPoints = n;
    if (n) s.lastHistUs = Math.max(s.lastHistUs || 0, h.last_utime[n - 1]);
    s.root.dataset.historyPoints = String(n);
    s.root.dataset.historyFrom = n ? String(h.first_utime[0]) : "";
    s.dirty = true;
  }

  function pushPoint(s, x, vals) {
    const D = s.data;
    D.x.push(x);
    for (const k of Object.keys(vals)) D[k].push(vals[k]);
  }

  function cageVals(m, s) {
    const lam = m.lambdas || [NaN, NaN, NaN, NaN, NaN];
    const [w, c] = thresholds(s);
    // The rope-force alarms' thresholds as the daemon publishes them (absent from older daemons).
    const kN = (x) => (typeof x === "number" && x > 0 ? x / 1e3 : NaN);
    const v = { y_c: m.y_c * 1e3, theta: m.theta * 1e3, l1: lam[1], l2: lam[2], l3: lam[3], l4: lam[4], l0: lam[0] / 1e3,
                slk: kN(m.rope_slack_threshold), ovl: kN(m.rope_overload_threshold),
                clr: m.min_clearance * 1e3, warn: w, crit: c, v: m.v, l: m.l };
    // uPlot's gaps are null: a NaN would spoil the axis range of its chart.
    for (const k of Object.keys(v)) if (!(typeof v[k] === "number" && isFinite(v[k]))) v[k] = null;
    return v;
  }

  function onCage(s, d) {
    const last = d.last;
    s.cage = last;
    s.everData = true;
    // Gaps from the message itself: clearance + excursion = gap (per side).
    const gp = last.clearance_pos_y + Math.max(last.y_top, last.y_bottom);
    const gn = last.clearance_neg_y + Math.max(-last.y_top, -last.y_bottom);
    if (isFinite(gp) && isFinite(gn)) s.gap = { pos: gp, neg: gn, guide: last.clearance_guide + last.guide_deflection };
    // Min/max decimation: the interval's minimum and maximum both enter the
    // trend (at its first and last time), so no peak is lost.
    const t0 = d.first.utime / 1e6, t1 = last.utime / 1e6;
    if (d.count > 1 && t1 > t0) {
      pushPoint(s, t0, cageVals(d.min, s));
      pushPoint(s, t1, cageVals(d.max, s));
    } else {
      pushPoint(s, t1, cageVals(last, s));
    }
    // Keep order (a restarted daemon) and length bounded.
    const D = s.data;
    const n = D.x.length;
    if (n > 1 && D.x[n - 1] < D.x[n - 2]) for (const k of Object.keys(D)) D[k].splice(0, n - 1);
    const tmin = D.x[D.x.length - 1] - KEEP_S;
    let cut = 0;
    while (cut < D.x.length && D.x[cut] < tmin) cut++;
    if (cut > 0) for (const k of Object.keys(D)) D[k].splice(0, cut);
    renderReadouts(s, last);
    s.dirty = true;
  }

  // Excursion threshold [m] of a cage side at a level: from the daemon's own
  // alarms once one was announced (alarm_t.threshold), else the fraction of
  // the gap given to hoist-dash (--warning-fraction, --critical-fraction).
  function sideThr(s, side, level) {
    const t = s.thr[`${side === "pos" ? "CAGE_POS_Y" : "CAGE_NEG_Y"}/${level}`];
    if (t > 0) return t;
    const m = state.meta[s.prefix] || state.meta["*"] || {};
    return (level === 1 ? (m.warning_fraction ?? 0.5) : (m.critical_fraction ?? 0.8)) * s.gap[side];
  }

  // WARNING / CRITICAL on the min-clearance trend: clearance = gap - excursion.
  function thresholds(s) {
    if (!s.gap) return [NaN, NaN];
    const clr = (level) => 1e3 * Math.min(s.gap.pos - sideThr(s, "pos", level), s.gap.neg - sideThr(s, "neg", level));
    return [clr(1), clr(2)];
  }

  function renderReadouts(s, m) {
    const set = (f, text, cls) => {
      const e = $(`[data-field="${f}"]`, s.ro);
      e.textContent = text;
      if (cls !== undefined) e.className = "v " + cls;
    };
    s.ro.dataset.utime = String(m.utime);
    set("t", fix(m.t, 2));
    set("l", fix(m.l, 2));
    set("y_c", fix(m.y_c * 1e3, 2));
    renderTilt(s);
    set("v", fix(m.v, 2));
    set("min_clearance", fix(m.min_clearance * 1e3, 1));
    set("alarm_level", levelName(m.alarm_level), "lvl" + m.alarm_level);
    set("degraded", m.degraded ? "DEGRADED" : "no", m.degraded ? "lvl2" : "");
    s.tab.querySelector(".dot").style.background = ["#2fbf71", "#f0b429", "#ef4444"][m.alarm_level] || "#8a96a3";
  }

  // The headline tilt: what the alarms judge.  While the daemon's alarms
  // judge the load estimate (estimate_t.in_use, a fresh estimate), the
  // estimate's theta, with the open-loop twin's beside it; else the twin's.
  function renderTilt(s) {
    const e = s.est, m = s.cage;
    const cell = $('[data-field="theta"]', s.ro);
    if (!m) return;
    const useEst = e && e.in_use === true && num(e.theta) && performance.now() - s.lastEst <= STALE_AFTER_MS;
    const main = useEst ? fix(e.theta * 1e3, 3) : fix(m.theta * 1e3, 3);
    const note = useEst ? `estimate; open loop ${fix(m.theta * 1e3, 3)}` : "";
    if (!cell.firstChild || cell.firstChild.nodeType !== Node.TEXT_NODE) cell.prepend(document.createTextNode(""));
    setText(cell.firstChild, main);
    let sub = cell.querySelector(".sub");
    if (!sub) { sub = el("span", { class: "sub", "data-field": "theta-open" }); cell.append(sub); }
    setText(sub, note);
    sub.hidden = !note;
    cell.dataset.source = useEst ? "estimate" : "open-loop";
  }

  // ---- alarms (ISA-18.2 states) ---------------------------------------------------
  // One row per alarm identity (kind, level), created when the alarm enters
  // the list and updated in place until it leaves: no row node is replaced
  // while its alarm lives, so a click between mouse-down and mouse-up always
  // lands on the row the operator pressed (docs/dashboard.md).
  function onAlarm(s, a) {
    for (const k of ["active", "acked", "shelved", "latched"]) a[k] = Boolean(a[k]);
    state.alarmEvents++;
    if ((a.kind === "CAGE_POS_Y" || a.kind === "CAGE_NEG_Y") && a.threshold > 0) s.thr[`${a.kind}/${a.level}`] = a.threshold;
    const key = `${a.kind}/${a.level}`;
    // The activation: hoist-dash's (kept across re-announces), else the page's own record.
    const prev = s.alarms.get(key);
    a.serverIdentity = a.dash_activation_utime > 0;
    if (!a.serverIdentity) {
      const raised = a.event_type === EVENT_RAISE;
      a.dash_activation_utime = raised || !prev ? a.utime : prev.dash_activation_utime;
      a.dash_activation_t = raised || !prev ? a.t : prev.dash_activation_t;
      a.dash_activation_known = raised || Boolean(prev && prev.dash_activation_known);
    }
    // When it returned to normal (RTN UNACK rows say since when).
    a.rtnUtime = !a.active ? (prev && !prev.active && prev.rtnUtime ? prev.rtnUtime : a.utime) : 0;
    s.alarms.set(key, a);
    renderAlarms(s);
  }

  // A new daemon instance on this shaft (health_t.instance_id changed): the
  // alarm states of the instance that has gone are void; the new one
  // announces its own (hoist-dash asks it to re-announce).  Events of the new
  // instance (utime from its start on) are kept.  hoist-dash clears its own
  // table the same way (Hub::daemonRestarted); this is the page's side.
  function onInstance(s, h) {
    const id = String(h.instance_id ?? "0");
    if (id === "0") return;
    const old = s.instance;
    s.instance = id;
    if (old === undefined || old === id) return;
    const start = Number(h.utime) - Number(h.uptime) * 1e6;
    let n = 0;
    for (const [key, a] of s.alarms) if (!(a.utime >= start)) { s.alarms.delete(key); n++; }
    s.root.dataset.instance = id;
    toast(`${s.prefix || "default shaft"}: the daemon restarted (a new instance)` +
          (n ? `: ${n} alarm state(s) of the old instance cleared` : ""));
    renderAlarms(s);
  }

  function stateText(a) {
    if (a.shelved) return "SHELVED";
    if (a.active && !a.acked) return a.latched ? "UNACK · LATCHED" : "UNACK";
    if (a.active && a.acked) return a.latched ? "ACKED · LATCHED" : "ACKED";
    if (!a.active && !a.acked) return "RTN UNACK";
    return "NORMAL";
  }

  // Value against threshold in the unit of the alarm's kind, from the one
  // table beside the contract (msgs/contract/alarm_units.json -> alarm_units.js).
  // A kind the table does not know is shown without a unit, never a wrong one.
  function fmtVal(a) {
    const u = ALARM_UNITS[a.kind];
    const sig = (x) => Number(x).toPrecision(4);
    if (!u) return `${sig(a.value)} / ${sig(a.threshold)}`;
    const one = (x, what) => {
      const n = u.format === "sig" ? sig(x) : fix(x * (u.scale ?? 1), u.decimals ?? 1);
      return `${n}${u.unit ? " " + u.unit : ""}${what ? " " + what : ""}`;
    };
    switch (u.format) {
      case "flag": return a.value >= 0.5 ? "on" : "off";
      case "instance": return `${u.value ? u.value + " " : ""}${fix(a.value, 0)}`;
      default: return `${one(a.value, u.value)} / ${one(a.threshold, u.threshold)}`;
    }
  }

  // Stable order: priority (CRITICAL first), then activation time (oldest
  // first: a new alarm is added below, rows above never move), then kind.
  function alarmOrder(a, b) {
    return (b.level - a.level) || (a.dash_activation_utime - b.dash_activation_utime) || (a.kind < b.kind ? -1 : a.kind > b.kind ? 1 : 0);
  }
  const alarmName = (a) => `${a.kind} ${levelName(a.level)}`;
  const activeSince = (a) => `${a.dash_activation_known === false ? "before " : ""}${clock(a.dash_activation_utime)}`;
  const listed = (a) => a.active || !a.acked || a.shelved;


  function makeRow(s, key) {
    const c = {
      lv: el("td", { class: "lv" }), kind: el("td", { class: "kind" }), state: el("td", { class: "state" }),
      act: el("td", { "data-field": "activation" }), actText: document.createTextNode(""),
      re: el("span", { class: "reann", "data-field": "reannounce", hidden: "" }),
      value: el("td", { "data-field": "value" }), valueText: document.createTextNode(""),
      est: el("span", { class: "reann", "data-field": "from-estimate", hidden: "" }),
      user: el("td", { class: "user" }), btns: el("td", { class: "btns cmd" }), buttons: null,
    };
    c.act.append(c.actText, c.re);
    c.value.append(c.valueText, c.est);
    const tr = el("tr", { "data-key": key });
    tr.append(c.lv, c.kind, c.state, c.act, c.value, c.user, c.btns);
    return { tr, c, key };
  }

  // The buttons of a row: created once (none with --read-only); each reads
  // its alarm's identity (kind, level, activation) when pressed, never a row
  // position.
  function rowButtons(s, row) {
    const want = !state.readOnly;
    if (want === (row.c.buttons !== null)) return;
    if (!want) { row.c.btns.textContent = ""; row.c.buttons = null; return; }
    const mk = (label, action) => el("button", { "data-action": label.toLowerCase(),
      onclick: () => { const a = s.alarms.get(row.key); if (a) command(s, identityOf(a), action, label); } }, label);
    row.c.buttons = { ack: mk("Acknowledge", 1), shelve: mk("Shelve", 2), unshelve: mk("Unshelve", 3) };
    row.c.btns.append(row.c.buttons.ack, row.c.buttons.shelve, row.c.buttons.unshelve);
  }

  const identityOf = (a) => ({ kind: a.kind, level: a.level, activation: a.dash_activation_utime, server: a.serverIdentity,
                               name: alarmName(a), since: activeSince(a), rtn: !a.active ? clock(a.rtnUtime || a.utime) : "" });

  function updateRow(s, row, a) {
    const { tr, c } = row;
    setAttr(tr, "class", `alarm lvl-${a.level} ${a.active ? "active" : ""} ${a.acked ? "acked" : "unacked"} ${a.shelved ? "shelved" : ""}`);
    for (const [k, v] of [["data-kind", a.kind], ["data-level", String(a.level)], ["data-active", String(a.active)],
                          ["data-acked", String(a.acked)], ["data-shelved", String(a.shelved)], ["data-latched", String(a.latched)],
                          ["data-activation", String(a.dash_activation_utime)], ["data-state", stateText(a)]]) setAttr(tr, k, v);
    setText(c.lv, levelName(a.level));
    setText(c.kind, a.kind);
    setAttr(c.kind, "title", a.message || "");
    setText(c.state, stateText(a));
    setText(c.actText, `${activeSince(a)} (t=${fix(a.dash_activation_t, 1)} s)`);
    const re = a.dash_reannounce_utime > 0 ? ` re-announced ${clock(a.dash_reannounce_utime)}` : "";
    setText(c.re, re);
    c.re.hidden = !re;
    setText(c.valueText, fmtVal(a));
    // Newer daemons say whether the alarm judged the load estimate (alarm_t.from_estimate).
    c.est.hidden = a.from_estimate !== true;
    setText(c.est, c.est.hidden ? "" : "judged on the load estimate");
    setText(c.user, a.user || "");
    rowButtons(s, row);
    if (c.buttons) {
      // RTN UNACK (returned to normal, unacknowledged) is acknowledged like an active alarm.
      c.buttons.ack.disabled = a.acked || a.shelved;
      c.buttons.shelve.disabled = a.shelved;
      c.buttons.unshelve.disabled = !a.shelved;
    }
  }

  // While a pointer is pressed on the alarm list, rows that leave it stay
  // (greyed, buttons disabled) until it is released: the row under the
  // operator's finger never moves between mouse-down and mouse-up.
  function renderAlarms(s) {
    const body = s.alarmsBody;
    const alarms = [...s.alarms.values()].filter(listed).sort(alarmOrder);
    $("[data-role=no-alarms]", s.root).hidden = alarms.length > 0;
    const keep = new Set(alarms.map((a) => `${a.kind}/${a.level}`));
    const leaving = new Set();
    for (const [key, row] of s.rows) {
      if (keep.has(key)) continue;
      if (state.pointerHeld) {
        leaving.add(row.tr);
        row.tr.classList.add("leaving");
        if (row.c.buttons) for (const b of Object.values(row.c.buttons)) b.disabled = true;
      } else { row.tr.remove(); s.rows.delete(key); }
    }
    const skip = (n) => { while (n && leaving.has(n)) n = n.nextSibling; return n; };
    let at = skip(body.firstChild);
    for (const a of alarms) {
      const key = `${a.kind}/${a.level}`;
      let row = s.rows.get(key);
      if (!row) { row = makeRow(s, key); s.rows.set(key, row); }
      updateRow(s, row, a);
      // Moved only if out of place (a new row; never an existing one in a stable order).
      if (row.tr !== at) body.insertBefore(row.tr, at);
      else at = skip(at.nextSibling);
    }
  }
  document.addEventListener("pointerdown", (e) => { if (e.target.closest && e.target.closest(".alarms")) state.pointerHeld = true; }, true);
  for (const ev of ["pointerup", "pointercancel"]) {
    window.addEventListener(ev, () => {
      if (!state.pointerHeld) return;
      state.pointerHeld = false;
      setTimeout(() => { for (const s of state.shafts.values()) renderAlarms(s); }, 0);  // after the click
    }, true);
  }

  function command(s, ident, action, label) {
    const user = userInput.value.trim();
    if (!user) { toast("Enter your name (Operator) before acknowledging or shelving.", true); userInput.focus(); return; }
    const cid = state.ackChannels.get(s.prefix);
    if (cid === undefined) { toast("No command channel for this shaft (read-only server?)", true); return; }
    const shelve = Number($("[data-role=shelve-s]", s.root).value);
    const since = ident.rtn ? `active since ${ident.since}, returned to normal at ${ident.rtn}` : `active since ${ident.since}`;
    const what = action === 2 ? `${label} ${ident.name} (${since}) for ${shelve / 60} min?` : `${label} ${ident.name} (${since})?`;
    if (!window.confirm(what)) return;
    const cmd = { utime: 0, kind: ident.kind, level: ident.level, action, shelve_duration: action === 2 ? shelve : 0, user };
    // The server refuses the command if this alarm changed since the page drew it.
    if (ident.server) cmd.activation_utime = ident.activation;
    if (!isOpen()) { toast("Not connected: the command was not sent", true); return; }
    state.client.sendMessage(cid, new TextEncoder().encode(JSON.stringify(cmd)));
  }

  // ---- load estimate (only when HOIST_ESTIMATE publishes) ----------------------------
  // The estimated payload Fa and its offset b with their sigmas ("n/a" when not
  // observed: sigma < 0), the moment, the sensors in use and their ages, a
  // MODEL_MISMATCH badge; trends of theta estimated with its +-2 sigma band
  // next to the open-loop theta, and of the window's NIS against its bound.
  const SENSOR_IMU_ACCEL = 1, SENSOR_IMU_RATE = 2, SENSOR_ROPE_LOAD = 4;  // estimate_t.SENSOR_*
  const EST_ROWS = [["Fa", "payload Fa"], ["b", "offset b"], ["moment", "moment M = Fa b"], ["y_c", "sway y_c"],
                    ["theta", "tilt θ"], ["nis", "NIS window / bound"], ["sensors", "sensors in use"],
                    ["counts", "updates / gated / refused"], ["in_use", "alarms judge"]];

  function makeEstimateCard() {
    const dl = el("dl", { "data-role": "estimate-values" });
    for (const [f, k] of EST_ROWS) dl.append(el("dt", {}, k), el("dd", { "data-field": `est-${f}` }, "–"));
    return el("div", { class: "card estimate", "data-role": "estimate", hidden: "" },
      el("h2", {}, "Load estimate ", el("span", { class: "badge", "data-field": "est-mismatch", "data-state": "ok" }, "")),
      dl, el("div", { class: "est-note", "data-field": "est-stale" }, ""),
      el("div", { class: "trends", "data-role": "estimate-trends" }));
  }

  // Decimals that show a value to its sigma's first digit (0 for sigma >= 1).
  const sigDecimals = (sigma) => Math.min(6, Math.max(0, -Math.floor(Math.log10(sigma) + 1e-9)));
  function withSigma(v, sigma, scale, unit) {
    if (!num(v) || !num(sigma) || sigma < 0) return "n/a";
    const d = sigma > 0 ? sigDecimals(sigma * scale) : 3;
    return `${fix(v * scale, d)} ± ${fix(sigma * scale, d)} ${unit}`;
  }

  function onEstimate(s, d) {
    const e = d.last;
    if (!e || typeof e !== "object") return;
    s.est = e;
    s.lastEst = performance.now();
    if (s.estBox.hidden) { s.estBox.hidden = false; makeEstimateCharts(s); }
    const D = s.estData;
    const vals = (m, sig) => {
      const th = num(m.theta) ? m.theta * 1e3 : null;
      const sg = num(sig) && sig >= 0 && th !== null ? 2 * sig * 1e3 : null;  // +-2 sigma [mrad]
      const v = { th: sig >= 0 ? th : null, hi: sg === null ? null : th + sg, lo: sg === null ? null : th - sg,
                  open: num(m.theta_open) ? m.theta_open * 1e3 : null,
                  nis: num(m.nis_window) && e.nis_dof > 0 ? m.nis_window : null,
                  bound: num(e.nis_bound) && e.nis_dof > 0 ? e.nis_bound : null,
                  nlo: num(e.nis_lower) && e.nis_dof > 0 ? e.nis_lower : null,
                  nup: num(e.nis_upper) && e.nis_dof > 0 ? e.nis_upper : null };
      return v;
    };
    const push = (x, v) => { D.x.push(x); for (const k of Object.keys(v)) D[k].push(v[k]); };
    // Min/max decimation as for the cage: the interval's extremes both enter
    // the trend; the band uses the interval's largest sigma.
    const t0 = d.first && num(d.first.utime) ? d.first.utime / 1e6 : e.utime / 1e6, t1 = e.utime / 1e6;
    const sigMax = d.max && num(d.max.sigma_theta) ? d.max.sigma_theta : e.sigma_theta;
    if (d.count > 1 && t1 > t0 && d.min && d.max) {
      push(t0, vals(d.min, e.sigma_theta < 0 ? -1 : sigMax));
      push(t1, vals(d.max, e.sigma_theta < 0 ? -1 : sigMax));
    } else {
      push(t1, vals(e, e.sigma_theta));
    }
    const n = D.x.length;
    if (n > 1 && D.x[n - 1] < D.x[n - 2]) for (const k of Object.keys(D)) D[k].splice(0, n - 1);
    const tmin = D.x[D.x.length - 1] - KEEP_S;
    let cut = 0;
    while (cut < D.x.length && D.x[cut] < tmin) cut++;
    if (cut > 0) for (const k of Object.keys(D)) D[k].splice(0, cut);
    renderEstimate(s, e, Boolean(d.max && d.max.mismatch));
    renderTilt(s);
    s.estDirty = true;
  }

  function renderEstimate(s, e, mismatchInInterval) {
    const box = s.estBox;
    const set = (f, text) => { $(`[data-field="est-${f}"]`, box).textContent = text; };
    box.dataset.utime = String(e.utime);
    // estimate_t's contract: sigma < 0 is "not observed"; so is a load whose
    // sensor was never used (fa_observed / moment_observed false), whatever
    // its sigma (the prior's, e.g. 5000 N without a rope load cell).
    const no = (f) => f === false || f === 0;
    const faObs = !no(e.fa_observed), mObs = !no(e.moment_observed);
    set("Fa", faObs ? withSigma(e.Fa, e.sigma_Fa, 1, "N") : "n/a");
    set("b", faObs && mObs ? withSigma(e.b, e.sigma_b, 1, "m") : "n/a");
    set("moment", mObs ? withSigma(e.moment, e.sigma_moment, 1, "N·m") : "n/a");
    set("y_c", withSigma(e.y_c, e.sigma_y_c, 1e3, "mm"));
    set("theta", `${withSigma(e.theta, e.sigma_theta, 1e3, "mrad")} (open loop ${num(e.theta_open) ? fix(e.theta_open * 1e3, 3) : "n/a"} mrad)`);
    set("nis", e.nis_dof > 0
      ? `${fix(e.nis_window, 1)} / ${fix(e.nis_bound, 1)} (${e.nis_dof} dof; 95 %: ${fix(e.nis_lower, 1)} … ${fix(e.nis_upper, 1)})`
      : "n/a (no sensor update in the window)");
    const age = (a) => (num(a) && a >= 0 ? `${fix(a * 1e3, 0)} ms ago` : "none yet");
    const used = [];
    const imu = e.sensors & (SENSOR_IMU_ACCEL | SENSOR_IMU_RATE);
    if (imu) used.push(`IMU${imu === (SENSOR_IMU_ACCEL | SENSOR_IMU_RATE) ? "" : imu & SENSOR_IMU_ACCEL ? " (accel)" : " (rate)"}, ${age(e.imu_age)}`);
    if (e.sensors & SENSOR_ROPE_LOAD) used.push(`rope load, ${age(e.rope_load_age)}`);
    set("sensors", used.length ? used.join("; ") : "none: the twin runs open loop");
    $('[data-field="est-sensors"]', box).dataset.sensors = String(e.sensors);
    set("counts", `${e.accepted} / ${e.gated} / ${e.implausible}`);
    // Newer daemons say whether their alarms judge this estimate (estimate_t.in_use).
    const inUse = $('[data-field="est-in_use"]', box);
    inUse.previousSibling.hidden = inUse.hidden = typeof e.in_use !== "boolean";
    inUse.textContent = e.in_use === true ? "the estimate" : e.in_use === false ? "the open-loop twin" : "";
    const badge = $('[data-field="est-mismatch"]', box);
    const on = Boolean(e.mismatch) || mismatchInInterval;
    badge.dataset.state = on ? "mismatch" : "ok";
    const why = [e.nis_exceeded ? "NIS" : "", e.drift_exceeded ? "load drift" : ""].filter(Boolean).join(", ");
    badge.textContent = on ? `MODEL_MISMATCH${why ? " (" + why + ")" : ""}` : "";
  }

  function makeEstimateCharts(s) {
    const host = $("[data-role=estimate-trends]", s.estBox);
    const defs = [
      ["θ estimated ±2σ and open loop [mrad]", "estimate-theta",
       [["th", "#a78bfa", "θ est."], ["hi", "#a78bfa55", "+2σ", [3, 3]], ["lo", "#a78bfa55", "−2σ", [3, 3]], ["open", "#fbbf24", "θ open loop", [6, 4]]],
       [{ series: [2, 3], fill: "rgba(167,139,250,0.18)" }], (u, lo, hi) => spanAtLeast(lo, hi, 0.02)],
      ["NIS over the window, its 95 % bounds and the MODEL_MISMATCH bound", "estimate-nis",
       [["nis", "#e5e7eb", "NIS"], ["nlo", "#2fbf71", "95 % low", [6, 4]], ["nup", "#2fbf71", "95 % high", [6, 4]], ["bound", "#ef4444", "bound", [2, 4]]],
       [], (u, lo, hi) => [Math.min(0, isFinite(lo) ? lo : 0), Math.max(1, isFinite(hi) ? hi * 1.1 : 1)]],
    ];
    for (const [title, role, series, bands, yrange] of defs) {
      const plotEl = el("div", { "data-role": role, "data-points": "0" });
      host.append(el("div", { class: "trend" }, el("h3", {}, title), plotEl));
      const hms = (u, vals) => vals.map((v) => new Date(v * 1000).toLocaleTimeString([], { hour12: false }));
      const opts = {
        ...chartSize(plotEl), width: 480, scales: { x: { time: true }, y: { range: yrange } },
        axes: [{ stroke: "#8a96a3", grid: { stroke: "#252c34" }, values: hms, size: 24, space: 90 },
               { stroke: "#8a96a3", grid: { stroke: "#252c34" }, size: 60, splits, values: ticks }],
        legend: { show: true, live: false }, cursor: { drag: { x: false, y: false } }, bands,
        series: [{}, ...series.map(([k, c, label, dash]) => ({ label, stroke: c, width: 1.2, dash: dash || undefined, points: { show: false } }))],
      };
      const u = new uPlot(opts, [s.estData.x, ...series.map(([k]) => s.estData[k])], plotEl);
      s.estCharts.push({ u, keys: series.map(([k]) => k), el: plotEl });
    }
  }

  function drawEstimate(s) {
    const D = s.estData;
    const xmax = D.x.length ? D.x[D.x.length - 1] : Date.now() / 1000;
    for (const c of s.estCharts) {
      c.u.setData([D.x, ...c.keys.map((k) => D[k])], false);
      c.u.setScale("x", { min: xmax - state.windowS, max: xmax });
      // For tests and readers: the points of each series in the window.
      const from = D.x.findIndex((x) => x >= xmax - state.windowS);
      for (const k of c.keys) {
        let n = 0;
        if (from >= 0) for (let i = from; i < D.x.length; i++) n += D[k][i] === null ? 0 : 1;
        c.el.dataset[`points_${k}`] = String(n);
      }
      c.el.dataset.points = String(Math.max(0, ...c.keys.map((k) => Number(c.el.dataset[`points_${k}`]))));
    }
  }

  // ---- health ---------------------------------------------------------------------
  function renderHealth(s) {
    const h = s.health;
    const dl = $("[data-role=health]", s.root);
    dl.textContent = "";
    const rows = [
      ["clock / rate", `${h.clock} / ${h.rate} Hz`],
      ["step time p50 / p99 / max", `${fix(h.step_p50_us, 1)} / ${fix(h.step_p99_us, 1)} / ${fix(h.step_max_us, 1)} µs`],
      ["tick lateness p50 / p99 / max", `${fix(h.late_p50_us, 1)} / ${fix(h.late_p99_us, 1)} / ${fix(h.late_max_us, 1)} µs`],
      ["deadline misses", String(h.deadline_misses)],
      ["input age", h.input_age < 0 ? "no input yet" : `${fix(h.input_age, 2)} s`],
      ["inputs accepted / lost (seq gaps)", `${h.accepted} / ${h.seq_gaps}`],
      ["rejected inputs", String(h.rejected_total)],
    ];
    (h.reject_reason || []).forEach((r, i) => { if (h.rejected[i] > 0) rows.push([`  rejected: ${r}`, String(h.rejected[i])]); });
    rows.push(["alarms active / unacked / shelved", `${h.alarms_active} / ${h.alarms_unacked} / ${h.alarms_shelved}`],
              ["model faults / resets", `${h.model_faults} / ${h.model_resets}`],
              ["publish failures", String(h.publish_failures)],
              ["uptime", `${fix(h.uptime, 0)} s`]);
    for (const [k, v] of rows) dl.append(el("dt", {}, k), el("dd", {}, v));
    dl.append(el("dt", {}, "degraded"), el("dd", { "data-field": "health-degraded" },
      el("span", { class: h.degraded ? "degraded-yes" : "" }, h.degraded ? "DEGRADED" : "no")));
  }

  // ---- forecasts (only when HOIST_FORECAST publishes) -------------------------------
  // Per scenario: worst clearance and when, time to violation (first CRITICAL
  // and WARNING crossing, "none" within the horizon), the lambda_0 range; and
  // the decimated series (min clearance, lambda_0 min..max) against the time
  // ahead, with the live thresholds (clearance WARNING/CRITICAL, ROPE_SLACK /
  // ROPE_OVERLOAD).  Every string from the network goes in as text.
  const SCN_COLORS = ["#f87171", "#60a5fa", "#34d399", "#fbbf24", "#a78bfa", "#f472b6", "#22d3ee", "#a3e635"];
  const STATUS = ["ok", "left the shaft", "non-finite"];
  const ahead = (t) => (typeof t === "number" && t >= 0 ? `${fix(t, 1)} s` : "none");

  function renderForecast(s) {
    const box = $("[data-role=forecast]", s.root);
    box.hidden = false;
    const body = $("[data-role=forecast-body]", s.root);
    body.textContent = "";
    const f = s.forecast;
    const scns = Array.isArray(f.scenarios) ? f.scenarios.slice(0, 8) : [];
    body.append(el("p", { class: "fc-note", "data-field": "forecast-from" },
      `from t=${fix(f.t_start, 2)} s, l=${fix(f.l, 1)} m` +
      (f.plan_seq >= 0 ? `, trip plan #${f.plan_seq}` : ", no trip plan") +
      ` (${fix(Number(f.compute_time) * 1e3, 0)} ms)`));
    const tbl = el("table", { class: "fc" }, el("thead", {}, el("tr", {},
      ...["Scenario", "Worst clearance", "CRITICAL in", "WARNING in", "λ0 min…max [kN]"].map((h) => el("th", {}, h)))));
    const tb = el("tbody");
    scns.forEach((sc, i) => {
      const crit = sc.t_critical >= 0, warn = sc.t_warning >= 0;
      const tr = el("tr", { class: crit ? "lvl-2" : warn ? "lvl-1" : "", "data-scenario": String(sc.name),
                            "data-t-critical": String(sc.t_critical), "data-t-warning": String(sc.t_warning) },
        el("td", {}, el("span", { class: "swatch", style: `background:${SCN_COLORS[i]}` }), String(sc.name),
           sc.status ? ` (stopped at ${fix(sc.t_reached, 1)} s: ${STATUS[sc.status] || "status " + sc.status})` : ""),
        el("td", { "data-field": "worst" }, `${fix(sc.min_clearance * 1e3, 1)} mm at +${fix(sc.t_min_clearance, 1)} s`),
        el("td", { "data-field": "t-critical", class: crit ? "lvl2" : "" }, ahead(sc.t_critical)),
        el("td", { "data-field": "t-warning", class: warn ? "lvl1" : "" }, ahead(sc.t_warning)),
        el("td", {}, `${fix(sc.lambda0_min / 1e3, 2)} … ${fix(sc.lambda0_max / 1e3, 2)}`));
      tb.append(tr);
    });
    tbl.append(tb);
    body.append(tbl);
    const [w, c] = thresholds(s);
    const cage = s.cage || {};
    body.append(fcPlot("min clearance [mm] vs time ahead [s]", scns, (sc) => [sc.series_min_clearance.map((v) => v * 1e3)],
                       [[w, "#f0b429"], [c, "#ef4444"]], "clearance"));
    body.append(fcPlot("hoisting-rope force λ0 [kN] (min…max) vs time ahead [s]", scns,
                       (sc) => [sc.series_lambda0_min.map((v) => v / 1e3), sc.series_lambda0_max.map((v) => v / 1e3)],
                       [[cage.rope_slack_threshold / 1e3, "#ef4444"], [cage.rope_overload_threshold / 1e3, "#ef4444"]], "lambda0"));
  }

  // A small line plot on a canvas: one colour per scenario, dashed threshold lines.
  function fcPlot(title, scns, ys, thr, role) {
    const W = 560, H = 180, ml = 44, mr = 8, mt = 8, mb = 20;
    const cv = el("canvas", { class: "fcplot", width: String(W), height: String(H), "data-role": `forecast-${role}` });
    const g = cv.getContext("2d");
    let tmax = 0, lo = Infinity, hi = -Infinity, npts = 0;
    for (const sc of scns) {
      const t = sc.series_t || [];
      if (t.length) tmax = Math.max(tmax, t[t.length - 1]);
      for (const arr of ys(sc)) for (const v of arr) if (isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); npts++; }
    }
    for (const [v] of thr) if (isFinite(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    cv.dataset.points = String(npts);
    if (!(tmax > 0) || !isFinite(lo)) return el("div", { class: "trend" }, el("h3", {}, title), el("p", { class: "empty" }, "no series"));
    if (hi - lo < 1e-9) { hi += 1; lo -= 1; }
    const pad = 0.05 * (hi - lo);
    lo -= pad; hi += pad;
    const X = (t) => ml + (W - ml - mr) * t / tmax, Y = (v) => mt + (H - mt - mb) * (hi - v) / (hi - lo);
    g.font = "10px system-ui"; g.fillStyle = "#8a96a3"; g.strokeStyle = "#252c34";
    // Nice ticks labelled with as many decimals as they need (distinct), as
    // on the trends: never "289 289 289 288".
    const yv = splits(null, 1, lo, hi), yl = ticks(null, yv);
    yv.forEach((v, k) => {
      g.beginPath(); g.moveTo(ml, Y(v)); g.lineTo(W - mr, Y(v)); g.stroke();
      g.fillText(yl[k], 2, Y(v) + 3);
    });
    const xv = splits(null, 0, 0, tmax), xl = ticks(null, xv);
    xv.forEach((t, k) => g.fillText(xl[k], X(t) - 4, H - 6));
    cv.dataset.yticks = yl.join("|");
    cv.dataset.xticks = xl.join("|");
    for (const [v, col] of thr) {
      if (!isFinite(v)) continue;
      g.strokeStyle = col; g.setLineDash([6, 4]); g.beginPath(); g.moveTo(ml, Y(v)); g.lineTo(W - mr, Y(v)); g.stroke();
    }
    g.setLineDash([]);
    scns.forEach((sc, i) => {
      const t = sc.series_t || [];
      g.strokeStyle = SCN_COLORS[i]; g.lineWidth = 1.5;
      for (const arr of ys(sc)) {
        g.beginPath();
        for (let k = 0; k < Math.min(t.length, arr.length); k++) {
          if (!isFinite(arr[k])) continue;
          k ? g.lineTo(X(t[k]), Y(arr[k])) : g.moveTo(X(t[k]), Y(arr[k]));
        }
        g.stroke();
      }
    });
    return el("div", { class: "trend" }, el("h3", {}, title), cv);
  }

  // ---- shaft view -----------------------------------------------------------------
  function drawShaft(s) {
    const cv = s.canvas, g = cv.getContext("2d");
    const W = cv.width, H = cv.height;
    g.setTransform(1, 0, 0, 1, 0, 0);
    g.clearRect(0, 0, W, H);
    g.scale(2, 2);  // canvas at 2x for crisp lines
    const w = W / 2, h = H / 2, top = 14, bot = h - 14;
    const L = s.shape && s.shape.x && s.shape.x.length ? s.shape.x[s.shape.x.length - 1] : 400;
    const vs = (bot - top) / L;                       // px per metre, vertical
    const gap = s.gap ? Math.max(s.gap.pos, s.gap.neg) : 0.3;
    const ls = 40 / Math.max(gap, 1e-3);              // px per metre, lateral: the gap is 40 px
    const mag = ls / vs;
    const cx = w / 2, half = 40;                      // guide ropes drawn 80 px apart
    const Y = (x) => top + x * vs;
    $("[data-role=scale]", s.root).textContent =
      `depth to scale 0…${fix(L, 0)} m; lateral ×${fix(mag, 0)} (${fix(gap * 1e3, 1)} mm = 40 px); gap ` +
      (s.gap ? `+y ${fix(s.gap.pos * 1e3, 1)} mm, −y ${fix(s.gap.neg * 1e3, 1)} mm` : "unknown (no cage state yet)");
    g.font = "10px system-ui"; g.fillStyle = "#8a96a3"; g.strokeStyle = "#222a33"; g.lineWidth = 1;
    for (let d = 0; d <= L + 1e-9; d += L > 200 ? 50 : 20) {
      g.beginPath(); g.moveTo(18, Y(d)); g.lineTo(w, Y(d)); g.stroke();
      g.fillText(`${fix(d, 0)}`, 0, Y(d) + 3);
    }
    // Clearance limits (cage sides): the gap (CRITICAL at the wall), WARNING dashed.
    if (s.gap) {
      const lines = [[s.gap.pos, "#ef4444", []], [-s.gap.neg, "#ef4444", []],
                     [sideThr(s, "pos", 1), "#f0b429", [5, 4]], [-sideThr(s, "neg", 1), "#f0b429", [5, 4]]];
      for (const [y, col, dash] of lines) {
        const px = cx + (y > 0 ? half : -half) + y * ls;
        g.strokeStyle = col; g.setLineDash(dash); g.beginPath(); g.moveTo(px, top); g.lineTo(px, bot); g.stroke();
      }
      g.setLineDash([]);
    }
    // Guide ropes, live shape.
    if (s.shape && s.shape.x) {
      const { x, y1, y2 } = s.shape;
      for (const [ys, off, col] of [[y1, -half, "#cbd5e1"], [y2, half, "#cbd5e1"]]) {
        g.strokeStyle = col; g.lineWidth = 1.5; g.beginPath();
        for (let i = 0; i < x.length; i++) { const px = cx + off + ys[i] * ls, py = Y(x[i]); i ? g.lineTo(px, py) : g.moveTo(px, py); }
        g.stroke();
      }
    }
    // The cage: top sleeves at depth l with excursion y_top, bottom sleeves at l + 2h with y_bottom.
    const c = s.cage;
    if (c) {
      const hh = s.shape ? s.shape.h : 8;
      const yt = cx + c.y_top * ls, yb = cx + c.y_bottom * ls;
      const stale = s.root.classList.contains("stale");
      const col = stale ? "#6b7280" : ["#2fbf71", "#f0b429", "#ef4444"][c.alarm_level] || "#6b7280";
      g.fillStyle = col; g.globalAlpha = 0.85;
      g.beginPath();
      g.moveTo(yt - half + 3, Y(c.l)); g.lineTo(yt + half - 3, Y(c.l));
      g.lineTo(yb + half - 3, Y(c.l + 2 * hh)); g.lineTo(yb - half + 3, Y(c.l + 2 * hh)); g.closePath();
      g.fill(); g.globalAlpha = 1;
      g.strokeStyle = "#fff"; g.lineWidth = 1; g.stroke();
      // Hoisting rope from the head sheave.
      g.strokeStyle = "#9ca3af"; g.beginPath(); g.moveTo(cx, top - 10); g.lineTo(yt, Y(c.l)); g.stroke();
      g.fillStyle = "#fff";
      g.fillText(`${fix(c.l, 1)} m`, yt + half + 4, Y(c.l) + 10);
    }
  }

  // ---- loop ---------------------------------------------------------------------
  function updateStale() {
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

  function frame() {
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
})();

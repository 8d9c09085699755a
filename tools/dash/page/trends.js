// hoist-dash page: the trends (uPlot), the cage state readouts and the
// headline tilt.
import { alarm_t } from "./hoist_msgs.js";
import { STALE_AFTER_MS, KEEP_S, state } from "./state.js";
import { levelName, $, el, fix, num, setText, keepWindow } from "./util.js";
import { subscribe } from "./main.js";

// ---- trends -------------------------------------------------------------------
export function chartSize(host) { return { width: Math.max(300, host.clientWidth || 600), height: 132 }; }

// Y ranges that suit the data: a minimum span around a flat signal (so the
// axis has at least three distinct labels), forces from 0, the speed from 0
// (or -vmax) to the trip's vmax.
export const spanAtLeast = (min, max, span) => {
  if (!isFinite(min) || !isFinite(max)) return [-span / 2, span / 2];
  if (max - min >= span) { const pad = 0.05 * (max - min); return [min - pad, max + pad]; }
  const c = (min + max) / 2;
  return [c - span / 2, c + span / 2];
};
// Ticks: the largest "nice" step (1, 2, 2.5, 5 x 10^k) of at most a third
// of the range -- so at least 3 and (the nice steps at most 2x apart) at
// most 6 ticks on every axis -- labelled with as many decimals as they need
// to be exact, hence distinct.
export const niceStep = (span) => {
  const raw = span / 3, p = Math.pow(10, Math.floor(Math.log10(raw)));
  let best = p;
  for (const m of [1, 2, 2.5, 5, 10]) if (m * p <= raw * (1 + 1e-9)) best = m * p;
  return best;
};
export const splits = (u, axisIdx, min, max) => {
  if (!(max > min) || !isFinite(min) || !isFinite(max)) return [min];
  const step = niceStep(max - min);
  const out = [];
  for (let k = Math.ceil(min / step - 1e-9); k * step <= max + 1e-9 * step; k++) out.push(k === 0 ? 0 : k * step);
  return out;
};
export const ticks = (u, vals) => {
  let d = 0;
  while (d < 8 && vals.some((v) => Math.abs(v * 10 ** d - Math.round(v * 10 ** d)) > 1e-6 * Math.max(1, Math.abs(v * 10 ** d)))) d++;
  return vals.map((v) => fix(v, d));
};
export function speedRange(s, min, max) {
  const seen = Math.max(Math.abs(isFinite(min) ? min : 0), Math.abs(isFinite(max) ? max : 0));
  const vmax = s.plan && s.plan.vmax > 0 ? Math.max(s.plan.vmax, seen) : Math.max(1, seen * 1.1);
  return [isFinite(min) && min < -0.05 * vmax ? -vmax : 0, vmax];
}

export function makeCharts(s, host) {
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
export function onHistory(s, h) {
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

export function pushPoint(s, x, vals) {
  const D = s.data;
  D.x.push(x);
  for (const k of Object.keys(vals)) D[k].push(vals[k]);
}

export function cageVals(m, s) {
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

export function onCage(s, d) {
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
  keepWindow(D, KEEP_S);
  renderReadouts(s, last);
  s.dirty = true;
}

// Excursion threshold [m] of a cage side at a level: from the daemon's own
// alarms once one was announced (alarm_t.threshold), else the fraction of
// the gap given to hoist-dash (--warning-fraction, --critical-fraction).
export function sideThr(s, side, level) {
  const t = s.thr[`${side === "pos" ? "CAGE_POS_Y" : "CAGE_NEG_Y"}/${level}`];
  if (t > 0) return t;
  const m = state.meta[s.prefix] || state.meta["*"] || {};
  return (level === 1 ? (m.warning_fraction ?? 0.5) : (m.critical_fraction ?? 0.8)) * s.gap[side];
}

// WARNING / CRITICAL on the min-clearance trend: clearance = gap - excursion.
export function thresholds(s) {
  if (!s.gap) return [NaN, NaN];
  const clr = (level) => 1e3 * Math.min(s.gap.pos - sideThr(s, "pos", level), s.gap.neg - sideThr(s, "neg", level));
  return [clr(1), clr(2)];
}

export function renderReadouts(s, m) {
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
export function renderTilt(s) {
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

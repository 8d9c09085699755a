// hoist-dash page: the health panel, the forecasts and the shaft view.
import { state } from "./state.js";
import { $, el, fix, clock } from "./util.js";
import { splits, ticks, sideThr, thresholds } from "./trends.js";

// ---- health ---------------------------------------------------------------------
export function renderHealth(s) {
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
            ["guide-rope preload (the twin's model)", typeof h.preload_scale !== "number" ? "n/a"
              : h.preload_scale === 1 ? "as configured"
              : `x${fix(h.preload_scale, 3)} of the configuration's (adopted by an operator)`],
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
export const SCN_COLORS = ["#f87171", "#60a5fa", "#34d399", "#fbbf24", "#a78bfa", "#f472b6", "#22d3ee", "#a3e635"];
export const STATUS = ["ok", "left the shaft", "non-finite"];
export const ahead = (t) => (typeof t === "number" && t >= 0 ? `${fix(t, 1)} s` : "none");

export function renderForecast(s) {
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
export function fcPlot(title, scns, ys, thr, role) {
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
export function drawShaft(s) {
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

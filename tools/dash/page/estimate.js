// hoist-dash page: the load-estimate panel and its trends.
import { KEEP_S, state } from "./state.js";
import { $, el, fix, num, keepWindow } from "./util.js";
import { chartSize, spanAtLeast, splits, ticks, renderTilt } from "./trends.js";
import { makeCalibrationForm, renderCalibrating } from "./calibrate.js";

// ---- load estimate (only when HOIST_ESTIMATE publishes) ----------------------------
// The estimated payload Fa and its offset b with their sigmas ("n/a" when not
// observed: sigma < 0), the moment, the sensors in use and their ages, a
// MODEL_MISMATCH badge; trends of theta estimated with its +-2 sigma band
// next to the open-loop theta, and of the window's NIS against its bound.
export const SENSOR_IMU_ACCEL = 1, SENSOR_IMU_RATE = 2, SENSOR_ROPE_LOAD = 4;  // estimate_t.SENSOR_*
export const EST_ROWS = [["Fa", "payload Fa"], ["b", "offset b"], ["moment", "moment M = Fa b"], ["y_c", "sway y_c"],
                  ["theta", "tilt θ"], ["nis", "NIS window / bound"], ["sensors", "sensors in use"],
                  ["counts", "updates / gated / refused"], ["in_use", "alarms judge"],
                  ["detect", "preload loss visible"]];

// `prefix`: the shaft's (its calibration's command channel).
export function makeEstimateCard(prefix) {
  const dl = el("dl", { "data-role": "estimate-values" });
  for (const [f, k] of EST_ROWS) dl.append(el("dt", {}, k), el("dd", { "data-field": `est-${f}` }, "–"));
  return el("div", { class: "card estimate", "data-role": "estimate", hidden: "" },
    el("h2", {}, "Load estimate ", el("span", { class: "badge", "data-field": "est-mismatch", "data-state": "ok" }, "")),
    dl, el("div", { class: "est-note", "data-field": "est-stale" }, ""),
    el("div", { class: "trends", "data-role": "estimate-trends" }),
    el("div", { class: "est-note calibrating", "data-field": "est-calibrating" }, ""),
    // No command controls at all on a read-only server's page (as the alarm rows' buttons).
    state.readOnly ? "" : makeCalibrationForm(prefix));
}

// Decimals that show a value to its sigma's first digit (0 for sigma >= 1).
export const sigDecimals = (sigma) => Math.min(6, Math.max(0, -Math.floor(Math.log10(sigma) + 1e-9)));
export function withSigma(v, sigma, scale, unit) {
  if (!num(v) || !num(sigma) || sigma < 0) return "n/a";
  const d = sigma > 0 ? sigDecimals(sigma * scale) : 3;
  return `${fix(v * scale, d)} ± ${fix(sigma * scale, d)} ${unit}`;
}

export function onEstimate(s, d) {
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
  keepWindow(D, KEEP_S);
  renderEstimate(s, e, Boolean(d.max && d.max.mismatch));
  renderTilt(s);
  s.estDirty = true;
}

export function renderEstimate(s, e, mismatchInInterval) {
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
  // The last recorded trip's detectability (estimate_t.detect_trip, newer
  // daemons with [history] on): could this IMU see a 30 % preload loss?
  const det = $('[data-field="est-detect"]', box);
  det.previousSibling.hidden = det.hidden = !num(e.detect_trip);
  det.textContent = detectText(e);
  renderCalibrating(box, e);
  const badge = $('[data-field="est-mismatch"]', box);
  const on = Boolean(e.mismatch) || mismatchInInterval;
  badge.dataset.state = on ? "mismatch" : "ok";
  // Neither of the estimator's tests: the trip-end preload test (docs/estimation.md).
  const why = e.mismatch && !e.nis_exceeded && !e.drift_exceeded ? "the trip's preload fit"
    : [e.nis_exceeded ? "NIS" : "", e.drift_exceeded ? "load drift" : ""].filter(Boolean).join(", ");
  badge.textContent = on ? `MODEL_MISMATCH${why ? " (" + why + ")" : ""}` : "";
}

// One plain sentence for estimate_t's detectability fields.
export function detectText(e) {
  if (!num(e.detect_trip) || e.detect_trip <= 0) return "no trip recorded yet (the twin identifies the preload per trip)";
  const sep = num(e.loss30_separation) && e.loss30_separation > 0 ? `: ${fix(e.loss30_separation, 1)} σ` : "";
  return `this IMU ${e.loss30_visible ? "can" : "cannot"} see a 30 % preload loss (trip ${e.detect_trip}${sep})`;
}

export function makeEstimateCharts(s) {
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

export function drawEstimate(s) {
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

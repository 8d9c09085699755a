// hoist-dash page: the "Shaft condition" view (issue 32, docs/dashboard.md).
// The trip records of the history database, as the server's ConditionView
// (src/condition.hpp) snapshots them at GET /api/condition: the preload
// trend over trips with its 95 % band and the GUIDE_PRELOAD_LOW thresholds,
// the depth x trip heat map of the residual RMS, the last trip's record with
// its depth-bin table, and the condition alarms (the trend's and the
// fingerprint's decisions).  Polled every 2 s; redrawn only when the
// snapshot's generation moves (a new trip, or a changed error).  A server
// without --history answers 404: the view stays hidden.  Every value is
// checked before it is drawn (a number that is not one is left out); all
// text goes in with textContent.
//
// Stable elements for tests: #condition[data-state=ok|error|loading]
// [data-generation][data-trips][data-last-trip], #cond-status,
// .cond-alarm[data-kind][data-level], #cond-trend and #cond-heat (canvases,
// data-points / data-cells = what was drawn), #cond-last td[data-field],
// #cond-bins tbody tr.
import { $, el, fix, num, setText, setAttr } from "./util.js";

const POLL_MS = 2000;
let shownGeneration = -1;

const fmt = (v, d) => (num(v) ? fix(v, d) : "–");
const pm = (v, s, d) => (num(v) ? (num(s) && s >= 0 ? `${fix(v, d)} ± ${fix(s, d)}` : `${fix(v, d)} (n/o)`) : "–");
// The record's alarms: the kinds, ';'-separated (history/schema.hpp joinAlarms).
const alarmList = (r) => (typeof r.alarms === "string" ? r.alarms.split(";").filter(Boolean) : []);
const iso = (us) => (num(us) && us > 0 ? new Date(us / 1000).toISOString().replace("T", " ").slice(0, 19) + " UTC" : "–");

async function poll() {
  let res;
  try {
    res = await fetch("/api/condition", { cache: "no-store" });
  } catch {
    setTimeout(poll, POLL_MS);  // the server is gone: the live view says so; try again
    return;
  }
  if (res.status === 404) return;  // an older hoist-dash without the view
  try {
    const j = await res.json();
    if (j && j.enabled === false) return;  // no --history: no view (and no polling)
    if (j && typeof j === "object" && j.generation !== shownGeneration) render(j);
  } catch (e) {
    showError(`unreadable answer from the server (${e})`);
  }
  setTimeout(poll, POLL_MS);
}

function showError(msg) {
  const root = $("#condition");
  root.hidden = false;
  $("#cond-link").hidden = false;
  setAttr(root, "data-state", "error");
  setText($("#cond-status"), `History database: ${msg}`);
  $("#cond-status").className = "cond-status bad";
}

function render(j) {
  const root = $("#condition");
  root.hidden = false;
  $("#cond-link").hidden = false;
  shownGeneration = j.generation;
  setAttr(root, "data-generation", String(j.generation));
  if (!j.ok) {
    if (j.loading) {
      setAttr(root, "data-state", "loading");
      setText($("#cond-status"), "reading the history database…");
      return;
    }
    showError(`${String(j.error || "unknown error")}${j.db ? ` (${j.db})` : ""}. Showing nothing until it can be read.`);
    return;
  }
  const trend = Array.isArray(j.trend) ? j.trend : [];
  const last = j.last && typeof j.last === "object" ? j.last : null;
  setAttr(root, "data-state", "ok");
  setAttr(root, "data-trips", String(j.trips));
  setAttr(root, "data-last-trip", last ? String(last.trip) : "");
  const rej = j.rejected > 0 ? `; ${j.rejected} record(s) rejected (${(j.rejected_notes || [])[0] || ""})` : "";
  // A long history is judged from its newest [condition] seed_trips trips (and the baseline before them).
  const shown = j.windowed ? `the newest ${j.trips} trips (up to trip ${j.stored_last_trip})` : `${j.trips} trip(s)`;
  setText($("#cond-status"), `${shown} of shaft ${j.shaft ? `'${j.shaft}'` : "(default)"} in ${j.db}${rej}`);
  $("#cond-status").className = j.rejected > 0 ? "cond-status warn" : "cond-status";
  renderAlarms(j, last);
  drawTrend($("#cond-trend"), trend, j.thresholds || {});
  drawHeat($("#cond-heat"), j.heatmap || {});
  renderLast(last);
}

// ---- condition alarms ----------------------------------------------------------
function renderAlarms(j, last) {
  const box = $("#cond-alarms");
  box.replaceChildren();
  const p = j.preload || {};
  const f = j.fingerprint || {};
  const rows = [
    ["GUIDE_PRELOAD_LOW", ["WARNING", "CRITICAL"].includes(p.level) ? p.level : "NONE",
     String(p.text || (p.valid ? "" : "no informative trip yet"))],
    ["SHAFT_FINGERPRINT", f.active ? "WARNING" : "NONE", String(f.text || "no bin left its baseline")],
  ];
  for (const [kind, level, text] of rows)
    box.append(el("div", { class: `cond-alarm lvl-${level.toLowerCase()}`, "data-kind": kind, "data-level": level },
                  el("b", {}, `${kind} ${level === "NONE" ? "clear" : level}`), el("span", {}, text)));
  if (last && alarmList(last).length)
    box.append(el("div", { class: "cond-alarm-last" }, `Raised during trip ${last.trip}: ${alarmList(last).join(", ")}`));
}

// ---- preload trend ---------------------------------------------------------------
function axes(ctx, W, H, m, xr, yr, xlabel, ylabel, yfmt) {
  ctx.strokeStyle = "#999";
  ctx.fillStyle = "#444";
  ctx.font = "11px sans-serif";
  ctx.strokeRect(m.l, m.t, W - m.l - m.r, H - m.t - m.b);
  ctx.textAlign = "center";
  ctx.fillText(xlabel, (m.l + W - m.r) / 2, H - 4);
  ctx.save();
  ctx.translate(12, (m.t + H - m.b) / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.fillText(ylabel, 0, 0);
  ctx.restore();
  for (let k = 0; k <= 4; k++) {
    const yv = yr[0] + ((yr[1] - yr[0]) * k) / 4;
    const y = m.t + (H - m.t - m.b) * (1 - k / 4);
    ctx.textAlign = "right";
    ctx.fillText(yfmt(yv), m.l - 4, y + 4);
  }
  const xt = Math.max(1, Math.ceil((xr[1] - xr[0]) / 10));
  ctx.textAlign = "center";
  for (let x = Math.ceil(xr[0]); x <= xr[1]; x += xt)
    ctx.fillText(String(x), m.l + ((x - xr[0]) / (xr[1] - xr[0])) * (W - m.l - m.r), H - m.b + 14);
}

function drawTrend(cv, trend, th) {
  const ctx = cv.getContext("2d");
  const W = cv.width, H = cv.height, m = { l: 52, r: 12, t: 12, b: 34 };
  ctx.clearRect(0, 0, W, H);
  const pts = trend.filter((t) => Number.isInteger(t.trip));
  const ident = pts.filter((t) => num(t.s) && num(t.sigma));
  setAttr(cv, "data-points", String(ident.length));
  let ymax = 1.3;
  for (const t of ident) ymax = Math.max(ymax, Math.min(3, t.s + t.sigma));
  const xr = pts.length ? [pts[0].trip - 0.5, pts[pts.length - 1].trip + 0.5] : [0, 1];
  const yr = [0, ymax];
  const X = (x) => m.l + ((x - xr[0]) / (xr[1] - xr[0])) * (W - m.l - m.r);
  const Y = (y) => m.t + (1 - (Math.min(Math.max(y, yr[0]), yr[1]) - yr[0]) / (yr[1] - yr[0])) * (H - m.t - m.b);
  axes(ctx, W, H, m, xr, yr, "trip", "preload scale s", (v) => fix(v, 1));
  // the combined estimate's 95 % band and line
  const comb = pts.filter((t) => num(t.combined) && num(t.combined_sigma));
  if (comb.length) {
    ctx.fillStyle = "rgba(31, 78, 156, 0.18)";
    ctx.beginPath();
    comb.forEach((t, i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, X(t.trip), Y(t.combined + 1.96 * t.combined_sigma)));
    for (let i = comb.length - 1; i >= 0; i--) ctx.lineTo(X(comb[i].trip), Y(comb[i].combined - 1.96 * comb[i].combined_sigma));
    ctx.closePath();
    ctx.fill();
    ctx.strokeStyle = "#1f4e9c";
    ctx.lineWidth = 2;
    ctx.beginPath();
    comb.forEach((t, i) => (i ? ctx.lineTo : ctx.moveTo).call(ctx, X(t.trip), Y(t.combined)));
    ctx.stroke();
    ctx.lineWidth = 1;
  }
  // thresholds and nominal
  const hline = (v, color, label, dash) => {
    if (!num(v)) return;
    ctx.strokeStyle = color;
    ctx.setLineDash(dash);
    ctx.beginPath();
    ctx.moveTo(m.l, Y(v));
    ctx.lineTo(W - m.r, Y(v));
    ctx.stroke();
    ctx.setLineDash([]);
    ctx.fillStyle = color;
    ctx.textAlign = "left";
    ctx.fillText(label, m.l + 4, Y(v) - 3);
  };
  hline(1, "#808080", "nominal", [2, 3]);
  hline(th.warning, "#d08000", `preload_warning ${fmt(th.warning, 2)}`, [6, 4]);
  hline(th.critical, "#c00000", `preload_critical ${fmt(th.critical, 2)}`, [6, 4]);
  // each trip: s ± sigma (informative filled, the others hollow grey)
  for (const t of ident) {
    const x = X(t.trip), color = t.informative ? "#1f4e9c" : "#909090";
    ctx.strokeStyle = color;
    ctx.beginPath();
    ctx.moveTo(x, Y(t.s - t.sigma));
    ctx.lineTo(x, Y(t.s + t.sigma));
    ctx.stroke();
    ctx.beginPath();
    ctx.arc(x, Y(t.s), 3, 0, 2 * Math.PI);
    if (t.informative) { ctx.fillStyle = color; ctx.fill(); } else ctx.stroke();
  }
  if (!ident.length) {
    ctx.fillStyle = "#666";
    ctx.textAlign = "center";
    ctx.fillText("no trip with an identified preload", W / 2, H / 2);
  }
}

// ---- depth x trip heat map ---------------------------------------------------------
const heatColor = (f) => {  // 0..1 -> light to dark orange-brown (as hoist-trips depth-map)
  const a = [255, 245, 235], b = [253, 141, 60], c = [127, 39, 4];
  const [p, q, u] = f < 0.5 ? [a, b, f * 2] : [b, c, (f - 0.5) * 2];
  return `rgb(${p.map((v, i) => Math.round(v + (q[i] - v) * u)).join(",")})`;
};

function drawHeat(cv, hm) {
  const ctx = cv.getContext("2d");
  const W = cv.width, H = cv.height, m = { l: 52, r: 70, t: 12, b: 34 };
  ctx.clearRect(0, 0, W, H);
  const trips = Array.isArray(hm.trips) ? hm.trips : [], depths = Array.isArray(hm.depths) ? hm.depths : [];
  const cells = Array.isArray(hm.cells) ? hm.cells : [];
  const bin = num(hm.bin) && hm.bin > 0 ? hm.bin : 10;
  let lo = Infinity, hi = -Infinity, n = 0;
  for (const row of cells) for (const v of Array.isArray(row) ? row : []) if (num(v)) { lo = Math.min(lo, v); hi = Math.max(hi, v); n++; }
  setAttr(cv, "data-cells", String(n));
  if (!n || !trips.length || !depths.length) {
    axes(ctx, W, H, m, [0, 1], [0, 1], "trip", "depth [m]", () => "");
    ctx.fillStyle = "#666";
    ctx.textAlign = "center";
    ctx.fillText("no trips with depth bins", W / 2, H / 2);
    return;
  }
  if (hi <= lo) hi = lo + 1e-9;
  const xr = [trips[0] - 0.5, trips[trips.length - 1] + 0.5];
  const d0 = depths[0], d1 = depths[depths.length - 1] + bin;
  const X = (x) => m.l + ((x - xr[0]) / (xr[1] - xr[0])) * (W - m.l - m.r);
  const Y = (d) => m.t + ((d - d0) / (d1 - d0)) * (H - m.t - m.b);  // depth grows downwards
  cells.forEach((row, i) => {
    if (!Array.isArray(row) || !Number.isInteger(trips[i])) return;
    row.forEach((v, k) => {
      if (!num(v) || !num(depths[k])) return;
      ctx.fillStyle = heatColor((v - lo) / (hi - lo));
      ctx.fillRect(X(trips[i] - 0.5), Y(depths[k]), Math.max(1, X(trips[i] + 0.5) - X(trips[i] - 0.5)), Math.max(1, Y(depths[k] + bin) - Y(depths[k])));
    });
  });
  // axes: depth labels top (d0) to bottom (d1)
  axes(ctx, W, H, m, xr, [d1, d0], "trip", "depth [m]", (v) => fix(v, 0));
  // colour bar
  const bx = W - m.r + 14, bh = H - m.t - m.b;
  for (let k = 0; k < bh; k++) {
    ctx.fillStyle = heatColor(1 - k / bh);
    ctx.fillRect(bx, m.t + k, 12, 1);
  }
  ctx.fillStyle = "#444";
  ctx.textAlign = "left";
  ctx.fillText(fix(hi, 3), bx + 14, m.t + 8);
  ctx.fillText(fix(lo, 3), bx + 14, m.t + bh);
  ctx.save();
  ctx.translate(bx + 26, m.t + bh / 2);
  ctx.rotate(-Math.PI / 2);
  ctx.textAlign = "center";
  ctx.fillText("residual RMS [m/s²]", 0, 0);
  ctx.restore();
}

// ---- the last trip's record ---------------------------------------------------------
function renderLast(r) {
  const box = $("#cond-last");
  box.replaceChildren();
  if (!r) {
    box.append(el("p", {}, "No trip recorded yet."));
    return;
  }
  const dir = r.direction === 1 ? "down" : r.direction === -1 ? "up" : "?";
  const fields = [
    ["trip", "Trip", String(r.trip)],
    ["direction", "Direction", dir],
    ["wall_start", "Departure", iso(r.wall_start_us)],
    ["wall_end", "Arrival", iso(r.wall_end_us)],
    ["depth", "Depth [m]", `${fmt(r.depth_start, 1)} → ${fmt(r.depth_end, 1)}`],
    ["peak_speed", "Peak |v| / |a|", `${fmt(r.peak_speed, 2)} m/s, ${fmt(r.peak_accel, 2)} m/s²`],
    ["Fa", "Fa at arrival [N]", pm(r.fa_end, r.sigma_fa_end, 0)],
    ["moment", "M at arrival [N m]", pm(r.moment_end, r.sigma_moment_end, 0)],
    ["preload_scale", "Preload scale s", r.id_attempted ? pm(r.id_scale, r.id_sigma_scale, 3) : "not attempted"],
    ["informative", "Informative", r.id_attempted ? (r.id_informative ? "yes" : `no${r.id_note ? ` (${r.id_note})` : ""}`) : "–"],
    ["imbalance", "Guide-rope imbalance", pm(r.id_imbalance, r.id_sigma_imbalance, 3)],
    ["mismatch", "MODEL_MISMATCH", r.mismatch ? "yes" : "no"],
    ["nis_peak", "NIS peak / constancy peak", `${fmt(r.nis_peak, 2)} / ${fmt(r.constancy_peak, 2)}`],
    ["min_clearance", "Min clearance", `${fmt(r.min_clearance * 1000, 1)} mm at ${fmt(r.min_clearance_depth, 1)} m`],
    ["alarms", "Alarms raised", alarmList(r).length ? alarmList(r).join(", ") : "none"],
  ];
  const t = el("table", { class: "cond-record" });
  for (const [key, label, value] of fields) t.append(el("tr", {}, el("th", {}, label), el("td", { "data-field": key }, value)));
  box.append(el("h3", {}, `Last trip: ${r.trip}`), t);
  const cols = [["depth_lo", "depth [m]", 1], ["samples", "samples", 0], ["fy_rms", "f_y RMS", 4], ["fy_hf_rms", "f_y above band", 4],
                ["resid_mean", "residual mean", 4], ["resid_rms", "residual RMS", 4], ["y_c_rms", "y_c RMS [m]", 5],
                ["theta_rms", "θ RMS [rad]", 6]];
  const bt = el("table", { id: "cond-bins", class: "cond-bins" });
  bt.append(el("thead", {}, el("tr", {}, ...cols.map(([, h]) => el("th", {}, h)))));
  const tb = el("tbody");
  for (const b of Array.isArray(r.bins) ? r.bins : [])
    tb.append(el("tr", {}, ...cols.map(([k, , d]) => el("td", {}, fmt(b[k], d)))));
  bt.append(tb);
  box.append(el("h3", {}, `Depth bins (${fmt(r.depth_bin, 1)} m)`), bt);
}

poll();

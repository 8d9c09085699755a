// hoist-dash page: small DOM and number helpers (no state).
import { alarm_t } from "./hoist_msgs.js";

// alarm_t.level's name (NONE, WARNING, CRITICAL), the number for a value without one.
export const levelName = (v) => alarm_t.LEVEL_NAMES[v - alarm_t.LEVEL_FIRST] ?? String(v);
export const EVENT_RAISE = alarm_t.EVENT_FIRST + alarm_t.EVENT_NAMES.indexOf("RAISE");

export const $ = (sel, root = document) => root.querySelector(sel);
export const el = (tag, attrs = {}, ...kids) => {
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
export const fix = (x, d) => {
  const t = Number(x).toFixed(d);
  return /^-0\.?0*$/.test(t) ? t.slice(1) : t;
};
export const num = (x) => typeof x === "number" && isFinite(x);
// Text and attributes are written only when they change (no DOM mutation
// without a change: the alarm rows' MutationObserver test counts them).
export const setText = (e, t) => { if (e.textContent !== t) e.textContent = t; };
export const setAttr = (e, k, v) => { if (e.getAttribute(k) !== v) e.setAttribute(k, v); };
export const clock = (utime) => new Date(utime / 1000).toLocaleTimeString([], { hour12: false });
export const toast = (msg, err = false) => {
  const d = el("div", { class: err ? "err" : "" }, msg);
  $("#toast").append(d);
  setTimeout(() => d.remove(), err ? 8000 : 4000);
  while ($("#toast").children.length > 5) $("#toast").firstChild.remove();
};

// A trend's columns (x and its series, by key) kept in time order (a
// restarted daemon's time goes back: its older points go) and to the last
// `keepS` seconds.
export function keepWindow(D, keepS) {
  const n = D.x.length;
  if (n > 1 && D.x[n - 1] < D.x[n - 2]) for (const k of Object.keys(D)) D[k].splice(0, n - 1);
  const tmin = D.x[D.x.length - 1] - keepS;
  let cut = 0;
  while (cut < D.x.length && D.x[cut] < tmin) cut++;
  if (cut > 0) for (const k of Object.keys(D)) D[k].splice(0, cut);
}

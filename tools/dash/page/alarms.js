// hoist-dash page: the ISA-18.2 alarm list and the operator commands.
import { ALARM_UNITS } from "./alarm_units.js";
import { state, userInput } from "./state.js";
import { levelName, EVENT_RAISE, $, el, fix, setText, setAttr, clock, toast } from "./util.js";
import { isOpen } from "./main.js";

// ---- alarms (ISA-18.2 states) ---------------------------------------------------
// One row per alarm identity (kind, level), created when the alarm enters
// the list and updated in place until it leaves: no row node is replaced
// while its alarm lives, so a click between mouse-down and mouse-up always
// lands on the row the operator pressed (docs/dashboard.md).
export function onAlarm(s, a) {
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
export function onInstance(s, h) {
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

export function stateText(a) {
  if (a.shelved) return "SHELVED";
  if (a.active && !a.acked) return a.latched ? "UNACK · LATCHED" : "UNACK";
  if (a.active && a.acked) return a.latched ? "ACKED · LATCHED" : "ACKED";
  if (!a.active && !a.acked) return "RTN UNACK";
  return "NORMAL";
}

// Value against threshold in the unit of the alarm's kind, from the one
// table beside the contract (msgs/contract/alarm_units.json -> alarm_units.js).
// A kind the table does not know is shown without a unit, never a wrong one.
export function fmtVal(a) {
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
// first: a new alarm is added below, rows above never move), then kind.  A
// listed row keeps the activation it entered the list with (an RTN UNACK
// alarm raised again keeps its place: a row never moves while it lives).
export function alarmOrder(s) {
  const since = (a) => s.rows.get(`${a.kind}/${a.level}`)?.since ?? a.dash_activation_utime;
  return (a, b) => (b.level - a.level) || (since(a) - since(b)) || (a.kind < b.kind ? -1 : a.kind > b.kind ? 1 : 0);
}
export const alarmName = (a) => `${a.kind} ${levelName(a.level)}`;
export const activeSince = (a) => `${a.dash_activation_known === false ? "before " : ""}${clock(a.dash_activation_utime)}`;
export const listed = (a) => a.active || !a.acked || a.shelved;


export function makeRow(s, key) {
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
export function rowButtons(s, row) {
  const want = !state.readOnly;
  if (want === (row.c.buttons !== null)) return;
  if (!want) { row.c.btns.textContent = ""; row.c.buttons = null; return; }
  const mk = (label, action) => el("button", { "data-action": label.toLowerCase(),
    onclick: () => { const a = s.alarms.get(row.key); if (a) command(s, identityOf(a), action, label); } }, label);
  row.c.buttons = { ack: mk("Acknowledge", 1), shelve: mk("Shelve", 2), unshelve: mk("Unshelve", 3) };
  row.c.btns.append(row.c.buttons.ack, row.c.buttons.shelve, row.c.buttons.unshelve);
}

export const identityOf = (a) => ({ kind: a.kind, level: a.level, activation: a.dash_activation_utime, server: a.serverIdentity,
                             name: alarmName(a), since: activeSince(a), rtn: !a.active ? clock(a.rtnUtime || a.utime) : "" });

export function updateRow(s, row, a) {
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
export function renderAlarms(s) {
  const body = s.alarmsBody;
  const alarms = [...s.alarms.values()].filter(listed).sort(alarmOrder(s));
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
    if (!row) { row = makeRow(s, key); row.since = a.dash_activation_utime; s.rows.set(key, row); }
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

export function command(s, ident, action, label) {
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

// hoist-dash page: the accelerometer's live calibration, a form in the
// load-estimate panel (alarm_ack_t ACTION_CALIBRATE; docs/service.md "The
// live calibration command", docs/estimation.md "Calibration").  The operator
// declares the load known for a while -- the empty conveyance at the bank, or
// a test weight at a known offset -- and the estimator learns the
// accelerometer's offset from it and keeps it.  The page checks only that the
// fields are numbers: hoist-dash applies the daemon's own rule
// (hoist::contract) before anything is published, and its answer ("sent
// calibrate: ..." or "rejected command: ..." with the bounds) comes back as
// a status.  Not made for a read-only server's page (hidden with class "cmd"
// besides), as the alarm commands are not.
import { state, userInput } from "./state.js";
import { $, el, num, setText, toast } from "./util.js";
import { isOpen } from "./main.js";

export const ACTION_CALIBRATE = 5;  // alarm_ack_t.ACTION_CALIBRATE (msgs/alarm_ack_t.lcm)

// The form: known payload Fa [N], its offset b [m], how long [s].
export function makeCalibrationForm(prefix) {
  const field = (name, label, value, unit, attrs = {}) =>
    el("label", {}, `${label} `, el("input", { "data-field": `cal-${name}`, type: "number", value, step: "any", ...attrs }),
       ` ${unit}`);
  const form = el("form", { class: "cmd calibrate", "data-role": "calibrate" },
    el("h3", {}, "Calibrate the accelerometer ",
       el("span", { class: "sub" }, "(declare the load known: the empty conveyance, or a test weight)")),
    field("fa", "payload Fa", "0", "N", { min: "0" }),
    field("b", "at offset b", "0", "m"),
    field("duration", "for", "30", "s", { min: "1" }),
    el("button", { type: "submit", "data-action": "calibrate" }, "Calibrate"));
  form.addEventListener("submit", (ev) => { ev.preventDefault(); calibrate(prefix, form); });
  return form;
}

// estimate_t.calibrating: a declared load is in force (shown on every page,
// read-only too: the note is the panel's, not the form's).
export function renderCalibrating(box, e) {
  const on = e.calibrating === true;
  const note = $('[data-field="est-calibrating"]', box);
  note.dataset.state = on ? "calibrating" : "idle";
  setText(note, on ? "CALIBRATING: the declared load is in force; the estimator is learning the accelerometer's offset" : "");
}

export function calibrate(prefix, form) {
  const user = userInput.value.trim();
  if (!user) { toast("Enter your name (Operator) before calibrating.", true); userInput.focus(); return; }
  const value = (name) => Number($(`[data-field="cal-${name}"]`, form).value);
  const fa = value("fa"), b = value("b"), duration = value("duration");
  if (![fa, b, duration].every(num)) { toast("Calibration: Fa, b and the duration must be numbers.", true); return; }
  const cid = state.ackChannels.get(prefix);
  if (cid === undefined) { toast("No command channel for this shaft (read-only server?)", true); return; }
  const where = prefix || "the default shaft";
  if (!window.confirm(`Calibrate the accelerometer of ${where}: the load is known, Fa = ${fa} N at b = ${b} m, ` +
                      `for the next ${duration} s?\nOnly with the conveyance empty or a test weight at that offset: ` +
                      `the estimator takes it as the truth.`)) return;
  if (!isOpen()) { toast("Not connected: the calibration was not sent", true); return; }
  const cmd = { utime: 0, kind: "", level: 0, action: ACTION_CALIBRATE, shelve_duration: 0, user,
                known_fa: fa, known_b: b, calibrate_duration: duration };
  state.client.sendMessage(cid, new TextEncoder().encode(JSON.stringify(cmd)));
}

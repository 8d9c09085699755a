#!/usr/bin/env python3
"""Checks a soak run (scripts/soak.sh) and writes its report.

  soak_check.py DIR --sent N --warmup S --rss-bound-kb K --max-miss-frac F
                [--storm-frac F] [--duration S] [--label TEXT]

DIR holds rss.csv (uptime_s,rss_kb) and csv/ (hoist-log2csv of the run's
HOIST_HEALTH, HOIST_ALARM and HOIST_WINDER).  Checks:
  * RSS flat: after the warm-up, max RSS - RSS at the end of warm-up <= bound;
  * counters add up: accepted + rejected == inputs seen on the wire (the
    logger's HOIST_WINDER count), the shortfall from the number sent is
    explained by sequence gaps, and every rejection has a reason;
  * health kept coming (no gap > 3 s) and counters never went down;
  * every alarm RAISE is followed by its CLEAR or is still active at the end,
    and the final number of active alarms matches HOIST_HEALTH;
  * no NaN: no non-finite value withheld, no model fault, no publish failure;
  * no deadline-miss storm: total misses <= max_miss_frac of ticks and no
    health window with more than storm_frac of its ticks missed.
Exit status 0 when every check passed, 1 otherwise (report.md says why).
"""
import argparse
import csv
import math
import os
import sys


def read_csv(path):
    if not os.path.exists(path):
        return []
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--sent", type=int, required=True)
    ap.add_argument("--warmup", type=float, default=30.0)
    ap.add_argument("--rss-bound-kb", type=float, default=2048.0)
    ap.add_argument("--max-miss-frac", type=float, default=0.005)
    ap.add_argument("--storm-frac", type=float, default=0.2)
    ap.add_argument("--duration", type=float, default=0.0)
    ap.add_argument("--label", default="")
    ap.add_argument("--timing-informational", action="store_true",
                    help="report the deadline-miss checks as INFO instead of failing on them "
                         "(CTest's 2-minute soak on shared, noisy machines: timing belongs to "
                         "bench/rt_report.sh and the timing test, not to a unit test)")
    a = ap.parse_args()

    fails, lines = [], []

    def check(ok, what):
        lines.append(("PASS " if ok else "FAIL ") + what)
        if not ok:
            fails.append(what)

    # --- RSS
    rss = [(float(r["uptime_s"]), float(r["rss_kb"])) for r in read_csv(os.path.join(a.dir, "rss.csv"))]
    after = [x for x in rss if x[0] >= a.warmup]
    rss_first = rss[0][1] if rss else float("nan")
    if after:
        base = after[0][1]
        peak = max(r for _, r in after)
        last = after[-1][1]
        growth = peak - base
        check(growth <= a.rss_bound_kb,
              "RSS flat after %.0f s warm-up: %.0f kB at warm-up, peak %.0f kB, end %.0f kB "
              "(growth %.0f kB, bound %.0f kB; %d samples; %.0f kB at start)"
              % (a.warmup, base, peak, last, growth, a.rss_bound_kb, len(rss), rss_first))
    else:
        check(False, "RSS samples after the warm-up (none recorded)")

    # --- health
    health = read_csv(os.path.join(a.dir, "csv", "HOIST_HEALTH.csv"))
    check(len(health) > 0, "HOIST_HEALTH recorded (%d messages)" % len(health))
    if not health:
        write(a, lines, fails)
        return
    H = health[-1]
    num = lambda r, k: float(r[k])
    gaps = [(float(health[i]["utime"]) - float(health[i - 1]["utime"])) * 1e-6 for i in range(1, len(health))]
    check(max(gaps or [0]) <= 3.0, "health kept coming: largest gap between reports %.2f s" % max(gaps or [0]))
    mono_keys = ["ticks", "steps", "accepted", "rejected_total", "seq_gaps", "alarm_events",
                 "deadline_misses", "publish_failures", "nonfinite_blocked", "model_faults"]
    decreasing = [k for k in mono_keys for i in range(1, len(health))
                  if num(health[i], k) < num(health[i - 1], k)]
    check(not decreasing, "counters never decrease" + (" (%s did)" % sorted(set(decreasing)) if decreasing else ""))
    nan_fields = [k for r in health for k, v in r.items() if v in ("nan", "-nan", "inf", "-inf")]
    check(not nan_fields, "no NaN/Inf in any health field")

    accepted, rejected, seq_gaps = int(H["accepted"]), int(H["rejected_total"]), int(H["seq_gaps"])
    reasons = {k[len("rejected_"):]: int(v) for k, v in H.items() if k.startswith("rejected_") and k != "rejected_total"}
    check(sum(reasons.values()) == rejected,
          "rejections by reason add up: %s = %d" % (
              ", ".join("%s %d" % kv for kv in reasons.items() if kv[1]) or "none", rejected))
    winder = read_csv(os.path.join(a.dir, "csv", "HOIST_WINDER.csv"))
    seen = len(winder)
    check(accepted + rejected <= a.sent,
          "accepted %d + rejected %d <= sent %d" % (accepted, rejected, a.sent))
    lost = a.sent - accepted - rejected
    check(lost <= seq_gaps + 1 and lost >= 0,
          "every input accounted for: sent %d = accepted %d + rejected %d + lost %d "
          "(daemon counted %d sequence gaps; the logger saw %d inputs)"
          % (a.sent, accepted, rejected, lost, seq_gaps, seen))

    # --- alarms
    alarms = read_csv(os.path.join(a.dir, "csv", "HOIST_ALARM.csv"))
    state, raises, clears, bad_order = {}, 0, 0, []
    for r in alarms:
        key = (r["kind"], r["level"])
        if r["event"] == "RAISE":
            raises += 1
            if state.get(key):
                bad_order.append("%s raised twice" % (key,))
            state[key] = True
        elif r["event"] == "CLEAR":
            clears += 1
            if not state.get(key):
                bad_order.append("%s cleared while not active" % (key,))
            state[key] = False
    still = sorted("%s/%s" % k for k, v in state.items() if v)
    check(not bad_order, "alarm raise/clear alternate per kind and level (%d raises, %d clears)"
          % (raises, clears) + ("; " + "; ".join(bad_order[:5]) if bad_order else ""))
    check(raises - clears == len(still) == int(H["alarms_active"]),
          "every raise has a clear or is still active: %d raises - %d clears = %d active at the end %s; "
          "HOIST_HEALTH says %s" % (raises, clears, len(still), still, H["alarms_active"]))
    check(int(H["alarm_events"]) >= len(alarms),
          "alarm events published %s >= recorded %d" % (H["alarm_events"], len(alarms)))

    # --- no NaN, faults, publish failures
    check(int(H["nonfinite_blocked"]) == 0 and int(H["model_faults"]) == 0,
          "no non-finite output withheld (%s), no model fault (%s)" % (H["nonfinite_blocked"], H["model_faults"]))
    check(int(H["publish_failures"]) == 0, "no LCM publish failure (%s)" % H["publish_failures"])

    # --- deadline misses
    ticks, misses = int(H["ticks"]), int(H["deadline_misses"])
    storms = []
    for i in range(1, len(health)):
        dt = int(health[i]["ticks"]) - int(health[i - 1]["ticks"])
        dm = int(health[i]["deadline_misses"]) - int(health[i - 1]["deadline_misses"])
        if dt + dm > 0 and dm > a.storm_frac * (dt + dm):
            storms.append((float(health[i]["uptime"]), dm, dt))
    frac = misses / max(1, ticks + misses)

    def timing_check(ok, what):
        if a.timing_informational:
            lines.append("INFO (timing, not judged here) " + ("within: " if ok else "outside: ") + what)
        else:
            check(ok, what)

    timing_check(frac <= a.max_miss_frac,
                 "deadline misses %d of %d ticks (%.4f %%, bound %.3f %%)" % (misses, ticks, 100 * frac, 100 * a.max_miss_frac))
    timing_check(not storms, "no deadline-miss storm (window with > %.0f %% missed): %s"
                 % (100 * a.storm_frac, storms[:5] if storms else "none"))
    p99 = max(float(r["step_p99_us"]) for r in health)
    smax = max(float(r["step_max_us"]) for r in health)
    lmax = max(float(r["late_max_us"]) for r in health)
    lines.append("INFO uptime %.0f s, model time %.1f s, %d steps; worst window step p99 %.0f us, "
                 "step max %.0f us, tick lateness max %.0f us"
                 % (float(H["uptime"]), float(H["t"]), int(H["steps"]), p99, smax, lmax))
    write(a, lines, fails)


def write(a, lines, fails):
    path = os.path.join(a.dir, "report.md")
    with open(path, "w") as f:
        f.write("# Soak report %s\n\n" % a.label)
        f.write("Result: **%s**\n\n" % ("PASS" if not fails else "FAIL (%d checks)" % len(fails)))
        for l in lines:
            f.write("- " + l + "\n")
    print(open(path).read())
    sys.exit(1 if fails else 0)


if __name__ == "__main__":
    main()

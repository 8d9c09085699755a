#!/usr/bin/env python3
"""Markdown report of bench/multishaft.sh: twins per core.

  multishaft_report.py [--command C] [--seconds S] [--max-step S] [--same-url 0|1] [--out-dir D]
                       NAME MODES:on|off N DAEMON.json TIMING.md CPU%/STEAL [...]

Each row is one run: daemon NAME (a label of the binary), the setting (modes
and static correction), N twins, the daemon's --report JSON, the timing
test's report, and the process CPU % / steal seconds measured by the script."""
import argparse
import json
import os
import platform
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rt_report import cpu_model, fmt_us, load_report, verdict  # noqa: E402

PHASES = [("model_step", "model step"), ("envelope", "envelope"), ("publish", "LCM publish"),
          ("receive", "LCM receive"), ("tick_other", "rest of the tick"), ("timer_and_rest", "timer, kernel, rest")]


MISS_PHASES = [("receive", "receive"), ("step", "step"), ("envelope", "envelope"), ("publish", "publish"),
               ("forecast", "forecast"), ("start", "start"), ("health", "health"), ("other", "other"),
               ("timer", "timer")]


def worst_miss_text(r):
    """The worst recorded miss of a run report and the split of the loop's time
    before it (the daemon's miss record), in one short cell; "" when the
    report has no miss record or no miss."""
    m = (r or {}).get("misses")
    if not m or not m.get("worst"):
        return ""
    w = m["worst"]
    sp = w.get("split_us", {})
    parts = [f"{lbl} {fmt_us(sp[k])}" for k, lbl in MISS_PHASES if sp.get(k, 0) >= 1.0]
    kept = f"{m.get('kept', '?')} kept" + (f", {m['dropped']} dropped" if m.get("dropped") else "")
    cpu = w.get("cpu_us", -1)
    cpu_txt = f"; loop thread CPU {fmt_us(cpu)}" if cpu is not None and cpu >= 0 else ""
    return (f"worst: tick {w.get('tick', '?')} at t = {w.get('model_t', 0):.2f} s, {fmt_us(w.get('late_us', float('nan')))} "
            f"late, {w.get('shafts_late', '?')}/{w.get('shafts', '?')} shafts; " + ", ".join(parts) + cpu_txt +
            f" ({kept})")


def bare_cell(b):
    if not b:
        return "—"
    return f"{b.get('deadline_misses', '?')} / {fmt_us(b.get('late_us', {}).get('max', float('nan')))}"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--command", default="")
    ap.add_argument("--seconds", default="")
    ap.add_argument("--max-step", default="")
    ap.add_argument("--same-url", default="0")
    ap.add_argument("--feeder-rt", default="0")
    ap.add_argument("--out-dir", default=".")
    ap.add_argument("--row-summary", metavar="JSON",
                    help="print one line for the run report JSON (misses and the worst miss's split) and exit")
    ap.add_argument("items", nargs="*")
    a = ap.parse_args()
    if a.row_summary:
        try:
            r = load_report(a.row_summary)
        except (OSError, ValueError) as e:
            print(f"no run report ({e})")
            return
        misses = sum(s["health"]["deadline_misses"] for s in r.get("shafts", []))
        print(f"deadline misses {misses}" + (f"; {worst_miss_text(r)}" if worst_miss_text(r) else ""))
        return
    if not a.items:
        sys.exit("multishaft_report.py: no runs given")
    if len(a.items) % 6:
        sys.exit("multishaft_report.py: arguments come in sextuples NAME SETTING N JSON MD CPU/STEAL")
    rows = []
    for i in range(0, len(a.items), 6):
        name, setting, n, js, md, cpu_steal = a.items[i:i + 6]
        try:
            r = load_report(js)
        except (OSError, ValueError):
            r = None
        cpu, _, steal = cpu_steal.partition("/")
        try:   # the bare-machine watcher of that run (hoist-wakeup-latency on the daemon's CPU)
            with open(md.replace(".timing.md", ".bare.json")) as f:
                bare = json.load(f)
        except (OSError, ValueError):
            bare = None
        rows.append(dict(name=name, setting=setting, n=int(n), r=r, md=md, cpu=float(cpu), steal=steal, bare=bare))
    first = next((x["r"] for x in rows if x["r"]), {})
    daemons = list(dict.fromkeys(x["name"] for x in rows))
    out = ["# Twins per core", ""]
    out.append(f"Produced by `{a.command.strip()}` on {first.get('date', '?')}; host `{first.get('host', '?')}`, "
               f"{cpu_model()}, {first.get('cpus_online', '?')} CPUs online, Linux {platform.release()}.  "
               f"Daemons compared side by side (each row of one count run one after the other): "
               + ", ".join(f"`{d}`" for d in daemons) + ".")
    out.append("")
    rt = first.get("realtime", {})
    out.append("One `hoist-twind` process hosts N shafts (100 Hz; every output on: HOIST_CAGE every step, "
               "HOIST_GUIDE_SHAPE at 5 Hz, HOIST_HEALTH at 1 Hz, alarms), **the whole process pinned to one CPU**, "
               "fed N winder streams at the step rate by `hoist-replay --timing-test --shafts N` on another CPU"
               + (" (with SCHED_FIFO 50). " if a.feeder_rt == "1" else ". ") +
               f"Real-time settings: memory lock {rt.get('memory_lock', '?')}, scheduling {rt.get('scheduling', '?')}, "
               f"affinity {rt.get('affinity', '?')}.  `[service] max_step` = {a.max_step} s (one model step per "
               f"tick).  {a.seconds} s per row.  "
               + ("Outputs on the input URL." if a.same_url == "1" else
                  "Outputs on a separate URL (`[service] lcm_url_out`, the next port), so the daemon's input socket "
                  "carries only inputs.")
               + "  Lateness is measured at the start of each shaft's own step, so it includes the work of the "
               "shafts stepped before it in the same tick.")
    out.append("")
    out.append("| setting | twins | daemon | deadline misses (worst miss: split of the loop's time before it) | worst lateness p99 / max | step p50 / p99 | CPU used "
               "| steal | inputs lost (seq. gaps) | of which rejected | kernel drops | bare machine: misses / max late "
               "| timing test |")
    out.append("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for x in rows:
        r = x["r"]
        setting = f"n = {x['setting'].replace(':', ', correction ')}"
        if not r:
            out.append(f"| {setting} | {x['n']} | {x['name']} | (no report) | | | {x['cpu']:.0f} % | {x['steal']} s | | | | | |")
            continue
        sh = r["shafts"]
        x["misses"] = sum(s["health"]["deadline_misses"] for s in sh)
        x["gaps"] = sum(s["health"]["seq_gaps"] for s in sh)
        rejected = sum(s["health"].get("rejected_total", 0) for s in sh)
        drops = r.get("input_socket", {}).get("kernel_drops")
        x["drops"] = drops or 0
        lp99 = max(s["late_us"]["p99"] for s in sh)
        lmax = max(s["late_us"]["max"] for s in sh)
        sp50 = sorted(s["step_us"]["p50"] for s in sh)[len(sh) // 2]
        sp99 = max(s["step_us"]["p99"] for s in sh)
        wm = worst_miss_text(r)
        out.append(f"| {setting} | {x['n']} | {x['name']} | **{x['misses']}**{' (' + wm + ')' if wm else ''} | "
                   f"{fmt_us(lp99)} / {fmt_us(lmax)} | "
                   f"{fmt_us(sp50)} / {fmt_us(sp99)} | {x['cpu']:.0f} % | {x['steal'] or '?'} s | **{x['gaps']}** | {rejected} | "
                   f"{'—' if drops is None else drops} | {bare_cell(x['bare'])} | {verdict(x['md'])} "
                   f"([report]({os.path.relpath(x['md'], a.out_dir)})) |")
    out.append("")
    # (A shaft with [forecast] enabled reports forecast_us; an old report, forecasts beside it.)
    fc_rows = [x for x in rows if x["r"] and any("forecast_us" in s or "forecasts" in s for s in x["r"]["shafts"])]
    if fc_rows:
        out.append("Forecasts (rows with `[forecast] enabled`; from the daemon's run report): done, snapshots the "
                   "workers never took (`dropped`: a newer one replaced it, i.e. the workers fell behind), "
                   "instants skipped (degraded state).")
        out.append("")
        for x in fc_rows:
            sh = x["r"]["shafts"]
            done = sum(s["health"].get("forecasts", 0) for s in sh)
            dropped = sum(s["health"].get("forecasts_dropped", 0) for s in sh)
            skipped = sum(s["health"].get("forecasts_skipped", 0) for s in sh)
            out.append(f"- {x['n']} twins, `{x['name']}`: {done} done ({done / max(1, len(sh)):.1f} per shaft), "
                       f"{dropped} dropped, {skipped} skipped")
        out.append("")
    out.append("\"CPU used\": the process's user + system time over the run (100 % = the whole core); \"steal\": "
               "time the hypervisor gave the daemon's virtual CPU to something else (`/proc/stat`); \"inputs "
               "lost\": sequence gaps seen by the daemon (every shaft's stream is contiguous; a rejected input, e.g. by "
               "the consistency check when a late feeder bunches its inputs, also leaves a gap: \"of which "
               "rejected\"); \"kernel drops\": "
               "datagrams the kernel dropped on the daemon's input socket because its buffer was full "
               "(SO_RXQ_OVFL; — where the daemon does not report it); \"bare machine\": a watcher thread on the "
               "daemon's CPU during the same run (`hoist-wakeup-latency`, same rate, SCHED_FIFO 90, no work): the "
               "ticks the machine itself woke up more than a period late, and its worst wake-up lateness.  A "
               "platform stall of more than a period makes every hosted shaft miss that tick (N misses per stall).  "
               "\"worst miss\": the daemon's miss record (`misses` in its run report): the tick that began latest in the run, how late, how "
               "many shafts began more than a period late, and where the loop's time went from the schedule's previous "
               "tick to it (receive, model step, envelope, publish, forecast hand-over, deferred starts, health, the rest "
               "of the tick, and timer: neither worked nor idle before the deadline, i.e. the wake-up, the kernel or a "
               "stall of the machine), and the loop thread's CPU time over the same interval (the phases are steady-clock "
               "spans: a thread preempted inside one counts the wait there, and its CPU time is then well below their "
               "sum); phases under 1 µs are left out.")
    out.append("")
    # Summary: per setting and daemon, the largest count that keeps up.
    out.append("## Twins per core")
    out.append("")
    out.append("A count **keeps up** when no input was lost and the deadline misses stay below 0.5 % of the "
               "twin-ticks: on this shared VM the vCPU itself stalls for tens of milliseconds now and then (every "
               "hosted shaft then misses the same tick, so misses come in multiples of N), which no daemon can "
               "avoid; an overloaded daemon misses thousands of ticks.  The last column extrapolates from the CPU "
               "the daemon used at that count.")
    out.append("")
    out.append("| setting | daemon | largest count that keeps up | its misses (platform stalls) | its CPU use | "
               "twins per core at that CPU use (N x 100 / CPU %) |")
    out.append("|---|---|---|---|---|---|")
    for setting in dict.fromkeys(x["setting"] for x in rows):
        for d in daemons:
            label = f"n = {setting.replace(':', ', correction ')}"
            ok = []
            for x in rows:
                if x["setting"] != setting or x["name"] != d or not x["r"]:
                    continue
                ticks = sum(s["health"]["ticks"] for s in x["r"]["shafts"])
                if x["gaps"] == 0 and ticks > 0 and x["misses"] < 0.005 * ticks:
                    ok.append(x)
            if not ok:
                out.append(f"| {label} | {d} | none of the counts run | | | |")
                continue
            best = max(ok, key=lambda x: x["n"])
            cap = best["n"] * 100.0 / best["cpu"] if best["cpu"] > 0 else float("nan")
            bm = best["bare"].get("deadline_misses", "?") if best["bare"] else "—"
            out.append(f"| {label} | {d} | **{best['n']}** | {best['misses']} ({best['misses'] / best['n']:.0f} "
                       f"per shaft; bare machine in that run: {bm}) | {best['cpu']:.0f} % | {cap:.0f} |")
    out.append("")
    # The daemon's own cost split (where it reports one).
    split_rows = [x for x in rows if x["r"] and "cost_split_us_per_twin_tick" in x["r"]]
    if split_rows:
        out.append("## Cost per twin and tick")
        out.append("")
        out.append("From the daemon's run report (`cost_split_us_per_twin_tick`: steady-clock time inside each "
                   "phase, divided by the twin-ticks; \"timer, kernel, rest\" is the process's CPU time minus "
                   "the measured phases: timer wake-ups, Asio, kernel work outside those calls, the log thread).  "
                   "µs per twin per tick; at 100 Hz, 300 twins per core need at most 33 µs.")
        out.append("")
        out.append("| setting | twins | daemon | " + " | ".join(p[1] for p in PHASES) +
                   " | total (process CPU) | envelope exact / all | deferred (longest, ticks) |")
        out.append("|---|---|---|" + "---|" * (len(PHASES) + 3))
        for x in split_rows:
            c = x["r"]["cost_split_us_per_twin_tick"]
            ev = c.get("envelope_exact", 0) + c.get("envelope_bounded", 0)
            frac = f"{100.0 * c.get('envelope_exact', 0) / ev:.1f} %" if ev else "—"
            dfr = (f"{c['envelope_deferred']} ({c.get('envelope_longest_deferral', '?')})"
                   if "envelope_deferred" in c else "—")
            out.append(f"| n = {x['setting'].replace(':', ', correction ')} | {x['n']} | {x['name']} | " +
                       " | ".join(f"{c.get(k, float('nan')):.2f}" for k, _ in PHASES) +
                       f" | {c.get('process_cpu', float('nan')):.2f} | {frac} | {dfr} |")
        out.append("")
    # perf profiles (bench/multishaft.sh --perf NAME): the largest count of each setting.
    for setting in dict.fromkeys(x["setting"] for x in rows):
        prof = [x for x in rows if x["setting"] == setting and os.path.exists(x["md"].replace(".timing.md", ".perf.txt"))]
        if not prof:
            continue
        x = max(prof, key=lambda y: y["n"])
        path = x["md"].replace(".timing.md", ".perf.txt")
        with open(path) as f:
            lines = [ln.strip() for ln in f if ln.strip()][:15]
        if not lines:
            continue
        out.append(f"## Profile: n = {setting.replace(':', ', correction ')}, {x['n']} twins, daemon `{x['name']}`")
        out.append("")
        out.append("`perf record -e cpu-clock` on the daemon for the middle half of the run, symbols above 1 % "
                   f"([all]({os.path.relpath(path, a.out_dir)})); `[k]` is the kernel.  On this virtual machine the "
                   "kernel's interrupt-enable at system-call entry (`pvm_irq_enable`) is where system calls cost.")
        out.append("")
        out.append("| share | where |")
        out.append("|---:|---|")
        for ln in lines:
            parts = ln.split(None, 2)
            if len(parts) < 3:
                continue
            sym = re.split(r"\s{2,}", parts[2].strip())[0].replace("|", "\\|")
            if len(sym) > 110:
                sym = sym[:107] + "..."
            out.append(f"| {parts[0]} | {parts[1]} `{sym}` |")
        out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Markdown real-time report from hoist-twind run reports (--report JSON) and
hoist-replay --timing-test reports.

  rt_report.py [--title T] [--minutes M] [--command C] TAG DAEMON.json TIMING.md [TAG JSON MD ...]

Used by bench/rt_report.sh and bench/multishaft.sh."""
import argparse
import json
import math
import os
import platform
import subprocess
import sys


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


# Reports written before the per-shaft counters moved under "health" (the
# final HOIST_HEALTH, health_t's names) kept them beside the histograms under
# other names; load_report() moves them there, so old runs still render.
_OLD_NAMES = {"ticks": "ticks", "steps": "steps", "deadline_misses": "deadline_misses",
              "inputs_accepted": "accepted", "inputs_rejected": "rejected_total", "sequence_gaps": "seq_gaps",
              "alarm_events": "alarm_events", "model_faults": "model_faults", "publish_failures": "publish_failures",
              "nonfinite_withheld": "nonfinite_blocked", "starts_deferred": "starts_deferred",
              "forecasts": "forecasts", "forecasts_dropped": "forecasts_dropped",
              "forecasts_skipped": "forecasts_skipped", "rate_hz": "rate", "clock": "clock"}


def load_report(path):
    """hoist-twind's run report (--report), every shaft with its "health"."""
    with open(path) as f:
        r = json.load(f)
    for s in r.get("shafts", []):
        if "health" not in s:
            s["health"] = {new: s[old] for old, new in _OLD_NAMES.items() if old in s}
    return r


def fmt_us(x):
    if x >= 1000:
        return f"{x / 1000:.2f} ms"
    if x >= 10:
        return f"{x:.0f} µs"
    return f"{x:.1f} µs"


def merged(bins, per_decade=5):
    """The histogram's bins (hoist::rt::LatencyHistogram, 100 per decade) -> `per_decade` bins: [(lower, upper, count)]."""
    out = {}
    for lower, count in bins:
        if lower <= 0:
            key = -1
        else:
            key = math.floor(math.log10(lower / 0.1) * per_decade + 1e-9)
        out[key] = out.get(key, 0) + count
    rows = []
    for key in sorted(out):
        if key < 0:
            rows.append((0.0, 0.1, out[key]))
        else:
            lo = 0.1 * 10 ** (key / per_decade)
            hi = 0.1 * 10 ** ((key + 1) / per_decade)
            rows.append((lo, hi, out[key]))
    return rows


def ascii_hist(h, width=50):
    rows = merged(h.get("bins", []))
    if not rows:
        return "(no samples)"
    total = sum(c for _, _, c in rows)
    # log-scaled bar lengths so one-in-a-million tail bins stay visible
    lmax = math.log10(max(c for _, _, c in rows) + 1)
    lines = []
    for lo, hi, c in rows:
        bar = "#" * max(1, int(round(width * math.log10(c + 1) / lmax)))
        lines.append(f"{fmt_us(lo):>9} - {fmt_us(hi):<9} {c:>10}  {100.0 * c / total:8.4f} %  {bar}")
    return "\n".join(lines)


def verdict(md_path):
    try:
        with open(md_path) as f:
            first = f.readline().strip()
        return first.replace("VERDICT:", "").strip() or "?"
    except OSError:
        return "(no timing-test report)"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--title", default="Real-time report")
    ap.add_argument("--minutes", default="")
    ap.add_argument("--command", default="")
    ap.add_argument("--out-dir", default=".", help="directory of the Markdown file (for relative links)")
    ap.add_argument("items", nargs="+")
    a = ap.parse_args()
    if len(a.items) % 3:
        sys.exit("rt_report.py: arguments come in triples TAG JSON MD")
    points = []
    for i in range(0, len(a.items), 3):
        tag, js, md = a.items[i:i + 3]
        points.append((tag, load_report(js), md))

    first = points[0][1]
    out = [f"# {a.title}", ""]
    out.append(f"Produced by `{a.command.strip()}` on {first.get('date', '?')}; host `{first.get('host', '?')}`, "
               f"{cpu_model()}, {first.get('cpus_online', '?')} CPUs online, Linux {platform.release()}.")
    out.append("")
    out.append(f"Real-time settings of the daemon: memory lock **{first['realtime']['memory_lock']}**, "
               f"scheduling **{first['realtime']['scheduling']}**, affinity **{first['realtime']['affinity']}**.")
    out.append("")
    out.append("Step time = one model step (with `[service].max_step` substeps) plus alarm evaluation, as "
               "timed by the daemon; tick lateness = start of a shaft's tick minus its deadline on the absolute "
               "schedule; a deadline miss = a whole period skipped.  Quantiles come from logarithmic histograms "
               "(100 bins per decade, about 1.2 % resolution).  The feeder (`hoist-replay --timing-test`) runs on "
               "another CPU and publishes the winder stream at the step rate over UDP multicast on loopback.")
    out.append("")
    out.append("| point | run | ticks | deadline misses | step p50 / p99 / p99.9 / max | lateness p50 / p99 / p99.9 / max | timing test |")
    out.append("|---|---|---|---|---|---|---|")
    for tag, r, md in points:
        for s in r["shafts"]:
            st, lt, h = s["step_us"], s["late_us"], s["health"]
            label = tag if len(r["shafts"]) == 1 else f"{tag} {s['label']}"
            out.append(
                f"| {label} ({h['rate']:g} Hz, n = {s['modes']}) | {r['duration_s'] / 60:.1f} min | {h['ticks']} | "
                f"**{h['deadline_misses']}** | {fmt_us(st['p50'])} / {fmt_us(st['p99'])} / {fmt_us(st['p999'])} / "
                f"{fmt_us(st['max'])} | {fmt_us(lt['p50'])} / {fmt_us(lt['p99'])} / {fmt_us(lt['p999'])} / "
                f"{fmt_us(lt['max'])} | {verdict(md)} ([report]({os.path.relpath(md, a.out_dir)})) |")
    base_rows = []
    for tag, r, md in points:
        bp = md.replace(".timing.md", ".baseline.json")
        if os.path.exists(bp):
            with open(bp) as f:
                b = json.load(f)
            lt = b["late_us"]
            base_rows.append(f"| {tag} ({b['rate_hz']:g} Hz, no work) | {b['seconds'] / 60:.1f} min | {b['ticks']} | "
                             f"**{b['deadline_misses']}** | - | {fmt_us(lt['p50'])} / {fmt_us(lt['p99'])} / "
                             f"{fmt_us(lt['p999'])} / {fmt_us(lt['max'])} | {b['scheduling']}, {b['affinity']} |")
    if base_rows:
        out.append("")
        out.append("**The bare machine**, measured just before each point with `hoist-wakeup-latency` (a "
                   "cyclictest-like loop: the same absolute schedule, the same CPU and real-time settings, no "
                   "work at all).  Wake-ups it gets late, the daemon gets late too:")
        out.append("")
        out.append("| point | run | ticks | deadline misses | - | lateness p50 / p99 / p99.9 / max | settings |")
        out.append("|---|---|---|---|---|---|---|")
        out.extend(base_rows)
    out.append("")
    for tag, r, md in points:
        for s in r["shafts"]:
            h = s["health"]
            out.append(f"## {tag}: {h['rate']:g} Hz, n = {s['modes']}")
            out.append("")
            sp = md.replace(".timing.md", ".steal")
            if os.path.exists(sp):
                with open(sp) as f:
                    steal = float(f.read().strip() or 0)
                out.append(f"Steal time on the daemon's CPU during the run (`/proc/stat`: time the hypervisor gave "
                           f"this virtual CPU's slot to something else): **{steal:.2f} s** "
                           f"({100.0 * steal / max(r['duration_s'], 1e-9):.2f} % of the run).")
                out.append("")
            out.append(f"Inputs accepted {h['accepted']}, rejected {h['rejected_total']}, sequence gaps "
                       f"{h['seq_gaps']}; alarm events {h['alarm_events']}; model faults {h['model_faults']}; "
                       f"publish failures {h['publish_failures']}; log lines dropped {r.get('log_lines_dropped', 0)}.")
            out.append("")
            out.append("Step time (count per bin, log-scaled bars):")
            out.append("```")
            out.append(ascii_hist(s["step_us"]))
            out.append("```")
            out.append("Tick lateness:")
            out.append("```")
            out.append(ascii_hist(s["late_us"]))
            out.append("```")
            out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main()

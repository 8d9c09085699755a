#!/usr/bin/env python3
"""Markdown report of bench/multishaft.sh: twins per core.

  multishaft_report.py [--command C] [--seconds S] [--out-dir D] N DAEMON.json TIMING.md CPU% [...]"""
import argparse
import json
import os
import platform
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from rt_report import cpu_model, fmt_us, verdict  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--command", default="")
    ap.add_argument("--seconds", default="")
    ap.add_argument("--max-step", default="")
    ap.add_argument("--out-dir", default=".")
    ap.add_argument("items", nargs="+")
    a = ap.parse_args()
    if len(a.items) % 4:
        sys.exit("multishaft_report.py: arguments come in quadruples N JSON MD CPU")
    rows = []
    for i in range(0, len(a.items), 4):
        n, js, md, cpu = a.items[i:i + 4]
        with open(js) as f:
            rows.append((int(n), json.load(f), md, cpu))
    first = rows[0][1]
    shaft0 = first["shafts"][0]
    out = ["# Twins per core", ""]
    out.append(f"Produced by `{a.command.strip()}` on {first.get('date', '?')}; host `{first.get('host', '?')}`, "
               f"{cpu_model()}, {first.get('cpus_online', '?')} CPUs online, Linux {platform.release()}.")
    out.append("")
    out.append(f"One `hoist-twind` process hosts N shafts ({shaft0['rate_hz']:g} Hz, n = {shaft0['modes']} modes "
               "each; every output on: HOIST_CAGE every step, HOIST_GUIDE_SHAPE at 5 Hz, HOIST_HEALTH at 1 Hz, "
               "alarms), **the whole process (loop, LCM receive thread, log writer) pinned to one CPU**, fed N "
               "winder streams at the step rate by `hoist-replay --timing-test --shafts N` on another CPU. "
               f"Real-time settings: memory lock {first['realtime']['memory_lock']}, scheduling "
               f"{first['realtime']['scheduling']}, affinity {first['realtime']['affinity']}.  "
               f"`[service] max_step` = {a.max_step} s.  {a.seconds} s per row.  Lateness is measured at the start of each shaft's own step, so it "
               "includes the work of the shafts stepped before it in the same tick.")
    out.append("")
    out.append("| twins | deadline misses (all shafts) | worst tick lateness p99 / p99.9 / max | step p50 / p99 (all shafts) | CPU used | steal | inputs lost | timing test |")
    out.append("|---|---|---|---|---|---|---|---|")
    best = None
    for n, r, md, cpu_steal in rows:
        cpu, _, steal = cpu_steal.partition("/")
        sh = r["shafts"]
        misses = sum(s["deadline_misses"] for s in sh)
        lp99 = max(s["late_us"]["p99"] for s in sh)
        lp999 = max(s["late_us"]["p999"] for s in sh)
        lmax = max(s["late_us"]["max"] for s in sh)
        sp50 = sorted(s["step_us"]["p50"] for s in sh)[len(sh) // 2]
        sp99 = max(s["step_us"]["p99"] for s in sh)
        gaps = sum(s["sequence_gaps"] for s in sh)
        v = verdict(md)
        out.append(f"| {n} | **{misses}** | {fmt_us(lp99)} / {fmt_us(lp999)} / {fmt_us(lmax)} | {fmt_us(sp50)} / "
                   f"{fmt_us(sp99)} | {cpu} % | {steal or '?'} s | {gaps} | {v} ([report]({os.path.relpath(md, a.out_dir)})) |")
        if misses == 0 and (best is None or n > best):
            best = n
    out.append("")
    if best is None:
        out.append("No count ran without a deadline miss.")
    else:
        out.append(f"**Largest count without a deadline miss: {best} twins on one core.**")
    out.append("")
    out.append("\"CPU used\" is the process's user + system time over the run (100 % = the whole core); "
               "\"steal\" is the time the hypervisor gave the daemon's virtual CPU to something else during "
               "the run (`/proc/stat`); \"inputs lost\" counts sequence gaps seen by the daemon.")
    print("\n".join(out))


if __name__ == "__main__":
    main()

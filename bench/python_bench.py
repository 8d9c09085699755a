#!/usr/bin/env python3
"""Speed of the Python module hoist (issue 34), for docs/performance.md.

  PYTHONPATH=build/python python3 bench/python_bench.py [--build build] [--repeat 7] [--runs 64] [--t-end 20]

(a) The paper's case (n = 50, 60 s, dt 0.01, max_step 0.0025, static start) from
    Python, hoist.simulate(Config.paper(), "paper"), against the same run inside
    C++ without process start-up: hoist-bench's BM_PaperCaseFastSubsteps (set-up
    and initialization included, as in hoist.simulate) and hoist-sim's own
    reported set-up + solve times.  Median of --repeat runs each.
(b) simulate_batch of --runs paper runs (a preload sweep, cut at --t-end s)
    with threads=2 against threads=1: the speed-up.
Prints one table (Markdown) and the machine's load, which these figures depend on.
"""
import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time


def median_time(fn, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times


def hoist_bench_ms(build, repeat):
    exe = os.path.join(build, "bin", "hoist-bench")
    if not os.access(exe, os.X_OK):
        return None
    out = subprocess.run([exe, "--benchmark_filter=BM_PaperCaseFastSubsteps$", "--benchmark_format=json",
                          f"--benchmark_repetitions={repeat}", "--benchmark_report_aggregates_only=true"],
                         capture_output=True, text=True, check=True).stdout
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            scale = {"ms": 1e-3, "us": 1e-6, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
            return b["real_time"] * scale
    return None


def hoist_sim_s(build, repeat):
    exe = os.path.join(build, "bin", "hoist-sim")
    setups, solves = [], []
    for _ in range(repeat):
        err = subprocess.run([exe, "--profile", "paper", "--out", "/dev/null"], capture_output=True, text=True,
                             check=True).stderr
        m = re.search(r"setup ([0-9.]+) s, solve ([0-9.]+) s", err)
        setups.append(float(m.group(1)))
        solves.append(float(m.group(2)))
    return statistics.median(setups), statistics.median(solves)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build", help="build directory (hoist-bench, hoist-sim)")
    ap.add_argument("--repeat", type=int, default=7, help="repetitions per figure (median)")
    ap.add_argument("--runs", type=int, default=64, help="runs in the batch")
    ap.add_argument("--t-end", type=float, default=20.0, help="end time of each batch run [s]")
    a = ap.parse_args()
    if a.repeat < 1 or a.runs < 1 or a.t_end <= 0:
        ap.error("--repeat and --runs must be >= 1, --t-end > 0")
    import hoist

    cfg = hoist.Config.paper()
    hoist.simulate(cfg, "paper", t_end=1.0)  # warm up (imports, page faults)
    py_s, _ = median_time(lambda: hoist.simulate(cfg, "paper"), a.repeat)
    bench_s = hoist_bench_ms(a.build, a.repeat)
    setup_s, solve_s = hoist_sim_s(a.build, a.repeat)

    configs = [cfg.copy().set("guide_ropes.preload", [15e3 + 45e3 * i / (a.runs - 1 or 1)] * 2)
               for i in range(a.runs)]
    one_s, _ = median_time(lambda: hoist.simulate_batch(configs, "paper", t_end=a.t_end, threads=1),
                           max(3, a.repeat // 3))
    two_s, _ = median_time(lambda: hoist.simulate_batch(configs, "paper", t_end=a.t_end, threads=2),
                           max(3, a.repeat // 3))

    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} CPUs; median of {a.repeat}")
    print("| what | time | ratio |")
    print("|---|---|---|")
    print(f"| paper case, hoist.simulate from Python | {py_s * 1e3:.1f} ms | |")
    if bench_s:
        print(f"| paper case, hoist-bench BM_PaperCaseFastSubsteps (C++) | {bench_s * 1e3:.1f} ms | "
              f"Python / C++ = {py_s / bench_s:.3f} |")
    print(f"| paper case, hoist-sim's reported set-up + solve | {(setup_s + solve_s) * 1e3:.1f} ms "
          f"(set-up {setup_s * 1e3:.1f} incl. its step-cost probe, solve {solve_s * 1e3:.1f}) | "
          f"Python / hoist-sim = {py_s / (setup_s + solve_s):.3f} |")
    print(f"| simulate_batch, {a.runs} runs of {a.t_end:g} s, threads=1 | {one_s:.2f} s | |")
    print(f"| simulate_batch, {a.runs} runs of {a.t_end:g} s, threads=2 | {two_s:.2f} s | "
          f"speed-up {one_s / two_s:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

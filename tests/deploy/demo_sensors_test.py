#!/usr/bin/env python3
"""scripts/demo.sh, the README's main job, with its simulated sensors (issue 30:
"the README's main job shows it"): at --speed 20 the twin, whose config says
1000 N at b = 1 m, finds the hidden 1600 N at -0.6 m, and says so with its
sigmas beside the open-loop tilt; the clearance alarms follow the estimate.
--no-sensors runs open loop (no estimate line); a bad --true-load is exit 2.

  demo_sensors_test.py SOURCE_DIR BIN_DIR LCM_PORT
"""
import os
import re
import subprocess
import sys

src, bin_dir, port = sys.argv[1], sys.argv[2], sys.argv[3]
env = dict(os.environ, HOIST_BIN_DIR=bin_dir)
demo = os.path.join(src, "scripts", "demo.sh")
failures = []


last_out = ""  # the demo run being checked: printed whole on a failure (the logs' folder is in it)


def check(ok, what, detail=""):
    print(("ok: " if ok else "FAIL: ") + what)
    if not ok:
        failures.append(what)
        print(detail or (last_out[:400] + "\n...\n" + last_out[-4000:]))


def run(*args, timeout=90):
    global last_out
    r = subprocess.run(["bash", demo, "--no-setup", "--no-dash", "--port", port, *args], env=env,
                       stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout)
    last_out = r.stdout + r.stderr
    return r.returncode, last_out


rc, out = run("--speed", "20")
check(rc == 0, f"demo.sh --speed 20 exits 0 (got {rc})", out[-3000:])
check("the twin's config says 1000.0 N at b 1.0 m" in out, "it says what the config believes", out[:1500])
est = re.findall(r"estimate: Fa (-?[\d.]+)\+-([\d.]+) N b (-?[\d.]+)\+-([\d.]+) m theta (\S+) \(open (\S+)\)", out)
check(len(est) >= 2, f"estimate lines beside the cage lines ({len(est)})", out[-3000:])
if est:
    fa, sfa, b, sb, th, th_open = est[-1]
    fa, sfa, b, sb, th, th_open = map(float, (fa, sfa, b, sb, th, th_open))
    # 3 sigma, floored at the printed resolution (1 N, 0.01 m).
    check(abs(fa - 1600.0) <= 3.0 * max(sfa, 1.0), f"Fa {fa} +- {sfa} N holds the hidden 1600 N")
    check(abs(b + 0.6) <= 3.0 * max(sb, 0.01), f"b {b} +- {sb} m holds the hidden -0.6 m")
    check(th * th_open < 0.0, f"the estimated tilt ({th}) leans the other way from the open-loop one ({th_open})")
check("[from the load estimate]" in out, "the alarms say they were judged on the estimate", out[-3000:])

rc, out = run("--speed", "20", "--no-sensors")
check(rc == 0 and "estimate:" not in out and "== sensors" not in out,
      f"--no-sensors: open loop, no estimate line (exit {rc})", out[-2000:])

rc, out = run("--true-load", "heavy")
check(rc == 2 and "--true-load" in out, f"a bad --true-load is exit 2 naming the option (exit {rc})", out)

sys.exit(1 if failures else 0)

#!/usr/bin/env python3
"""What a new user meets first, for every program in BIN_DIR:
  * --help exits 0, its usage line names the program (not the path it was run
    by) and it points at no file outside the repository (shared/spec/...);
  * --version exits 0 and prints "<program> <project version>[ (git ...)]";
  * an unknown option exits 2 naming the program and the option;
  * a bad --lcm-url (ttl=abc, bogus://x, '') exits 2 naming the program, the
    option and the fault, in every program that takes one;
  * hoist-alarm-ack --shelve beyond the daemon's limit exits 2 naming the limit;
  * hoist-sim and hoist-study document --initial with the same values and default;
  * the shipped configs (example.toml, demo.toml) are accepted by hoist-twind;
  * every other tool that takes the daemon's --config accepts every section of
    the shipped example.toml (says once which it ignores), and a misspelt key
    in a section it does use is still an error naming the key.
usage: cli_test.py BIN_DIR PROJECT_VERSION CONFIG_DIR
"""
import os
import re
import subprocess
import sys

bin_dir, version, config_dir = sys.argv[1], sys.argv[2], sys.argv[3]
failures = []


def check(cond, what, detail=""):
    print(("ok   " if cond else "FAIL ") + what + ("" if cond or not detail else "\n" + detail))
    if not cond:
        failures.append(what)


def run(args, env=None):
    e = dict(os.environ)
    e.pop("LCM_DEFAULT_URL", None)
    e.update(env or {})
    r = subprocess.run(args, capture_output=True, text=True, timeout=60, env=e)
    return r.returncode, r.stdout + r.stderr


expected = ["hoist-sim", "hoist-study", "hoist-twind", "hoist-replay", "hoist-log2csv", "hoist-monitor",
            "hoist-alarm-ack", "hoist-wakeup-latency", "hoist-bench", "hoist-lcm-spy", "hoist-timing-test",
            "hoist-forecast-bench", "hoist-forecast-table", "hoist-dash", "hoist-mqtt"]
# Every program in BIN_DIR, not a list that can fall behind.
programs = sorted(f for f in os.listdir(bin_dir)
                  if os.path.isfile(os.path.join(bin_dir, f)) and os.access(os.path.join(bin_dir, f), os.X_OK))
for p in expected:
    if p not in programs:
        print(f"skip {p}: not built")
for p in programs:
    exe = os.path.join(bin_dir, p)
    if not os.path.exists(exe):
        print(f"skip {p}: not built")
        continue
    if p not in ("hoist-bench",):  # Google Benchmark's own --help
        rc, out = run([exe, "--help"])
        check(rc == 0, f"{p} --help exits 0 (exit {rc})", out)
        usage = [l for l in out.splitlines() if l.lower().lstrip().startswith(("usage:", p))]
        check(bool(usage) and all("/" not in l.split()[1 if l.lower().startswith("usage") else 0] for l in usage[:1]),
              f"{p} --help: the usage line names the program, not a path", "\n".join(usage[:2]))
        for ref in ("shared/", "INTERFACES.md", "MODEL.md"):
            check(ref not in out, f"{p} --help mentions no file outside the repository ({ref})")
    rc, out = run([exe, "--version"])
    check(rc == 0 and re.match(rf"^{re.escape(p)} {re.escape(version)}( \(git [0-9a-f]+(-modified)?\))?$",
                               out.strip()) is not None,
          f"{p} --version prints '{p} {version} (git HASH)'", out)

ack = os.path.join(bin_dir, "hoist-alarm-ack")
if os.path.exists(ack):
    rc, out = run([ack, "--shelve", "99999", "--lcm-url", "memq://"])
    check(rc == 2 and "3600" in out, "hoist-alarm-ack --shelve 99999 exits 2 and names the 3600 s limit", out)
    rc, out = run([ack, "--shelve", "600", "--lcm-url", "memq://"])
    check(rc == 0, "hoist-alarm-ack --shelve 600 is sent", out)

sim, study = os.path.join(bin_dir, "hoist-sim"), os.path.join(bin_dir, "hoist-study")
if os.path.exists(sim) and os.path.exists(study):
    def initial_help(args):
        out = run(args)[1]
        m = re.search(r"--initial[^\n]*\n?(?:[^\n-][^\n]*\n)*", out)
        return " ".join(m.group(0).split()) if m else ""
    hs, ht = initial_help([sim, "--help"]), initial_help([study, "preload", "--help"])
    check("default: config" in hs and "default: config" in ht and "static" in hs and "rest" in ht,
          "hoist-sim and hoist-study: --initial static|rest|config, default config in both", hs + "\n" + ht)
    rc, out = run([sim, "--initial", "bogus", "--profile", "rest:t_end=1", "--out", os.devnull])
    check(rc == 2, "hoist-sim --initial bogus exits 2")

# An unknown option: exit 2, and the message names the program and the option
# (hoist-log2csv --bogus-opt said only "LOGFILE is required").
for p in programs:
    exe = os.path.join(bin_dir, p)
    rc, out = run([exe, "--bogus-opt"])
    check(rc == 2 and p in out and "--bogus-opt" in out,
          f"{p} --bogus-opt exits 2 naming the program and the option (exit {rc})", out[-600:])

# Every program that takes --lcm-url (its --help says so) checks it with the
# shared validator (hoist/bus/lcm_url.hpp): exit 2, naming the program, the
# option and what is wrong -- before opening anything.
takes_url = [p for p in programs if "--lcm-url" in run([os.path.join(bin_dir, p), "--help"])[1]]
check(set(takes_url) >= {p for p in ("hoist-twind", "hoist-dash", "hoist-mqtt", "hoist-replay", "hoist-monitor",
                                      "hoist-alarm-ack", "hoist-timing-test", "hoist-lcm-spy") if p in programs},
      "every LCM program documents --lcm-url", " ".join(takes_url))
for p in takes_url:
    exe = os.path.join(bin_dir, p)
    for u, names in (("udpm://239.255.76.67:7667?ttl=abc", "ttl"), ("bogus://x", "bogus"), ("", "empty")):
        rc, out = run([exe, "--lcm-url", u])
        check(rc == 2 and p in out and "--lcm-url" in out and names in out,
              f"{p} --lcm-url '{u}' exits 2 naming {p}, --lcm-url and '{names}' (exit {rc})", out[-600:])

# A malformed LCM URL is bad input (exit 2) in every LCM program; a
# well-formed one that cannot be opened stays exit 1 (environment).
bad_urls = ["bogus://x", "udpm://10.0.0.1:7667", "udpm://239.255.76.67:99999", "udpm://239.255.76.67:7667?tll=0",
            "239.255.76.67:7667"]
for p, extra in (("hoist-twind", ["--duration", "1"]), ("hoist-replay", ["--profile", "rest:t_end=1"]),
                 ("hoist-monitor", []), ("hoist-alarm-ack", []), ("hoist-lcm-spy", [])):
    exe = os.path.join(bin_dir, p)
    if not os.path.exists(exe):
        continue
    for u in bad_urls:
        rc, out = run([exe, "--lcm-url", u] + extra)
        check(rc == 2 and "URL" in out, f"{p} --lcm-url {u} exits 2 naming the URL (exit {rc})", out[-600:])
    rc, out = run([exe] + extra, env={"LCM_DEFAULT_URL": "bogus://y"})
    check(rc == 2, f"{p} with LCM_DEFAULT_URL=bogus://y exits 2 (exit {rc})", out[-600:])

twind = os.path.join(bin_dir, "hoist-twind")
if os.path.exists(twind):
    for cfg in ("example.toml", "demo.toml"):
        path = os.path.join(config_dir, cfg)
        rc, out = run([twind, "--config", path, "--print-config"])
        check(rc == 0 and "[alarms]" in out, f"hoist-twind accepts the shipped {cfg}", out[-2000:])

# Every tool that takes hoist-twind's --config: the example is accepted whole.
# (No daemon runs here: the timing tests give up after --health-timeout, which
# is not a configuration error, exit 2.)
example = os.path.join(config_dir, "example.toml")
misspelt = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"cli_test_{os.getpid()}_misspelt.toml")
with open(example) as f:
    text = f.read()
with open(misspelt, "w") as f:
    f.write(text.replace("[cage]\n", "[cage]\nmas_typo = 1.0\n", 1))
quiet_url = ["--lcm-url", "udpm://239.255.76.67:7936?ttl=0"]
# hoist-estimate's input: a short trip's measurements, written by hoist-sim.
meas = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"cli_test_{os.getpid()}_meas.csv")
if os.path.exists(os.path.join(bin_dir, "hoist-sim")):
    run([os.path.join(bin_dir, "hoist-sim"), "--profile", "trapezoid:vmax=4,travel=20,l0=50,t_end=2", "--modes", "2",
         "--write-measurements", meas, "-q"])
config_tools = [
    ("hoist-timing-test", [], ["--duration", "0.5", "--health-timeout", "0.5"] + quiet_url),
    ("hoist-replay", ["--timing-test"], ["--duration", "0.5", "--health-timeout", "0.5"] + quiet_url),
    ("hoist-study", ["advise"], ["--samples", "3", "--modes", "2", "--clearance", "0.05", "--max-sleeve-force", "1e9",
                                 "--profile", "trapezoid:vmax=4,travel=20,l0=50,t_end=2", "--no-plots", "-j", "1",
                                 "--out-dir", os.path.join(os.environ.get("TMPDIR", "/tmp"),
                                                           f"cli_test_{os.getpid()}_advise")]),
    ("hoist-sim", [], ["--profile", "trapezoid:vmax=4,travel=20,l0=50,t_end=2", "--modes", "2", "--out", os.devnull,
                       "-q"]),
    ("hoist-estimate", [], ["--measurements", meas, "--out", os.devnull, "--modes", "2", "-q"]),
]
for p, pre, post in config_tools:
    exe = os.path.join(bin_dir, p)
    if not os.path.exists(exe):
        print(f"skip {p} --config: not built")
        continue
    rc, out = run([exe] + pre + ["--config", example] + post)
    check(rc != 2 and "unknown section" not in out,
          f"{' '.join([p] + pre)} --config example.toml: every section accepted (exit {rc})", out[-1500:])
    if p not in ("hoist-sim", "hoist-estimate"):  # (they read [sensors]/[estimator] too: nothing to say)
        check(out.count("ignoring [") == 1 and "[service]" in out,
              f"{' '.join([p] + pre)} says once which sections it ignores", out[-1500:])
    rc, out = run([exe] + pre + ["--config", misspelt] + post)
    check(rc == 2 and "mas_typo" in out, f"{' '.join([p] + pre)} --config: a misspelt shaft key exits 2 naming it "
          f"(exit {rc})", out[-1500:])
os.unlink(misspelt)
if os.path.exists(meas):
    os.unlink(meas)
import shutil
shutil.rmtree(os.path.join(os.environ.get("TMPDIR", "/tmp"), f"cli_test_{os.getpid()}_advise"), ignore_errors=True)

print(f"\n{len(failures)} failure(s)")
sys.exit(1 if failures else 0)

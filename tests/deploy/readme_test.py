#!/usr/bin/env python3
"""Every command of the README's shell blocks (and docs/deploy.md's), so that they cannot drift.

Each command line of every ```sh block is either RUN (the fast ones: it must
exit 0, run in a scratch directory with build/bin/ mapped to BIN_DIR and the
files it names prepared) or SKIPPED by a rule below that says why (a live LCM
session, minutes of run time, root, a GUI).  A command that no rule knows
fails the test: add it to RUN or SKIP here when you add it to the README.
Also checks that the options the README lists for a program are in its --help,
that scripts/demo.sh --help lists --mqtt and hoist-twind's --log-level help every level,
that the install command installs every package cpack makes (and names it),
that the wall-screen dashboard (--bind 0.0.0.0) has its --allow-host and
hoist-dash warns when bound beyond loopback without one, and that the
Sparkplug demo shows the edge node's births before its data.
usage: readme_test.py README BIN_DIR SOURCE_DIR WORK_DIR
"""
import os
import re
import shutil
import subprocess
import sys
import time

readme, bin_dir, src_dir, work = sys.argv[1:5]
failures = []


def check(cond, what, detail=""):
    print(("ok   " if cond else "FAIL ") + what + ("" if cond or not detail else "\n" + detail))
    if not cond:
        failures.append(what)


# (regex on the command, reason).  First match wins; RUN rules come first.
RUN = [
    r"^build/bin/hoist-sim (?!study )(?!.*--method paper)",
    r"^build/bin/hoist-study (sweep|preload|tension-difference|eccentric-load|mass)\b",
    r"^build/bin/hoist-estimate ",
    r"^hoist-twind --config /etc/hoist-twin/\w+\.toml --print-config$",
]
SKIP = [
    (r"^scripts/(demo|test)\.sh", "minutes of set-up and run time (CI runs scripts/test.sh; demo_* tests)"),
    (r"^build/bin/hoist-sim .*--method paper", "the paper's literal method: slow (tests/model compare it)"),
    (r"^build/bin/hoist-(sim study|study) ", "a study of several minute-long runs (tests/study)"),
    (r"^export LCM_DEFAULT_URL=", "environment of the live session below"),
    (r"^kill -INT %2 %1 && wait$", "ends the live session above (its jobs)"),
    (r"^(build/bin/)?hoist-twind( --clock input)?( &)?$|^lcm-logger |^lcm-logplayer |^build/bin/hoist-replay |^build/bin/hoist-log2csv run\.lcm",
     "a live LCM session of minutes (tests/integration, deploy_python_reader)"),
    (r"^build/bin/hoist-lcm-spy", "a GUI (deploy_lcm_spy opens it under Xvfb)"),
    (r"^build/bin/hoist-dash ", "a server that runs until stopped (tests/dash)"),
    (r"^lcm-gen -p |^PYTHONPATH=", "deploy_python_reader runs these against a live twin"),
    (r"^bench/", "benchmarks of 10-20 minutes"),
    (r"^cmake --build build -j && \(cd build && cpack", "the whole build and package (deploy_deb)"),
    (r"# as root\b|^systemctl |^journalctl ", "root / systemd on the target machine (deploy_install, deploy_unit_verify)"),
    (r"^hoist-replay --timing-test .*--duration 600", "a 10-minute timing test (timing_test_test runs short ones)"),
]


def commands(text):
    """(line number, command with its trailing comment) of every ```sh block."""
    out, block, start, cont = [], False, 0, ""
    for i, line in enumerate(text.splitlines(), 1):
        if line.startswith("```"):
            block = line.strip() in ("```sh", "```bash", "```shell")
            cont = ""
            continue
        if not block or not line.strip() or (not cont and line.lstrip().startswith("#")):
            continue
        if cont:
            line = cont + " " + line.strip()
        else:
            start = i
        if line.rstrip().endswith("\\") or re.search(r"\\\s+#", line):
            cont = re.sub(r"\\(\s+#.*)?$", "", line.rstrip()).rstrip()
            continue
        cont = ""
        out.append((start, line.strip()))
    return out


# The README and the pages it hands a whole procedure to (docs/deploy.md: the
# plant's install, units, network and timing test) are checked alike.
pages = [readme, os.path.join(src_dir, "docs", "deploy.md")]
texts = {pg: open(pg, encoding="utf-8").read() for pg in pages}
text = "\n".join(texts.values())
cmds = [(f"{os.path.basename(pg)}:{ln}", c) for pg, t in texts.items() for ln, c in commands(t)]
check(len(cmds) >= 20, f"{len(cmds)} README commands found")

shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
env = dict(os.environ)
env.pop("LCM_DEFAULT_URL", None)
env["PATH"] = bin_dir + os.pathsep + env.get("PATH", "/usr/bin:/bin")
os.symlink(os.path.dirname(os.path.abspath(bin_dir)), os.path.join(work, "build"))
for d in ("service", "tools", "msgs"):
    os.symlink(os.path.join(os.path.abspath(src_dir), d), os.path.join(work, d))
sim = os.path.join(bin_dir, "hoist-sim")
# The files the commands name: a shaft (the plant template) and a trip.
shutil.copy(os.path.join(src_dir, "service/config/example.toml"), os.path.join(work, "shaft.toml"))
subprocess.run([sim, "--profile", "paper", "--write-profile", os.path.join(work, "trip.csv")],
               check=True, capture_output=True, timeout=60)

ran = 0
for line, cmd in cmds:
    bare = re.sub(r"\s+#.*$", "", cmd).strip()
    if any(re.search(r, bare) for r in RUN):
        # As typed, through bash, from a directory that looks like the
        # repository root (build/, service/, tools/, msgs/ link to the real
        # ones); installed names (hoist-twind) found on PATH in BIN_DIR.
        script = "set -o pipefail\n" + cmd.replace("/etc/hoist-twin/north.toml",
                                                     os.path.join(src_dir, "service/config/example.toml"))
        t0 = time.monotonic()
        try:
            r = subprocess.run(["bash", "-c", script], cwd=work, env=env, capture_output=True, text=True, timeout=180)
            rc, out = r.returncode, r.stdout[-3000:] + r.stderr[-3000:]
        except subprocess.TimeoutExpired:
            rc, out = -1, "timed out after 180 s"
        check(rc == 0, f"{line}: exit {rc} in {time.monotonic() - t0:.1f} s: {bare}", out)
        ran += 1
        continue
    why = next((reason for r, reason in SKIP if re.search(r, bare) or re.search(r, cmd)), None)
    check(why is not None, f"{line}: classified: {bare}",
          "a README command no rule of tests/deploy/readme_test.py knows: add it to RUN or SKIP")
    if why:
        print(f"     skipped ({why})")
check(ran >= 6, f"{ran} README commands run")

# The options the README names in its synopsis lines exist in each program's --help.
for m in re.finditer(r"^(hoist-[a-z0-9-]+) (\[.*)$", text, re.M):
    prog, rest = m.group(1), m.group(2)
    exe = os.path.join(bin_dir, prog)
    if not os.path.exists(exe):
        continue
    r = subprocess.run([exe, "--help"], capture_output=True, text=True, timeout=60, env=env)
    for opt in sorted(set(re.findall(r"(--[a-z][a-z0-9-]+)", rest))):
        check(opt in r.stdout + r.stderr, f"README synopsis: {prog} --help lists {opt}")

# Help texts the README relies on.
r = subprocess.run(["bash", os.path.join(src_dir, "scripts/demo.sh"), "--help"], capture_output=True, text=True,
                   timeout=60)
check(r.returncode == 0 and "--mqtt" in r.stdout, "scripts/demo.sh --help lists --mqtt", r.stdout[-1500:])
twind = os.path.join(bin_dir, "hoist-twind")
if os.path.exists(twind):
    out = subprocess.run([twind, "--help"], capture_output=True, text=True, timeout=60, env=env).stdout
    m = re.search(r"--log-level[^\n]*(\n\s{20,}[^\n]*)*", out)
    # The description (the lines under the option; CLI11's own {a,b,...} list is on the first).
    desc = m.group(0).split("\n", 1)[1] if m and "\n" in m.group(0) else ""
    check(all(l in desc for l in ("trace", "debug", "info", "warn", "error", "critical", "off")),
          "hoist-twind --help: --log-level lists every level it accepts (critical too)", m.group(0) if m else out)

# Every channel of the generated channel table (msgs/*.lcm "@channel NAME") is in the README's
# channel table and in hoist-twind --help.
import glob
channels = sorted({m.group(1) for f in glob.glob(os.path.join(src_dir, "msgs", "*.lcm"))
                   for m in re.finditer(r"@channel (HOIST_[A-Z_]+)", open(f, encoding="utf-8").read())})
check(len(channels) >= 11, f"{len(channels)} channels in msgs/*.lcm")
table = {m.group(1) for m in re.finditer(r"^\| `(HOIST_[A-Z_]+)` \|", text, re.M)}
for c in channels:
    check(c in table, f"the README's channel table lists {c}")
if os.path.exists(twind):
    h = subprocess.run([twind, "--help"], capture_output=True, text=True, timeout=60, env=env).stdout
    for c in channels:
        check(c in h, f"hoist-twind --help names {c}")

# The install: every package cpack makes is installed by the README's command and named in its text.
build_dir = os.path.dirname(os.path.abspath(bin_dir))
cpack_cfg = os.path.join(build_dir, "CPackConfig.cmake")
if os.path.exists(cpack_cfg):
    cfg = open(cpack_cfg, encoding="utf-8").read()
    pkgs = sorted(set(re.findall(r'set\(CPACK_DEBIAN_[A-Z]+_PACKAGE_NAME "([^"]+)"\)', cfg)))
    check(len(pkgs) >= 2, f"cpack makes {pkgs}")
    installs = [c for _, c in cmds if re.match(r"^(sudo )?apt(-get)? install ", c)]
    check(len(installs) == 1, "the README has one apt install command", "\n".join(installs))
    for p in pkgs:
        check(any(f"./build/{p}_*.deb" in c for c in installs), f"the README's install command installs {p}",
              "\n".join(installs))
        check(f"**{p}**" in text, f"the README names the package {p} and what it holds")
else:
    print(f"skip the install check: no {cpack_cfg}")

# The wall-screen dashboard: reachable from other machines (an --allow-host).
walls = [c for _, c in cmds if "hoist-dash" in c and "--bind 0.0.0.0" in c]
check(bool(walls), "the README shows a wall-screen dashboard (--bind 0.0.0.0)")
for c in walls:
    check("--allow-host" in c, f"the wall-screen example names the hosts it answers (--allow-host): {c}")
dash = os.path.join(bin_dir, "hoist-dash")
if os.path.exists(dash):
    # Bound beyond loopback without --allow-host: a warning at start-up (it then serves until stopped).
    p = subprocess.Popen([dash, "--read-only", "--bind", "0.0.0.0", "--port", "0", "--lcm-url",
                          "udpm://239.255.76.67:7937?ttl=0"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         text=True, env=env)
    time.sleep(2.0)
    p.terminate()
    try:
        out = p.communicate(timeout=10)[0]
    except subprocess.TimeoutExpired:
        p.kill()
        out = p.communicate()[0]
    check("--allow-host" in out and "warn" in out.lower(),
          "hoist-dash --bind 0.0.0.0 without --allow-host warns at start-up", out[-1500:])

# The Sparkplug demo: the subscriber hears the births (NBIRTH, DBIRTH) before any data.
mosq = shutil.which("mosquitto") or ("/usr/sbin/mosquitto" if os.path.exists("/usr/sbin/mosquitto") else None)
needed = ["hoist-twind", "hoist-mqtt", "hoist-replay"]
if mosq and shutil.which("mosquitto_sub") and all(os.path.exists(os.path.join(bin_dir, b)) for b in needed):
    denv = dict(env)
    denv["HOIST_BIN_DIR"] = bin_dir
    denv["PATH"] = os.path.dirname(mosq) + os.pathsep + denv["PATH"]
    try:
        r = subprocess.run(["bash", os.path.join(src_dir, "scripts/demo.sh"), "--no-setup", "--mqtt", "--sparkplug",
                            "--quick", "--port", "7938"], capture_output=True, text=True, timeout=120, env=denv,
                           stdin=subprocess.DEVNULL)
        rc, out = r.returncode, r.stdout + r.stderr
    except subprocess.TimeoutExpired:
        rc, out = -1, "timed out after 120 s"
    shown = out.split("== bridge log:")[0]
    topics = [l.split()[0] for l in shown.splitlines() if l.startswith("spBv1.0/")]
    first_data = next((i for i, t in enumerate(topics) if "/DDATA/" in t or "/NDATA/" in t), len(topics))
    births = [t for t in topics[:first_data] if "/NBIRTH/" in t or "/DBIRTH/" in t]
    check(rc == 0 and any("/NBIRTH/" in t for t in births) and any("/DBIRTH/" in t for t in births),
          f"the Sparkplug demo shows NBIRTH and DBIRTH before its data (exit {rc})", shown[-2500:])
else:
    print("skip the Sparkplug demo: mosquitto, mosquitto_sub or the programs are missing")

print(f"{len(failures)} failure(s)")
sys.exit(1 if failures else 0)

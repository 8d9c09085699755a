#!/usr/bin/env python3
"""hoist-twind under systemd's notify protocol, without systemd.

The test plays systemd's part: it binds a unix datagram socket, starts the
daemon with NOTIFY_SOCKET pointing at it and WATCHDOG_USEC set (as systemd does
for Type=notify and WatchdogSec=), and reads what the daemon says.

  1. ready + alive: READY=1 first, then WATCHDOG=1 pings about every
     WATCHDOG_USEC/2 for as long as the loop runs, STOPPING=1 at the end.
  2. hung loop: with --test-stall-at S the loop thread hangs at S seconds;
     the pings must stop (systemd would kill and restart the service).
  3. journal logging: with JOURNAL_STREAM naming stderr, log lines carry a
     <N> priority prefix and no timestamp of their own.

LCM runs on memq:// (in-process), so nothing touches the network.
usage: sd_notify_test.py HOIST_TWIND WORK_DIR
"""
import os
import signal
import socket
import subprocess
import sys
import time

twind, work = sys.argv[1], sys.argv[2]
os.makedirs(work, exist_ok=True)
failures = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        failures.append(what)


def run(extra_args, watchdog_usec, listen_s, kill_after=False):
    """Start the daemon, collect (time, message) pairs for listen_s seconds."""
    path = os.path.join(work, "notify.sock")
    if os.path.exists(path):
        os.unlink(path)
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
    sock.bind(path)
    sock.settimeout(0.05)
    env = {k: v for k, v in os.environ.items() if k not in ("LCM_DEFAULT_URL", "JOURNAL_STREAM", "WATCHDOG_PID")}
    env["NOTIFY_SOCKET"] = path
    env["WATCHDOG_USEC"] = str(watchdog_usec)
    log_path = os.path.join(work, "twind.log")
    with open(log_path, "w") as log:
        t0 = time.monotonic()
        p = subprocess.Popen([twind, "--lcm-url", "memq://", "--rate", "100"] + extra_args,
                             env=env, stdout=log, stderr=subprocess.STDOUT)
        msgs = []
        while time.monotonic() - t0 < listen_s:
            try:
                data = sock.recv(4096).decode()
                msgs.append((time.monotonic() - t0, data))
            except socket.timeout:
                pass
            if p.poll() is not None and not kill_after:
                # drain what is left
                try:
                    while True:
                        msgs.append((time.monotonic() - t0, sock.recv(4096).decode()))
                except socket.timeout:
                    pass
                break
        if kill_after and p.poll() is None:
            p.send_signal(signal.SIGKILL)
        rc = p.wait(timeout=30)
    sock.close()
    with open(log_path) as f:
        return msgs, rc, f.read()


# ---- 1. READY, then watchdog pings while the loop runs, STOPPING at the end ----
msgs, rc, log = run(["--duration", "3"], watchdog_usec=400000, listen_s=10)
print("\n".join(f"  {t:6.3f} s  {m!r}" for t, m in msgs))
check(rc == 0, f"the daemon stops cleanly after --duration (exit {rc})")
check(bool(msgs) and msgs[0][1].startswith("READY=1"), "the first notification is READY=1")
pings = [t for t, m in msgs if m == "WATCHDOG=1"]
check(len(pings) >= 8, f"WATCHDOG=1 pings every ~0.2 s over 3 s (got {len(pings)})")
if len(pings) >= 2:
    gaps = [b - a for a, b in zip(pings, pings[1:])]
    check(max(gaps) < 0.6, f"no gap between pings longer than 0.6 s (largest {max(gaps):.3f} s)")
check(any(m == "STOPPING=1" for _, m in msgs), "STOPPING=1 at the clean stop")
check("systemd watchdog: 400 ms timeout" in log, "the log states the watchdog timeout")

# ---- 2. a hung loop stops the pings ----------------------------------------------
listen_end = 4.5
msgs, rc, log = run(["--test-stall-at", "1.0"], watchdog_usec=400000, listen_s=listen_end, kill_after=True)
print("\n".join(f"  {t:6.3f} s  {m!r}" for t, m in msgs))
pings = [t for t, m in msgs if m == "WATCHDOG=1"]
check(bool(msgs) and msgs[0][1].startswith("READY=1"), "stall run: READY=1 first")
check(len(pings) >= 2, f"stall run: pings while the loop still ran (got {len(pings)})")
# The loop hangs 1.0 s after it started (READY=1); one more ping may be in
# flight (interval 0.2 s), none may come later.
ready_t = msgs[0][0] if msgs else 0.0
last = max(pings) if pings else float("nan")
check(bool(pings) and last < ready_t + 1.0 + 0.35 and listen_end - last > 1.5,
      f"stall run: no ping after the loop hung (READY at {ready_t:.3f} s, hang at {ready_t + 1.0:.3f} s, "
      f"last ping at {last:.3f} s, listened until {listen_end:.1f} s)")
check("withholding the ping" in log, "stall run: the log says the ping is withheld")

# ---- 3. under the journal: no own timestamp, <N> priority prefixes ----------------
log_path = os.path.join(work, "journal.log")
with open(log_path, "w") as log:
    st = os.fstat(log.fileno())
    env = {k: v for k, v in os.environ.items() if k not in ("LCM_DEFAULT_URL", "NOTIFY_SOCKET", "WATCHDOG_USEC")}
    env["JOURNAL_STREAM"] = f"{st.st_dev}:{st.st_ino}"
    rc = subprocess.run([twind, "--lcm-url", "memq://", "--duration", "0.5"], env=env, stdout=log,
                        stderr=subprocess.STDOUT, timeout=30).returncode
with open(log_path) as f:
    lines = [l for l in f.read().splitlines() if l]
print("\n".join("  " + l for l in lines[:4]))
check(rc == 0, f"journal run exits 0 (exit {rc})")
check(bool(lines) and all(l[0] == "<" and l[2] == ">" for l in lines), "every journal line starts with <N>")
check(any(l.startswith("<6>hoist-twind started") for l in lines), "info lines are <6> and start with the message")
check(not any(l[3:7].isdigit() and l[7] == "-" for l in lines), "no timestamp of the daemon's own")

print(f"\n{len(failures)} failure(s)")
sys.exit(1 if failures else 0)

#!/usr/bin/env python3
"""Read the hoist twin from Python: print the cage state and alarm events.

Needs the Python LCM types, generated once:
    lcm-gen -p --ppath ~/hoist_py msgs/*.lcm            # in a checkout
    lcm-gen -p --ppath ~/hoist_py /usr/share/hoist-twin/lcm/*.lcm   # installed
    PYTHONPATH=~/hoist_py read_twin.py --lcm-url 'udpm://239.255.76.67:7667?ttl=0'

With LCM's Python module (`import lcm`) it uses LCM itself.  Without it
(Debian ships no python3-lcm) it joins the multicast group with a plain UDP
socket and decodes LCM's small-message packets (every hoist message but a
very large HOIST_GUIDE_SHAPE fits one packet): enough to read, not to publish.
Exit status: 0 after --count messages, 1 timeout, 2 bad usage.
"""
import argparse
import re
import socket
import struct
import sys
import time


def parse_udpm(url):
    m = re.fullmatch(r"udpm://([0-9.]+):(\d+)(\?.*)?", url)
    if not m:
        raise ValueError(f"--lcm-url: expected udpm://GROUP:PORT[?ttl=N], got '{url}'")
    return m.group(1), int(m.group(2))


def raw_messages(url):
    """(channel, payload) from LCM's UDP multicast, without the lcm module."""
    group, port = parse_udpm(url)
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind(("", port))
    s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP,
                 struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("0.0.0.0")))
    s.settimeout(0.5)
    while True:
        try:
            pkt = s.recv(65536)
        except socket.timeout:
            yield None, None
            continue
        if len(pkt) < 9 or struct.unpack(">I", pkt[:4])[0] != 0x4C433032:  # "LC02": one-packet message
            continue
        end = pkt.find(b"\0", 8)
        if end < 0:
            continue
        yield pkt[8:end].decode("utf-8", "replace"), pkt[end + 1:]


def lcm_messages(url):
    import lcm  # LCM's own Python module, when installed
    lc = lcm.LCM(url) if url else lcm.LCM()
    box = []
    lc.subscribe(".*", lambda ch, data: box.append((ch, data)))
    while True:
        if lc.handle_timeout(500) <= 0:
            yield None, None
        while box:
            yield box.pop(0)


def safe(s, limit=200):
    """A string from the network, safe to print on a terminal: control characters
    (C0, DEL, C1: escape sequences, bell, carriage return) shown as \\xHH, cut to `limit`."""
    out = "".join(c if (" " <= c < "\x7f" or c > "\x9f") else f"\\x{ord(c):02x}" for c in str(s)[:limit])
    return out + ("..." if len(str(s)) > limit else "")


def main():
    ap = argparse.ArgumentParser(prog="read_twin.py", description=__doc__.split("\n")[0])
    ap.add_argument("--lcm-url", default="udpm://239.255.76.67:7667?ttl=0")
    ap.add_argument("--channel-prefix", default="")
    ap.add_argument("--count", type=int, default=0, help="stop after this many HOIST_CAGE messages (0: never)")
    ap.add_argument("--timeout", type=float, default=0,
                    help="give up when --count cage states have not arrived within this many seconds of the "
                         "start (a bound on the whole run, not on the gap between messages; 0: never)")
    ap.add_argument("--raw", action="store_true", help="use the plain-socket reader even if `lcm` is installed")
    a = ap.parse_args()
    try:
        parse_udpm(a.lcm_url)
    except ValueError as e:
        print(f"read_twin.py: {e}", file=sys.stderr)
        return 2
    global hoist
    try:
        import hoist  # the generated types
    except ImportError:
        print("read_twin.py: no module 'hoist': generate the types with lcm-gen -p and put them on PYTHONPATH "
              "(see --help)", file=sys.stderr)
        return 2
    try:
        import lcm  # noqa: F401
        source = raw_messages(a.lcm_url) if a.raw else lcm_messages(a.lcm_url)
    except ImportError:
        source = raw_messages(a.lcm_url)
    cage_ch, alarm_ch = a.channel_prefix + "HOIST_CAGE", a.channel_prefix + "HOIST_ALARM"
    t0, seen = time.monotonic(), 0
    for channel, data in source:
        if a.timeout and time.monotonic() - t0 > a.timeout:
            wanted = f" of the {a.count} wanted (--count)" if a.count else ""
            print(f"read_twin.py: --timeout {a.timeout} s elapsed since the start: {seen}{wanted} {cage_ch} "
                  f"messages received", file=sys.stderr)
            return 1
        if channel == cage_ch:
            try:
                m = hoist.cage_state_t.decode(data)
            except Exception:  # another fingerprint (ValueError), truncated or hostile bytes: skip it
                continue
            print(f"t={m.t:8.2f} s  l={m.l:7.2f} m  y_c={m.y_c * 1e3:+8.3f} mm  theta={m.theta * 1e3:+7.4f} mrad  "
                  f"lambda_1={m.lambdas[1]:8.1f} N  min_clearance={m.min_clearance * 1e3:7.1f} mm  "
                  f"alarm_level={m.alarm_level}{'  DEGRADED' if m.degraded else ''}", flush=True)
            seen += 1
            if a.count and seen >= a.count:
                return 0
        elif channel == alarm_ch:
            try:
                e = hoist.alarm_t.decode(data)
            except Exception:
                continue
            print(f">> {safe(e.kind, 40)} level={e.level} event_type={e.event_type}: {safe(e.message)}", flush=True)
    return 1


if __name__ == "__main__":
    sys.exit(main())

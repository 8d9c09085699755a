#!/bin/sh
# The README's "Reading the twin from Python", end to end: lcm-gen -p the
# types, run hoist-twind and hoist-replay on loopback multicast (port 7861),
# and tools/python/read_twin.py must print HOIST_CAGE states; hostile
# datagrams (escape sequences in an alarm, truncated and garbage payloads)
# neither kill it nor reach the terminal.
#   python_reader_test.sh PYTHON3 BIN_DIR SOURCE_DIR WORK_DIR
set -u
py=$1 bin=$2 src=$3 work=$4
url='udpm://239.255.76.67:7861?ttl=0'
rm -rf "$work" && mkdir -p "$work/py" || exit 1
lcm-gen -p --ppath "$work/py" "$src"/msgs/*.lcm || exit 1
"$bin/hoist-twind" --lcm-url "$url" --duration 8 >"$work/twind.log" 2>&1 &
daemon=$!
PYTHONPATH="$work/py" "$py" "$src/tools/python/read_twin.py" --lcm-url "$url" --raw --count 5 --timeout 7 \
  >"$work/out.txt" 2>&1 &
reader=$!
sleep 0.5
# Hostile datagrams first -- an alarm_t whose message and kind carry
# terminal escape sequences, a truncated alarm_t and garbage with the cage
# fingerprint: the reader must neither die nor pass a control byte through.
PYTHONPATH="$work/py" "$py" - "$url" <<'PYEOF' || exit 1
import socket, struct, sys
import hoist
port = int(sys.argv[1].split(":")[2].split("?")[0])
s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
s.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
def send(ch, data):
    s.sendto(struct.pack(">II", 0x4C433032, 0) + ch.encode() + b"\0" + data, ("239.255.76.67", port))
a = hoist.alarm_t()
a.kind = "CAGE_POS_Y\x1b[5m"
a.message = "\x1b[2J\x1b[HFAKE: all clear\r\n\x07"
a.user = ""
good = a.encode()
send("HOIST_ALARM", good)
send("HOIST_ALARM", good[:30])
send("HOIST_CAGE", hoist.cage_state_t._get_packed_fingerprint() + b"\xff" * 11)
PYEOF
"$bin/hoist-replay" --lcm-url "$url" --profile rest:t_end=6 -q >"$work/replay.log" 2>&1 &
replay=$!
wait "$reader"
rc=$?
kill "$replay" "$daemon" 2>/dev/null
wait "$replay" "$daemon" 2>/dev/null
cat "$work/out.txt"
[ $rc -eq 0 ] || { echo "FAIL: read_twin.py exited $rc (daemon log: $work/twind.log)"; exit 1; }
grep -q "$(printf '\033')" "$work/out.txt" && { echo "FAIL: an escape character reached the terminal"; exit 1; }
grep -q 'FAKE: all clear' "$work/out.txt" || { echo "FAIL: the hostile alarm was not shown (inert)"; exit 1; }
n=$(grep -c '^t= .*y_c= *+4\.9[0-9]* mm' "$work/out.txt")
[ "$n" -ge 5 ] || { echo "FAIL: expected 5 cage states with the static sway y_c = +4.94 mm, got $n"; exit 1; }
"$py" "$src/tools/python/read_twin.py" --lcm-url 'bogus://x' >/dev/null 2>&1
[ $? -eq 2 ] || { echo "FAIL: a bad --lcm-url must exit 2"; exit 1; }
echo "ok: $n cage states read from Python"

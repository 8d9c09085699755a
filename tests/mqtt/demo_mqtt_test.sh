#!/usr/bin/env bash
# scripts/demo.sh --mqtt exits in time, 10 runs in a row, with its output read
# through a pipe (the reader waits for EOF: a process left holding the output
# hangs it), and never touches a broker that is already running: a decoy
# mosquitto, subscribed to hoist/#, receives nothing, and --broker-port on its
# port is refused with exit 2.
#   demo_mqtt_test.sh SOURCE_DIR BIN_DIR MOSQUITTO WORK_DIR
set -uo pipefail
src="$1" bin="$2" mosq="$3" work="$4"
rm -rf "$work" && mkdir -p "$work"
fail=0
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null; wait "$p" 2>/dev/null; done; }
trap cleanup EXIT

port_taken() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
decoy=0
for _ in $(seq 20); do
  p=$((20000 + RANDOM % 30000))
  port_taken "$p" && continue
  printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\n' "$p" > "$work/decoy.conf"
  "$mosq" -c "$work/decoy.conf" > "$work/decoy.log" 2>&1 &
  dpid=$!
  for _ in $(seq 50); do port_taken "$p" && break; sleep 0.1; done
  if kill -0 "$dpid" 2>/dev/null && port_taken "$p"; then decoy=$p; pids+=("$dpid"); break; fi
  kill "$dpid" 2>/dev/null; wait "$dpid" 2>/dev/null
done
[[ $decoy -ne 0 ]] || { echo "FAIL: could not start the decoy broker"; exit 1; }
mosquitto_sub -h 127.0.0.1 -p "$decoy" -v -t 'hoist/#' > "$work/decoy_sub.log" 2>&1 &
pids+=($!)
sleep 0.3

export HOIST_BIN_DIR="$bin"
out=$(timeout 20 "$src/scripts/demo.sh" --no-setup --mqtt --quick --broker-port "$decoy" --port 7940 2>&1 < /dev/null)
rc=$?
if [[ $rc -ne 2 || "$out" != *"--broker-port $decoy"* ]]; then
  echo "FAIL: --broker-port on a port in use: exit $rc (want 2 and a message naming it): $out"; fail=1
fi

for i in $(seq 10); do
  t0=$(date +%s.%N)
  timeout 60 "$src/scripts/demo.sh" --no-setup --mqtt --quick --port 7940 < /dev/null 2>&1 | cat > "$work/run$i.log"
  rc=${PIPESTATUS[0]}
  dt=$(awk -v a="$t0" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
  echo "run $i: exit $rc after $dt s"
  if [[ $rc -ne 0 ]]; then
    echo "FAIL: run $i exit $rc (124 = hung, killed after 60 s)"; tail -20 "$work/run$i.log"; fail=1
  fi
  grep -q '^hoist/default/cmd/result' "$work/run$i.log" || { echo "FAIL: run $i: no command result shown"; fail=1; }
done
sleep 0.3
if [[ -s "$work/decoy_sub.log" ]]; then
  echo "FAIL: the demo published to the broker already running on $decoy:"; head "$work/decoy_sub.log"; fail=1
fi
# Nothing the demo started is left running.
if pgrep -f "hoist-mqtt-demo" > /dev/null; then echo "FAIL: a demo process is still running"; pgrep -af hoist-mqtt-demo; fail=1; fi
[[ $fail -eq 0 ]] && echo "PASS: 10 runs exited, the running broker was left alone"
exit $fail

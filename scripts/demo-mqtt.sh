#!/usr/bin/env bash
# The live twin in an MQTT client (scripts/demo.sh --mqtt): builds the project
# (scripts/setup.sh), uses the MQTT broker on 127.0.0.1:1883 or starts a
# private mosquitto if none answers there, starts hoist-twind
# (service/config/demo.toml: tight gaps, so alarms show), the bridge
# hoist-mqtt, and `mosquitto_sub -v -t 'hoist/#'`, then replays the paper's
# trip.  At the end it acknowledges the alarms through MQTT
# (hoist/default/cmd/ack) and lists the retained alarm states a late SCADA
# client would get.  Everything is stopped at the end (or on Ctrl-C).
#
#   scripts/demo-mqtt.sh [--no-setup] [--speed X] [--broker-port N] [--port N]
#
#   --no-setup       skip scripts/setup.sh (the build must exist)
#   --speed X        replay speed (default 3: the 60-s trip in 20 s)
#   --broker-port N  MQTT port on 127.0.0.1 (default 1883)
#   --port N         UDP port of the private LCM URL (default 7691)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
setup=1 speed=3 bport=1883 port=7691
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-setup) setup=0; shift ;;
    --speed) speed="$2"; shift 2 ;;
    --broker-port) bport="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo-mqtt.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ $setup -eq 1 ]] && "$here/scripts/setup.sh"
bin="${HOIST_BIN_DIR:-$here/build/bin}"
for b in hoist-twind hoist-replay hoist-mqtt; do
  [[ -x "$bin/$b" ]] || { echo "demo-mqtt.sh: $bin/$b not found; run scripts/setup.sh" >&2; exit 2; }
done
for c in mosquitto_sub mosquitto_pub; do
  command -v "$c" >/dev/null || { echo "demo-mqtt.sh: $c not found (apt-get install mosquitto-clients)" >&2; exit 2; }
done

url="udpm://239.255.76.67:${port}?ttl=0"
logdir="$(mktemp -d "${TMPDIR:-/tmp}/hoist-mqtt-demo.XXXXXX")"
pids=()
cleanup() {
  trap - EXIT INT TERM
  local p
  for p in "${pids[@]}"; do kill -TERM "$p" 2>/dev/null || true; done
  for p in "${pids[@]}"; do wait "$p" 2>/dev/null || true; done
}
trap cleanup EXIT
trap 'echo; echo "demo-mqtt.sh: interrupted"; cleanup; exit 130' INT TERM

broker="mqtt://127.0.0.1:$bport"
if mosquitto_pub -h 127.0.0.1 -p "$bport" -t hoist/_demo/probe -n 2>/dev/null; then
  echo "== using the MQTT broker already on 127.0.0.1:$bport"
else
  mosq="$(command -v mosquitto || echo /usr/sbin/mosquitto)"
  [[ -x "$mosq" ]] || { echo "demo-mqtt.sh: no broker on 127.0.0.1:$bport and mosquitto not installed" >&2; exit 2; }
  printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\n' "$bport" > "$logdir/mosquitto.conf"
  "$mosq" -c "$logdir/mosquitto.conf" > "$logdir/mosquitto.log" 2>&1 &
  pids+=($!)
  for _ in $(seq 50); do mosquitto_pub -h 127.0.0.1 -p "$bport" -t hoist/_demo/probe -n 2>/dev/null && break; sleep 0.1; done
  echo "== started a private mosquitto on 127.0.0.1:$bport (log: $logdir/mosquitto.log)"
fi

echo "== LCM $url; logs in $logdir"
"$bin/hoist-twind" --config "$here/service/config/demo.toml" --clock input --lcm-url "$url" 2> "$logdir/hoist-twind.log" &
pids+=($!)
"$bin/hoist-mqtt" --broker "$broker" --lcm-url "$url" --cage-rate 1 --client-id hoist-mqtt-demo 2> "$logdir/hoist-mqtt.log" &
pids+=($!)
echo "== mosquitto_sub -v -t 'hoist/#'  (cage states at 1 Hz for the demo; payloads cut to 160 characters)"
mosquitto_sub -h 127.0.0.1 -p "$bport" -v -t 'hoist/#' | cut -c1-160 &
pids+=($!)
sleep 1.5
echo "== replay: the paper's trip at speed $speed"
"$bin/hoist-replay" --lcm-url "$url" --profile paper --speed "$speed" -q
echo "== an operator acknowledges every alarm over MQTT:"
echo "   mosquitto_pub -t hoist/default/cmd/ack -m '{\"kind\":\"*\",\"level\":0,\"action\":1,\"user\":\"demo\"}'"
mosquitto_pub -h 127.0.0.1 -p "$bport" -q 1 -t hoist/default/cmd/ack -m '{"kind":"*","level":0,"action":1,"user":"demo"}'
sleep 1.5
echo "== what a SCADA client connecting now gets at once (retained): mosquitto_sub --retained-only -t 'hoist/+/alarm/#' -t 'hoist/_bridge/+/status'"
mosquitto_sub -h 127.0.0.1 -p "$bport" -v --retained-only -W 2 -t 'hoist/+/alarm/#' -t 'hoist/_bridge/+/status' 2>/dev/null | cut -c1-200 || true
cleanup
echo "== bridge log:"
cat "$logdir/hoist-mqtt.log"

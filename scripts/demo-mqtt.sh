#!/usr/bin/env bash
# The live twin in an MQTT client (scripts/demo.sh --mqtt): builds the project
# (scripts/setup.sh), starts a private mosquitto on a free loopback port (never
# a broker that is already running: the demo publishes an acknowledge-all),
# hoist-twind (service/config/demo.toml: tight gaps, so alarms show), the
# bridge hoist-mqtt, and `mosquitto_sub -v -t 'hoist/#'`, then replays the
# paper's trip.  At the end it acknowledges the alarms through MQTT
# (hoist/default/cmd/ack), shows the bridge's answer (cmd/result) and lists
# the retained alarm states a late SCADA client would get.  Everything it
# started is stopped at the end (or on Ctrl-C), and the script returns.
#
# With --sparkplug the bridge speaks Sparkplug B instead (edge node Edge1 of
# group Mine, the shaft as device "default"): the subscriber shows
# spBv1.0/# (topic, size and the start of the protobuf in hex: NBIRTH,
# DBIRTH, DDATA), and the acknowledge is a DCMD write to
# Alarms/CAGE_POS_Y/Ack.
#
#   scripts/demo-mqtt.sh [--no-setup] [--speed X] [--quick] [--broker-port N] [--port N] [--sparkplug]
#
#   --no-setup       skip scripts/setup.sh (the build must exist)
#   --speed X        replay speed (default 3: the 60-s trip in 20 s)
#   --quick          speed 30 and short pauses (about 6 s in all; for tests)
#   --broker-port N  the private broker's port on 127.0.0.1 (default: a free one);
#                    exit 2 if N is taken
#   --port N         UDP port of the private LCM URL (default 7691)
#   --sparkplug      Sparkplug B mode (hoist-mqtt --sparkplug Mine/Edge1)
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
setup=1 speed=3 bport="" port=7691 pause=1.5 sparkplug=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-setup) setup=0; shift ;;
    --speed) speed="$2"; shift 2 ;;
    --quick) speed=30; pause=0.5; shift ;;
    --broker-port) bport="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    --sparkplug) sparkplug=1; shift ;;
    -h|--help) sed -n '2,27p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
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
mosq="$(command -v mosquitto || echo /usr/sbin/mosquitto)"
[[ -x "$mosq" ]] || { echo "demo-mqtt.sh: mosquitto not installed (apt-get install mosquitto)" >&2; exit 2; }

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

port_taken() { (exec 3<>"/dev/tcp/127.0.0.1/$1") 2>/dev/null; }
if [[ -n "$bport" ]]; then
  if port_taken "$bport"; then
    echo "demo-mqtt.sh: --broker-port $bport: something already listens on 127.0.0.1:$bport (the demo runs its own broker)" >&2
    exit 2
  fi
  candidates=("$bport")
else
  candidates=()
  for _ in $(seq 20); do candidates+=($((20000 + RANDOM % 30000))); done
fi
started=0
for bp in "${candidates[@]}"; do
  port_taken "$bp" && continue
  printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\n' "$bp" > "$logdir/mosquitto.conf"
  "$mosq" -c "$logdir/mosquitto.conf" > "$logdir/mosquitto.log" 2>&1 &
  mpid=$!
  for _ in $(seq 50); do port_taken "$bp" && break; kill -0 "$mpid" 2>/dev/null || break; sleep 0.1; done
  if kill -0 "$mpid" 2>/dev/null && port_taken "$bp"; then
    pids+=("$mpid"); bport="$bp"; started=1; break
  fi
  kill "$mpid" 2>/dev/null || true; wait "$mpid" 2>/dev/null || true
done
[[ $started -eq 1 ]] || { echo "demo-mqtt.sh: could not start mosquitto (log: $logdir/mosquitto.log)" >&2; exit 1; }
broker="mqtt://127.0.0.1:$bport"
echo "== started a private mosquitto on 127.0.0.1:$bport (log: $logdir/mosquitto.log)"

echo "== LCM $url; logs in $logdir"
if [[ $sparkplug -eq 1 ]]; then
  # Subscribed before the bridge starts: its NBIRTH and DBIRTH (not retained)
  # are the first lines shown.  (cut line-buffered: whole lines only.)
  echo "== mosquitto_sub -t 'spBv1.0/#' -F '%t (%l bytes) %x'  (Sparkplug B: protobuf, shown as hex, cut to 160 characters)"
  mosquitto_sub -h 127.0.0.1 -p "$bport" -t 'spBv1.0/#' -F '%t (%l bytes) %x' > >(stdbuf -oL cut -c1-160) &
  pids+=($!)
  sleep 0.3  # (subscribed)
fi
"$bin/hoist-twind" --config "$here/service/config/demo.toml" --clock input --lcm-url "$url" 2> "$logdir/hoist-twind.log" &
pids+=($!)
spargs=()
[[ $sparkplug -eq 1 ]] && spargs=(--sparkplug Mine/Edge1)
"$bin/hoist-mqtt" --broker "$broker" --lcm-url "$url" --cage-rate 1 --client-id hoist-mqtt-demo "${spargs[@]}" \
  2> "$logdir/hoist-mqtt.log" &
pids+=($!)
# Wait (at most 15 s) until the daemon runs -- its start-up measures a tick,
# which a loaded machine makes slow, and inputs sent before that are only
# queued -- and the bridge has found the shaft and subscribed to its
# commands; otherwise the replay's outputs arrive in one burst at the end
# and the operator's command may come before the bridge listens.
wait_for_line() {  # FILE TEXT
  for _ in $(seq 150); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.1; done
  echo "demo-mqtt.sh: no \"$2\" in $1 after 15 s; going on" >&2
}
wait_for_line "$logdir/hoist-twind.log" "hoist-twind started"
wait_for_line "$logdir/hoist-mqtt.log" "shaft 'default'"
if [[ $sparkplug -eq 1 ]]; then
  sleep "$pause"
  echo "== replay: the paper's trip at speed $speed"
  "$bin/hoist-replay" --lcm-url "$url" --profile paper --speed "$speed" -q
  # A Sparkplug payload with one metric: name "Alarms/CAGE_POS_Y/Ack",
  # datatype Boolean (11), boolean_value true (protobuf written out by hand).
  name="Alarms/CAGE_POS_Y/Ack"
  dcmd="$logdir/dcmd.bin"
  hex() { printf "\\x$(printf %02x "$1")"; }
  { printf '\x12'; hex $(( ${#name} + 6 )); printf '\x0a'; hex "${#name}"; printf '%s' "$name"; printf '\x20\x0b\x70\x01'; } > "$dcmd"
  echo "== an operator acknowledges CAGE_POS_Y from a Sparkplug host: DCMD spBv1.0/Mine/DCMD/Edge1/default, Alarms/CAGE_POS_Y/Ack = true"
  mosquitto_pub -h 127.0.0.1 -p "$bport" -q 1 -t spBv1.0/Mine/DCMD/Edge1/default -f "$dcmd"
  sleep "$pause"
  cleanup
  echo "== bridge log:"
  cat "$logdir/hoist-mqtt.log"
  exit 0
fi
echo "== mosquitto_sub -v -t 'hoist/#'  (cage states at 1 Hz for the demo; payloads cut to 160 characters)"
# The subscriber's own pid is kept (not a pipeline's last element), so it is
# stopped at the end; the cut behind it ends at its EOF.  (A pipeline in the
# background left mosquitto_sub running, holding the terminal's output open.)
# cut is line-buffered (stdbuf -oL): two subscribers never interleave mid-line.
mosquitto_sub -h 127.0.0.1 -p "$bport" -v -t 'hoist/#' > >(stdbuf -oL cut -c1-160) &
pids+=($!)
sleep "$pause"
echo "== replay: the paper's trip at speed $speed"
"$bin/hoist-replay" --lcm-url "$url" --profile paper --speed "$speed" -q
echo "== an operator acknowledges every alarm over MQTT:"
echo "   mosquitto_pub -p $bport -t hoist/default/cmd/ack -m '{\"kind\":\"*\",\"level\":0,\"action\":1,\"user\":\"demo\"}'"
mosquitto_pub -h 127.0.0.1 -p "$bport" -q 1 -t hoist/default/cmd/ack -m '{"kind":"*","level":0,"action":1,"user":"demo"}'
sleep "$pause"
echo "== what a SCADA client connecting now gets at once (retained): mosquitto_sub --retained-only -t 'hoist/+/alarm/#' -t 'hoist/_bridge/+/status'"
timeout 5 mosquitto_sub -h 127.0.0.1 -p "$bport" -v --retained-only -W 2 -t 'hoist/+/alarm/#' -t 'hoist/_bridge/+/status' \
  2>/dev/null < /dev/null | stdbuf -oL cut -c1-200 || true
cleanup
echo "== bridge log:"
cat "$logdir/hoist-mqtt.log"

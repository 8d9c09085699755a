#!/usr/bin/env bash
# The digital twin, live: builds the project (scripts/setup.sh), starts the
# daemon hoist-twind, feeds it the paper's hoist trip (Fig. 2: 50 m -> 300 m
# in 60 s) from hoist-replay in real time over LCM, and shows once a second
# the model time, depth, speed, sway, tilt, largest guide-sleeve force,
# minimum clearance and the active alarms (hoist-monitor).  Everything runs on
# a private loopback multicast URL (ttl=0: nothing leaves this machine) and is
# stopped cleanly at the end (or on Ctrl-C).  The live dashboard (hoist-dash)
# runs alongside: open the URL it prints in a browser.
# The cage also carries simulated sensors (an IMU and a rope load cell, from
# hoist-sim on a shaft whose load the twin's config does not know): the
# "estimate:" lines show the twin finding the payload and its offset, with
# their sigmas, beside the open-loop tilt it would show without sensors.
#
#   scripts/demo.sh [--no-setup] [--speed X] [--profile SPEC|FILE]
#                   [--config FILE] [--port N] [--with-length]
#                   [--true-load FA,B] [--no-sensors]
#                   [--dash-port N] [--no-dash] [--mqtt [...]]
#
#   --no-setup     skip scripts/setup.sh (the build must exist)
#   --speed X      replay X times faster than real time (default 1: 60 s).
#                  At speed 1 the daemon runs on the wall clock (the real-time
#                  twin); at any other speed it runs with --clock input, so
#                  model time follows the replayed profile time.
#   --profile P    hoist profile (default: paper; see hoist-replay --help)
#   --config FILE  daemon configuration (default: service/config/demo.toml,
#                  the paper's shaft with tight clearances so alarms show)
#   --port N       UDP port of the private LCM URL (default 7690)
#   --with-length  send the encoder rope length too (without sensors; the
#                  sensors' replay always sends it)
#   --true-load FA,B  the load the simulated sensors carry: FA [N] at offset
#                  B [m] (default 1600,-0.6; the config says 1000 N at 1 m)
#   --no-sensors   the winder only: the twin runs open loop
#   --dash-port N  TCP port of the dashboard, http://127.0.0.1:N/ (default 8080)
#   --no-dash      do not start the dashboard
#   --mqtt [...]   the same twin seen through MQTT: scripts/demo-mqtt.sh [...]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
setup=1
speed=1
profile=paper
config="$here/service/config/demo.toml"
port=7690
dash_port=8080
dash=1
sensors=1
true_load=1600,-0.6
replay_extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-setup) setup=0; shift ;;
    --speed) speed="$2"; shift 2 ;;
    --profile) profile="$2"; shift 2 ;;
    --config) config="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    --with-length) replay_extra+=(--with-length); shift ;;
    --dash-port) dash_port="$2"; shift 2 ;;
    --no-dash) dash=0; shift ;;
    --no-sensors) sensors=0; shift ;;
    --true-load)
      [[ "${2:-}" =~ ^-?[0-9.]+(e-?[0-9]+)?,-?[0-9.]+(e-?[0-9]+)?$ ]] ||
        { echo "demo.sh: --true-load takes FA,B (newtons, metres), e.g. 1600,-0.6; got '${2:-}'" >&2; exit 2; }
      true_load="$2"; shift 2 ;;
    --mqtt) shift; [[ $setup -eq 0 ]] && set -- --no-setup "$@"; exec "$here/scripts/demo-mqtt.sh" "$@" ;;
    -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d' | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "demo.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done

if [[ $setup -eq 1 ]]; then
  if [[ -x "$here/scripts/setup.sh" ]]; then
    "$here/scripts/setup.sh"
  else
    echo "demo.sh: scripts/setup.sh not found; building with cmake" >&2
    cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
    cmake --build "$here/build" -j"$(nproc)" --target hoist-twind hoist-replay hoist-monitor
  fi
fi
bin="${HOIST_BIN_DIR:-$here/build/bin}"   # HOIST_BIN_DIR: use another build
programs=(hoist-twind hoist-replay hoist-monitor)
[[ $sensors -eq 1 ]] && programs+=(hoist-sim)
for b in "${programs[@]}"; do
  if [[ ! -x "$bin/$b" ]]; then
    echo "demo.sh: $bin/$b not found; run scripts/setup.sh (or drop --no-setup)" >&2
    exit 2
  fi
done

# LCM on one machine needs multicast on the loopback interface.
multicast_ok() {
  ip link show lo 2>/dev/null | grep -q MULTICAST && ip route show 2>/dev/null | grep -q '^224\.0\.0\.0/4.* dev lo'
}
if ! multicast_ok; then
  if [[ $(id -u) -eq 0 ]]; then
    echo "demo.sh: enabling multicast on the loopback interface (ip link / ip route)" >&2
    ip link set lo multicast on
    ip route add 224.0.0.0/4 dev lo 2>/dev/null || true
  fi
  if ! multicast_ok; then
    cat >&2 <<'MSG'
demo.sh: UDP multicast on the loopback interface is off, so LCM cannot work on this machine.
Enable it as root, then re-run:
    sudo ip link set lo multicast on
    sudo ip route add 224.0.0.0/4 dev lo
MSG
    exit 1
  fi
fi

url="udpm://239.255.76.67:${port}?ttl=0"
logdir="$(mktemp -d "${TMPDIR:-/tmp}/hoist-demo.XXXXXX")"
daemon_pid="" monitor_pid="" dash_pid=""
cleanup() {
  trap - EXIT INT TERM
  [[ -n "$dash_pid" ]] && kill -TERM "$dash_pid" 2>/dev/null || true
  [[ -n "$monitor_pid" ]] && kill -TERM "$monitor_pid" 2>/dev/null || true
  if [[ -n "$daemon_pid" ]] && kill -0 "$daemon_pid" 2>/dev/null; then
    kill -TERM "$daemon_pid" 2>/dev/null || true
    wait "$daemon_pid" 2>/dev/null || true
  fi
  [[ -n "$monitor_pid" ]] && wait "$monitor_pid" 2>/dev/null || true
  [[ -n "$dash_pid" ]] && wait "$dash_pid" 2>/dev/null || true
}
trap cleanup EXIT
trap 'echo; echo "demo.sh: interrupted"; cleanup; exit 130' INT TERM

echo "== hoist-twin demo: LCM $url, logs in $logdir"
replay_input=(--profile "$profile" "${replay_extra[@]}")
if [[ $sensors -eq 1 ]]; then
  # The shaft the sensors ride in: the twin's config with another load.  The
  # twin's own config gets the load estimator (unless it has an [estimator]).
  fa=${true_load%,*} b=${true_load#*,}
  # [load] of the config dropped, ours appended (one table per name in TOML).
  awk '/^\[/{skip=($0 ~ /^\[load\][[:space:]]*(#.*)?$/)} !skip' "$config" > "$logdir/true-shaft.toml"
  printf '\n[load]\neccentric_force = %s\noffset = %s\n' "$fa" "$b" >> "$logdir/true-shaft.toml"
  twin_config="$logdir/twin.toml"
  cp "$config" "$twin_config"
  grep -q '^\[estimator\]' "$config" || printf '\n[estimator]\nenabled = true\n' >> "$twin_config"
  if ! "$bin/hoist-sim" --config "$logdir/true-shaft.toml" --profile "$profile" --seed 7 -q \
        --write-measurements "$logdir/sensors.csv" 2> "$logdir/hoist-sim.log"; then
    echo "demo.sh: hoist-sim could not simulate the sensors:" >&2
    cat "$logdir/hoist-sim.log" >&2
    exit 1
  fi
  config_load=$("$bin/hoist-twind" --config "$config" --print-config 2>/dev/null |
                awk '/^\[load\]/{in_load=1; next} /^\[/{in_load=0}
                     in_load && $1=="eccentric_force"{fa=$3} in_load && $1=="offset"{b=$3}
                     END{printf "%s N at b %s m", fa, b}')
  echo "== sensors: a cage IMU and a rope load cell simulated by hoist-sim on a shaft whose load is"
  echo "   Fa $fa N at b $b m; the twin's config says $config_load.  The 'estimate:' lines show"
  echo "   what the twin finds, with its sigmas; 'open' is the tilt the twin would show without sensors."
  replay_input=(--measurements "$logdir/sensors.csv")
  config="$twin_config"
fi
clock=wall
daemon_url="$url"
if ! awk -v s="$speed" 'BEGIN { exit !(s == 1) }'; then
  clock=input
  # The daemon sizes its input socket for 200 ms of real-time inputs; a
  # replay X times faster fills it X times sooner, and a loaded machine that
  # stalls the daemon for a few tens of ms would lose inputs (seen at --speed
  # 20: winder samples lost, sensors refused, a biased estimate).  Ask for X
  # times the buffer (the daemon's --lcm-url recv_buf_size; at most 64 MiB).
  rcvbuf=$(awk -v s="$speed" 'BEGIN { b = int(s * 1048576); if (b < 1048576) b = 1048576; if (b > 67108864) b = 67108864; print b }')
  daemon_url="${url}&recv_buf_size=${rcvbuf}"
fi
if [[ $dash -eq 1 ]]; then
  if [[ -x "$bin/hoist-dash" ]]; then
    # Before the daemon, so that the page sees its first alarms.
    "$bin/hoist-dash" --port "$dash_port" --lcm-url "$url" \
        > "$logdir/hoist-dash.out" 2> "$logdir/hoist-dash.log" &
    dash_pid=$!
    for _ in $(seq 1 30); do
      grep -q serving "$logdir/hoist-dash.out" 2>/dev/null && break
      kill -0 "$dash_pid" 2>/dev/null || break
      sleep 0.1
    done
    if grep -q serving "$logdir/hoist-dash.out" 2>/dev/null; then
      dash_url=$(grep -o 'http://[^ ]*' "$logdir/hoist-dash.out" | head -1)
      echo "== dashboard: open $dash_url in a browser (hoist-dash; log $logdir/hoist-dash.log)"
    else
      echo "demo.sh: the dashboard did not start (port $dash_port in use? try --dash-port N):" >&2
      cat "$logdir/hoist-dash.log" >&2
      dash_pid=""
    fi
  else
    echo "demo.sh: $bin/hoist-dash not built; running without the dashboard" >&2
  fi
fi
echo "== daemon: $bin/hoist-twind --config $config --clock $clock --lcm-url '$daemon_url'"
"$bin/hoist-twind" --config "$config" --clock "$clock" --lcm-url "$daemon_url" 2> "$logdir/hoist-twind.log" &
daemon_pid=$!
"$bin/hoist-monitor" --lcm-url "$url" --no-forecast &   # (as the README's sample: no forecast lines)
monitor_pid=$!
# The replay starts once the daemon runs (its start-up measures a tick, which
# a loaded machine makes slow): at most 15 s, then anyway.
for _ in $(seq 150); do
  grep -q "hoist-twind started" "$logdir/hoist-twind.log" 2>/dev/null && break
  kill -0 "$daemon_pid" 2>/dev/null || break
  sleep 0.1
done
sleep 0.3
if ! kill -0 "$daemon_pid" 2>/dev/null; then
  echo "demo.sh: hoist-twind failed to start:" >&2
  cat "$logdir/hoist-twind.log" >&2
  exit 1
fi
echo "== replay: the $profile trip at speed $speed (Ctrl-C stops everything)"
"$bin/hoist-replay" --lcm-url "$url" "${replay_input[@]}" --speed "$speed" -q
sleep 2.2   # the last monitor lines, and the input going stale
cleanup
echo "== daemon log (alarms and final health):"
grep -E "ALARM|alarm:|final health|rejected|  rejected" "$logdir/hoist-twind.log" || true
echo "== done (full log: $logdir/hoist-twind.log)"

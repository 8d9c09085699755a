#!/usr/bin/env bash
# Real-time report: runs hoist-twind for a long stretch at each of two
# operating points, fed by `hoist-replay --timing-test` (a hoist moving the
# whole time), and writes docs/realtime-report.md with the step-time and
# tick-lateness histograms (p50, p99, p99.9, max), deadline misses and the
# timing-test verdicts.
#
#   bench/rt_report.sh [--minutes M] [--points "RATE:N ..."] [--no-rt] [--daemon-cpu C]
#                      [--feeder-cpu C] [--out FILE] [--port P] [--baseline-seconds S]
#
# Defaults: 10 minutes per point; points "1000:50 100:200" (1 kHz with 50
# modes, 100 Hz with 200 modes); the daemon pinned to the last CPU with
# --mlockall --rt-priority 80 (reported as refused, not fatal, without the
# privileges; --no-rt runs without them), the feeder on CPU 0; UDP multicast
# on loopback port 7870 (ttl=0).  Each point's raw daemon report (JSON) and
# timing-test report are kept next to the output (FILE.d/).  Needs a built
# tree (scripts/setup.sh) and two or more CPUs for the pinning to mean
# "an otherwise idle core".  Before each point the bare machine's timer
# wake-up latency is measured the same way for --baseline-seconds (default
# 60; build/bin/hoist-wakeup-latency, cyclictest-like, no work at all): if the
# machine itself misses deadlines, the daemon cannot do better.
set -euo pipefail
orig_args="$*"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
minutes=10
points="1000:50 100:200"
rt=1
ncpu=$(nproc)
daemon_cpu=$((ncpu > 1 ? ncpu - 1 : 0))
feeder_cpu=0
out="$here/docs/realtime-report.md"
port=7870
baseline=60
while [[ $# -gt 0 ]]; do
  case "$1" in
    --minutes) minutes="$2"; shift 2 ;;
    --points) points="$2"; shift 2 ;;
    --no-rt) rt=0; shift ;;
    --daemon-cpu) daemon_cpu="$2"; shift 2 ;;
    --feeder-cpu) feeder_cpu="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    --baseline-seconds) baseline="$2"; shift 2 ;;
    -h|--help) sed -n '2,22p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "rt_report.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
bin="$here/build/bin"
for b in hoist-twind hoist-replay; do
  [[ -x "$bin/$b" ]] || { echo "rt_report.sh: $bin/$b not found; build first (scripts/setup.sh)" >&2; exit 2; }
done
url="udpm://239.255.76.67:$port?ttl=0"
raw="$out.d"
mkdir -p "$raw"
secs=$(python3 -c "print(int(round(float('$minutes') * 60)))")
rtargs=()
[[ $rt -eq 1 ]] && rtargs=(--mlockall --rt-priority 80)
daemon_pid=""
cleanup() { [[ -n "$daemon_pid" ]] && kill -TERM "$daemon_pid" 2>/dev/null || true; }
trap cleanup EXIT INT TERM

args=()
for p in $points; do
  rate="${p%%:*}"; n="${p##*:}"
  tag="rate${rate}-n${n}"
  cfg="$raw/$tag.toml"
  printf '[model]\nmodes = %s\n[service]\nrate = %s.0\nchannel_prefix = "rt/"\n' "$n" "$rate" > "$cfg"
  if [[ -x "$bin/hoist-wakeup-latency" ]]; then
    echo "[rt_report] $tag: the bare machine's wake-up latency at $rate Hz on CPU $daemon_cpu, $baseline s ..." >&2
    taskset -c "$daemon_cpu" "$bin/hoist-wakeup-latency" --rate "$rate" --seconds "$baseline" --cpus "$daemon_cpu" \
      "${rtargs[@]}" > "$raw/$tag.baseline.json"
  fi
  echo "[rt_report] $tag: daemon on CPU $daemon_cpu, feeder on CPU $feeder_cpu, $minutes min ..." >&2
  taskset -c "$daemon_cpu" "$bin/hoist-twind" --config "$cfg" --lcm-url "$url" --cpus "$daemon_cpu" \
    "${rtargs[@]}" --report "$raw/$tag.json" --log-level warn 2> "$raw/$tag.daemon.log" &
  daemon_pid=$!
  sleep 2
  steal0=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
  set +e
  taskset -c "$feeder_cpu" "$bin/hoist-replay" --timing-test --lcm-url "$url" --channel-prefix rt/ \
    --rate "$rate" --duration "$secs" --max-misses 0 --report "$raw/$tag.timing.md" > "$raw/$tag.feeder.log"
  verdict=$?
  set -e
  steal1=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
  kill -TERM "$daemon_pid"
  wait "$daemon_pid" || true
  daemon_pid=""
  # Time the hypervisor ran something else on the daemon's CPU (steal), in s.
  python3 -c "print(($steal1 - $steal0) / $(getconf CLK_TCK))" > "$raw/$tag.steal"
  echo "[rt_report] $tag: timing test exit status $verdict, steal on CPU $daemon_cpu $(cat "$raw/$tag.steal") s" >&2
  args+=("$tag" "$raw/$tag.json" "$raw/$tag.timing.md")
done
python3 "$here/bench/rt_report.py" --title "Real-time report" --minutes "$minutes" \
  --command "bench/rt_report.sh $orig_args" --out-dir "$(dirname "$out")" "${args[@]}" > "$out"
echo "[rt_report] wrote $out" >&2
cat "$out"

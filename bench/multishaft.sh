#!/usr/bin/env bash
# Twins per core: one hoist-twind process hosting N shafts (100 Hz, n = 50
# modes each, every output on: cage state at 100 Hz, guide-rope shape at 5 Hz,
# health at 1 Hz, alarms), the whole process pinned to ONE CPU, fed by
# `hoist-replay --timing-test --shafts N` (N winder streams at 100 Hz, a hoist
# moving the whole time) on another CPU.  For each N it records deadline
# misses, tick lateness, step time and the CPU the process used, and writes
# docs/multishaft-report.md with the largest N that ran without a miss.
#
#   bench/multishaft.sh [--counts "50 100 200 300"] [--seconds S] [--modes N] [--rate HZ]
#                       [--max-step S] [--daemon-cpu C] [--feeder-cpu C] [--no-rt] [--out FILE] [--port P]
#
# Defaults: counts "100 200 300 400", 60 s each, n = 50, 100 Hz, [service]
# max_step 0.01 s (one model step per tick, the paper's step: within 2 % of
# the reference solution from a static start; the daemon's default 2.5 ms
# substeps cost four steps per tick, --max-step 0.0025), daemon on
# the last CPU with --mlockall --rt-priority 80 (reported, not fatal, when
# refused), feeder on CPU 0, UDP multicast on loopback port 7880 (ttl=0).
set -euo pipefail
orig_args="$*"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
counts="100 200 300 400"
seconds=60
modes=50
rate=100
max_step=0.01
rt=1
ncpu=$(nproc)
daemon_cpu=$((ncpu > 1 ? ncpu - 1 : 0))
feeder_cpu=0
out="$here/docs/multishaft-report.md"
port=7880
while [[ $# -gt 0 ]]; do
  case "$1" in
    --counts) counts="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --modes) modes="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --max-step) max_step="$2"; shift 2 ;;
    --daemon-cpu) daemon_cpu="$2"; shift 2 ;;
    --feeder-cpu) feeder_cpu="$2"; shift 2 ;;
    --no-rt) rt=0; shift ;;
    --out) out="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "multishaft.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
bin="$here/build/bin"
for b in hoist-twind hoist-replay; do
  [[ -x "$bin/$b" ]] || { echo "multishaft.sh: $bin/$b not found; build first (scripts/setup.sh)" >&2; exit 2; }
done
url="udpm://239.255.76.67:$port?ttl=0"
raw="$out.d"
mkdir -p "$raw"
rtargs=()
[[ $rt -eq 1 ]] && rtargs=(--mlockall --rt-priority 80)
clk=$(getconf CLK_TCK)
daemon_pid=""
cleanup() { [[ -n "$daemon_pid" ]] && kill -TERM "$daemon_pid" 2>/dev/null || true; }
trap cleanup EXIT INT TERM

rows=()
for N in $counts; do
  cfgdir="$raw/configs-$N"
  rm -rf "$cfgdir"; mkdir -p "$cfgdir"
  cfgs=()
  for ((i = 1; i <= N; i++)); do
    printf '[model]\nmodes = %s\n[service]\nrate = %s.0\nmax_step = %s\nchannel_prefix = "shaft%d/"\n' \
      "$modes" "$rate" "$max_step" "$i" > "$cfgdir/shaft$i.toml"
    cfgs+=(--config "$cfgdir/shaft$i.toml")
  done
  echo "[multishaft] N = $N: daemon (all threads) on CPU $daemon_cpu, feeder on CPU $feeder_cpu, $seconds s ..." >&2
  taskset -c "$daemon_cpu" "$bin/hoist-twind" "${cfgs[@]}" --lcm-url "$url" --cpus "$daemon_cpu" "${rtargs[@]}" \
    --report "$raw/N$N.json" --log-level warn 2> "$raw/N$N.daemon.log" &
  daemon_pid=$!
  sleep 3
  read -r -a st0 < <(cut -d' ' -f14,15 "/proc/$daemon_pid/stat")
  steal0=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
  t0=$(date +%s.%N)
  set +e
  taskset -c "$feeder_cpu" "$bin/hoist-replay" --timing-test --lcm-url "$url" --shafts "$N" --rate "$rate" \
    --duration "$seconds" --max-misses 0 --quiet --report "$raw/N$N.timing.md" > "$raw/N$N.feeder.log"
  verdict=$?
  set -e
  read -r -a st1 < <(cut -d' ' -f14,15 "/proc/$daemon_pid/stat")
  steal1=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
  t1=$(date +%s.%N)
  kill -TERM "$daemon_pid"
  wait "$daemon_pid" || true
  daemon_pid=""
  cpu=$(python3 -c "print(f'{100.0 * ((${st1[0]} + ${st1[1]}) - (${st0[0]} + ${st0[1]})) / $clk / ($t1 - $t0):.0f}')")
  steal=$(python3 -c "print(f'{($steal1 - $steal0) / $clk:.2f}')")
  echo "[multishaft] N = $N: timing test exit $verdict, daemon CPU $cpu %, steal $steal s" >&2
  rows+=("$N" "$raw/N$N.json" "$raw/N$N.timing.md" "$cpu/$steal")
done
python3 "$here/bench/multishaft_report.py" --max-step "$max_step" --command "bench/multishaft.sh $orig_args" --seconds "$seconds" \
  --out-dir "$(dirname "$out")" "${rows[@]}" > "$out"
echo "[multishaft] wrote $out" >&2
cat "$out"

#!/usr/bin/env bash
# Twins per core: one hoist-twind process hosting N shafts (100 Hz, every
# output on: cage state at 100 Hz, guide-rope shape at 5 Hz, health at 1 Hz,
# alarms), the whole process pinned to ONE CPU, fed by
# `hoist-replay --timing-test --shafts N` (N winder streams at 100 Hz, a hoist
# moving the whole time) on another CPU.  For each setting (modes, static
# correction), each N and each daemon binary it records deadline misses, tick
# lateness, step time, the CPU the process used, inputs lost (sequence gaps,
# and the kernel's drops on the daemon's input socket) and the daemon's own
# cost split, and writes docs/multishaft-report.md.
#
#   bench/multishaft.sh [--counts "100 200 300"] [--seconds S] [--setting MODES:on|off ...]
#                       [--daemon NAME=PATH[,key=value...] ...] [--feeder PATH] [--rate HZ] [--max-step S]
#                       [--daemon-cpu C] [--feeder-cpu C] [--no-rt] [--feeder-rt] [--perf NAME]
#                       [--same-url] [--no-watch] [--out FILE] [--port P]
#
# --setting (repeatable; default 50:off and 25:on: the paper's n without the
#   static correction, and the converged setting with it): n modes
#   and [model] static_correction.
# --daemon (repeatable; default this=build/bin/hoist-twind): the binaries to
#   compare, each run side by side (interleaved) for every setting and N; extra
#   key=value pairs go into the [service] section of its configs (e.g.
#   envelope_tolerance=0), except forecast=true, which turns the look-ahead
#   forecasts on ([forecast] enabled; without it every config says
#   enabled = false, as the daemon's default is on), and estimator=true, which turns the load
#   estimator on ([estimator] enabled; the feeder sends no sensor samples, so
#   this is the cost of its per-tick step without the O(1) updates), and
#   history=true, which records every trip ([history] enabled: the trip
#   room's per-tick copy and its workers; without it every config says
#   enabled = false, as the daemon's default is on with a config file).  The feeder (--feeder PATH; default this build's
#   hoist-replay) is the same for every daemon.
# Defaults: counts "100 200 300 400", 60 s each, 100 Hz, [service] max_step
# 0.01 s (one model step per tick), outputs to [service] lcm_url_out on port
# P+1 (--same-url: on the input URL, as without lcm_url_out), daemon on the last
# CPU with --mlockall --rt-priority 80 (reported, not fatal, when refused),
# feeder on CPU 0 (--feeder-rt: with SCHED_FIFO 50, so that a busy CPU 0 does
# not make it late: a late feeder's bunched inputs fail the daemon's
# consistency check and show up as rejected), UDP multicast on loopback port
# P = 7880 (ttl=0).  --perf NAME: `perf record -e cpu-clock` on daemon NAME
# for the middle half of each of its runs; the report lists its hottest symbols.
# Every run also has a bare-machine watcher on the daemon's CPU
# (build/bin/hoist-wakeup-latency at the same rate, SCHED_FIFO 90, no work):
# the deadlines the machine itself missed during that very run, i.e. the
# platform's stalls that no daemon can avoid (--no-watch: without it).
set -euo pipefail
orig_args="$*"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
counts="100 200 300 400"
seconds=60
settings=()
daemons=()
feeder="$here/build/bin/hoist-replay"
rate=100
max_step=0.01
rt=1
feeder_rt=0
perf_name=""
same_url=0
watch=1
ncpu=$(nproc)
daemon_cpu=$((ncpu > 1 ? ncpu - 1 : 0))
feeder_cpu=0
out="$here/docs/multishaft-report.md"
port=7880
while [[ $# -gt 0 ]]; do
  case "$1" in
    --counts) counts="$2"; shift 2 ;;
    --seconds) seconds="$2"; shift 2 ;;
    --setting) settings+=("$2"); shift 2 ;;
    --modes) settings+=("$2:on"); shift 2 ;;
    --daemon) daemons+=("$2"); shift 2 ;;
    --feeder) feeder="$2"; shift 2 ;;
    --rate) rate="$2"; shift 2 ;;
    --max-step) max_step="$2"; shift 2 ;;
    --daemon-cpu) daemon_cpu="$2"; shift 2 ;;
    --feeder-cpu) feeder_cpu="$2"; shift 2 ;;
    --no-rt) rt=0; shift ;;
    --feeder-rt) feeder_rt=1; shift ;;
    --perf) perf_name="$2"; shift 2 ;;
    --same-url) same_url=1; shift ;;
    --no-watch) watch=0; shift ;;
    --out) out="$2"; shift 2 ;;
    --port) port="$2"; shift 2 ;;
    -h|--help) sed -n '2,37p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "multishaft.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
[[ ${#settings[@]} -eq 0 ]] && settings=("50:off" "25:on")
[[ ${#daemons[@]} -eq 0 ]] && daemons=("this=$here/build/bin/hoist-twind")
for s in "${settings[@]}"; do
  [[ "$s" =~ ^[0-9]+:(on|off)$ ]] || { echo "multishaft.sh: --setting: MODES:on|off, got '$s'" >&2; exit 2; }
done
watcher="$here/build/bin/hoist-wakeup-latency"
if [[ $watch -eq 1 && ! -x "$watcher" ]]; then
  echo "multishaft.sh: $watcher not found (build the bench targets, or --no-watch)" >&2; exit 2
fi
[[ -x "$feeder" ]] || { echo "multishaft.sh: $feeder not found; build first (scripts/setup.sh)" >&2; exit 2; }
for d in "${daemons[@]}"; do
  [[ "$d" == *=* ]] || { echo "multishaft.sh: --daemon: NAME=PATH[,key=value...], got '$d'" >&2; exit 2; }
  p="${d#*=}"; p="${p%%,*}"
  [[ -x "$p" ]] || { echo "multishaft.sh: --daemon: $p is not an executable" >&2; exit 2; }
done
url="udpm://239.255.76.67:$port?ttl=0"
url_out="udpm://239.255.76.67:$((port + 1))?ttl=0"
raw="$out.d"
mkdir -p "$raw"
rtargs=()
[[ $rt -eq 1 ]] && rtargs=(--mlockall --rt-priority 80)
outargs=()
[[ $same_url -eq 0 ]] && outargs=(--lcm-url-out "$url_out")
clk=$(getconf CLK_TCK)
daemon_pid=""
cleanup() { [[ -n "$daemon_pid" ]] && kill -TERM "$daemon_pid" 2>/dev/null || true; }
trap cleanup EXIT INT TERM

rows=()
for setting in "${settings[@]}"; do
  modes="${setting%%:*}"
  corr="${setting##*:}"
  corr_toml=$([[ $corr == on ]] && echo true || echo false)
  for N in $counts; do
    for d in "${daemons[@]}"; do
      name="${d%%=*}"
      spec="${d#*=}"
      bin="${spec%%,*}"
      extra=""
      est_section=""
      # Forecasts off unless forecast=true (they default to on in the daemon)
      fc_section="[forecast]"$'\n'"enabled = false"$'\n'
      # The trip history off unless history=true (on by default with a config file)
      hist_section="[history]"$'\n'"enabled = false"$'\n'
      if [[ "$spec" == *,* ]]; then
        IFS=',' read -r -a kvs <<< "${spec#*,}"
        for kv in "${kvs[@]}"; do
          # estimator=true: the load estimator on ([estimator] enabled, its own section)
          if [[ "${kv%%=*}" == estimator ]]; then est_section="[estimator]"$'\n'"enabled = ${kv#*=}"$'\n'; continue; fi
          # forecast=true: the look-ahead forecasts on ([forecast] enabled, the defaults otherwise)
          if [[ "${kv%%=*}" == forecast ]]; then fc_section="[forecast]"$'\n'"enabled = ${kv#*=}"$'\n'; continue; fi
          # history=true: every trip recorded ([history] enabled, history.sqlite in the configs' folder)
          if [[ "${kv%%=*}" == history ]]; then hist_section="[history]"$'\n'"enabled = ${kv#*=}"$'\n'; continue; fi
          extra+="${kv%%=*} = ${kv#*=}"$'\n'
        done
      fi
      tag="n${modes}${corr}-N$N-$name"
      cfgdir="$raw/configs-$tag"
      rm -rf "$cfgdir"; mkdir -p "$cfgdir"
      cfgs=()
      outline=""
      [[ $same_url -eq 0 ]] && outline="lcm_url_out = \"$url_out\""$'\n'
      for ((i = 1; i <= N; i++)); do
        printf '[model]\nmodes = %s\nstatic_correction = %s\n[service]\nrate = %s.0\nmax_step = %s\nchannel_prefix = "shaft%d/"\n%s%s%s%s%s' \
          "$modes" "$corr_toml" "$rate" "$max_step" "$i" "$outline" "$extra" "$est_section" "$fc_section" "$hist_section" > "$cfgdir/shaft$i.toml"
        cfgs+=(--config "$cfgdir/shaft$i.toml")
      done
      echo "[multishaft] n = $modes (correction $corr), N = $N, daemon $name: daemon (all threads) on CPU $daemon_cpu, feeder on CPU $feeder_cpu, $seconds s ..." >&2
      # --force: run even when the daemon's start-up measurement says the
      # ticks will not fit (an overloaded count is a result too).
      taskset -c "$daemon_cpu" "$bin" "${cfgs[@]}" --lcm-url "$url" --cpus "$daemon_cpu" "${rtargs[@]}" --force \
        --report "$raw/$tag.json" --log-level warn 2> "$raw/$tag.daemon.log" &
      daemon_pid=$!
      sleep 3
      if [[ ! -e "/proc/$daemon_pid/stat" ]]; then
        echo "[multishaft] $tag: the daemon exited at start (see $raw/$tag.daemon.log)" >&2
        wait "$daemon_pid" || true
        daemon_pid=""
        rm -rf "$cfgdir"
        continue
      fi
      read -r -a st0 < <(cut -d' ' -f14,15 "/proc/$daemon_pid/stat")
      steal0=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
      t0=$(date +%s.%N)
      set +e
      perf_pid=""
      if [[ -n "$perf_name" && "$name" == "$perf_name" ]] && command -v perf > /dev/null; then
        (sleep "$(python3 -c "print($seconds / 4)")"
         exec perf record -q -e cpu-clock -F 499 -p "$daemon_pid" -o "$raw/$tag.perf.data" -- sleep "$(python3 -c "print($seconds / 2)")") \
          > /dev/null 2>&1 &
        perf_pid=$!
      fi
      watch_pid=""
      rm -f "$raw/$tag.bare.json"
      if [[ $watch -eq 1 ]]; then
        wrt=()
        [[ $rt -eq 1 ]] && wrt=(--mlockall --rt-priority 90)
        taskset -c "$daemon_cpu" "$watcher" --rate "$rate" --seconds "$seconds" --cpus "$daemon_cpu" "${wrt[@]}" \
          > "$raw/$tag.bare.json" 2> /dev/null &
        watch_pid=$!
      fi
      frt=()
      [[ $feeder_rt -eq 1 ]] && frt=(chrt -f 50)
      taskset -c "$feeder_cpu" "${frt[@]}" "$feeder" --timing-test --lcm-url "$url" "${outargs[@]}" --shafts "$N" --rate "$rate" \
        --duration "$seconds" --max-misses 0 --quiet --report "$raw/$tag.timing.md" > "$raw/$tag.feeder.log"
      verdict=$?
      [[ -n "$watch_pid" ]] && { wait "$watch_pid" || true; }
      set -e
      if [[ -n "$perf_pid" ]]; then
        wait "$perf_pid" || true
        perf report -i "$raw/$tag.perf.data" --stdio --no-children --sort symbol --percent-limit 1 2> /dev/null \
          | grep -E '^ +[0-9.]+%' > "$raw/$tag.perf.txt" || true
        rm -f "$raw/$tag.perf.data" "$raw/$tag.perf.data.old"
      fi
      read -r -a st1 < <(cut -d' ' -f14,15 "/proc/$daemon_pid/stat")
      steal1=$(awk -v c="cpu$daemon_cpu" '$1 == c {print $9}' /proc/stat)
      t1=$(date +%s.%N)
      kill -TERM "$daemon_pid"
      wait "$daemon_pid" || true
      daemon_pid=""
      # The report's per-shaft histograms (bins) make it megabytes at
      # hundreds of shafts; the summary does not read them: keep it compact.
      python3 - "$raw/$tag.json" <<'PY' || true
import json, sys
p = sys.argv[1]
try:
    r = json.load(open(p))
except (OSError, ValueError):
    sys.exit(0)
def strip(o):
    if isinstance(o, dict):
        o.pop("bins", None)
        for v in o.values(): strip(v)
    elif isinstance(o, list):
        for v in o: strip(v)
strip(r)
json.dump(r, open(p, "w"), separators=(",", ":"))
PY
      cpu=$(python3 -c "print(f'{100.0 * ((${st1[0]} + ${st1[1]}) - (${st0[0]} + ${st0[1]})) / $clk / ($t1 - $t0):.0f}')")
      steal=$(python3 -c "print(f'{($steal1 - $steal0) / $clk:.2f}')")
      echo "[multishaft] $tag: timing test exit $verdict, daemon CPU $cpu %, steal $steal s;" \
        "$(python3 "$here/bench/multishaft_report.py" --row-summary "$raw/$tag.json")" >&2
      rm -rf "$cfgdir"
      rows+=("$name" "$modes:$corr" "$N" "$raw/$tag.json" "$raw/$tag.timing.md" "$cpu/$steal")
    done
  done
done
python3 "$here/bench/multishaft_report.py" --max-step "$max_step" --command "bench/multishaft.sh $orig_args" \
  --seconds "$seconds" --out-dir "$(dirname "$out")" --same-url "$same_url" --feeder-rt "$feeder_rt" "${rows[@]}" > "$out"
echo "[multishaft] wrote $out" >&2
cat "$out"

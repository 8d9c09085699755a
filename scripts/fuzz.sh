#!/usr/bin/env bash
# Build the libFuzzer targets (fuzz/, clang, ASan+UBSan) into build-fuzz and
# run each for a set time, one after the other (one core each).
#
#   scripts/fuzz.sh [--time S] [--jobs N] [--build-dir DIR] [--no-build] [TARGET...]
#
# --jobs N runs N targets side by side (default 1; each still gets --time S of
# wall time, so give each a core of its own: N <= nproc).
# Targets: config (TOML loader), csv (profile CSV reader), winder (LCM input
# decoder + validator + TwinCore), msgs (every LCM type of msgs/ through the
# generated checked decoders and JSON), lcmlog (the safe LCM log reader),
# msg_<type> (one per msgs/<type>.lcm: that decoder alone, seeded with
# fuzz/corpus/msgs/<type>_*), types (all the msg_<type> targets).
# Default: config csv winder msgs lcmlog and every msg_<type>, 600 s each.  The seed
# corpus is fuzz/corpus/<target>/ (committed); new inputs go to
# BUILD/corpus/<target>/, crashes to BUILD/artifacts/<target>/, logs to
# BUILD/logs/<target>.log.  Prints executions and coverage per target; exit
# status 1 if any target found a crash, leak or timeout.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
time_s=600; jobs=1; build_dir="$here/build-fuzz"; build=1; targets=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --time) time_s="$2"; shift 2 ;;
    --jobs) jobs="$2"; shift 2
      [[ $jobs =~ ^[1-9][0-9]*$ ]] || { echo "fuzz.sh: --jobs wants a positive integer, got '$jobs'" >&2; exit 2; } ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    --no-build) build=0; shift ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    config|csv|winder|msgs|lcmlog) targets+=("$1"); shift ;;
    types) for f in "$here"/msgs/*.lcm; do b=$(basename "$f" .lcm); targets+=("msg_$b"); done; shift ;;
    msg_*)
      [[ -f "$here/msgs/${1#msg_}.lcm" ]] || { echo "fuzz.sh: no type msgs/${1#msg_}.lcm for target $1" >&2; exit 2; }
      targets+=("$1"); shift ;;
    *) echo "fuzz.sh: unknown option or target $1 (see --help)" >&2; exit 2 ;;
  esac
done
if [[ ${#targets[@]} -eq 0 ]]; then
  targets=(config csv winder msgs lcmlog)
  for f in "$here"/msgs/*.lcm; do targets+=("msg_$(basename "$f" .lcm)"); done
fi
if [[ $build -eq 1 ]]; then
  command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found" >&2; exit 2; }
  CC=clang CXX=clang++ cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DHOIST_FUZZ=ON \
    -DHOIST_BUILD_TESTS=OFF -DHOIST_BUILD_BENCH=OFF >/dev/null
  cmake --build "$build_dir" -j"$(nproc)" --target $(printf 'fuzz_%s ' "${targets[@]}")
fi
declare -A max_len=([config]=4096 [csv]=8192 [winder]=2048 [msgs]=4096 [lcmlog]=8192)
for t in "${targets[@]}"; do [[ $t == msg_* ]] && max_len[$t]=4096; done
run_one() {   # run_one TARGET: fuzz it, write BUILD/logs/TARGET.line, exit status 1 on a finding
  local t="$1" log seeds st execs last cov ft corp eps line
  mkdir -p "$build_dir/corpus/$t" "$build_dir/artifacts/$t" "$build_dir/logs"
  log="$build_dir/logs/$t.log"
  seeds="$here/fuzz/corpus/$t"
  if [[ $t == msg_* ]]; then   # that type's seeds out of the msgs corpus
    seeds="$build_dir/seeds/$t"; mkdir -p "$seeds"
    cp "$here/fuzz/corpus/msgs/${t#msg_}"_* "$seeds"/ 2>/dev/null || true
  fi
  echo "[fuzz] $t for $time_s s (log $log)"
  set +e
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build_dir/bin/fuzz_$t" -max_total_time="$time_s" -max_len="${max_len[$t]}" -timeout=10 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$build_dir/artifacts/$t/" \
    "$build_dir/corpus/$t" "$seeds" >"$log" 2>&1
  st=$?
  set -e
  execs=$(awk '/stat::number_of_executed_units/{print $NF}' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last"); ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  corp=$(sed -n 's/.* corp: \([0-9]*\/[0-9]*[a-zA-Z]*\).*/\1/p' <<<"$last")
  eps=$(awk '/stat::average_exec_per_sec/{print $NF}' "$log" | tail -1)
  line="$t: status $st, ${execs:-?} executions (${eps:-?}/s), coverage ${cov:-?} edges, ${ft:-?} features, corpus ${corp:-?}"
  echo "$line" >"$build_dir/logs/$t.line"
  echo "[fuzz] $line"
  if [[ $st -ne 0 ]] || ls "$build_dir/artifacts/$t"/* >/dev/null 2>&1; then
    echo "[fuzz] $t FOUND A PROBLEM: see $log and $build_dir/artifacts/$t/" >&2
    echo found >"$build_dir/logs/$t.status"
  else
    echo clean >"$build_dir/logs/$t.status"
  fi
}
for t in "${targets[@]}"; do rm -f "$build_dir/logs/$t.line" "$build_dir/logs/$t.status"; done
for t in "${targets[@]}"; do
  while [[ $(jobs -rp | wc -l) -ge $jobs ]]; do wait -n || true; done
  run_one "$t" &
done
wait
rc=0
summary=""
for t in "${targets[@]}"; do
  summary+="$(cat "$build_dir/logs/$t.line" 2>/dev/null || echo "$t: no result")"$'\n'
  [[ $(cat "$build_dir/logs/$t.status" 2>/dev/null) == clean ]] || rc=1
done
printf '%s' "$summary" >"$build_dir/logs/summary.txt"
echo "[fuzz] summary:"; cat "$build_dir/logs/summary.txt"
exit $rc

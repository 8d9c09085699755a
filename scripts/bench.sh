#!/usr/bin/env bash
# Runs the model benchmarks (Google Benchmark) side by side in one run and
# writes docs/benchmarks.md: step time of the fast and paper paths against n,
# their ratio, the fitted growth exponent, and the whole paper case.
#
#   scripts/bench.sh [--repetitions N] [--quick]
#
# Medians over N repetitions (default 5).  --quick: 2 repetitions, short min time.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
reps=5
extra=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --repetitions) reps="$2"; shift 2 ;;
    --quick) reps=2; extra+=(--benchmark_min_time=0.05); shift ;;
    -h|--help) sed -n '2,9p' "$0"; exit 0 ;;
    *) echo "bench.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
bin="$here/build/bin/hoist-bench"
if [[ ! -x "$bin" ]]; then
  echo "bench.sh: $bin not found; build first (scripts/setup.sh)" >&2
  exit 2
fi
# The raw results stay in build/ (re-format with scripts/bench_report.py).
json="$here/build/bench.json"
echo "running $bin ($reps repetitions; a few minutes) ..." >&2
"$bin" --benchmark_repetitions="$reps" --benchmark_report_aggregates_only=true \
  --benchmark_out="$json" --benchmark_out_format=json "${extra[@]}" >&2
python3 "$here/scripts/bench_report.py" "$json" > "$here/docs/benchmarks.md"
echo "wrote docs/benchmarks.md" >&2
cat "$here/docs/benchmarks.md"

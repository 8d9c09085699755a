#!/bin/sh
# Converged lateral reference WITHOUT the static correction for the cases
# c1-paper (static start) and c1-paper-rest (rest start), by Richardson
# extrapolation in the number of modes: the truncation error of the sine
# series falls as 1/n, so  y_inf = 2 y(n = 400) - y(n = 200).
# Generated once (about a minute per case on one core) and committed;
# tests/model/static_correction_test.cpp compares the corrected n = 20 model
# against it.
#
#   tests/data/c1-converged/generate.sh [path/to/hoist-sim]
#
# Both runs: dt = 0.01 s output, 2.5 ms integration substeps (hoist-sim's
# default), the fast path, --static-correction off.  Output: static.csv and
# rest.csv with t,y_c,theta,lambda_1..lambda_4 every 0.02 s.
set -eu
SIM=${1:-build/bin/hoist-sim}
D=$(cd "$(dirname "$0")" && pwd)
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
for c in c1-paper:static c1-paper-rest:rest; do
  name=${c%%:*}
  init=${c##*:}
  for n in 200 400; do
    "$SIM" --config "$D/../$name/shaft.toml" --profile "$D/../$name/profile.csv" --modes "$n" \
      --static-correction off --initial "$init" --dt 0.01 --max-step 0.0025 --out "$T/$init-$n.csv" -q
  done
  python3 "$D/richardson.py" "$T/$init-200.csv" "$T/$init-400.csv" "$D/$init.csv"
done

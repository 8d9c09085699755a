#!/bin/sh
# The corrected model's convergence in n against the converged references
# (tests/data/c1-converged): the error table of docs/model.md ("Dynamics
# against a converged model"), errors.csv, and the rest-start figure
# rest_start.png (gnuplot).  About 20 s of CPU.
#
#   docs/figures/convergence/convergence.sh [path/to/hoist-sim]
#
# Runs hoist-sim's defaults (output every 0.01 s, 2.5 ms substeps) for the
# paper's two cases at several n, with the correction on and off.
set -eu
SIM=${1:-build/bin/hoist-sim}
D=$(cd "$(dirname "$0")" && pwd)
DATA="$D/../../../tests/data"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
run() {  # case init n corr out
  "$SIM" --config "$DATA/$1/shaft.toml" --profile "$DATA/$1/profile.csv" --modes "$3" --static-correction "$4" \
    --initial "$2" --dt 0.01 --max-step 0.0025 --out "$5" -q
}
for n in 5 10 20 25 30 50 100; do
  run c1-paper static "$n" on "$T/static-$n-on.csv"
  run c1-paper-rest rest "$n" on "$T/rest-$n-on.csv"
done
for n in 20 50; do
  run c1-paper static "$n" off "$T/static-$n-off.csv"
  run c1-paper-rest rest "$n" off "$T/rest-$n-off.csv"
done
python3 "$D/convergence.py" "$T" "$D"
if command -v gnuplot > /dev/null; then
  (cd "$D" && gnuplot rest_start.gp)
else
  echo "gnuplot not found: rest_start.png not redrawn" >&2
fi

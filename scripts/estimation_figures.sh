#!/usr/bin/env bash
# The figures of docs/estimation.md: a truth (the paper trip at n = 200 with a
# load the twin's config does not know) read by the sensors with seeded
# noise, estimated at n = 25 by hoist-estimate, plotted by gnuplot.
#
#   scripts/estimation_figures.sh [BUILD_DIR]      (default: build)
#
# Writes docs/figures/estimation/{loads,theta,nis}.png.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bin="${1:-$here/build}/bin"
out="$here/docs/figures/estimation"
mkdir -p "$out"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
command -v gnuplot >/dev/null || { echo "estimation_figures.sh: gnuplot not found" >&2; exit 1; }

printf '[load]\neccentric_force = 1500.0\noffset = 0.6\n' > "$work/truth.toml"
# A calibrated accelerometer (the truth's has no offset): the figures show
# what the sensors' white noise leaves; the default (imu_accel_offset_sigma
# 0.005) widens M's band to about 4 % (docs/estimation.md).
printf '[model]\nmodes = 25\n[sensors]\nimu_accel_offset_sigma = 0\n' > "$work/twin.toml"
echo "[figures] truth: paper trip, Fa = 1500 N at b = 0.6 m, n = 200 (the twin's config: 1000 N at 1 m)"
"$bin/hoist-sim" --config "$work/truth.toml" --profile paper --modes 200 --out "$work/truth.csv" \
  --write-measurements "$work/measurements.csv" --sensor-noise 0.002,0.0001,20 --seed 1 -q
echo "[figures] estimate at n = 25"
"$bin/hoist-estimate" --config "$work/twin.toml" --measurements "$work/measurements.csv" --out "$work/estimate.csv"

gnuplot <<GP
set datafile separator ','
set terminal pngcairo size 1000,700 font 'DejaVu Sans,11'
set key autotitle columnhead
set grid
set output '$out/loads.png'
set multiplot layout 2,1 title 'Load estimated from a rope load cell and a cage IMU (n = 25) against the truth (n = 200)'
set ylabel 'Fa [N]'
set yrange [1400:1600]
plot '$work/estimate.csv' using 1:(\$3-2*\$6):(\$3+2*\$6) with filledcurves lc rgb '#c6dbef' title '+-2 sigma', \
     '' using 1:3 with lines lw 2 lc rgb '#08519c' title 'Fa estimated', \
     1500 with lines dt 2 lw 2 lc rgb 'black' title 'true 1500 N', \
     1000 with lines dt 3 lc rgb '#a50f15' title 'configured 1000 N'
set ylabel 'M = Fa b [N m]'
set xlabel 't [s]'
set yrange [700:1100]
plot '$work/estimate.csv' using 1:(\$5-2*\$7):(\$5+2*\$7) with filledcurves lc rgb '#c7e9c0' title '+-2 sigma', \
     '' using 1:5 with lines lw 2 lc rgb '#006d2c' title 'M estimated', \
     900 with lines dt 2 lw 2 lc rgb 'black' title 'true 900 N m', \
     1000 with lines dt 3 lc rgb '#a50f15' title 'configured 1000 N m'
unset multiplot
set output '$out/theta.png'
set title 'Cage tilt: estimated (+-2 sigma), open loop (configured load) and true'
set xlabel 't [s]'
set ylabel 'theta [mrad]'
set autoscale y
plot '$work/estimate.csv' using 1:(1e3*(\$9-2*\$11)):(1e3*(\$9+2*\$11)) with filledcurves lc rgb '#c6dbef' title '+-2 sigma', \
     '' using 1:(1e3*\$9) with lines lw 2 lc rgb '#08519c' title 'estimated', \
     '$work/truth.csv' using 1:(1e3*column('theta')) with lines lw 1 lc rgb 'black' title 'true (n = 200)', \
     '$work/estimate.csv' using 1:(1e3*column('theta_open')) with lines dt 2 lc rgb '#a50f15' title 'open loop'
set output '$out/nis.png'
set title 'Model check: windowed NIS against its bounds (MODEL_MISMATCH above the bound)'
set ylabel 'NIS over 5 s'
plot '$work/estimate.csv' using 1:(column('nis_window')) with lines lw 2 lc rgb '#08519c' title 'NIS window', \
     '' using 1:(column('nis_lower')) with lines dt 2 lc rgb 'gray' title '95 % bounds', \
     '' using 1:(column('nis_upper')) with lines dt 2 lc rgb 'gray' notitle, \
     '' using 1:(column('nis_bound')) with lines lw 2 lc rgb '#a50f15' title 'MODEL_MISMATCH bound'
GP
echo "[figures] wrote $out/{loads,theta,nis}.png"

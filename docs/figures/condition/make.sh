#!/bin/bash
# docs/condition.md's figures: 8 recorded runs (each down 250 m and up again,
# 100 Hz, hoist-sim's default sensor noise: IMU 0.002 m/s^2) of a truth at
# n = 20 whose guide-rope preload is nominal for 4 runs, then 30 % low, with
# a different eccentric load each run; each run ingested by hoist-trips
# through the trip pipeline into an SQLite history (the twin at n = 10 with
# the nominal preload: twind.toml), then the trend and the depth map drawn.
#   docs/figures/condition/make.sh [BUILD_DIR]     (about a minute)
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
B="$(cd "${1:-$here/../../../build}" && pwd)/bin"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cd "$work"
python3 - <<'PY'
dt, amax, vmax, travel, rest = 0.01, 1.0, 5.0, 250.0, 4.0
ta = vmax / amax; tc = (travel - vmax * ta) / vmax; trip = 2 * ta + tc
total = 3 * rest + 2 * trip
with open("profile.csv", "w") as f:
    f.write("t,v,a\n")
    i = 0
    while i * dt <= total + 1e-9:
        t = i * dt; v = a = 0.0; sign = 1.0; u = -1.0
        if rest < t < rest + trip: u = t - rest
        elif 2 * rest + trip < t < 2 * rest + 2 * trip: u = t - 2 * rest - trip; sign = -1.0
        if u >= 0:
            if u < ta: v, a = amax * u, amax
            elif u < ta + tc: v = vmax
            else: v, a = max(0.0, vmax - amax * (u - ta - tc)), -amax
        f.write(f"{t:.2f},{sign * v:.6f},{sign * a:.6f}\n")
        i += 1
PY
loads=("2000 1.0" "1500 -0.8" "3000 0.5" "2500 -1.0" "2000 0.8" "1800 -0.6" "3000 1.0" "2200 -0.9")
for k in 0 1 2 3 4 5 6 7; do
  set -- ${loads[$k]}
  pre=30000.0; [ $k -ge 4 ] && pre=21000.0
  printf '[guide_ropes]\npreload = [%s, %s]\n[load]\neccentric_force = %s\noffset = %s\n' $pre $pre $1 $2 > truth$k.toml
  "$B/hoist-sim" --config truth$k.toml --profile profile.csv --modes 20 --write-measurements meas$k.csv \
    --seed $((k + 1)) -q --out /dev/null
  "$B/hoist-trips" ingest --config "$here/twind.toml" --measurements meas$k.csv --db demo.sqlite \
    --wall-start 2026-12-0$((k + 1))T08:00:00Z -q
done
"$B/hoist-trips" list --db demo.sqlite --format csv --out "$here/trips.csv"
"$B/hoist-trips" trend --db demo.sqlite --config "$here/twind.toml" --out trend.png
"$B/hoist-trips" depth-map --db demo.sqlite --out depth_map.png
cp trend.png depth_map.png "$here/"

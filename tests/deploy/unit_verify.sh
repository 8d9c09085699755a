#!/bin/sh
# systemd-analyze verify on hoist-twind@.service (an instance of it), with
# the unit's paths pointed at this build.  Any complaint fails the test;
# exit 77 (skipped) when systemd-analyze is not installed.
#   unit_verify.sh UNIT_TEMPLATE.in HOIST_TWIND WORK_DIR
set -u
in=$1 twind=$2 work=$3
command -v systemd-analyze >/dev/null 2>&1 || { echo "SKIP: systemd-analyze not installed"; exit 77; }
rm -rf "$work" && mkdir -p "$work" || exit 1
sed -e "s|@HOIST_BIN_DIR@|$(dirname "$twind")|g" -e "s|@HOIST_CONFIG_DIR@|$work|g" -e "s|@HOIST_DOC_DIR@|$work|g" \
    "$in" >"$work/hoist-twind@.service"
grep -n '@[A-Z_]*@' "$work/hoist-twind@.service" && { echo "FAIL: unsubstituted @VARIABLE@ left"; exit 1; }
cp "$work/hoist-twind@.service" "$work/hoist-twind@north.service"
touch "$work/north.toml"
out=$(cd "$work" && systemd-analyze verify --man=no ./hoist-twind@north.service 2>&1)
rc=$?
echo "$out"
[ $rc -eq 0 ] || { echo "FAIL: systemd-analyze verify exited $rc"; exit 1; }
[ -z "$out" ] || { echo "FAIL: systemd-analyze verify complained (above)"; exit 1; }
for key in Type=notify WatchdogSec= Restart=on-failure LimitRTPRIO= LimitMEMLOCK=infinity "--config $work/%i.toml"; do
  grep -q -- "$key" "$work/hoist-twind@.service" || { echo "FAIL: the unit lacks $key"; exit 1; }
done
echo "ok: hoist-twind@.service verifies"

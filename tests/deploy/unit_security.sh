#!/bin/sh
# The three units (hoist-twind@, hoist-mqtt@, hoist-dash@): each verifies, and
# `systemd-analyze security --offline=true` scores it <= 3.0; the daemon keeps
# real time (CAP_SYS_NICE, CAP_IPC_LOCK in its bounding set, LimitRTPRIO,
# LimitMEMLOCK, no RestrictRealtime); the bridge takes its password and TLS
# key as systemd credentials; no comment points into the source tree.
# Exit 77 (skipped) without systemd-analyze.
#   unit_security.sh SYSTEMD_DIR BIN_DIR WORK_DIR
set -u
units=$1 bin=$2 work=$3
command -v systemd-analyze >/dev/null 2>&1 || { echo "SKIP: systemd-analyze not installed"; exit 77; }
rm -rf "$work" && mkdir -p "$work/mqtt" "$work/dash" || exit 1
fail=0
for u in hoist-twind@ hoist-mqtt@ hoist-dash@; do
  f="$work/$u.service"
  sed -e "s|@HOIST_BIN_DIR@|$bin|g" -e "s|@HOIST_CONFIG_DIR@|$work|g" -e "s|@HOIST_DOC_DIR@|/usr/share/doc/hoist-twin|g" \
      "$units/$u.service.in" >"$f" || { echo "FAIL: $u.service.in missing"; fail=1; continue; }
  grep -n '@[A-Z_]*@' "$f" && { echo "FAIL: $u: unsubstituted @VARIABLE@"; fail=1; }
  grep -n 'tools/\|service/systemd\|\.\./' "$f" && { echo "FAIL: $u: a comment points into the source tree"; fail=1; }
  cp "$f" "$work/${u}site1.service"
  out=$(cd "$work" && systemd-analyze verify --man=no "./${u}site1.service" 2>&1 | grep -v "is not executable\|Assertion")
  [ -z "$out" ] || { echo "FAIL: $u: systemd-analyze verify: $out"; fail=1; }
  score=$(systemd-analyze security --offline=true --no-pager "$f" 2>/dev/null | sed -n 's/.*Overall exposure level for [^:]*: \([0-9.]*\).*/\1/p')
  echo "$u.service: exposure $score"
  [ -n "$score" ] || { echo "FAIL: $u: no exposure level"; fail=1; continue; }
  awk -v s="$score" 'BEGIN { exit !(s <= 3.0) }' || { echo "FAIL: $u: exposure $score > 3.0"; fail=1; }
  for key in "SystemCallFilter=@system-service" "ProtectSystem=strict" "PrivateTmp=yes" "ProtectClock=yes" \
             "ProtectProc=invisible" "MemoryDenyWriteExecute=yes" "CapabilityBoundingSet=" "NoNewPrivileges=yes"; do
    grep -qx "$key.*" "$f" || { echo "FAIL: $u lacks $key"; fail=1; }
  done
done
t="$work/hoist-twind@.service"
grep -qx "AmbientCapabilities=CAP_SYS_NICE CAP_IPC_LOCK" "$t" || { echo "FAIL: twind: AmbientCapabilities"; fail=1; }
grep -qx "CapabilityBoundingSet=CAP_SYS_NICE CAP_IPC_LOCK" "$t" || { echo "FAIL: twind: bounding set"; fail=1; }
grep -q "^LimitRTPRIO=" "$t" && grep -q "^LimitMEMLOCK=" "$t" || { echo "FAIL: twind: rlimits for real time"; fail=1; }
grep -q "^RestrictRealtime=yes" "$t" && { echo "FAIL: twind: RestrictRealtime would forbid --rt-priority"; fail=1; }
grep -q "^PrivateUsers=yes" "$t" && { echo "FAIL: twind: PrivateUsers voids its capabilities"; fail=1; }
m="$work/hoist-mqtt@.service"
grep -qx "LoadCredential=mqtt-password:$work/mqtt/%i.password" "$m" || { echo "FAIL: mqtt: LoadCredential for the password"; fail=1; }
grep -qx "LoadCredential=mqtt-tls-key:$work/mqtt/%i.key" "$m" || { echo "FAIL: mqtt: LoadCredential for the TLS key"; fail=1; }
grep -q "^SetCredential=mqtt-password:" "$m" && grep -q "^SetCredential=mqtt-tls-key:" "$m" ||
  { echo "FAIL: mqtt: no SetCredential= defaults (a missing file would fail the unit)"; fail=1; }
[ $fail -eq 0 ] && echo "ok: the three units verify and score <= 3.0"
exit $fail

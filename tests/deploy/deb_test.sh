#!/bin/sh
# cpack -G DEB: the package's control fields (name, version, Depends from
# dpkg-shlibdeps, conffiles, maintainer scripts) and file list, checked with
# dpkg-deb; its contents extracted into a scratch root run; apt resolves its
# dependencies (simulated: nothing is installed on this machine).
# Exit 77 (skipped) without dpkg-deb / dpkg-shlibdeps.
#   deb_test.sh BUILD_DIR VERSION WORK_DIR
set -u
build=$1 version=$2 work=$3
fail() { echo "FAIL: $*"; exit 1; }
command -v dpkg-deb >/dev/null 2>&1 && command -v dpkg-shlibdeps >/dev/null 2>&1 ||
  { echo "SKIP: dpkg-deb/dpkg-shlibdeps missing (package dpkg-dev)"; exit 77; }
rm -rf "$work" && mkdir -p "$work" || exit 1
(cd "$work" && cpack --config "$build/CPackConfig.cmake" -G DEB -B "$work/pkg") >"$work/cpack.log" 2>&1 ||
  { tail -40 "$work/cpack.log"; fail "cpack -G DEB"; }
deb=$(ls "$work"/pkg/hoist-twin_*.deb 2>/dev/null | head -1)
[ -n "$deb" ] || { tail -20 "$work/cpack.log"; fail "no hoist-twin_*.deb written"; }
echo "package: $(basename "$deb") ($(du -k "$deb" | cut -f1) kB)"
dpkg-deb --info "$deb" >"$work/info.txt" || fail "dpkg-deb --info"
cat "$work/info.txt"
field() { dpkg-deb --field "$deb" "$1"; }
[ "$(field Package)" = hoist-twin ] || fail "Package: $(field Package)"
[ "$(field Version)" = "$version" ] || fail "Version: $(field Version), expected $version"
[ -n "$(field Architecture)" ] || fail "no Architecture"
deps=$(field Depends)
for d in libc6 libstdc++6 liblcm1 libsystemd0; do
  echo "$deps" | grep -q "$d" || fail "Depends lacks $d (dpkg-shlibdeps): $deps"
done
echo "$deps" | grep -q -- "-dev" && fail "Depends names a -dev package: $deps"
echo "$(field Recommends)" | grep -q libjchart2d-java || fail "Recommends lacks libjchart2d-java (hoist-lcm-spy)"
dpkg-deb --ctrl-tarfile "$deb" | tar -t | grep -q conffiles || fail "no conffiles"
dpkg-deb --ctrl-tarfile "$deb" | tar -xO ./conffiles | grep -qx /etc/hoist-twin/example.toml ||
  fail "/etc/hoist-twin/example.toml is not a conffile"
dpkg-deb --contents "$deb" >"$work/contents.txt" || fail "dpkg-deb --contents"
for f in ./usr/bin/hoist-twind ./usr/bin/hoist-sim ./usr/bin/hoist-alarm-ack ./etc/hoist-twin/example.toml \
         ./usr/lib/systemd/system/hoist-twind@.service ./usr/share/hoist-twin/lcm/cage_state_t.lcm \
         ./usr/include/hoist/cage_state_t.hpp ./usr/share/doc/hoist-twin/README.md; do
  grep -q " $f\$" "$work/contents.txt" || fail "$f missing from the package"
done
grep -q "hoistConfig.cmake$" "$work/contents.txt" || fail "hoistConfig.cmake missing from the package"
if grep -q "/usr/local\|$(cd "$build" && pwd)" "$work/contents.txt"; then fail "the package holds /usr/local or build-tree paths"; fi
echo "ok: $(wc -l <"$work/contents.txt") entries, control fields as expected"
dpkg-deb -x "$deb" "$work/root" || fail "dpkg-deb -x"
"$work/root/usr/bin/hoist-twind" --version || fail "the packaged hoist-twind does not run"
grep -q "^ExecStart=/usr/bin/hoist-twind" "$work/root/usr/lib/systemd/system/hoist-twind@.service" ||
  fail "the packaged unit does not run /usr/bin/hoist-twind"
if command -v apt-get >/dev/null 2>&1; then
  apt-get install --simulate --no-install-recommends "$deb" >"$work/apt.log" 2>&1 ||
    { cat "$work/apt.log"; fail "apt-get cannot resolve the package's dependencies"; }
  echo "ok: apt-get --simulate install resolves it"
fi

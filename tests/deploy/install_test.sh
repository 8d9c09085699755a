#!/bin/sh
# `cmake --install` into a scratch root (DESTDIR, prefix /usr): the expected
# files are there, the installed unit names the installed paths, the
# installed programs run, and a tiny downstream project (consumer/) finds
# the package with find_package(hoist) and links hoist::model, hoist::io and
# hoist::msgs.
#   install_test.sh BUILD_DIR TEST_SOURCE_DIR WORK_DIR
set -u
build=$1 src=$2 work=$3
fail() { echo "FAIL: $*"; exit 1; }
rm -rf "$work" && mkdir -p "$work" || exit 1
root="$work/root"
DESTDIR="$root" cmake --install "$build" --prefix /usr >"$work/install.log" 2>&1 ||
  { cat "$work/install.log"; fail "cmake --install"; }
for f in usr/bin/hoist-twind usr/bin/hoist-sim usr/bin/hoist-study usr/bin/hoist-replay usr/bin/hoist-monitor \
         usr/bin/hoist-alarm-ack usr/bin/hoist-log2csv usr/bin/hoist-wakeup-latency \
         etc/hoist-twin/example.toml usr/lib/systemd/system/hoist-twind@.service \
         usr/share/hoist-twin/lcm/cage_state_t.lcm usr/include/hoist/cage_state_t.hpp usr/include/hoist/params.hpp \
         usr/include/hoist/io/config.hpp usr/share/doc/hoist-twin/README.md usr/share/doc/hoist-twin/examples/demo.toml; do
  [ -e "$root/$f" ] || fail "not installed: /$f"
done
cfg=$(find "$root/usr/lib" -name hoistConfig.cmake | head -1)
[ -n "$cfg" ] || fail "hoistConfig.cmake not installed"
echo "ok: files installed (package config: ${cfg#$root})"
grep -q "^ExecStart=/usr/bin/hoist-twind --config /etc/hoist-twin/%i.toml" "$root/usr/lib/systemd/system/hoist-twind@.service" ||
  fail "the installed unit does not run /usr/bin/hoist-twind with /etc/hoist-twin/%i.toml"
if grep -rq "$(cd "$build" && pwd)" "$root/usr/lib/systemd" "$root/usr/bin/hoist-lcm-spy" "$cfg" 2>/dev/null; then
  fail "an installed file names the build tree"
fi
"$root/usr/bin/hoist-twind" --version || fail "installed hoist-twind --version"
"$root/usr/bin/hoist-twind" --config "$root/etc/hoist-twin/example.toml" --print-config >/dev/null ||
  fail "the installed example.toml is refused"
if [ -x "$root/usr/bin/hoist-lcm-spy" ]; then
  cp=$("$root/usr/bin/hoist-lcm-spy" --print-classpath) || fail "installed hoist-lcm-spy --print-classpath"
  case "$cp" in *"$root/usr/bin/../share/java/hoist_msgs.jar"*) ;; *) fail "installed hoist-lcm-spy class path: $cp" ;; esac
  echo "ok: installed hoist-lcm-spy uses $cp"
fi
# The downstream project.
cmake -S "$src/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$root/usr" \
      >"$work/consumer.log" 2>&1 || { cat "$work/consumer.log"; fail "configuring the consumer (find_package(hoist))"; }
cmake --build "$work/consumer" >>"$work/consumer.log" 2>&1 || { tail -40 "$work/consumer.log"; fail "building the consumer"; }
"$work/consumer/hoist-consumer" || fail "running the consumer"
echo "ok: find_package(hoist) from the install tree"

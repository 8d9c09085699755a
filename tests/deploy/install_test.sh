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
         usr/include/hoist/io/config.hpp usr/include/hoist/bus/channels.hpp usr/include/hoist/bus/lcm_util.hpp usr/share/doc/hoist-twin/README.md usr/share/doc/hoist-twin/examples/demo.toml; do
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
  case "$cp" in *"$root/usr/bin/../share/java/hoist-msgs.jar"*) ;; *) fail "installed hoist-lcm-spy class path: $cp" ;; esac
  echo "ok: installed hoist-lcm-spy uses $cp"
fi
# Nothing installed names the build tree (hoistTargets.cmake carried
# <build>/msgs/generated), in any text file of the staging root.
build_abs=$(cd "$build" && pwd)
named=$(grep -rIl -F "$build_abs" "$root" 2>/dev/null)
[ -z "$named" ] || fail "installed files name the build tree $build_abs: $named"
echo "ok: no installed text file names the build tree"
# The downstream project, against a COPY of the staged install at another
# path (a relocated prefix), so that nothing can reach the build tree's
# generated headers; it sets no C++ standard (the targets carry cxx_std_20).
grep -q "CMAKE_CXX_STANDARD *[0-9]" "$src/consumer/CMakeLists.txt" && fail "the consumer sets a C++ standard itself"
targets="$(dirname "$cfg")/hoistTargets.cmake"
grep -q "cxx_std_20" "$targets" || fail "hoistTargets.cmake: no cxx_std_20 on the targets"
# Every include directory of the exported targets is under the install prefix.
bad_inc=$(grep -E "INCLUDE_DIRECTORIES \"" "$targets" | tr ';' '\n' | sed 's/.*INCLUDE_DIRECTORIES "//; s/"$//' |
          grep -v '^\${_IMPORT_PREFIX}/')
[ -z "$bad_inc" ] || fail "hoistTargets.cmake: include directories outside the install prefix: $bad_inc"
stage="$work/relocated"
cp -a "$root" "$stage" || fail "copying the staged install"
cmake -S "$src/consumer" -B "$work/consumer" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$stage/usr" \
      -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF \
      >"$work/consumer.log" 2>&1 || { cat "$work/consumer.log"; fail "configuring the consumer (find_package(hoist))"; }
grep -q "$stage/usr/lib" "$work/consumer/CMakeCache.txt" || fail "the consumer did not find the relocated package"
cmake --build "$work/consumer" >>"$work/consumer.log" 2>&1 || { tail -40 "$work/consumer.log"; fail "building the consumer"; }
src_abs=$(cd "$src/../.." && pwd)
for tree in "$build_abs" "$src_abs"; do
  if grep -q -F "$tree/" "$work/consumer/compile_commands.json"; then
    grep -o -F "$tree/[^ \"]*" "$work/consumer/compile_commands.json" | grep -v "/tests/deploy/consumer/" | head -3 >"$work/leak"
    [ -s "$work/leak" ] && { cat "$work/leak"; fail "the consumer compiles with a path of $tree"; }
  fi
done
grep -q -- "-std=c++20\|-std=gnu++20\|-std=c++2a\|-std=gnu++2a" "$work/consumer/compile_commands.json" ||
  fail "the consumer is not compiled as C++20 (cxx_std_20 not carried by the targets)"
"$work/consumer/hoist-consumer" || fail "running the consumer"
echo "ok: find_package(hoist) from a relocated copy of the install tree, no C++ standard set downstream"

#!/usr/bin/env bash
# One-time set-up on a fresh Debian machine, safe to rerun:
#   1. installs the Debian packages the project needs (skipped when present),
#      and the dashboard's npm packages (tools/dash: `npm ci`, package-lock.json),
#   2. makes sure UDP multicast works on loopback (LCM's transport),
#   3. configures and builds everything into ./build (Release).
#
#   scripts/setup.sh [--no-build] [--build-dir DIR] [--build-type TYPE] [--cmake-args "..."]
#
# Environment: HOIST_SKIP_APT=1 skips step 1 (for machines set up by hand);
# JOBS=N sets the build parallelism (default: nproc).
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir="$here/build"
build_type=Release
do_build=1
cmake_args=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-build) do_build=0; shift ;;
    --build-dir) build_dir="$2"; shift 2 ;;
    --build-type) build_type="$2"; shift 2 ;;
    --cmake-args) cmake_args="$2"; shift 2 ;;
    -h|--help) sed -n '2,11p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "setup.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
say() { printf '\033[1m[setup]\033[0m %s\n' "$*"; }

# ---- 1. Debian packages -----------------------------------------------------
required=(build-essential cmake pkg-config libeigen3-dev libboost-dev liblcm-dev liblcm-bin
          libglib2.0-dev libspdlog-dev libgtest-dev libgmock-dev libbenchmark-dev libtomlplusplus-dev
          libcli11-dev gnuplot-nox python3 python3-jinja2 iproute2 libsystemd-dev nlohmann-json3-dev)
# hoist-dash's page (uPlot and the @foxglove/ws-protocol client, bundled by esbuild,
# from npm) and its browser tests (headless Chromium driven by puppeteer-core, the
# @foxglove/ws-protocol client): Node, npm, Chromium.
dashboard=(nodejs npm chromium fonts-dejavu-core)
# MQTT bridge (hoist-mqtt): the client library, and the broker, clients and openssl (TLS test) its tests and demo use.
required+=(libmosquitto-dev mosquitto mosquitto-clients openssl)
# The history database (history/, hoist-trips): SQLite embedded (the CLI checks
# integrity in the tests), PostgreSQL through libpq; the server runs the PG tests;
# zlib for the outage queue's CRC-32.
required+=(libsqlite3-dev sqlite3 libpq-dev postgresql zlib1g-dev)
# Its Sparkplug B mode: nanopb's generator (runs at build time; pulls protoc
# and python3-protobuf) and its library.  Without them: no Sparkplug mode.
required+=(nanopb libnanopb-dev)
# The Python module `import hoist` (python/, docs/python.md): pybind11 builds it,
# numpy holds its arrays, pytest runs tests/python, matplotlib draws the doc's example.
required+=(pybind11-dev python3-pybind11 python3-dev python3-numpy python3-pytest python3-matplotlib)
# Java bindings let lcm-spy decode the hoist channels (jchart2d draws its
# plots; xvfb lets the test open its window headless); clang gives the
# fuzzers; dpkg-dev gives dpkg-shlibdeps for the .deb (cpack -G DEB);
# help2man makes the man pages from --help; lintian checks the .deb (tests/deploy).
# ccache keeps recompiles (the sanitizer builds, CI's clean clone) cheap.
optional=(ccache liblcm-java default-jdk-headless libjchart2d-java xvfb clang libclang-rt-14-dev dpkg-dev help2man lintian)
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
missing=()
for p in "${required[@]}"; do installed "$p" || missing+=("$p"); done
# An optional package is not needed when what it provides is already there.
for p in "${optional[@]}"; do
  case "$p" in
    default-jdk-headless) command -v javac >/dev/null 2>&1 && continue ;;
    clang) command -v clang++ >/dev/null 2>&1 && continue ;;
  esac
  installed "$p" || missing+=("$p")
done
for p in "${dashboard[@]}"; do
  case "$p" in
    nodejs) command -v node >/dev/null 2>&1 && continue ;;
    npm) command -v npm >/dev/null 2>&1 && continue ;;   # e.g. NodeSource's nodejs ships npm
    chromium) command -v chromium >/dev/null 2>&1 && continue ;;
  esac
  installed "$p" || missing+=("$p")
done
if [[ ${#missing[@]} -gt 0 && "${HOIST_SKIP_APT:-0}" != 1 ]]; then
  sudo=""
  [[ $(id -u) -ne 0 ]] && sudo="sudo"
  say "installing: ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${required[@]}"
  # Optional packages one by one: a missing one must not stop the set-up.
  for p in "${optional[@]}"; do
    [[ " ${missing[*]} " == *" $p "* ]] || continue
    $sudo apt-get install -y -qq --no-install-recommends "$p" >/dev/null 2>&1 ||
      say "optional package $p not available (continuing without it)"
  done
  for p in "${dashboard[@]}"; do
    [[ " ${missing[*]} " == *" $p "* ]] || continue
    $sudo apt-get install -y -qq --no-install-recommends "$p" >/dev/null 2>&1 ||
      say "WARNING: package $p not available: the dashboard's browser tests will be skipped"
  done
else
  say "Debian packages: all present"
fi

# ---- 1b. npm packages of the dashboard (exact versions from package-lock.json) --
dash="$here/tools/dash"
if [[ -f "$dash/package-lock.json" ]]; then
  if ! command -v npm >/dev/null 2>&1; then
    say "WARNING: npm not found: hoist-dash's page will have no charts nor protocol client and its browser tests are skipped"
  elif [[ -f "$dash/node_modules/.package-lock.json" && "$dash/node_modules/.package-lock.json" -nt "$dash/package-lock.json" ]]; then
    say "npm packages (tools/dash): up to date"
  else
    say "npm ci in tools/dash (uPlot, @foxglove/ws-protocol, esbuild, puppeteer-core, ws)"
    (cd "$dash" && npm ci --no-audit --no-fund --loglevel=error) ||
      { say "npm ci failed in $dash"; exit 1; }
  fi
fi

# ---- 1c. npm packages of the Sparkplug host of hoist-mqtt's tests -----------
# (sparkplug-payload, mqtt; exact versions from package-lock.json)
sphost="$here/tests/mqtt/sparkplug_host"
if [[ -f "$sphost/package-lock.json" ]] && command -v npm >/dev/null 2>&1; then
  if [[ -f "$sphost/node_modules/.package-lock.json" && "$sphost/node_modules/.package-lock.json" -nt "$sphost/package-lock.json" ]]; then
    say "npm packages (tests/mqtt/sparkplug_host): up to date"
  else
    say "npm ci in tests/mqtt/sparkplug_host (sparkplug-payload, mqtt)"
    (cd "$sphost" && npm ci --no-audit --no-fund --loglevel=error) ||
      say "WARNING: npm ci failed in $sphost: the Sparkplug host tests will be skipped"
  fi
fi

# ---- 2. loopback multicast (LCM) ---------------------------------------------
# LCM's default transport is UDP multicast; with ttl=0 it stays on this host,
# which needs the loopback interface to accept multicast and a route for
# 224.0.0.0/4.  Tests and the demo use it.
multicast_ok() {
  ip link show lo 2>/dev/null | grep -q MULTICAST &&
    ip route get 239.255.76.67 2>/dev/null | grep -q "dev lo"
}
if multicast_ok; then
  say "loopback multicast: enabled"
elif [[ $(id -u) -eq 0 ]] || sudo -n true 2>/dev/null; then
  sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo -n"
  $sudo ip link set lo multicast on 2>/dev/null || true
  $sudo ip route replace 224.0.0.0/4 dev lo 2>/dev/null || true
  if multicast_ok; then say "loopback multicast: enabled now (ip link set lo multicast on; ip route add 224.0.0.0/4 dev lo)"
  else say "WARNING: could not enable loopback multicast; the LCM integration tests will fail fast"; fi
else
  say "WARNING: loopback multicast is off and this user cannot enable it. As root run:"
  say "    ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo"
  say "(the LCM integration tests and the demo need it; the other tests do not)"
fi

# ---- 3. configure and build ---------------------------------------------------
if [[ $do_build -eq 1 ]]; then
  jobs="${JOBS:-$(nproc)}"
  say "configuring $build_dir ($build_type)"
  launcher=""
  if command -v ccache >/dev/null 2>&1; then
    # Paths under the checkout are hashed relative to it, so a clone in
    # another folder (CI) reuses this machine's cache.
    ccache --max-size=8G >/dev/null 2>&1 || true
    launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=env;CCACHE_BASEDIR=$here;CCACHE_NOHASHDIR=1;ccache"
    say "compiler cache: ccache (CCACHE_BASEDIR=$here)"
  fi
  # shellcheck disable=SC2086
  cmake -S "$here" -B "$build_dir" -DCMAKE_BUILD_TYPE="$build_type" $launcher $cmake_args >"$build_dir.configure.log" 2>&1 ||
    { cat "$build_dir.configure.log"; exit 1; }
  say "building with $jobs jobs (log: $build_dir.build.log)"
  if ! cmake --build "$build_dir" -j"$jobs" >"$build_dir.build.log" 2>&1; then
    tail -50 "$build_dir.build.log"; say "build FAILED (full log: $build_dir.build.log)"; exit 1
  fi
  say "built: $(ls "$build_dir/bin" | tr '\n' ' ')"
fi

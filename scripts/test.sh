#!/usr/bin/env bash
# Set-up (scripts/setup.sh: packages, loopback multicast, build) and the whole
# test suite with CTest.  Exit status 0 only when every test passed.
#
#   scripts/test.sh [--no-setup] [-L LABEL] [-R REGEX] [-E REGEX] [--sanitize address|thread]
#
# Labels: model, io, sim, service, tools, study, layers, integration, lcm, realtime,
# hardening, deploy, install, soak (the 2-minute soak; leave it out with -E soak).
# --sanitize builds into build-asan / build-tsan (HOIST_SANITIZE) and tests there.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
setup=1
build_dir="$here/build"
setup_args=()
ctest_args=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --no-setup) setup=0; shift ;;
    -L|-R|-E) ctest_args+=("$1" "$2"); shift 2 ;;
    --sanitize)
      case "$2" in
        address) build_dir="$here/build-asan" ;;
        thread) build_dir="$here/build-tsan" ;;
        *) echo "test.sh: --sanitize takes address or thread" >&2; exit 2 ;;
      esac
      setup_args+=(--build-dir "$build_dir" --build-type RelWithDebInfo
                   --cmake-args "-DHOIST_SANITIZE=$2 -DHOIST_BUILD_BENCH=OFF"); shift 2 ;;
    -h|--help) sed -n '2,9p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "test.sh: unknown option $1 (see --help)" >&2; exit 2 ;;
  esac
done
if [[ $setup -eq 1 ]]; then "$here/scripts/setup.sh" "${setup_args[@]}"; fi
if [[ "$build_dir" == */build-tsan ]]; then
  # Uninstrumented glib (LCM's receive thread) gives false positives; see the file.
  export TSAN_OPTIONS="suppressions=$here/scripts/tsan.supp ${TSAN_OPTIONS:-}"
fi
start=$(date +%s)
set +e
ctest --test-dir "$build_dir" --output-on-failure -j"$(nproc)" --timeout 600 "${ctest_args[@]}"
rc=$?
set -e
echo "[test] ctest finished in $(( $(date +%s) - start )) s with status $rc"
exit $rc

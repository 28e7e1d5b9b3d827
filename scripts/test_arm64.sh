#!/usr/bin/env bash
# The arm64 stage of CI (issue 70, docs/arm64.md), run by .ci/run after README command 2 (whose
# x86-64 release build it compares against):
#   1. the cross tools (scripts/setup.sh --arm64) and the arm64 sysroot (scripts/sysroot_arm64.sh);
#   2. the cross build with both robot links and the GoogleTest binaries (preset arm64);
#   3. every GoogleTest case (label `unit`) under qemu user-mode emulation, but the closed loops
#      tests/arm64/skipped_tests.txt names (too slow emulated; each with its reason);
#   4. the same decisions as x86-64: a teach and a repeat on the simulator by both builds
#      (tests/arm64/same_decisions.sh);
#   5. with --package: the arm64 .deb (cpack), installed with its Depends in a clean arm64 Debian
#      12 root and run there under emulation (tests/arm64/install_deb.sh --short: `mapless demo
#      --help` and a short teach and repeat; the whole demo is `--demo`). Not in CI: the whole
#      `.ci/run` would pass 40 minutes (docs/ci.md gives the times).
# Usage: scripts/test_arm64.sh [--package] [X86_MAPLESS]   (default build/release/apps/mapless)
set -euo pipefail
cd "$(dirname "$0")/.."
package=0
if [ "${1:-}" = "--package" ]; then package=1; shift; fi
X86=${1:-build/release/apps/mapless}
jobs=$(nproc)
stage() { echo "test_arm64: $1 ($(date -u +%H:%M:%S))"; }
[ -x "$X86" ] || { echo "test_arm64: no x86-64 build at $X86 (README command 2 makes it)" >&2; exit 1; }

stage "tools and sysroot"
bash scripts/setup.sh --arm64
bash scripts/sysroot_arm64.sh

stage "cross build"
cmake --preset arm64 -DMAPLESS_BUILD_TESTS=ON -DMAPLESS_BUILD_BENCHMARKS=OFF >build/arm64.log 2>&1 ||
  { tail -30 build/arm64.log; exit 1; }
grep -q "ROS 1 robot link: built" build/arm64.log && grep -q "ROS 2 robot link: built" build/arm64.log ||
  { echo "test_arm64: the arm64 build must have both robot links" >&2; grep "robot link" build/arm64.log; exit 1; }
cmake --build --preset arm64 -j "$jobs"

stage "unit tests under qemu"
# The skip list: one name per line, then why; every name must be a GoogleTest case.
skipped=$(grep -v '^[[:space:]]*#' tests/arm64/skipped_tests.txt | awk 'NF {print $1}')
listed=$(ctest --preset arm64 -N -L '^unit$' | sed -n 's/^ *Test *#[0-9]*: //p')
for name in $skipped; do
  grep -qxF "$name" <<<"$listed" ||
    { echo "test_arm64: tests/arm64/skipped_tests.txt names $name, which is not a GoogleTest case" >&2; exit 1; }
done
echo "test_arm64: $(wc -w <<<"$skipped") of $(wc -l <<<"$listed") cases skipped under emulation (tests/arm64/skipped_tests.txt)"
regex="^($(sed 's/\./\\./g' <<<"$skipped" | paste -sd'|'))\$"
rc=0
ctest --preset arm64 -j "$jobs" -L '^unit$' -E "$regex" --timeout 300 || rc=$?

stage "the same decisions as x86-64"
bash tests/arm64/same_decisions.sh "$X86" build/arm64/apps/mapless build/sysroot-arm64 || rc=$?

if [ "$package" = 1 ]; then
  stage "the arm64 package"
  bash tests/arm64/install_deb.sh build/arm64 --short || rc=$?
fi
stage "done (exit $rc)"
exit "$rc"

#!/usr/bin/env bash
# README command 2: install what is missing, check the style, build and run the whole test suite.
# .ci/run calls exactly this. Each test runs in one build (docs/ci.md: where the time goes):
#   1. the release build with both robot links (ROS 1 and ROS 2): the script tests (the command
#      line, the robot links, the fleet, recordings, installing; lowercase names like cli.probe)
#      and the GoogleTest cases listed in tests/release_only_tests.txt (statistics and closed loops
#      whose code other tests run under the sanitizers);
#   2. the configurations with one robot link each and with none (a newcomer's): configured, and
#      the code that differs between configurations (the registration of the middlewares)
#      compiled with the default compiler;
#   3. the configuration a newcomer gets (no ROS 1, no ROS 2; preset `asan`, compiled by clang,
#      which builds it in 0.6x GCC's time), under AddressSanitizer + UndefinedBehaviorSanitizer: every GoogleTest case but the release-only
#      ones, the bad-input probe and the soak (memory errors and leaks; the release build checks
#      their time and memory), and `mapless demo`, the main job (newcomer.demo).
# The sanitizer build compiles at low priority (nice 19) while step 1's tests run and takes the CPU
# time they leave (a third of the build in the run docs/ci.md measured).
# Extra arguments go to both ctest runs (e.g. -E Renderer; an -R replaces step 1's selection).
# MAPLESS_SKIP_SANITIZERS=1 skips step 3 and runs every test in step 1 (a quicker local check; CI
# never sets it).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
bash scripts/setup.sh --test
bash scripts/check_format.sh
# No function over 120 lines in src/ or apps/ (issue 41: the long ones are where people change code).
bash scripts/long_functions.sh 120 || { echo "test.sh: split the functions above (scripts/long_functions.sh)" >&2; exit 1; }
# The command line stays a thin layer: apps/ at most 3,500 lines of code (.cc), the rest belongs in
# the library's modules (docs/architecture.md).
apps_lines=$(cat apps/*.cc | wc -l)
[ "$apps_lines" -le 3500 ] ||
  { echo "test.sh: apps/*.cc is $apps_lines lines (at most 3,500): move code into src/mapless/" >&2; exit 1; }

# A GoogleTest case (label `unit`) runs in the release build only when tests/release_only_tests.txt
# names it; every name there must be one.
list_names() { grep -v '^[[:space:]]*#' "$1" | awk 'NF {print $1}'; }
as_regex() { echo "^($(sed 's/\./\\./g' <<<"$1" | paste -sd'|'))\$"; }
check_names() {  # check_names FILE NAMES...
  local file=$1 listed name
  shift
  listed=$(ctest --preset release -N -L unit | sed -n 's/^ *Test *#[0-9]*: //p')
  for name in "$@"; do
    grep -qxF "$name" <<<"$listed" ||
      { echo "test.sh: $file names $name, which is not a GoogleTest case" >&2; exit 1; }
  done
}
release_only=$(list_names tests/release_only_tests.txt)

# Only the GoogleTest binaries with a release-only case are built here (the others run under the
# sanitizers); MAPLESS_SKIP_SANITIZERS=1 builds and runs them all.
only_listed=$([ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ] && echo OFF || echo ON)
cmake --preset release -DMAPLESS_RELEASE_ONLY_TESTS="$only_listed"
cmake --build --preset release -j "$jobs"
# shellcheck disable=SC2086
check_names tests/release_only_tests.txt $release_only
# (The binaries left unbuilt show as one NAME_NOT_BUILT placeholder each, without a label.)
scripts=$(ctest --preset release -N -LE unit | sed -n 's/^ *Test *#[0-9]*: //p' | grep -v '_NOT_BUILT$')
# The robot links' own GoogleTest cases (label `unit-middleware`): only this build has the links.
middleware=$(ctest --preset release -N -L '^unit-middleware$' | sed -n 's/^ *Test *#[0-9]*: //p')

asan_build=""
if [ "${MAPLESS_SKIP_SANITIZERS:-0}" != "1" ]; then
  # Its binaries whose every case is release-only are left out (MAPLESS_RELEASE_ONLY_TESTS).
  cmake --preset asan -DMAPLESS_RELEASE_ONLY_TESTS=ON
  # A process group of its own (job control), stopped whole if this script ends early; the same
  # session, so that its nice value counts against the tests (a new session, as setsid makes, is a
  # scheduling group of its own under Linux's autogroup, and would take half of the machine).
  set -m
  nice -n 19 cmake --build --preset asan -j "$jobs" >build/asan.log 2>&1 &
  asan_build=$!
  set +m
  trap '[ -z "$asan_build" ] || kill -- "-$asan_build" 2>/dev/null' EXIT
fi
release_rc=0
if [ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ]; then
  ctest --preset release -j "$jobs" "$@" || release_rc=$?
else
  ctest --preset release -j "$jobs" -R "$(as_regex "$scripts"$'\n'"$release_only"$'\n'"$middleware")" "$@" ||
    release_rc=$?
fi

# The same file in the newcomer's configuration with the default compiler (GCC; the sanitizer
# build, which runs that configuration's demo, is compiled by clang).
for only in ros1 ros2 none; do
  case "$only" in
    ros1) off=(-DMAPLESS_ROS2=OFF); built=("ROS 1 robot link: built") ;;
    ros2) off=(-DMAPLESS_ROS1=OFF); built=("ROS 2 robot link: built") ;;
    none) off=(-DMAPLESS_ROS1=OFF -DMAPLESS_ROS2=OFF)
          built=("ROS 1 robot link: NOT built" "ROS 2 robot link: NOT built") ;;
  esac
  dir=build/only-$only
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release "${off[@]}" \
    -DMAPLESS_BUILD_TESTS=OFF -DMAPLESS_BUILD_BENCHMARKS=OFF >"$dir.log" 2>&1 ||
    { cat "$dir.log"; exit 1; }
  for line in "${built[@]}"; do
    grep -q "mapless: $line" "$dir.log" ||
      { echo "test.sh: $dir: expected \"$line\""; cat "$dir.log"; exit 1; }
  done
  cmake --build "$dir" --target apps/CMakeFiles/mapless.dir/builtin_middlewares.cc.o
  echo "test.sh: the configuration with robot links '$only' compiles its middleware registration"
done

if [ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ]; then
  echo "test.sh: sanitizer suite skipped (MAPLESS_SKIP_SANITIZERS=1)"
  exit "$release_rc"
fi
echo "test.sh: waiting for the sanitizer build (log: build/asan.log)"
wait "$asan_build" || { tail -40 build/asan.log; echo "test.sh: the sanitizer build failed"; exit 1; }
asan_build=""
tail -1 build/asan.log
# The bad-input probe makes its fixtures (taught routes, rendered frames) with the release build:
# they are its inputs, computed identically by both builds; what it probes runs sanitized.
MAPLESS_FIXTURES="$PWD/build/release/apps/mapless" \
  ctest --preset asan -j "$jobs" -E "$(as_regex "$release_only")|_NOT_BUILT\$" "$@" || exit $?
exit "$release_rc"

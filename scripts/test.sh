#!/usr/bin/env bash
# README command 2: install what is missing, check the style, build and run the whole test suite.
# .ci/run calls exactly this.
#   1. the release build with both robot links (ROS 1 and ROS 2), every test but the closed loops
#      that step 3 runs under the sanitizers (tests/sanitizer_only_tests.txt);
#   2. the configurations with one robot link each: configured, and the code that differs between
#      configurations (the registration of the middlewares) compiled;
#   3. the configuration a newcomer gets (no ROS 1, no ROS 2; preset `asan`), under
#      AddressSanitizer + UndefinedBehaviorSanitizer: every test but the release-only ones
#      (tests/release_only_tests.txt: statistics and closed loops whose code other tests run
#      under the sanitizers), and `mapless demo`, the main job (newcomer.demo).
# Extra arguments go to both ctest runs (e.g. -R Renderer). MAPLESS_SKIP_SANITIZERS=1 skips step 3
# and runs every test in step 1 (a quicker local check; CI never sets it). Where the time goes:
# docs/ci.md.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
bash scripts/setup.sh --test
bash scripts/check_format.sh

# A test may run in one of the two builds only (each list says why); every name must be a test.
list_names() { grep -v '^[[:space:]]*#' "$1" | awk 'NF {print $1}'; }
as_regex() { echo "^($(sed 's/\./\\./g' <<<"$1" | paste -sd'|'))\$"; }
check_names() {  # check_names FILE NAMES...
  local file=$1 listed name
  shift
  listed=$(ctest --preset release -N | sed -n 's/^ *Test *#[0-9]*: //p')
  for name in "$@"; do
    grep -qxF "$name" <<<"$listed" || { echo "test.sh: $file names $name, which is not a test" >&2; exit 1; }
  done
}
release_only=$(list_names tests/release_only_tests.txt)
sanitizer_only=$(list_names tests/sanitizer_only_tests.txt)
both=$(comm -12 <(sort <<<"$release_only") <(sort <<<"$sanitizer_only"))
[ -z "$both" ] || { echo "test.sh: in both lists, so run by neither build: $both" >&2; exit 1; }

cmake --preset release
cmake --build --preset release -j "$jobs"
# shellcheck disable=SC2086
check_names tests/release_only_tests.txt $release_only
# shellcheck disable=SC2086
check_names tests/sanitizer_only_tests.txt $sanitizer_only
if [ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ]; then
  ctest --preset release -j "$jobs" "$@"
else
  ctest --preset release -j "$jobs" -E "$(as_regex "$sanitizer_only")" "$@"
fi

for only in ros1 ros2; do
  other=$([ "$only" = ros1 ] && echo ROS2 || echo ROS1)
  dir=build/only-$only
  cmake -S . -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DMAPLESS_${other}=OFF \
    -DMAPLESS_BUILD_TESTS=OFF -DMAPLESS_BUILD_BENCHMARKS=OFF >"$dir.log" 2>&1 ||
    { cat "$dir.log"; exit 1; }
  grep -q "mapless: $(tr a-z A-Z <<<"${only:0:3}") ${only:3} robot link: built" "$dir.log" ||
    { echo "test.sh: $dir: the $only link is not built"; cat "$dir.log"; exit 1; }
  cmake --build "$dir" --target apps/CMakeFiles/mapless.dir/builtin_middlewares.cc.o
  echo "test.sh: the configuration with $only alone compiles its robot links"
done

if [ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ]; then
  echo "test.sh: sanitizer suite skipped (MAPLESS_SKIP_SANITIZERS=1)"
  exit 0
fi
cmake --preset asan
cmake --build --preset asan -j "$jobs"
ctest --preset asan -j "$jobs" -E "$(as_regex "$release_only")" "$@"

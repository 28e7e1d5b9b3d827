#!/usr/bin/env bash
# README command 2: install what is missing, build, and run the whole test suite: first the release
# build, then the same suite under AddressSanitizer + UndefinedBehaviorSanitizer (preset `asan`,
# unit tests, closed-loop runs, the short soak and the kept fuzz inputs, but for the release-only
# tests listed in tests/release_only_tests.txt). .ci/run calls exactly this.
# Extra arguments go to both ctest runs (e.g. -R Renderer). MAPLESS_SKIP_SANITIZERS=1 skips the
# second run (a quicker local check; CI never sets it).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh --ros
cmake --preset release
cmake --build --preset release -j "$(nproc)"
ctest --preset release -j "$(nproc)" "$@"
if [ "${MAPLESS_SKIP_SANITIZERS:-0}" = "1" ]; then
  echo "test.sh: sanitizer suite skipped (MAPLESS_SKIP_SANITIZERS=1)"
  exit 0
fi
# The sanitizer run leaves out the tests listed in tests/release_only_tests.txt (closed loops and
# statistics whose code paths other tests run under the sanitizers); each must exist.
release_only=$(grep -v '^[[:space:]]*#' tests/release_only_tests.txt | awk 'NF {print $1}')
listed=$(ctest --preset release -N | sed -n 's/^ *Test *#[0-9]*: //p')
for name in $release_only; do
  grep -qxF "$name" <<<"$listed" || { echo "test.sh: tests/release_only_tests.txt names $name, which is not a test" >&2; exit 1; }
done
exclude="^($(sed 's/\./\\./g' <<<"$release_only" | paste -sd'|'))\$"
cmake --preset asan
cmake --build --preset asan -j "$(nproc)"
ctest --preset asan -j "$(nproc)" -E "$exclude" "$@"

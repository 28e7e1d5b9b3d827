#!/usr/bin/env bash
# README command 2: install what is missing, build, and run the whole test suite: first the release
# build, then the same suite under AddressSanitizer + UndefinedBehaviorSanitizer (preset `asan`,
# unit tests, closed-loop runs, the short soak and the kept fuzz inputs). .ci/run calls exactly this.
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
cmake --preset asan
cmake --build --preset asan -j "$(nproc)"
ctest --preset asan -j "$(nproc)" "$@"

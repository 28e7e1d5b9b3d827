#!/usr/bin/env bash
# README command 2: install what is missing, build (release), and run the whole test suite (ctest).
# .ci/run calls exactly this. Extra arguments go to ctest (e.g. -R Renderer).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release
cmake --build --preset release -j "$(nproc)"
ctest --preset release -j "$(nproc)" "$@"

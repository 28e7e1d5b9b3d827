#!/usr/bin/env bash
# README command 1: install what is missing, build (release), and run the main job, `mapless demo`
# on the built-in simulator. Extra arguments go to `mapless demo` (see `mapless demo --help`).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
cmake --preset release
cmake --build --preset release -j "$(nproc)" --target mapless   # the demo needs only the CLI
./build/release/apps/mapless demo "$@"

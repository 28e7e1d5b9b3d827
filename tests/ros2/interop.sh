#!/usr/bin/env bash
# The ROS 2 wire format (issue 18): every message type mapless writes, in the bytes its DDS writer
# puts on the wire, decoded by Foxglove's ROS 2 CDR reader (npm @foxglove/rosmsg2-serialization,
# the reader Foxglove uses for ROS 2) against the ROS 2 .msg definitions, field by field; and every
# message type mapless reads, encoded by Foxglove's writer, decoded by mapless. The npm packages
# are pinned in tests/ros2/interop/package-lock.json and installed into the build folder.
# Exit 77 (skipped) only when node or npm is absent.
#   tests/ros2/interop.sh CDR_TOOL WORK_DIR
set -uo pipefail
TOOL=$1; WORK=$2
HERE=$(cd "$(dirname "$0")" && pwd)
command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 ||
  { echo "interop.sh: SKIPPED: node and npm are needed for Foxglove's reader"; exit 77; }
mkdir -p "$WORK/js" "$WORK/bytes"
rm -f "$WORK/bytes"/*
cp "$HERE/interop/package.json" "$HERE/interop/package-lock.json" "$HERE/interop/"*.mjs "$WORK/js/"
if ! cmp -s "$HERE/interop/package-lock.json" "$WORK/js/node_modules/.package-lock.json.installed" 2>/dev/null; then
  (cd "$WORK/js" && npm ci --no-audit --no-fund --loglevel=error) >"$WORK/npm.log" 2>&1 ||
    { echo "interop.sh: npm ci failed:"; tail -5 "$WORK/npm.log"; exit 1; }
  cp "$HERE/interop/package-lock.json" "$WORK/js/node_modules/.package-lock.json.installed"
fi
export ROS_DOMAIN_ID=$((1 + ($$ * 7) % 200)) ROS_LOCALHOST_ONLY=1
unset CYCLONEDDS_URI
FAILS=0
echo "-- mapless writes, Foxglove reads"
"$TOOL" encode "$WORK/bytes" || FAILS=$((FAILS + 1))
node "$WORK/js/interop.mjs" read "$WORK/bytes" || FAILS=$((FAILS + 1))
echo "-- Foxglove writes, mapless reads"
node "$WORK/js/interop.mjs" write "$WORK/bytes" || FAILS=$((FAILS + 1))
"$TOOL" decode "$WORK/bytes" || FAILS=$((FAILS + 1))
node "$WORK/js/interop.mjs" check "$WORK/bytes" || FAILS=$((FAILS + 1))
[ "$FAILS" = 0 ] && echo "interop.sh: all agree" || echo "interop.sh: $FAILS steps failed"
[ "$FAILS" = 0 ]

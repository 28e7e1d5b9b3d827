#!/usr/bin/env bash
# Recordings against the reference MCAP implementation (issue 20). mapless records three runs
# (a teach: zstd chunks, raw images; two repeats: lz4 chunks with PNG images, no compression with
# JPEG images); @mcap/core (npm, pinned in tests/recording/interop/package-lock.json) reads every
# record of each, streamed and through the indexes, and Foxglove's ROS 2 CDR reader decodes every
# message (decode.mjs). Then @mcap/core writes the teach again in its own layout (rewrite.mjs) and
# mapless teaches from that file: the route must be byte-identical to the one taught live.
# Exit 77 (skipped) only when node or npm is absent.
#   tests/recording/interop.sh MAPLESS WORK_DIR
set -uo pipefail
MAPLESS=$1; WORK=$2
HERE=$(cd "$(dirname "$0")" && pwd)
command -v node >/dev/null 2>&1 && command -v npm >/dev/null 2>&1 ||
  { echo "interop.sh: SKIPPED: node and npm are needed for @mcap/core"; exit 77; }
rm -rf "$WORK/run"
mkdir -p "$WORK/run"
# shellcheck source=../support/npm_folder.sh
source "$HERE/../support/npm_folder.sh"
npm_folder "$HERE/interop" "$WORK"
R=$WORK/run
S=sim:table1_almost_straight
FAILS=0
step() {  # step NAME COMMAND...: runs it, output to R/NAME.log
  local name=$1; shift
  if "$@" >"$R/$name.log" 2>&1; then echo "ok   $name"; else
    echo "FAIL $name:"; tail -5 "$R/$name.log"; FAILS=$((FAILS + 1)); fi
}
step teach "$MAPLESS" teach --source $S --out "$R/route" --record "$R/teach.mcap"
step repeat_lz4_png "$MAPLESS" repeat --route "$R/route" --source $S --log "$R/a.jsonl" \
  --record "$R/repeat_lz4_png.mcap" --record-compression lz4 --record-images png
step repeat_none_jpeg "$MAPLESS" repeat --route "$R/route" --source $S --seed 2 --log "$R/b.jsonl" \
  --record "$R/repeat_none_jpeg.mcap" --record-compression none --record-images jpeg
echo "-- @mcap/core reads what mapless wrote"
node "$WORK/js/decode.mjs" "$R/teach.mcap" "$R/repeat_lz4_png.mcap" "$R/repeat_none_jpeg.mcap" ||
  FAILS=$((FAILS + 1))
echo "-- mapless reads what @mcap/core wrote"
node "$WORK/js/rewrite.mjs" "$R/teach.mcap" "$R/rewritten.mcap" || FAILS=$((FAILS + 1))
step teach_from_rewritten "$MAPLESS" teach --source "$R/rewritten.mcap" --out "$R/route_rw"
if diff -r "$R/route" "$R/route_rw" >"$R/diff.log" 2>&1; then
  echo "ok   the route taught from @mcap/core's file is the route taught live"
else
  echo "FAIL the routes differ:"; head -5 "$R/diff.log"; FAILS=$((FAILS + 1))
fi
[ "$FAILS" = 0 ] && echo "interop.sh: all agree" || echo "interop.sh: $FAILS steps failed"
[ "$FAILS" = 0 ]

#!/usr/bin/env bash
# The main job in a newcomer's configuration (issue 39): README command 1 builds mapless without
# ROS 1 or ROS 2 and runs `mapless demo`; this runs the same demo from such a build (CI: the
# sanitizer build, configured without middleware) and checks what it writes. Its output stays in
# OUT for report.chromium, which opens the report in a browser.
#   tests/newcomer/demo.sh MAPLESS OUT
set -uo pipefail
BIN=$1
OUT=$2
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }

"$BIN" --version >"$OUT.version" 2>&1
grep -q "^robot links: none" "$OUT.version"; st=$?; check "this build has no robot link, as a newcomer's ($(tail -1 "$OUT.version" | cut -c1-40))" $st
rm -rf "$OUT"
"$BIN" demo --out "$OUT" >"$OUT.log" 2>&1
code=$?
[ $code -eq 0 ] || tail -5 "$OUT.log" | sed 's/^/     | /'
check "mapless demo exits 0 (got $code)" $code
for f in report/index.html report/repeat_topdown.png report/eigenspace_plot3.png \
         report/potential_topdown.png summary.json repeat.jsonl route/manifest.json \
         teach/groundtruth.tum teach/frames/000000.png; do
  [ -s "$OUT/$f" ]; check "demo writes $f" $?
done
[ "$(grep -c '"success": true' "$OUT/summary.json")" -eq 3 ]; check "all three methods succeeded" $?
tail -1 "$OUT/repeat.jsonl" | grep -q '"status":"completed"' &&
  tail -1 "$OUT/repeat.jsonl" | grep -Eq '"local_scale":1\.'
check "the repeat completed, its route ending on a local scale above 1" $?
grep -q "report: $OUT/report/index.html" "$OUT.log"; check "the demo says where its report is" $?
echo "$failed failed"
[ "$failed" -eq 0 ]

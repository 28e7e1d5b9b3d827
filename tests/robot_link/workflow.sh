#!/usr/bin/env bash
# A robot owner's day (issue 42), through ROS 1 or ROS 2, with the documented commands only:
#   1. `mapless sim serve` is the robot; `mapless teleop` drives it from keys typed into a
#      pseudo-terminal (`script`), while `mapless teach --robot` records the route;
#   2. the teach ends with SIGINT (Ctrl-C): exit 0, a complete route, a duration in seconds (and
#      a second teach of appearance route images beside it, the same);
#   3. `mapless repeat --robot` of that route, with the robot back at the start, completes;
#   4. the same repeat with a box on the route that is never taken away ends after the robot
#      file's safety.max_blocked_s, exit 1, with the documented reason.
# Exit 77 (skipped) without the middleware or without `script` (util-linux).
#   tests/robot_link/workflow.sh MAPLESS ros1|ros2
set -uo pipefail
BIN=$1; MW=$2
# shellcheck source=env.sh
source "$(dirname "$0")/env.sh" workflow.sh "$MW"
HERE=$(cd "$(dirname "$0")/../.." && pwd)
command -v script >/dev/null || { echo "workflow.sh: SKIPPED: no script (util-linux)"; exit 77; }
FAILS=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; FAILS=$((FAILS + 1)); fi; }

# The world: Table I's almost straight path; at repeat time a box stands on it 2.5 m ahead and
# stays (the scenario of `eval obstacles` without its leaving time).
sed -e 's/center: \[5.0, 0.15\], size_m: \[0.5, 0.5, 0.5\], leaves_s: 45,/center: [2.5, 0.0], size_m: [0.5, 0.5, 0.5],/' \
  -e 's/^name: .*/name: workflow_box_stays/' \
  "$HERE/config/scenarios/obstacle_box_table1.yaml" >"$OUT/world.yaml"
grep -q "center: \[2.5, 0.0\]" "$OUT/world.yaml" || { echo "workflow.sh: the scenario did not edit"; exit 1; }
# One robot file for every command, as a robot owner has (node names differ by command).
# Teaching is driven by a person, in real time; the repeats run in the simulator's time (ROS
# use_sim_time, lockstep: as fast as the method decides, and the same on a loaded machine).
robot_file() {  # robot_file NODE USE_SIM_TIME
  printf 'middleware: %s\nname: workflow robot\nnode_name: %s\nuse_sim_time: %s\nsafety: {max_blocked_s: 6}\n' \
    "$MW" "$1" "$2" >"$OUT/$1.yaml"
}
for node in serve teleop teach teach_eigenspace; do robot_file "$node" false; done
robot_file serve_sim true
robot_file repeat true
serve() {  # serve ROBOT_FILE LIKE LOG: the simulated robot, in the background
  "$BIN" sim serve --scenario "$OUT/world.yaml" --robot "$OUT/$1.yaml" --like "$2" \
    --motion-noise 0 --image-noise 0 >"$OUT/$3" 2>&1 &
  SERVE=$!; PIDS+=("$SERVE")
}

# 1-2. Teach while teleop drives: 12 s of the forward key at full speed (0.3 m/s), a key every
# 0.1 s as a held key repeats, then Ctrl-D ends teleop.
serve serve teach serve_teach.log
"$BIN" teach --robot "$OUT/teach.yaml" --out "$OUT/route" >"$OUT/teach.log" 2>&1 &
TEACH=$!; PIDS+=("$TEACH")
# The other route kind at the same time, as a second node: appearance route images (`follow`).
"$BIN" teach --robot "$OUT/teach_eigenspace.yaml" --method eigenspace --out "$OUT/images" \
  >"$OUT/teach_eigenspace.log" 2>&1 &
TEACH2=$!; PIDS+=("$TEACH2")
sleep 2
{ sleep 1; for _ in $(seq 1 120); do printf w; sleep 0.1; done; printf '\004'; } |
  timeout 60 script -q -e -c "$BIN teleop --robot $OUT/teleop.yaml --speed-fraction 1" /dev/null \
    >"$OUT/teleop.log" 2>&1
check "teleop from a pseudo-terminal: keys in, exit 0 on Ctrl-D" $?
grep -q "teleop: finished" "$OUT/teleop.log" && grep -q "ended from the keyboard" "$OUT/teleop.log"
check "teleop says it ended from the keyboard" $?
sleep 1
kill -INT "$TEACH" "$TEACH2"; wait "$TEACH"; R=$?; wait "$TEACH2"; R2=$?
check "teach --robot ended by SIGINT exits 0 (exit $R)" "$R"
IMAGES=$(ls "$OUT/images/images" 2>/dev/null | wc -l)
[ "$R2" = 0 ] && grep -q '"complete": true' "$OUT/images/appearance.json" && [ "$IMAGES" -ge 5 ]
check "teach --robot --method eigenspace too: exit $R2, a complete route of $IMAGES images" $?
"$BIN" route info "$OUT/route" --json >"$OUT/info.json" 2>"$OUT/info.err"
grep -q '"complete": *true' "$OUT/info.json"
st=$?; check "the taught route is complete: $(grep -o '"keyframes": *[0-9]*' "$OUT/info.json")" $st
awk -v d="$(grep -o '"duration_s": *[0-9.e+-]*' "$OUT/info.json" | sed 's/.*: *//')" \
  'BEGIN { exit !(d != "" && d + 0 > 5 && d + 0 < 60) }'
st=$?; check "its duration is the driving time: $(grep -o '"duration_s": *[0-9.]*' "$OUT/info.json")" $st
[ "$(grep -o '"keyframes": *[0-9]*' "$OUT/info.json" | sed 's/.*: *//')" -ge 3 ]
check "teleop drove the robot: keyframes along the way, not one where it stood" $?
kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null

# 3. Repeat it from the start: completes.
serve serve_sim teach serve_repeat.log
sleep 1
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/repeat.yaml" >"$OUT/repeat.log" 2>&1
R=$?
check "repeat --robot of the teleop-taught route completes (exit $R)" "$R"
kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null

# 4. A box on the route that never goes: blocked, then the end after max_blocked_s (6 s).
serve serve_sim repeat serve_blocked.log
sleep 1
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/repeat.yaml" >"$OUT/blocked.log" 2>&1
R=$?
[ "$R" = 1 ]; check "a repeat blocked for good exits 1 (exit $R)" $?
grep -q "blocked for [0-9.]* s (.*): clear the way and start again, or raise safety.max_blocked_s in the robot file" \
  "$OUT/blocked.log"
st=$?; check "it says why and what to do: $(grep -o 'blocked for [0-9.]* s' "$OUT/blocked.log" | tail -1)" $st
kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null

[ "$FAILS" = 0 ] || { tail -5 "$OUT"/*.log; exit 1; }

#!/usr/bin/env bash
# Safety on the robot link, ROS 1 or ROS 2 (issues 17, 18): while `mapless repeat --robot` drives a simulated robot
# (`mapless sim serve`, real time), each of these must give a zero Twist within 0.3 s:
#   - the camera publisher killed (SIGKILL): the watchdog;
#   - Ctrl-C (SIGINT) to the method: the zero goes out before it leaves;
#   - true on the e-stop topic: zero until false, then the robot is driven again; while it is held,
#     at most 15 commands a second (the 10 Hz camera plus the watchdog; issue 40: it was 30,700).
# First (mode topics) it checks the status (JSON per frame) and debug image topics while it drives.
# A probe (safety_probe) waits until the robot is driven, acts, and times the first command after.
# Exit 77 (skipped) without the middleware. The probe is the middleware's own (tests/ros1,
# tests/ros2: safety_probe.cc).
#   tests/robot_link/safety.sh MAPLESS SAFETY_PROBE ros1|ros2 [RUNS]
set -uo pipefail
BIN=$1; PROBE=$2; MW=$3; RUNS=${4:-3}
# shellcheck source=env.sh
source "$(dirname "$0")/env.sh" safety.sh "$MW"
printf 'middleware: %s\nname: real-time simulated robot\nuse_sim_time: false\n' "$MW" >"$OUT/robot.yaml"
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/route" >"$OUT/teach.log" 2>&1 ||
  { echo "safety.sh: teach failed"; exit 1; }
FAILS=0
TOTAL=0
for mode in topics kill int estop; do
  for k in $(seq 1 "$RUNS"); do
    "$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/robot.yaml" --like repeat \
      --seed "$k" >"$OUT/serve.log" 2>&1 &
    SERVE=$!; PIDS+=("$SERVE")
    timeout 60 "$BIN" repeat --route "$OUT/route" --robot "$OUT/robot.yaml" >"$OUT/repeat.log" 2>&1 &
    REPEAT=$!; PIDS+=("$REPEAT")
    TARGET=$SERVE
    [ "$mode" = int ] && TARGET=$REPEAT
    RESULT=$(timeout 70 "$PROBE" "$mode" "$TARGET" 0.3 10 15)
    RC=$?
    TOTAL=$((TOTAL + 1))
    echo "safety $mode run $k: $RESULT"
    [ "$RC" = 0 ] || FAILS=$((FAILS + 1))
    kill -INT "$REPEAT" 2>/dev/null; wait "$REPEAT" 2>/dev/null
    REPEAT_RC=$?
    if [ "$mode" = int ] && [ "$REPEAT_RC" != 130 ]; then
      echo "safety int run $k: repeat exited $REPEAT_RC after SIGINT (want 130)"; FAILS=$((FAILS + 1))
    fi
    kill -INT "$SERVE" 2>/dev/null; sleep 0.2; kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null
  done
done
echo "safety.sh: $((TOTAL - FAILS))/$TOTAL runs passed (topics: status and debug image; kill, int, estop: a zero Twist within 0.3 s)"
[ "$FAILS" = 0 ]

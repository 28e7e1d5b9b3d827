#!/usr/bin/env bash
# Watchdog (issue 17): the camera publisher killed mid-run gives a zero Twist within 0.3 s.
# A ROS master on loopback, `mapless sim serve` in real time (the camera), `mapless repeat --robot`
# driving, and a probe that kills the camera once the robot is driven and times the first command
# after it. Exit 77 (skipped) without ROS 1.
#   tests/ros1/watchdog.sh MAPLESS WATCHDOG_PROBE [RUNS]
set -uo pipefail
BIN=$1; PROBE=$2; RUNS=${3:-3}
command -v rosmaster >/dev/null 2>&1 || { echo "watchdog.sh: SKIPPED: no rosmaster (scripts/setup.sh --ros)"; exit 77; }
OUT=$(mktemp -d /tmp/mapless_watchdog.XXXXXX)
PORT=$((20000 + ($$ + 7) % 20000))
export ROS_MASTER_URI="http://127.0.0.1:$PORT" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1 ROS_HOME="$OUT/roshome"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; wait "$p" 2>/dev/null; done; rm -rf "$OUT"; }
trap cleanup EXIT INT TERM
rosmaster --core -p "$PORT" >"$OUT/master.log" 2>&1 &
PIDS+=($!)
for _ in $(seq 1 100); do (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null && break; sleep 0.1; done
printf 'name: real-time simulated robot\nuse_sim_time: false\n' >"$OUT/robot.yaml"
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/route" >"$OUT/teach.log" 2>&1 ||
  { echo "watchdog.sh: teach failed"; exit 1; }
FAILS=0
for k in $(seq 1 "$RUNS"); do
  "$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/robot.yaml" --like repeat \
    --seed "$k" >"$OUT/serve$k.log" 2>&1 &
  SERVE=$!; PIDS+=("$SERVE")
  timeout 60 "$BIN" repeat --route "$OUT/route" --robot "$OUT/robot.yaml" >"$OUT/repeat$k.log" 2>&1 &
  REPEAT=$!; PIDS+=("$REPEAT")
  RESULT=$(timeout 70 "$PROBE" "$SERVE" 0.3 10)
  RC=$?
  echo "watchdog run $k: $RESULT"
  [ "$RC" = 0 ] || FAILS=$((FAILS + 1))
  kill -INT "$REPEAT" 2>/dev/null; wait "$REPEAT" 2>/dev/null
  kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null
done
echo "watchdog.sh: $((RUNS - FAILS))/$RUNS runs published a zero Twist within 0.3 s of the camera's death"
[ "$FAILS" = 0 ]

#!/usr/bin/env bash
# Teaching on a robot (issues 17, 18): `mapless teach --robot` records while the robot is driven by
# someone else — here `mapless repeat --robot` of a route taught on the simulator stands in for the
# person with the joystick — and Ctrl-C ends the teach with a complete route that loads. Both route
# kinds at once: keyframes (funnel lanes) and appearance route images (eigenspace). Exit 77
# (skipped) without the middleware.
#   tests/robot_link/teach.sh MAPLESS ros1|ros2 [SECONDS of driving]
set -uo pipefail
BIN=$1; MW=$2; SECONDS_TO_TEACH=${3:-15}
# shellcheck source=env.sh
source "$(dirname "$0")/env.sh" teach.sh "$MW"
printf 'middleware: %s\nname: real-time simulated robot\nuse_sim_time: false\n' "$MW" >"$OUT/robot.yaml"
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/driver_route" >"$OUT/t0.log" 2>&1 ||
  { echo "teach.sh: teach on the simulator failed"; exit 1; }
# The teach nodes are distinct ROS nodes: each gets its own node name through its own robot file.
printf 'middleware: %s\nuse_sim_time: false\nnode_name: teach_funnel\n' "$MW" >"$OUT/teach_funnel.yaml"
printf 'middleware: %s\nuse_sim_time: false\nnode_name: teach_eigenspace\n' "$MW" >"$OUT/teach_eigenspace.yaml"
"$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/robot.yaml" --like teach \
  >"$OUT/serve.log" 2>&1 &
PIDS+=($!)
"$BIN" teach --robot "$OUT/teach_funnel.yaml" --out "$OUT/funnel" >"$OUT/t1.log" 2>&1 &
T1=$!; PIDS+=("$T1")
"$BIN" teach --robot "$OUT/teach_eigenspace.yaml" --method eigenspace --out "$OUT/eigenspace" \
  >"$OUT/t2.log" 2>&1 &
T2=$!; PIDS+=("$T2")
sleep 1
timeout 120 "$BIN" repeat --route "$OUT/driver_route" --robot "$OUT/robot.yaml" \
  --log "$OUT/driver.jsonl" >"$OUT/driver.log" 2>&1 &
DRIVER=$!; PIDS+=("$DRIVER")
# The teach lasts SECONDS of driving (10 frames a second with a forward command), not of wall time:
# on a loaded machine the driver starts later and may stop on stale frames. At most 90 s.
WANT=$((SECONDS_TO_TEACH * 10)); DRIVEN=0
for _ in $(seq 1 900); do
  # The log is written to driver.jsonl.partial until the run ends (io::JournalFile).
  DRIVEN=$(cat "$OUT/driver.jsonl.partial" "$OUT/driver.jsonl" 2>/dev/null |
    grep -vc '"v_mps":0.0[,}]') || true
  [ "${DRIVEN:-0}" -ge "$WANT" ] && break
  kill -0 "$DRIVER" 2>/dev/null || break
  sleep 0.1
done
echo "driver: ${DRIVEN:-0} frames with a forward command (wanted $WANT)"
kill -INT "$T1" "$T2"
wait "$T1"; R1=$?
wait "$T2"; R2=$?
kill -INT "$DRIVER" 2>/dev/null
FAILS=0
# The route's duration runs from its first keyframe to its last (a robot's keyframes carry the ROS
# clock's time: it was reported as 1.8e9 s).
duration_ok() {
  awk -v d="$(grep -o '"duration_s": *[0-9.e+-]*' "$1" | sed 's/.*: *//')" \
    'BEGIN { exit !(d != "" && d + 0 > 0 && d + 0 < 600) }'
}
if [ "$R1" = 0 ] && "$BIN" route info "$OUT/funnel" --json >"$OUT/info.json" 2>"$OUT/info.err" &&
   grep -q '"complete": *true' "$OUT/info.json" && duration_ok "$OUT/info.json"; then
  echo "ok   teach --robot (funnel): Ctrl-C, exit 0, complete route: $(grep -o '"keyframes": *[0-9]*' "$OUT/info.json"), $(grep -o '"duration_s": *[0-9.]*' "$OUT/info.json")"
else
  echo "FAIL teach --robot (funnel): exit $R1"; tail -3 "$OUT/t1.log" "$OUT/info.err" 2>/dev/null; FAILS=$((FAILS + 1))
fi
if [ "$R2" = 0 ] && grep -q '"complete": true' "$OUT/eigenspace/appearance.json" &&
   [ "$(ls "$OUT/eigenspace/images" | wc -l)" -ge 5 ]; then
  echo "ok   teach --robot --method eigenspace: Ctrl-C, exit 0, complete route of $(ls "$OUT/eigenspace/images" | wc -l) images"
else
  echo "FAIL teach --robot --method eigenspace: exit $R2"; tail -3 "$OUT/t2.log"; FAILS=$((FAILS + 1))
fi

[ "$FAILS" = 0 ]

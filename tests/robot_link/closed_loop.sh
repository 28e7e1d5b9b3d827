#!/usr/bin/env bash
# Closed loop through ROS 1 or ROS 2 on loopback (issues 17, 18): `mapless sim serve` as the robot
# and the method as a second process (with a private ROS master for ROS 1, a domain of its own on
# loopback for ROS 2), in simulated time (lockstep), compared run by run with the same run driven
# directly on the simulator (same scenario, seed and options).
#
#   tests/robot_link/closed_loop.sh [--middleware ros1|ros2] [--runs N]
#       [--methods repeat,navigate,follow] [--repeat-scenarios S1,S2] [--seed S] [--out DIR]
#       [--mapless BIN] [--direct DIR] [--direct-only]
# --direct DIR: where the routes, the calibration and the direct runs are (default OUT); a run
# already there (its exit code written) is not run again, so two middlewares can share one set
# (ctest: the closed_loop.direct fixture). --direct-only: teach, calibrate and run directly (into
# DIR, emptied first), then exit (no middleware needed).
# --repeat-scenarios: the scenarios `repeat` is run on (default both Table I paths; CI runs the
# sharp low-texture turn, the harder one). --no-homing: navigate to the destination only (CI).
#
# Per line: runs that completed through ROS, runs that completed directly, the largest distance
# between the final poses of the two (the pose at the method's last decision), collisions. A line
# passes when every run completed both ways, without a collision, and every pair of final poses
# lies within 0.05 m. Exit 0 when every line passes, 1 otherwise, 2 on bad usage; 77 (skipped)
# when the middleware or its adapter is absent.
set -uo pipefail
cd "$(dirname "$0")/../.."
RUNS=10
METHODS=repeat,navigate,follow
REPEAT_SCENARIOS=table1_sharp_turn_low_texture,table1_almost_straight
HOMING=--homing
SEED=1
OUT=""
BIN=build/release/apps/mapless
MW=ros1
DIRECT_DIR=""
DIRECT_ONLY=0
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) RUNS="$2"; shift 2 ;;
    --methods) METHODS="$2"; shift 2 ;;
    --repeat-scenarios) REPEAT_SCENARIOS="$2"; shift 2 ;;
    --no-homing) HOMING=""; shift ;;
    --seed) SEED="$2"; shift 2 ;;
    --out) OUT="$2"; shift 2 ;;
    --mapless) BIN="$2"; shift 2 ;;
    --middleware) MW="$2"; shift 2 ;;
    --direct) DIRECT_DIR="$2"; shift 2 ;;
    --direct-only) DIRECT_ONLY=1; shift ;;
    *) echo "closed_loop.sh: unknown option $1" >&2; exit 2 ;;
  esac
done
case "$RUNS" in ''|*[!0-9]*) echo "closed_loop.sh: --runs $RUNS: not a number" >&2; exit 2 ;; esac
if [ "$DIRECT_ONLY" = 0 ] && { ! "$BIN" sim serve --help >/dev/null 2>&1 ||
                                ! "$BIN" sim serve --help | grep -q -- --robot; }; then
  echo "closed_loop.sh: SKIPPED: $BIN has no sim serve" ; exit 77
fi
BIN=$(realpath "$BIN")
[ -n "$OUT" ] || OUT=$(mktemp -d /tmp/mapless_closed_loop.XXXXXX)  # kept: the runs are in it
if [ "$DIRECT_ONLY" = 0 ]; then
  # shellcheck source=env.sh
  source "$(dirname "$0")/env.sh" closed_loop "$MW"
else  # made afresh: what an older build left there is not reused
  rm -rf "$OUT" ${DIRECT_DIR:+"$DIRECT_DIR"}; mkdir -p "$OUT"; OUT=$(realpath "$OUT")
fi
[ -n "$DIRECT_DIR" ] || DIRECT_DIR=$OUT
mkdir -p "$DIRECT_DIR"; DIRECT_DIR=$(realpath "$DIRECT_DIR")

cat >"$OUT/robot.yaml" <<YAML
middleware: $MW
# The simulated robot over the middleware, in simulated time (lockstep with the method). The limits are
# the simulated robot's own (sim::RobotOptions), so that they clamp nothing the direct run does not.
name: simulated
use_sim_time: true
limits: {max_speed_mps: 1.0, max_turn_rate_radps: 2.0}
YAML

field() { grep -o "\"$2\": *[-0-9.e]*" "$1" | tail -1 | sed 's/.*: *//'; }
last_field() { tail -1 "$1" | grep -o "\"$2\":[-0-9.e]*" | sed 's/.*://'; }

# run_pair NAME SEED SCENARIO LIKE DIRECT_CMD... -- ROS_CMD...
ALL_OK=1
line() {  # name scenario like direct... ; uses globals DIRECT ROSCMD
  local name="$1" scenario="$2" like="$3"
  local done_ros=0 done_direct=0 collisions=0 worst=0 fails=""
  for k in $(seq 0 $((RUNS - 1))); do
    local s=$((SEED + k)) d="$OUT/$name/seed$((SEED + k))" dd="$DIRECT_DIR/$name/seed$((SEED + k))"
    mkdir -p "$d" "$dd"
    if [ ! -s "$dd/direct.rc" ]; then  # the direct twin, unless a run before this one made it
      rm -f "$dd/direct.jsonl"
      "${DIRECT[@]}" --seed "$s" --log "$dd/direct.jsonl" >"$dd/direct.log" 2>&1
      echo $? >"$dd/direct.rc.partial" && mv "$dd/direct.rc.partial" "$dd/direct.rc"
    fi
    local direct_rc
    direct_rc=$(cat "$dd/direct.rc")
    [ "$DIRECT_ONLY" = 1 ] && continue
    timeout 600 "$BIN" sim serve --scenario "$scenario" --robot "$OUT/robot.yaml" --like "$like" \
      --seed "$s" --summary "$d/serve.json" >"$d/serve.log" 2>&1 &
    local serve=$!
    PIDS+=("$serve")
    timeout 600 "${ROSCMD[@]}" --log "$d/ros.jsonl" >"$d/ros.log" 2>&1
    local ros_rc=$?
    wait "$serve"
    [ "$direct_rc" = 0 ] && done_direct=$((done_direct + 1))
    [ "$ros_rc" = 0 ] && done_ros=$((done_ros + 1))
    grep -q '"collided": true' "$d/serve.json" 2>/dev/null && collisions=$((collisions + 1))
    local dx dy rx ry dist
    dx=$(last_field "$dd/direct.jsonl" x_m); dy=$(last_field "$dd/direct.jsonl" y_m)
    rx=$(field "$d/serve.json" decided_x_m); ry=$(field "$d/serve.json" decided_y_m)
    if [ -z "$dx" ] || [ -z "$rx" ]; then
      dist=inf
    else
      dist=$(awk -v a="$dx" -v b="$dy" -v c="$rx" -v e="$ry" 'BEGIN{printf "%.4f", sqrt((a-c)^2+(b-e)^2)}')
    fi
    worst=$(awk -v w="$worst" -v d="$dist" 'BEGIN{ if (d == "inf" || d + 0 > w + 0) print d; else print w }')
    echo "{\"line\":\"$name\",\"seed\":$s,\"ros_exit\":$ros_rc,\"direct_exit\":$direct_rc,\"final_pose_difference_m\":\"$dist\"}" >>"$OUT/runs.jsonl"
    [ "$ros_rc" = 0 ] || fails="$fails seed$s(ros exit $ros_rc)"
  done
  [ "$DIRECT_ONLY" = 1 ] && { echo "$name: $RUNS direct run(s) in $DIRECT_DIR/$name"; return; }
  local ok=1
  [ "$done_ros" = "$RUNS" ] && [ "$done_direct" = "$RUNS" ] && [ "$collisions" = 0 ] || ok=0
  awk -v w="$worst" 'BEGIN{ exit !(w != "inf" && w + 0 <= 0.05) }' || ok=0
  [ "$ok" = 1 ] || ALL_OK=0
  printf "%-42s ros %2d/%d  direct %2d/%d  max final-pose difference %s m  collisions %d  %s%s\n" \
    "$name" "$done_ros" "$RUNS" "$done_direct" "$RUNS" "$worst" "$collisions" \
    "$([ $ok = 1 ] && echo PASS || echo FAIL)" "${fails:+ ($fails)}"
}

: >"$OUT/runs.jsonl"
START=$(date +%s)
IFS=, read -r -a M <<<"$METHODS"
for m in "${M[@]}"; do
  case "$m" in
    repeat)
      IFS=, read -r -a RS <<<"$REPEAT_SCENARIOS"
      for sc in "${RS[@]}"; do
        [ -s "$DIRECT_DIR/routes/$sc/manifest.json" ] ||
          "$BIN" teach --source "sim:$sc" --out "$DIRECT_DIR/routes/$sc" --overwrite >"$DIRECT_DIR/teach_$sc.log" 2>&1 ||
          { echo "closed_loop.sh: teach $sc failed (see $DIRECT_DIR/teach_$sc.log)"; exit 1; }
        DIRECT=("$BIN" repeat --route "$DIRECT_DIR/routes/$sc" --source "sim:$sc")
        ROSCMD=("$BIN" repeat --route "$DIRECT_DIR/routes/$sc" --robot "$OUT/robot.yaml")
        line "repeat sloped $sc" "$sc" repeat
      done ;;
    navigate)
      CAL="$DIRECT_DIR/obstacle_field_calibration.yaml"
      [ -s "$CAL" ] ||
        "$BIN" navigate --scenario obstacle_field --destination-index 0 --seed 0 --motion-noise 0 \
          --image-noise 0 --save-calibration "$CAL" >"$DIRECT_DIR/calibrate.log" 2>&1 || true
      [ -s "$CAL" ] ||
        { echo "closed_loop.sh: calibration failed (see $DIRECT_DIR/calibrate.log)"; exit 1; }
      DIRECT=("$BIN" navigate --scenario obstacle_field --destination-index 0 $HOMING
              --calibration "$CAL")
      ROSCMD=("$BIN" navigate --robot "$OUT/robot.yaml" --scenario obstacle_field
              --destination-index 0 $HOMING --calibration "$CAL")
      line "navigate obstacle_field destination 0${HOMING:+ + home}" obstacle_field navigate ;;
    follow)
      [ -s "$DIRECT_DIR/routes/office_eigenspace/appearance.json" ] ||
        "$BIN" teach --source sim:office_aliasing --method eigenspace --out "$DIRECT_DIR/routes/office_eigenspace" \
          --overwrite >"$DIRECT_DIR/teach_office_eigenspace.log" 2>&1 ||
        { echo "closed_loop.sh: teach office_aliasing failed"; exit 1; }
      DIRECT=("$BIN" follow --route "$DIRECT_DIR/routes/office_eigenspace" --source sim:office_aliasing)
      ROSCMD=("$BIN" follow --route "$DIRECT_DIR/routes/office_eigenspace" --robot "$OUT/robot.yaml")
      line "follow office_aliasing" office_aliasing follow ;;
    *) echo "closed_loop.sh: unknown method $m (repeat, navigate, follow)" >&2; exit 2 ;;
  esac
done
echo "closed_loop.sh: $(( $(date +%s) - START )) s; runs in $OUT"
[ "$ALL_OK" = 1 ]

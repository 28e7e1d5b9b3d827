#!/usr/bin/env bash
# A real ROS 2 middleware on the other end (issue 40): `mapless sim serve` (a simulated robot in
# namespace /sim, real time) and `mapless repeat --robot` run on ROS 2 (Cyclone DDS, loopback
# only: ROS_LOCALHOST_ONLY=1 in a domain of the test's own); then fastdds_robot, an eProsima Fast
# DDS participant with types from the ROS 2 message definitions, joins after them and relays the
# robot's camera and odometry to the method and its commands back, presses the e-stop and checks
# discovery within 2 s, every message type, the command rate and the e-stop's rate
# (tests/ros2/fastdds/fastdds_robot.cc). Then the same in lockstep under use_sim_time with a JPEG
# camera: the clock and CompressedImages relayed by the Fast DDS node.
#   tests/ros2/fastdds.sh MAPLESS FASTDDS_ROBOT
# The Fast DDS node discovers as rmw_fastrtps does on loopback (multicast, which mapless does not
# hear there): mapless finds it by its own announcements, once a second (src/mapless/ros2/dds.cc).
# Loopback with a domain of its own, not a network namespace: the other ROS 2 tests do the same
# and it needs no root.
set -uo pipefail
BIN=$1; PEER=$2
# shellcheck source=../robot_link/env.sh
source "$(dirname "$0")/../robot_link/env.sh" fastdds.sh ros2
printf 'middleware: ros2\nname: simulated robot\nnamespace: sim\nuse_sim_time: false\n' >"$OUT/sim.yaml"
printf 'middleware: ros2\nname: robot behind Fast DDS\nuse_sim_time: false\n' >"$OUT/robot.yaml"
failed() {  # failed WHERE LOG...: says so with the end of each log, and exits 1
  echo "fastdds.sh: FAILED$1 (exit $RC)"
  shift
  for f in "$@"; do echo "== $f.log"; tail -5 "$OUT/$f.log"; done
  exit 1
}
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/route" >"$OUT/teach.log" 2>&1 ||
  { echo "fastdds.sh: teach failed"; exit 1; }
"$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/sim.yaml" --like repeat \
  >"$OUT/serve.log" 2>&1 &
PIDS+=($!)
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/robot.yaml" >"$OUT/repeat.log" 2>&1 &
PIDS+=($!)
sleep 2  # both are up and have announced themselves: the Fast DDS node is the newcomer
RESULT=$(timeout 90 "$PEER" 40 2.0 15)
RC=$?
echo "fastdds: $RESULT"
[ "$RC" = 0 ] || failed "" serve repeat
for p in "${PIDS[@]}"; do kill -INT "$p" 2>/dev/null; done
wait 2>/dev/null
PIDS=()
# Lockstep under use_sim_time, the camera as JPEG CompressedImages: the clock and the compressed
# frames come to the method from the Fast DDS node.
printf 'middleware: ros2
name: simulated robot
namespace: sim
use_sim_time: true
topics: {compressed_image: camera/image_raw/compressed}
' >"$OUT/sim2.yaml"
printf 'middleware: ros2
name: robot behind Fast DDS
use_sim_time: true
topics: {compressed_image: camera/image_raw/compressed}
' >"$OUT/robot2.yaml"
"$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/sim2.yaml" --like repeat   --encoding jpeg >"$OUT/serve2.log" 2>&1 &
PIDS+=($!)
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/robot2.yaml" >"$OUT/repeat2.log" 2>&1 &
PIDS+=($!)
sleep 1
RESULT=$(timeout 90 "$PEER" lockstep 60)
RC=$?
echo "fastdds: $RESULT"
[ "$RC" = 0 ] || failed " in lockstep" serve2 repeat2
echo "fastdds.sh: passed"

#!/usr/bin/env bash
# Discovery and matching (issue 18): a plain Cyclone DDS program (dds_spy, no mapless code) sees
# mapless's ROS 2 endpoints with the ROS 2 topic names, type names, QoS and type hash, while
# `mapless repeat --robot` drives `mapless sim serve` over DDS. Exit 77 without Cyclone.
#   tests/ros2/discovery.sh MAPLESS DDS_SPY
set -uo pipefail
BIN=$1; SPY=$2
# shellcheck source=../robot_link/env.sh
source "$(dirname "$0")/../robot_link/env.sh" discovery ros2
printf 'middleware: ros2\nuse_sim_time: true\nnamespace: /robot1\n' >"$OUT/robot.yaml"
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/route" >"$OUT/teach.log" 2>&1 ||
  { echo "discovery.sh: teach failed"; exit 1; }
"$BIN" sim serve --scenario table1_almost_straight --robot "$OUT/robot.yaml" --like repeat \
  >"$OUT/serve.log" 2>&1 &
PIDS+=($!)
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/robot.yaml" >"$OUT/repeat.log" 2>&1 &
PIDS+=($!)
"$SPY" 4 >"$OUT/spy.jsonl"
FAILS=0
expect() {  # kind topic type reliability history hash
  local line
  line=$(grep "\"kind\":\"$1\",\"topic\":\"$2\",\"type\":\"$3\",\"reliability\":\"$4\",\"history\":$5,\"durability\":\"volatile\",\"user_data\":\"typehash=$6;\"" "$OUT/spy.jsonl" | head -1)
  if [ -n "$line" ]; then
    echo "ok   $1 $2 $3 $4 keep last $5"
  else
    echo "FAIL no $1 on $2 with type $3, $4, keep last $5, type hash $6"
    grep "\"topic\":\"$2\"" "$OUT/spy.jsonl" | sed 's/^/     seen: /'
    FAILS=$((FAILS + 1))
  fi
}
TWIST=RIHS01_9c45bf16fe0983d80e3cfe750d6835843d265a9a6c46bd2e609fcddde6fb8d2a
IMAGE=RIHS01_d31d41a9a4c4bc8eae9be757b0beed306564f7526c88ea6a4588fb9582527d47
ODOM=RIHS01_3cc97dc7fb7502f8714462c526d369e35b603cfc34d946e3f2eda2766dfec6e0
STRING=RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18
BOOL=RIHS01_feb91e995ff9ebd09c0cb3d2aed18b11077585839fb5db80193b62d74528f6c9
CLOCK=RIHS01_692f7a66e93a3c83e71765d033b60349ba68023a8c689a79e48078bcb5c58564
# The method (mapless repeat --robot).
expect reader rt/robot1/camera/image_raw "sensor_msgs::msg::dds_::Image_" best_effort 5 "$IMAGE"
expect reader rt/robot1/odom "nav_msgs::msg::dds_::Odometry_" best_effort 5 "$ODOM"
expect reader rt/robot1/mapless/estop "std_msgs::msg::dds_::Bool_" reliable 10 "$BOOL"
expect reader rt/clock "rosgraph_msgs::msg::dds_::Clock_" best_effort 1 "$CLOCK"
expect writer rt/robot1/cmd_vel "geometry_msgs::msg::dds_::Twist_" reliable 10 "$TWIST"
expect writer rt/robot1/mapless/status "std_msgs::msg::dds_::String_" reliable 10 "$STRING"
expect writer rt/robot1/mapless/debug_image "sensor_msgs::msg::dds_::Image_" best_effort 5 "$IMAGE"
# The simulated robot (mapless sim serve).
expect writer rt/robot1/camera/image_raw "sensor_msgs::msg::dds_::Image_" best_effort 5 "$IMAGE"
expect writer rt/robot1/odom "nav_msgs::msg::dds_::Odometry_" reliable 10 "$ODOM"
expect writer rt/clock "rosgraph_msgs::msg::dds_::Clock_" best_effort 1 "$CLOCK"
expect reader rt/robot1/cmd_vel "geometry_msgs::msg::dds_::Twist_" reliable 10 "$TWIST"
N=$(wc -l <"$OUT/spy.jsonl")
echo "discovery.sh: $N endpoints seen, $FAILS missing"
[ "$FAILS" = 0 ]

# Hardening round 3 (issue 40), sourced by probe.sh (its fixtures, probe() and check()): the kinds of
# wrong answers that round found, each probed with inputs of its own. ROUND3_FIRST is the case
# count before this file; probe.sh checks that at least 80 cases come from here.
ROUND3_FIRST=$cases

# ---------------------------------------------------------------------------------------------
echo "# round 3: readers that accept junk"
robot() {  # robot NAME TEXT: a robot file
  printf '%b' "$2" >"$FX/$1.yaml"
}
robot r3_dup_middleware 'middleware: ros2\nmiddleware: ros1\n'
robot r3_dup_topic 'topics:\n  image: a/image\n  image: b/image\n'
robot r3_dup_limits 'limits: {max_speed_mps: 0.5, max_speed_mps: 5}\n'
robot r3_cmd_is_camera 'topics: {cmd_vel: camera/image_raw}\n'
robot r3_status_is_cmd 'topics: {status: cmd_vel}\n'
robot r3_estop_is_odom 'namespace: r1\ntopics: {estop: /r1/odom}\n'
robot r3_debug_is_camera 'topics: {image: cam, debug_image: cam}\n'
robot r3_compressed_is_cmd 'topics: {compressed_image: /cmd_vel}\n'
probe "robot file naming middleware twice" 2 "duplicate key 'middleware'" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_dup_middleware.yaml"
probe "robot file naming a topic twice" 2 "duplicate key 'image'" -- "$MAPLESS" teach --robot "$FX/r3_dup_topic.yaml" --out "$NEW/r3t1"
probe "robot file naming a limit twice" 2 "duplicate key 'max_speed_mps'" -- "$MAPLESS" follow --route "$FX/aroute" --robot "$FX/r3_dup_limits.yaml"
probe "robot file: cmd_vel on the camera topic" 2 "topics.cmd_vel: 'camera/image_raw' is also the image topic" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_cmd_is_camera.yaml"
probe "robot file: status on cmd_vel" 2 "is also the cmd_vel topic" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_status_is_cmd.yaml"
probe "robot file: e-stop on the odometry (namespaced)" 2 "is also the odometry topic" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_estop_is_odom.yaml"
probe "robot file: debug image on the camera" 2 "is also the image topic" -- "$MAPLESS" sim serve --scenario table1_almost_straight --robot "$FX/r3_debug_is_camera.yaml"
probe "robot file: compressed camera on cmd_vel" 2 "is also the" -- "$MAPLESS" teach --robot "$FX/r3_compressed_is_cmd.yaml" --out "$NEW/r3t2"
sed 's/^name: probe/name: probe\nname: again/' "$FX/ok.yaml" >"$FX/r3_dup_scenario.yaml"
probe "scenario naming a field twice" 2 "r3_dup_scenario.yaml:2:1: duplicate key 'name'" -- "$MAPLESS" sim render --scenario "$FX/r3_dup_scenario.yaml" --pose 0,0,0 --out "$NEW/r3.png"
sed 's/{type: box, center: \[3, 1.5\]/{type: box, center: [3, 1.5], type: cylinder/' "$FX/ok.yaml" >"$FX/r3_dup_object.yaml"
probe "scenario object naming its type twice" 2 "duplicate key 'type'" -- "$MAPLESS" teach --source "sim:$FX/r3_dup_object.yaml" --out "$NEW/r3t3"
printf 'drive: {seed: 1}\ndrive: {seed: 2}\n' >"$FX/r3_dup_config.yaml"
probe "run config naming a section twice" 2 "duplicate key 'drive'" -- "$MAPLESS" sim drive --scenario "$FX/ok.yaml" --config "$FX/r3_dup_config.yaml" --out "$NEW/r3d1"
{ cat "$FX/calibration.yaml"; echo "width: 640"; } >"$FX/r3_dup_calibration.yaml"
probe "calibration naming a field twice" 2 "duplicate key 'width'" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r3_dup_calibration.yaml"
{ cat "$FX/fleet.key"; grep public_key "$FX/fleet.key"; } >"$FX/r3_dup.key"
probe "key file naming its public key twice" 2 "duplicate key 'public_key'" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l1" --bind tcp://127.0.0.1:1 --curve-key "$FX/r3_dup.key"
printf 'image_width: 320\nimage_height: 240\nimage_width: 640\n' >"$FX/r3_dup_camera_info.yaml"
probe "camera_info naming a field twice" 2 "duplicate key 'image_width'" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --record "$NEW/r3.mcap" --camera-info "$FX/r3_dup_camera_info.yaml"
robot r3_dup_safety 'safety:\n  camera_timeout_s: 0.2\n  camera_timeout_s: 5\n'
robot r3_dup_obstacles 'obstacles: {on_obstacle: stop, on_obstacle: off}\n'
robot r3_dup_camera 'camera: {mount: upright, mount: rotated_180}\n'
probe "robot file naming a safety timeout twice" 2 "duplicate key 'camera_timeout_s'" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_dup_safety.yaml"
probe "robot file naming on_obstacle twice" 2 "duplicate key 'on_obstacle'" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r3_dup_obstacles.yaml"
probe "robot file naming the camera mount twice" 2 "duplicate key 'mount'" -- "$MAPLESS" follow --route "$FX/aroute" --robot "$FX/r3_dup_camera.yaml"
sed 's/^  start: \[0, 0, 0\]/  start: [0, 0, 0]\n  start: [1, 0, 0]/' "$FX/ok.yaml" >"$FX/r3_dup_start.yaml"
probe "scenario naming the teach start twice" 2 "duplicate key 'start'" -- "$MAPLESS" sim drive --scenario "$FX/r3_dup_start.yaml" --out "$NEW/r3d2"
{ cat "$FX/ok.yaml"; echo "destinations: [[1, 0]]"; } >"$FX/r3_dup_destinations.yaml"
probe "scenario naming its destinations twice" 2 "duplicate key 'destinations'" -- "$MAPLESS" navigate --scenario "$FX/r3_dup_destinations.yaml"
t_ns_route() {  # t_ns_route NAME VALUE: the route with keyframe 1's t_ns replaced
  cp -r "$FX/route" "$FX/$1"
  sed -i "s/^t_ns: \".*\"/t_ns: \"$2\"/" "$FX/$1/keyframes/000001.yml"
}
t_ns_route r3_t_half 0.5
t_ns_route r3_t_junk 12abc
t_ns_route r3_t_exp 1e3
t_ns_route r3_t_empty ""
t_ns_route r3_t_huge 99999999999999999999
t_ns_route r3_t_space " 7"
t_ns_route r3_t_negative_half -0.5
t_ns_route r3_t_plus +5
probe "keyframe t_ns 0.5" 2 "t_ns: expected a whole number of nanoseconds, got '0.5'" -- "$MAPLESS" route info "$FX/r3_t_half"
probe "keyframe t_ns 12abc" 2 "got '12abc'" -- "$MAPLESS" route info "$FX/r3_t_junk"
probe "keyframe t_ns 1e3" 2 "got '1e3'" -- "$MAPLESS" repeat --route "$FX/r3_t_exp" --source "$FX/frames"
probe "keyframe t_ns empty" 2 "t_ns" -- "$MAPLESS" route info "$FX/r3_t_empty"
probe "keyframe t_ns beyond 64 bits" 2 "got '99999999999999999999'" -- "$MAPLESS" route info "$FX/r3_t_huge"
probe "keyframe t_ns with a leading space" 2 "t_ns" -- "$MAPLESS" route info "$FX/r3_t_space"
probe "keyframe t_ns -0.5" 2 "got '-0.5'" -- "$MAPLESS" route info "$FX/r3_t_negative_half"
probe "keyframe t_ns +5" 2 "got '+5'" -- "$MAPLESS" route info "$FX/r3_t_plus"

# ---------------------------------------------------------------------------------------------
echo "# round 3: silent garbage"
for rate in 1e-300 1e-9 -1 nan 1e300 1001; do
  probe "teach --rate $rate" 2 "--rate" -- "$MAPLESS" teach --source "$FX/frames" --out "$NEW/r3t4" --rate "$rate"
done
probe "repeat --rate 1e-300" 2 "--rate: '1e-300'" -- "$MAPLESS" repeat --route "$FX/route" --source "$FX/frames" --rate 1e-300
probe "lead --real-time-factor 1e-300" 2 "--real-time-factor: '1e-300'" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l2" --bind tcp://127.0.0.1:1 --real-time-factor 1e-300
probe "follow --connect --real-time-factor 1e-9" 2 "--real-time-factor: '1e-9'" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r3c1" --real-time-factor 1e-9
probe "follow --connect --real-time-factor 1e300" 2 "--real-time-factor: '1e300'" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r3c1" --real-time-factor 1e300
probe "lead --real-time-factor 1e-9" 2 "--real-time-factor: '1e-9'" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l2" --bind tcp://127.0.0.1:1 --real-time-factor 1e-9
for port in 99999 65536 -1 5x "" 1234567; do
  probe "lead --bind port '$port'" 2 "--bind tcp://127.0.0.1:$port: " -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l3" --bind "tcp://127.0.0.1:$port"
  probe "follow --connect port '$port'" 2 "--connect tcp://127.0.0.1:$port: " -- "$MAPLESS" follow --connect "tcp://127.0.0.1:$port" --source sim:table1_almost_straight --route "$NEW/r3c2"
done
probe "follow --connect to port 0" 2 "a follower needs the leader's port" -- "$MAPLESS" follow --connect tcp://127.0.0.1:0 --source sim:table1_almost_straight --route "$NEW/r3c3"
probe "follow --connect with no host" 2 "no host" -- "$MAPLESS" follow --connect tcp://:5600 --source sim:table1_almost_straight --route "$NEW/r3c4"
probe "lead --bind udp://" 2 "expected tcp://HOST:PORT or ipc://PATH" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l4" --bind udp://127.0.0.1:5600
probe "lead --bind ipc:// with no path" 2 "ipc:// needs a path" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3l5" --bind ipc://
# A recording of a short simulated teach (camera and odometry), and the route taught with it.
"$FIXTURES" teach --source "sim:$FX/ok.yaml" --out "$TMP/r3route" --record "$FX/r3_odom.mcap" >/dev/null 2>&1
[ -s "$FX/r3_odom.mcap" ] && [ -s "$TMP/r3route/manifest.json" ]; check "round 3 fixtures: a recording and its route" $?
probe "follow on a recording without odometry" 1 "stopped on all" -- "$MAPLESS" follow --route "$FX/aroute" --source "$FX/r3_odom.mcap" --odom-topic none --log "$NEW/r3f.jsonl"
corrupt_length() {  # corrupt_length NAME LOG2: r3_odom.mcap with its second record's length 2^LOG2
  python3 - "$FX/r3_odom.mcap" "$FX/$1.mcap" "$2" <<'EOF'
import struct, sys
data = bytearray(open(sys.argv[1], 'rb').read())
at = 8  # after the magic: the header record
at += 9 + struct.unpack_from('<Q', data, at + 1)[0]
struct.pack_into('<Q', data, at + 1, 1 << int(sys.argv[3]))
open(sys.argv[2], 'wb').write(data)
EOF
}
corrupt_length r3_len62 62
corrupt_length r3_len40 40
corrupt_length r3_len33 33
corrupt_length r3_len63 63
probe "recording with a record length of 2^62" 2 "not a record length" -- "$MAPLESS" teach --source "$FX/r3_len62.mcap" --out "$NEW/r3t5"
probe "recording with a record length of 2^40" 2 "not a record length" -- "$MAPLESS" localize --database "$FX/r3_len40.mcap" --query "$FX/frames" --json
probe "recording with a record length of 2^33" 2 "not a record length" -- "$MAPLESS" teach --source "$FX/r3_len33.mcap" --out "$NEW/r3t7"
probe "recording with a record length of 2^63" 2 "not a record length" -- "$MAPLESS" repeat --route "$TMP/r3route" --source "$FX/r3_len63.mcap"
probe "follow on a recording with a corrupt length" 2 "r3_len62.mcap" -- "$MAPLESS" follow --route "$FX/aroute" --source "$FX/r3_len62.mcap"

# ---------------------------------------------------------------------------------------------
echo "# round 3: late checks and what the user made"
for suite in table1 funnel-scenarios obstacles potential eigenspace; do
  probe "eval $suite --report /dev/null" 2 "--report /dev/null: is not a directory" -- "$MAPLESS" eval "$suite" --runs 1 --report /dev/null
done
probe "eval --report onto a file" 2 "f0.png: is not a directory" -- "$MAPLESS" eval table1 --runs 1 --report "$FX/f0.png"
mkdir -p "$FX/r3_site" && echo '<html>my page</html>' >"$FX/r3_site/index.html"
probe "eval --report into a user's site" 2 "index.html exists and is not a mapless report" -- "$MAPLESS" eval table1 --runs 1 --report "$FX/r3_site"
probe "eval potential --report into a user's site" 2 "is not a mapless report" -- "$MAPLESS" eval potential --runs 1 --report "$FX/r3_site"
probe "eval eigenspace --report into a user's site" 2 "is not a mapless report" -- "$MAPLESS" eval eigenspace --runs 1 --report "$FX/r3_site"
probe "demo --out /dev/null" 2 "/dev/null" -- "$MAPLESS" demo --out /dev/null
mkdir -p "$FX/r3_keydir"
probe "fleet keygen onto a directory" 2 "r3_keydir: exists" -- "$MAPLESS" fleet keygen "$FX/r3_keydir"
cp "$FX/fleet.key.pub" "$FX/r3_only.key.pub"
probe "fleet keygen where only FILE.pub exists" 2 "r3_only.key.pub: exists" -- "$MAPLESS" fleet keygen "$FX/r3_only.key"
ln -s "$FX/nowhere" "$FX/r3_dangling.key"
probe "fleet keygen onto a dangling link" 2 "r3_dangling.key: exists" -- "$MAPLESS" fleet keygen "$FX/r3_dangling.key"

# ---------------------------------------------------------------------------------------------
echo "# round 3: two writers"
"$MAPLESS" lead --source sim:table1_almost_straight --method eigenspace --route "$NEW/r3lead" \
  --bind tcp://127.0.0.1:0 --real-time-factor 0 >"$TMP/r3lead.out" 2>"$TMP/r3lead.err" &
r3lead=$!
wait_until 120 "$r3lead" grep -q "route complete" "$TMP/r3lead.err"
grep -q "route complete" "$TMP/r3lead.err"; check "round 3 fixture: a leader serving its route" $?
probe "teach --overwrite onto a leader's route" 2 "r3lead: another mapless process is writing" -- "$MAPLESS" teach --source sim:table1_almost_straight --method eigenspace --out "$NEW/r3lead" --overwrite
probe "a second leader on a leader's route" 2 "r3lead: another mapless process is writing" -- "$MAPLESS" lead --source sim:table1_almost_straight --method eigenspace --route "$NEW/r3lead" --bind tcp://127.0.0.1:1
probe "a follower copying into a leader's route" 2 "r3lead: another mapless process is writing" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r3lead"
kill -INT "$r3lead"; wait "$r3lead" 2>/dev/null
"$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --log "$NEW/r3two.jsonl" >/dev/null 2>&1 &
r3rep=$!
wait_until 120 "$r3rep" test -s "$NEW/r3two.jsonl.partial"
probe "two runs writing one log" 2 "r3two.jsonl: another mapless process is writing this file" -- "$MAPLESS" repeat --route "$FX/route" --source "$FX/frames" --log "$NEW/r3two.jsonl"
kill -INT "$r3rep"; wait "$r3rep" 2>/dev/null
"$MAPLESS" teach --source sim:outdoor_70m --out "$NEW/r3teaching" >/dev/null 2>&1 &
r3teach=$!
wait_until 120 "$r3teach" test -f "$NEW/r3teaching/keyframes/000001.yml"
probe "a leader on a route a teach is writing" 2 "r3teaching: another mapless process is writing" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r3teaching" --bind tcp://127.0.0.1:1
probe "a follower copying into a route a teach is writing" 2 "r3teaching: another mapless process is writing" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r3teaching"
probe "a learning repeat on a route a teach is writing" 2 "r3teaching: another mapless process is writing" -- "$MAPLESS" repeat --learn --route "$NEW/r3teaching" --source sim:table1_almost_straight
kill -INT "$r3teach"; wait "$r3teach" 2>/dev/null
[ -s "$NEW/r3two.jsonl" ]; check "the first run's log is whole after the second was refused" $?

# ---------------------------------------------------------------------------------------------
echo "# round 3: silent waits"
"$FIXTURES" fleet keygen "$FX/r3_leader.key" >/dev/null 2>&1
"$FIXTURES" fleet keygen "$FX/r3_other.key" >/dev/null 2>&1
"$MAPLESS" lead --source sim:table1_almost_straight --method eigenspace --route "$NEW/r3curve" \
  --bind tcp://127.0.0.1:0 --real-time-factor 0 --curve-key "$FX/r3_leader.key" --curve-allow "$FX/r3_other.key.pub" \
  >"$TMP/r3curve.out" 2>"$TMP/r3curve.err" &
r3curve=$!
"$MAPLESS" lead --source sim:table1_almost_straight --method eigenspace --route "$NEW/r3plain" \
  --bind tcp://127.0.0.1:0 --real-time-factor 0 >"$TMP/r3plain.out" 2>"$TMP/r3plain.err" &
r3plain=$!
endpoint() { grep -o 'lead: serving .* on tcp://127.0.0.1:[0-9]*' "$1" | grep -o 'tcp://.*' | head -1; }
both_serving() { [ -n "$(endpoint "$TMP/r3curve.err")" ] && [ -n "$(endpoint "$TMP/r3plain.err")" ]; }
wait_until 120 "$r3curve" both_serving
curve_at=$(endpoint "$TMP/r3curve.err")
plain_at=$(endpoint "$TMP/r3plain.err")
[ -n "$curve_at" ] && [ -n "$plain_at" ]; check "round 3 fixture: two leaders ($curve_at, $plain_at)" $?
probe "follower without a key, leader with CURVE" 1 "the handshake with $curve_at failed" -- "$MAPLESS" follow --connect "$curve_at" --source sim:table1_almost_straight --route "$NEW/r3k1"
probe "follower with the wrong leader key" 1 "the handshake with $curve_at failed" -- "$MAPLESS" follow --connect "$curve_at" --source sim:table1_almost_straight --route "$NEW/r3k2" --curve-key "$FX/fleet.key" --curve-leader "$FX/r3_other.key.pub"
probe "follower whose key the leader does not admit" 1 "refused this follower's CURVE key" -- "$MAPLESS" follow --connect "$curve_at" --source sim:table1_almost_straight --route "$NEW/r3k3" --curve-key "$FX/fleet.key" --curve-leader "$FX/r3_leader.key.pub"
probe "follower with a key, leader without" 1 "the handshake with $plain_at failed" -- "$MAPLESS" follow --connect "$plain_at" --source sim:table1_almost_straight --route "$NEW/r3k4" --curve-key "$FX/fleet.key" --curve-leader "$FX/r3_leader.key.pub"
kill -INT "$r3curve" "$r3plain"; wait "$r3curve" "$r3plain" 2>/dev/null
"$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r3k5" >/dev/null 2>"$TMP/r3wait.err" &
r3wait=$!
wait_until 60 "$r3wait" grep -q "still waiting" "$TMP/r3wait.err"
kill -INT "$r3wait"; wait "$r3wait" 2>/dev/null
grep -q "still waiting for the leader's route: no connection to tcp://127.0.0.1:1" "$TMP/r3wait.err"; st=$?; check "a follower with no leader says what it waits for ($(head -c 200 "$TMP/r3wait.err"))" $st

# ---------------------------------------------------------------------------------------------
echo "# round 3: a crash"
cut_when_mapped() {  # cut_when_mapped FILE: once a process has FILE mapped and plays it, copy a
  # short file over it (what `cp new.mcap FILE` does: truncate, then write)
  for _ in $(seq 1 600); do
    grep -qs "$1" /proc/[0-9]*/maps && break
    sleep 0.05
  done
  sleep 0.5
  cp "$TMP/r3small.mcap" "$1"
}
cp "$FX/r3_odom.mcap" "$NEW/r3play.mcap"
head -c 20000 "$FX/r3_odom.mcap" >"$TMP/r3small.mcap"
cut_when_mapped "$NEW/r3play.mcap" &
probe "a recording cut while it plays" 2 "r3play.mcap: the file changed while it was read" -- "$MAPLESS" teach --source "$NEW/r3play.mcap" --out "$NEW/r3t6" --rate 1
wait
[ ! -e "$NEW/r3t6" ]; check "the failed teach left no route behind" $?
cp "$FX/r3_odom.mcap" "$NEW/r3play2.mcap"
cut_when_mapped "$NEW/r3play2.mcap" &
probe "a recording cut while a repeat plays it" 2 "r3play2.mcap: the file changed while it was read" -- "$MAPLESS" repeat --route "$TMP/r3route" --source "$NEW/r3play2.mcap" --rate 1
wait

ROUND3_CASES=$((cases - ROUND3_FIRST))
echo "probe: $ROUND3_CASES cases of round 3"

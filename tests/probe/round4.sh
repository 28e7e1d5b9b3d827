# Hardening round 4 (issue 67), sourced by probe.sh (its fixtures, probe() and check()): the kinds
# of wrong answers that round found, each probed with inputs of its own. ROUND4_FIRST is the case
# count before this file; probe.sh checks that at least 100 cases come from here.
ROUND4_FIRST=$cases

# ---------------------------------------------------------------------------------------------
echo "# round 4: YAML that expands (every reader, refused by its expanded size)"
# laughs FILE LEVELS [PREFIX]: nested aliases, ten of the level below on each level (10^LEVELS
# values from a file of about 60 bytes a level), after PREFIX (the reader's own first lines).
laughs() {
  local file=$1 levels=$2 prefix=${3:-}
  {
    printf '%b' "$prefix"
    printf 'x0: &a0 [x, x, x, x, x, x, x, x, x, x]\n'
    for i in $(seq 1 $((levels - 1))); do
      printf 'x%d: &a%d [' "$i" "$i"
      for k in 1 2 3 4 5 6 7 8 9 10; do printf '*a%d%s' $((i - 1)) "$([ $k -lt 10 ] && echo ', ')"; done
      printf ']\n'
    done
  } >"$file"
}
# maplaughs FILE LEVELS: the same shape with mappings (a key per copy) under one field.
maplaughs() {
  local file=$1 levels=$2
  {
    printf 'x0: &a0 {a: x, b: x, c: x, d: x, e: x, f: x, g: x, h: x, i: x, j: x}\n'
    for i in $(seq 1 $((levels - 1))); do
      printf 'x%d: &a%d {' "$i" "$i"
      for k in a b c d e f g h i j; do printf '%s: *a%d%s' "$k" $((i - 1)) "$([ $k != j ] && echo ', ')"; done
      printf '}\n'
    done
  } >"$file"
}
for shape in list map; do
  for levels in 7 10 20; do
    f="$FX/r4_${shape}_$levels"
    if [ "$shape" = list ]; then laughs "$f.yaml" "$levels"; else maplaughs "$f.yaml" "$levels"; fi
    probe "scenario of $levels levels of aliases ($shape)" 2 "expands to more than 1048576 values" -- "$MAPLESS" sim render --scenario "$f.yaml" --pose 0,0,0 --out "$NEW/r4.png"
  done
done
laughs "$FX/r4_config.yaml" 10
laughs "$FX/r4_calibration.yaml" 10 'format: mapless-planar-flow-calibration\n'
laughs "$FX/r4_camera_info.yaml" 10 'image_width: 320\n'
laughs "$FX/r4_robot.yaml" 10 'middleware: ros2\n'
laughs "$FX/r4_world_inner.yaml" 10
laughs "$FX/r4_key.yaml" 10
sed 's/^world:/world: r4_world_inner.yaml/; /^  objects:/d; /^    - /d' "$FX/ok.yaml" >"$FX/r4_world.yaml"
printf 'name: probe\nworld: &w\n  objects: [*w]\n' >"$FX/r4_cycle.yaml"
probe "scenario with an alias inside its own node" 2 "an alias inside the node it names" -- "$MAPLESS" sim render --scenario "$FX/r4_cycle.yaml" --pose 0,0,0 --out "$NEW/r4.png"
printf 'drive: &d {seed: 1, again: *d}\n' >"$FX/r4_cycle_config.yaml"
probe "run config with an alias inside its own node" 2 "an alias inside the node it names" -- "$MAPLESS" sim drive --scenario "$FX/ok.yaml" --config "$FX/r4_cycle_config.yaml" --out "$NEW/r4d3"
probe "run config of nested aliases" 2 "r4_config.yaml:" -- "$MAPLESS" sim drive --scenario "$FX/ok.yaml" --config "$FX/r4_config.yaml" --out "$NEW/r4d1"
probe "calibration of nested aliases" 2 "r4_calibration.yaml:" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_calibration.yaml"
probe "camera_info of nested aliases" 2 "r4_camera_info.yaml:" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --record "$NEW/r4.mcap" --camera-info "$FX/r4_camera_info.yaml"
probe "robot file of nested aliases (repeat)" 2 "r4_robot.yaml:" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r4_robot.yaml"
probe "robot file of nested aliases (teleop)" 2 "r4_robot.yaml:" -- "$MAPLESS" teleop --robot "$FX/r4_robot.yaml"
probe "robot file of nested aliases (sim serve)" 2 "r4_robot.yaml:" -- "$MAPLESS" sim serve --scenario table1_almost_straight --robot "$FX/r4_robot.yaml"
probe "world file of nested aliases" 2 "r4_world_inner.yaml:" -- "$MAPLESS" sim render --scenario "$FX/r4_world.yaml" --pose 0,0,0 --out "$NEW/r4.png"
probe "fleet key of nested aliases" 2 "r4_key.yaml:" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r4l1" --bind tcp://127.0.0.1:1 --curve-key "$FX/r4_key.yaml"
cp -r "$FX/route" "$FX/r4_route_laughs"
laughs "$FX/r4_route_laughs/keyframes/000001.yml" 10 '%%YAML:1.0\n---\nformat: mapless-keyframe\n'
probe "keyframe file of nested aliases" 2 "000001.yml:" -- "$MAPLESS" repeat --route "$FX/r4_route_laughs" --source "$FX/frames"

# ---------------------------------------------------------------------------------------------
echo "# round 4: an empty value is no value"
probe "repeat --live ''" 2 "--live: an empty value" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --live ""
probe "repeat --live=" 2 "--live: an empty value" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --live=
probe "teach --live ''" 2 "--live: an empty value" -- "$MAPLESS" teach --source sim:table1_almost_straight --out "$NEW/r4t1" --live ""
probe "follow --live ''" 2 "--live: an empty value" -- "$MAPLESS" follow --route "$FX/aroute" --source sim:table1_almost_straight --live ""
probe "navigate --live ''" 2 "--live: an empty value" -- "$MAPLESS" navigate --scenario obstacle_field --live ""
probe "sim serve --live ''" 2 "--live: an empty value" -- "$MAPLESS" sim serve --scenario table1_almost_straight --robot "$FX/robot_ok.yaml" --live ""
probe "eval lifelong --only ''" 2 "--only: an empty value" -- "$MAPLESS" eval lifelong --only ""
probe "eval funnel-scenarios --only=" 2 "--only: an empty value" -- "$MAPLESS" eval funnel-scenarios --only=
probe "teach --out ''" 2 "--out: an empty value" -- "$MAPLESS" teach --source sim:table1_almost_straight --out ""
probe "repeat --route ''" 2 "--route: an empty value" -- "$MAPLESS" repeat --route "" --source "$FX/frames"
probe "repeat --source ''" 2 "--source: an empty value" -- "$MAPLESS" repeat --route "$FX/route" --source ""
probe "repeat --log ''" 2 "--log: an empty value" -- "$MAPLESS" repeat --route "$FX/route" --source "$FX/frames" --log ""
probe "repeat --record ''" 2 "--record: an empty value" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --record ""
probe "teach --robot ''" 2 "--robot: an empty value" -- "$MAPLESS" teach --robot "" --out "$NEW/r4t2"
probe "sim render --scenario ''" 2 "--scenario: an empty value" -- "$MAPLESS" sim render --scenario "" --pose 0,0,0 --out "$NEW/r4.png"
probe "sim drive --seed ''" 2 "--seed: an empty value" -- "$MAPLESS" sim drive --scenario "$FX/ok.yaml" --out "$NEW/r4d2" --seed ""
probe "teach --topic ''" 2 "--topic: an empty value" -- "$MAPLESS" teach --source "$FX/r3_odom.mcap" --out "$NEW/r4t3" --topic ""
probe "route info ''" 2 "argument 3 is empty" -- "$MAPLESS" route info ""
probe "shift with an empty image" 2 "is empty" -- "$MAPLESS" shift "$FX/f0.png" ""
probe "lead --bind ''" 2 "--bind: an empty value" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r4l2" --bind ""
probe "follow --connect=" 2 "--connect: an empty value" -- "$MAPLESS" follow --connect= --source sim:table1_almost_straight --route "$NEW/r4c1"
probe "eval shift --sessions ''" 2 "--sessions: an empty value" -- "$MAPLESS" eval shift --sessions ""

# ---------------------------------------------------------------------------------------------
echo "# round 4: options renamed (--rate is --real-time-factor)"
for v in nan inf -1 1e300 abc; do
  probe "lead --rate $v" 2 "--rate: '$v'" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r4l3" --bind tcp://127.0.0.1:1 --rate "$v"
done
probe "follow --connect --rate nan" 2 "--rate: 'nan'" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r4c2" --rate nan
probe "eval fleet --rate nan" 2 "--rate: 'nan'" -- "$MAPLESS" eval fleet --rate nan
probe "lead with --rate and --real-time-factor" 2 "--real-time-factor excludes --rate" -- "$MAPLESS" lead --source sim:table1_almost_straight --route "$NEW/r4l4" --bind tcp://127.0.0.1:1 --rate 2 --real-time-factor 1
probe "follow --connect with both names" 2 "excludes --rate" -- "$MAPLESS" follow --connect tcp://127.0.0.1:1 --source sim:table1_almost_straight --route "$NEW/r4c3" --real-time-factor 1 --rate 3
probe "eval fleet with both names" 2 "excludes --rate" -- "$MAPLESS" eval fleet --rate 2 --real-time-factor 1

# ---------------------------------------------------------------------------------------------
echo "# round 4: still open from earlier rounds"
kf_version() {  # kf_version NAME VALUE: the route with keyframe 1's version line replaced
  cp -r "$FX/route" "$FX/$1"
  sed -i "s/^version: .*/version: $2/" "$FX/$1/keyframes/000001.yml"
}
kf_version r4_kv_trailing "1 trailing"
kf_version r4_kv_two 2
kf_version r4_kv_float 1.0
kf_version r4_kv_comment_text "1x"
probe "keyframe version with trailing text" 2 "version: expected 1, got '1 trailing'" -- "$MAPLESS" repeat --route "$FX/r4_kv_trailing" --source "$FX/frames"
probe "keyframe version 2" 2 "version: expected 1, got '2'" -- "$MAPLESS" repeat --route "$FX/r4_kv_two" --source "$FX/frames"
probe "keyframe version 1.0" 2 "got '1.0'" -- "$MAPLESS" repeat --route "$FX/r4_kv_float" --source "$FX/frames"
probe "keyframe version 1x" 2 "got '1x'" -- "$MAPLESS" repeat --route "$FX/r4_kv_comment_text" --source "$FX/frames"
for theta in 1e300 -1e300 3601 inf nan; do
  probe "sim render --pose 0,0,$theta" 2 "THETA_DEG" -- "$MAPLESS" sim render --scenario table1_almost_straight --pose "0,0,$theta" --out "$NEW/r4.png"
done
probe "navigate --start-pose with a heading of 1e300" 2 "THETA_DEG" -- "$MAPLESS" navigate --scenario obstacle_field --start-pose 0,0,1e300
calibration() {  # calibration NAME TRANSLATIONAL ROTATIONAL: a whole calibration file
  printf 'format: mapless-planar-flow-calibration\nversion: 1\nwidth: 320\nheight: 240\nperiod_s: 0.1\nspeed_mps: 0.2\nomega_radps: 0.5\ntranslational: [%s]\nrotational: [%s]\n' "$2" "$3" >"$FX/$1.yaml"
}
good_t='1.0027, -0.0104, -0.386, 0.00013, 1.0047, -0.1328, 6.8e-07, -6.4e-05, 1'
good_r='0.9276, -0.0298, 15.327, 0.0038, 0.9657, -0.6978, -0.000227, 4.455e-06, 1'
calibration r4_cal_ok "$good_t" "$good_r"
calibration r4_cal_zero '0, 0, 0, 0, 0, 0, 0, 0, 0' '0, 0, 0, 0, 0, 0, 0, 0, 0'
calibration r4_cal_zero_rot "$good_t" '0, 0, 0, 0, 0, 0, 0, 0, 0'
calibration r4_cal_identity '1, 0, 0, 0, 1, 0, 0, 0, 1' "$good_r"
calibration r4_cal_identity_rot "$good_t" '1, 0, 0, 0, 1, 0, 0, 0, 1'
calibration r4_cal_singular '1, 2, 3, 2, 4, 6, 0, 0, 1' "$good_r"
calibration r4_cal_scaled_identity '5, 0, 0, 0, 5, 0, 0, 0, 5' "$good_r"
probe "a zero calibration" 2 "r4_cal_zero.yaml: translational: a singular homography" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_zero.yaml"
probe "a zero rotational calibration" 2 "r4_cal_zero_rot.yaml: rotational: a singular homography" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_zero_rot.yaml"
probe "an identity calibration" 2 "r4_cal_identity.yaml: translational: the homography moves no pixel" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_identity.yaml"
probe "an identity rotational calibration" 2 "r4_cal_identity_rot.yaml: rotational: the homography moves no pixel" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_identity_rot.yaml"
probe "a singular calibration" 2 "r4_cal_singular.yaml: translational: a singular homography" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_singular.yaml"
probe "a scaled identity calibration" 2 "r4_cal_scaled_identity.yaml: translational: the homography moves no pixel" -- "$MAPLESS" navigate --scenario obstacle_field --calibration "$FX/r4_cal_scaled_identity.yaml"
probe "a zero calibration on a robot" 2 "r4_cal_zero.yaml: translational" -- "$MAPLESS" navigate --robot "$FX/robot_ok.yaml" --calibration "$FX/r4_cal_zero.yaml"
cp -r "$FX/route" "$FX/r4_route_16k" && sed -i 's/"image_width": 320/"image_width": 16384/; s/"image_height": 240/"image_height": 16384/' "$FX/r4_route_16k/manifest.json"
probe "a route of 16384x16384 images" 2 "at most 40 megapixels" -- "$MAPLESS" route info "$FX/r4_route_16k"
cp -r "$FX/aroute" "$FX/r4_aroute_16k" && sed -i 's/"image_width": *[0-9]*/"image_width": 16384/; s/"image_height": *[0-9]*/"image_height": 16384/' "$FX/r4_aroute_16k/appearance.json"
probe "an appearance route of 16384x16384 images" 2 "at most 40 megapixels" -- "$MAPLESS" follow --route "$FX/r4_aroute_16k" --source sim:table1_almost_straight
printf 'image_width: 16384\nimage_height: 16384\ncamera_matrix: {rows: 3, cols: 3, data: [300, 0, 160, 0, 300, 120, 0, 0, 1]}\n' >"$FX/r4_camera_info_16k.yaml"
probe "a camera_info of 16384x16384" 2 "at most 40 megapixels" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --record "$NEW/r4b.mcap" --camera-info "$FX/r4_camera_info_16k.yaml"

# ---------------------------------------------------------------------------------------------
echo "# round 4: paths the library cannot follow"
ln -s r4_loop_b "$FX/r4_loop_a"
ln -s r4_loop_a "$FX/r4_loop_b"
probe "eval shift --sessions a symlink loop" 2 "r4_loop_a: Too many levels of symbolic links" -- "$MAPLESS" eval shift --sessions "$FX/r4_loop_a"
probe "eval localize --database a symlink loop" 2 "r4_loop_a: Too many levels of symbolic links" -- "$MAPLESS" eval localize --database "$FX/r4_loop_a" --query "$FX/frames"
probe "eval localize --query a symlink loop" 2 "r4_loop_a: Too many levels of symbolic links" -- "$MAPLESS" eval localize --database "$FX/frames" --query "$FX/r4_loop_a"
probe "eval ground --frames a symlink loop" 2 "r4_loop_a: Too many levels of symbolic links" -- "$MAPLESS" eval ground --frames "$FX/r4_loop_a" --masks "$FX/frames"
probe "eval ground --masks a symlink loop" 2 "r4_loop_a: Too many levels of symbolic links" -- "$MAPLESS" eval ground --frames "$FX/frames" --masks "$FX/r4_loop_a"
probe "repeat --route a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" repeat --route "$FX/r4_loop_a" --source "$FX/frames"
probe "route info on a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" route info "$FX/r4_loop_a"
probe "teach --source a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" teach --source "$FX/r4_loop_a" --out "$NEW/r4t4"
probe "sim render --scenario a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" sim render --scenario "$FX/r4_loop_a" --pose 0,0,0 --out "$NEW/r4.png"
probe "repeat --robot a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" repeat --route "$FX/route" --robot "$FX/r4_loop_a"
probe "localize --database a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" localize --database "$FX/r4_loop_a" --query "$FX/frames"
probe "localize --query a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" localize --database "$FX/frames" --query "$FX/r4_loop_a"

# ---------------------------------------------------------------------------------------------
echo "# round 4: evaluations on user data"
mkdir -p "$FX/r4_two/summer" "$FX/r4_two/winter"
cp "$FX/frames/0.png" "$FX/r4_two/summer/000.png"; cp "$FX/frames/1.png" "$FX/r4_two/winter/000.png"
cp "$FX/frames/2.png" "$FX/r4_two/summer/001.png"; cp "$FX/small_frames/0.pgm" "$FX/r4_two/winter/001.pgm"
printf '000.png 0\n001.png 0\n' >"$FX/r4_two/dx.txt"
probe "eval shift: images of two sizes" 2 "r4_two" -- "$MAPLESS" eval shift --sessions "$FX/r4_two"
mkdir -p "$FX/r4_cut/summer" "$FX/r4_cut/winter"
cp "$FX/frames/0.png" "$FX/r4_cut/summer/000.png"; cp "$FX/truncated.png" "$FX/r4_cut/winter/000.png"
printf '000.png 0\n' >"$FX/r4_cut/dx.txt"
probe "eval shift: a cut image" 2 "r4_cut/winter/000.png" -- "$MAPLESS" eval shift --sessions "$FX/r4_cut"
mkdir -p "$FX/r4_huge/summer" "$FX/r4_huge/winter"
cp "$FX/huge.png" "$FX/r4_huge/summer/000.png"; cp "$FX/frames/0.png" "$FX/r4_huge/winter/000.png"
printf '000.png 0\n' >"$FX/r4_huge/dx.txt"
probe "eval shift: an image of 30000x30000" 2 "the limit is 40 megapixels" -- "$MAPLESS" eval shift --sessions "$FX/r4_huge"
mkdir -p "$FX/r4_db_mixed"
cp "$FX/frames/0.png" "$FX/r4_db_mixed/000.png"; cp "$FX/notimage.png" "$FX/r4_db_mixed/001.png"
probe "eval localize: a database with a file that is no image" 2 "r4_db_mixed/001.png" -- "$MAPLESS" eval localize --database "$FX/r4_db_mixed" --query "$FX/frames"
probe "eval localize: a query with an image of 30000x30000" 2 "the limit is 40 megapixels" -- "$MAPLESS" eval localize --database "$FX/frames" --query "$FX/huge_frames"
mkdir -p "$FX/r4_masks"
cp "$FX/small_frames/0.pgm" "$FX/r4_masks/0.png"
probe "eval ground: a mask of another size" 2 "r4_masks/0.png" -- "$MAPLESS" eval ground --frames "$FX/frames" --masks "$FX/r4_masks"
probe "eval ground: --frames a file" 2 "f0.png" -- "$MAPLESS" eval ground --frames "$FX/f0.png" --masks "$FX/frames"
probe "eval shift --sessions a file" 2 "f0.png" -- "$MAPLESS" eval shift --sessions "$FX/f0.png"
probe "eval localize --database missing" 2 "r4_nothing_here" -- "$MAPLESS" eval localize --database "$FX/r4_nothing_here" --query "$FX/frames"
probe "eval lifelong --only a scenario it does not have" 2 "no_such_scenario" -- "$MAPLESS" eval lifelong --only no_such_scenario
mkdir -p "$FX/r4_two_ok/summer" "$FX/r4_two_ok/winter"
cp "$FX/frames/0.png" "$FX/r4_two_ok/summer/000.png"; cp "$FX/frames/1.png" "$FX/r4_two_ok/winter/000.png"
printf '000.png 0\n' >"$FX/r4_two_ok/dx.txt"
if [ -w /dev/full ]; then
  probe "route info --json to a full disk" 1 "standard output: the results could not be written" -- bash -c "\"$MAPLESS\" route info \"$FX/route\" --json >/dev/full"
  probe "shift --json to a full disk" 1 "standard output: the results could not be written" -- bash -c "\"$MAPLESS\" shift \"$FX/f0.png\" \"$FX/f1.png\" --json >/dev/full"
  probe "localize to a full disk" 1 "standard output: the results could not be written" -- bash -c "\"$MAPLESS\" localize --database \"$FX/frames\" --query \"$FX/frames\" --json >/dev/full"
fi

# ---------------------------------------------------------------------------------------------
echo "# round 4: learning routes"
cp -r "$FX/route" "$FX/r4_cut_teach" && sed -i 's/"complete": true/"complete": false/' "$FX/r4_cut_teach/manifest.json"
probe "repeat --learn on an interrupted teach" 2 "is an interrupted teach; views are learned into complete routes" -- "$MAPLESS" repeat --route "$FX/r4_cut_teach" --source sim:table1_almost_straight --learn
visits_route() {  # visits_route NAME VISITS: a route of format 2 with that many visits
  cp -r "$FX/route" "$FX/$1"
  sed -i "s/\"version\": 1\b/\"version\": 2, \"visits\": $2/" "$FX/$1/manifest.json"
  grep -q "\"visits\": $2" "$FX/$1/manifest.json" || echo "round4.sh: the visits of $1 did not edit"
}
visits_route r4_visits_max 2147483647
visits_route r4_visits_million 1000001
visits_route r4_visits_negative -1
visits_route r4_visits_full 1000000
visits_route r4_visits_full_copy 5
probe "a route with 2^31-1 visits" 2 "visits 2147483647; must be 0 to 1000000" -- "$MAPLESS" route info "$FX/r4_visits_max"
probe "repeat --learn on 2^31-1 visits" 2 "visits 2147483647" -- "$MAPLESS" repeat --route "$FX/r4_visits_max" --source sim:table1_almost_straight --learn
probe "a route with a million and one visits" 2 "must be 0 to 1000000" -- "$MAPLESS" route info "$FX/r4_visits_million"
probe "a route with -1 visits" 2 "visits -1" -- "$MAPLESS" route info "$FX/r4_visits_negative"
probe "repeat --learn on a route that counts a million visits" 2 "has 1000000 visits, the most a route counts" -- "$MAPLESS" repeat --route "$FX/r4_visits_full" --source sim:table1_almost_straight --learn
probe "route merge of a route that counts a million visits" 2 "more than 1000000 together" -- "$MAPLESS" route merge "$FX/r4_visits_full" "$FX/r4_visits_full_copy"
cp -r "$FX/aroute" "$FX/r4_aroute_visits" && sed -i 's/"version": 1\b/"version": 2, "visits": 1000000/' "$FX/r4_aroute_visits/appearance.json"
probe "follow --learn on a route that counts a million visits" 2 "the most a route counts" -- "$MAPLESS" follow --route "$FX/r4_aroute_visits" --source sim:table1_almost_straight --learn
if [ "$(id -u)" != 0 ]; then  # root writes anywhere: the case needs another user
  cp -r "$FX/route" "$FX/r4_readonly" && chmod a-w "$FX/r4_readonly"
  probe "repeat --learn on a route that cannot be written" 2 "cannot be written" -- "$MAPLESS" repeat --route "$FX/r4_readonly" --source sim:table1_almost_straight --learn
  chmod u+w "$FX/r4_readonly"
else
  echo "skip repeat --learn on a read-only route: running as root (not counted)"
fi

# ---------------------------------------------------------------------------------------------
echo "# round 4: the live view's address, teleop's keys"
for v in 99999 "[::1]" abc:80 127.0.0.1: 300.1.1.1:80 "[::1]:x"; do
  probe "repeat --live '$v'" 2 "--live $v" -- "$MAPLESS" repeat --route "$FX/route" --source sim:table1_almost_straight --live "$v"
done
probe "teleop --hold nan" 2 "--hold nan" -- "$MAPLESS" teleop --robot "$FX/robot_ok.yaml" --hold nan
probe "teleop --hold -1" 2 "--hold -1" -- "$MAPLESS" teleop --robot "$FX/robot_ok.yaml" --hold -1
probe "teleop --speed-fraction 2" 2 "--speed-fraction 2" -- "$MAPLESS" teleop --robot "$FX/robot_ok.yaml" --speed-fraction 2
probe "teleop --robot ''" 2 "--robot: an empty value" -- "$MAPLESS" teleop --robot ""
probe "teleop --robot a symlink loop" 2 "r4_loop_a" -- "$MAPLESS" teleop --robot "$FX/r4_loop_a"

ROUND4_CASES=$((cases - ROUND4_FIRST))
echo "probe: $ROUND4_CASES cases of round 4"

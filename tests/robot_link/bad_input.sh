#!/usr/bin/env bash
# Bad input on the robot link (issues 17, 18): each case must end with one clear line naming the field,
# topic or encoding, the robot stopped (exit 1) or the input refused (exit 2), never a crash; and a
# camera of another size or a compressed camera is converted, not refused. Exit 77 without the
# middleware.
#   tests/robot_link/bad_input.sh MAPLESS ros1|ros2
set -uo pipefail
BIN=$1; MW=$2
# shellcheck source=env.sh
source "$(dirname "$0")/env.sh" bad_input.sh "$MW"
"$BIN" teach --source sim:table1_almost_straight --out "$OUT/route" >"$OUT/teach.log" 2>&1 ||
  { echo "bad_input.sh: teach failed"; exit 1; }
FAILS=0
check() {  # name expected_exit actual_exit stderr_file needle
  local name="$1" want="$2" got="$3" err="$4" needle="$5"
  local lines
  lines=$(grep -c '^mapless:' "$err")
  if [ "$got" = "$want" ] && grep -q -- "$needle" "$err" && [ "$lines" -le 1 ] &&
     ! grep -q -E 'Segmentation|terminate called|Aborted|AddressSanitizer' "$err"; then
    echo "ok   $name (exit $got)"
  else
    echo "FAIL $name: exit $got (want $want), '$needle' $(grep -q -- "$needle" "$err" && echo found || echo missing), $lines error lines"
    sed 's/^/     /' "$err" | tail -5
    FAILS=$((FAILS + 1))
  fi
}
serve() {  # robot.yaml extra-args...
  local robot="$1"; shift
  "$BIN" sim serve --scenario table1_almost_straight --robot "$robot" --like repeat "$@" \
    >"$OUT/serve.log" 2>&1 &
  SERVE=$!; PIDS+=("$SERVE")
}
stop_serve() { kill -INT "$SERVE" 2>/dev/null; sleep 0.3; kill -9 "$SERVE" 2>/dev/null; wait "$SERVE" 2>/dev/null; }

# 1. A robot file with an unknown field: refused before anything connects.
printf 'middleware: %s\nuse_sim_time: true\ntopics: {imag: camera/image_raw}\n' "$MW" >"$OUT/unknown.yaml"
timeout 30 "$BIN" repeat --route "$OUT/route" --robot "$OUT/unknown.yaml" 2>"$OUT/e1" >/dev/null
check "robot file with an unknown field" 2 $? "$OUT/e1" "topics.imag"

# 2. A wrong encoding: one warning, the robot stopped, giving up after 2 s.
printf 'middleware: %s\nuse_sim_time: true\nsafety: {give_up_without_frames_s: 2}\n' "$MW" >"$OUT/giveup.yaml"
serve "$OUT/giveup.yaml" --encoding yuv422
timeout 30 "$BIN" repeat --route "$OUT/route" --robot "$OUT/giveup.yaml" 2>"$OUT/e2" >/dev/null
check "camera in an unsupported encoding" 1 $? "$OUT/e2" "encoding 'yuv422' is not supported"
[ "$(grep -c "yuv422" "$OUT/e2")" -ge 1 ] && [ "$(grep -c "said once" "$OUT/e2")" = 1 ] ||
  { echo "FAIL the encoding warning is not said exactly once"; FAILS=$((FAILS + 1)); }
stop_serve

# 3. A missing topic: nobody publishes the camera the robot file names.
printf 'middleware: %s\nuse_sim_time: false\ntopics: {image: front_camera/image_raw}\nsafety: {give_up_without_frames_s: 2, connect_timeout_s: 1}\n' "$MW" >"$OUT/missing.yaml"
timeout 30 "$BIN" repeat --route "$OUT/route" --robot "$OUT/missing.yaml" 2>"$OUT/e3" >/dev/null
check "camera topic with no publisher" 1 $? "$OUT/e3" "/front_camera/image_raw.*no publisher"

# 4. A camera of another size, JPEG-compressed: converted and resized, the repeat completes.
printf 'middleware: %s\nuse_sim_time: true\ntopics: {compressed_image: camera/image_raw/compressed}\n' "$MW" >"$OUT/jpeg.yaml"
serve "$OUT/jpeg.yaml" --encoding jpeg --size 640x480
timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/jpeg.yaml" 2>"$OUT/e4" >/dev/null
RC=$?
if [ "$RC" = 0 ] && grep -q "route completed" "$OUT/e4"; then
  echo "ok   640x480 JPEG camera for a 320x240 route (completed)"
else
  echo "FAIL 640x480 JPEG camera: exit $RC"; tail -3 "$OUT/e4"; FAILS=$((FAILS + 1))
fi
stop_serve

# 5. An RGB camera: converted to grey, the decisions are those of the mono8 camera.
# The first 12 simulated seconds of the route (the serve ends there, and the repeat gives up 2 s
# later): enough frames to compare decision by decision.
printf 'middleware: %s\nuse_sim_time: true\nsafety: {give_up_without_frames_s: 2}\n' "$MW" >"$OUT/rgb.yaml"
for enc in mono8 rgb8; do
  serve "$OUT/rgb.yaml" --encoding "$enc" --seed 3 --timeout 12
  timeout 120 "$BIN" repeat --route "$OUT/route" --robot "$OUT/rgb.yaml" --log "$OUT/$enc.jsonl" \
    2>"$OUT/e5_$enc" >/dev/null
  stop_serve
done
if cmp -s "$OUT/mono8.jsonl" "$OUT/rgb8.jsonl" && [ "$(wc -l <"$OUT/mono8.jsonl")" -ge 100 ]; then
  echo "ok   rgb8 camera gives the same decisions as mono8 ($(wc -l <"$OUT/mono8.jsonl") frames)"
else
  echo "FAIL rgb8 and mono8 decisions differ"; FAILS=$((FAILS + 1))
fi

# 6. Two robots with one node name (ROS 1; issue 40): the master shuts the first down; it says why
# in mapless's own error line, and no raw roscpp line (colour codes and all) reaches the terminal.
if [ "$MW" = ros1 ]; then
  printf 'middleware: ros1\nuse_sim_time: false\nsafety: {give_up_without_frames_s: 0}\n' >"$OUT/twin.yaml"
  timeout 30 "$BIN" teach --robot "$OUT/twin.yaml" --out "$OUT/twin1" 2>"$OUT/e6" >/dev/null &
  T1=$!; PIDS+=("$T1")
  sleep 2
  timeout 10 "$BIN" teach --robot "$OUT/twin.yaml" --out "$OUT/twin2" 2>"$OUT/e6b" >/dev/null &
  T2=$!; PIDS+=("$T2")
  wait "$T1"
  check "two robots with one node name" 1 $? "$OUT/e6" "new node registered with same name"
  if grep -v -E '^(\[info\]|\[warning\]|mapless:) ' "$OUT/e6" | grep -q .; then
    echo "FAIL two robots with one node name: lines not mapless's own:"
    grep -v -E '^(\[info\]|\[warning\]|mapless:) ' "$OUT/e6" | head -3 | cat -v | sed 's/^/     /'
    FAILS=$((FAILS + 1))
  fi
  kill -INT "$T2" 2>/dev/null; wait "$T2" 2>/dev/null
fi

echo "bad_input.sh: $FAILS failures"
[ "$FAILS" = 0 ]

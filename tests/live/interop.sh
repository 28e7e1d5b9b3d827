#!/usr/bin/env bash
# The live view against Foxglove's reference implementation (issue 43). `mapless repeat --live`
# drives the simulator while three clients watch it: Foxglove's client (@foxglove/ws-protocol, npm,
# pinned in tests/live/interop/package-lock.json) once under each subprotocol name
# (foxglove.sdk.v1 as current Foxglove offers it, foxglove.websocket.v1 as Lichtblick and the npm
# client do), each subscribing to every channel and decoding every message (watch.mjs: CDR with
# @foxglove/rosmsg2-serialization, JSON against the channel's JSON Schema with ajv), and
# mcap-record (@foxglove/ws-protocol-examples) recording the stream into an MCAP that @mcap/core
# then reads (read_mcap.mjs). The repeat must still complete. Then the page of its own
# (http://ADDRESS:PORT/) in Debian's Chromium through playwright-core (page.mjs) while a repeat
# goes on: no console error, no failed request, nothing asked of anywhere else, and a screenshot
# that shows the camera with its overlay, a plot and the map.
# Then follow (the belief channel decoded too), navigate and lead (the teach's frames) with --live;
# teach --live says its address. (`sim serve --live` is the same link; its robot links are tested
# in tests/ros1 and tests/ros2.)
# Exit 77 (skipped) when node or npm is absent. Node.js 18 (Debian 12's) is enough: playwright-core
# is pinned to 1.61.1, the last release for Node.js 18.
#   tests/live/interop.sh MAPLESS WORK_DIR
set -uo pipefail
MAPLESS=$1; WORK=$2
HERE=$(cd "$(dirname "$0")" && pwd)
if ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; then
  echo "interop.sh: SKIPPED: node and npm are needed for @foxglove/ws-protocol"; exit 77
fi
# shellcheck source=../support/npm_folder.sh
source "$HERE/../support/npm_folder.sh"
npm_folder "$HERE/interop" "$WORK"
R=$WORK/run
rm -rf "$R"; mkdir -p "$R"
S=sim:table1_almost_straight
FAILS=0
pids=()
cleanup() { local p; for p in "${pids[@]}"; do kill "$p" 2>/dev/null; done; }
trap cleanup EXIT

"$MAPLESS" teach --source $S --out "$R/route" --live 127.0.0.1:0 >"$R/teach.log" 2>&1 ||
  { echo "FAIL teach:"; tail -5 "$R/teach.log"; exit 1; }
grep -q "live view: http://127.0.0.1:[0-9]*/" "$R/teach.log" ||
  { echo "FAIL teach --live said no address"; FAILS=$((FAILS + 1)); }
# Port 0: a free port, read back from the line the command says. Paced at 5x while watched.
"$MAPLESS" repeat --route "$R/route" --source $S --log "$R/repeat.jsonl" \
  --live 127.0.0.1:0 --live-rate 10 >"$R/repeat.log" 2>&1 &
repeat=$!; pids+=("$repeat")
port_of() {  # the port the command said it serves on
  local port=""
  for _ in $(seq 100); do
    port=$(sed -n 's|.*live view: http://127.0.0.1:\([0-9]*\)/.*|\1|p' "$1")
    [ -n "$port" ] && break
    sleep 0.1
  done
  [ -n "$port" ] || { echo "FAIL no live view address in $1:" >&2; cat "$1" >&2; exit 1; }
  echo "$port"
}
PORT=$(port_of "$R/repeat.log") || exit 1
URL=ws://127.0.0.1:$PORT
echo "-- three clients on $URL"
declare -A watchers
node "$WORK/js/watch.mjs" "$URL" foxglove.sdk.v1 120 >"$R/sdk.json" 2>"$R/sdk.err" & pids+=($!); watchers[sdk]=$!
node "$WORK/js/watch.mjs" "$URL" foxglove.websocket.v1 120 >"$R/v1.json" 2>"$R/v1.err" & pids+=($!); watchers[v1]=$!
timeout 120 node "$WORK/js/node_modules/@foxglove/ws-protocol-examples/dist/cjs/ws-protocol-examples/src/index.js" \
  mcap-record "$URL" -o "$R/live.mcap" >"$R/record.log" 2>&1 & pids+=($!); rec=$!

if wait "$repeat"; then echo "ok   the repeat completed while watched"; else
  echo "FAIL the repeat:"; tail -5 "$R/repeat.log"; FAILS=$((FAILS + 1)); fi
for name in sdk v1; do
  pid=${watchers[$name]}
  if wait "$pid"; then echo "ok   $name: $(cut -c1-400 "$R/$name.json")"; else
    echo "FAIL $name: $(cat "$R/$name.json") $(tail -3 "$R/$name.err")"; FAILS=$((FAILS + 1)); fi
done
wait "$rec"
echo "-- @mcap/core reads what mcap-record recorded"
if node "$WORK/js/read_mcap.mjs" "$R/live.mcap" /camera/image_raw/compressed \
  /mapless/debug_image/compressed /mapless/decision /tf /mapless/path /mapless/route /odom /cmd_vel; then
  echo "ok   the live stream, recorded, reads back"
else
  echo "FAIL the recording:"; tail -5 "$R/record.log"; FAILS=$((FAILS + 1))
fi

echo "-- the other commands: follow (with the belief), navigate, lead"
"$MAPLESS" teach --source sim:office_aliasing --method eigenspace --out "$R/eroute" >"$R/eteach.log" 2>&1 ||
  { echo "FAIL teach eigenspace:"; tail -5 "$R/eteach.log"; exit 1; }
"$MAPLESS" follow --route "$R/eroute" --source sim:office_aliasing --live 127.0.0.1:0 --live-rate 20 \
  >"$R/follow.log" 2>&1 & pids+=($!); follow=$!
PORT=$(port_of "$R/follow.log") || exit 1
node "$WORK/js/watch.mjs" "ws://127.0.0.1:$PORT" foxglove.sdk.v1 120 >"$R/follow.json" 2>"$R/follow.err"
watched=$?
if wait "$follow" && [ "$watched" = 0 ] && grep -q '"/mapless/belief":[1-9]' "$R/follow.json"; then
  echo "ok   follow: $(cut -c1-300 "$R/follow.json")"
else
  echo "FAIL follow: $(cat "$R/follow.json") $(tail -3 "$R/follow.err" "$R/follow.log")"; FAILS=$((FAILS + 1))
fi
if "$MAPLESS" navigate --scenario obstacle_field --destination-index 1 --live 127.0.0.1:0 \
  >"$R/navigate.log" 2>&1 && grep -q "live view: http://127.0.0.1:[0-9]*/" "$R/navigate.log"; then
  echo "ok   navigate --live (served; the run succeeded)"
else
  echo "FAIL navigate --live:"; tail -3 "$R/navigate.log"; FAILS=$((FAILS + 1))
fi
# The leader teaches at 20x wall-clock time; its live view shows the teach.
"$MAPLESS" lead --source $S --route "$R/lead" --bind "ipc://$R/lead.ipc" --real-time-factor 20 \
  --live 127.0.0.1:0 >"$R/lead.log" 2>&1 & pids+=($!); lead=$!
PORT=$(port_of "$R/lead.log") || exit 1
node "$WORK/js/watch.mjs" "ws://127.0.0.1:$PORT" foxglove.websocket.v1 3 >"$R/lead.json" 2>"$R/lead.err"
kill -INT "$lead" 2>/dev/null; wait "$lead"
if grep -q '"/mapless/decision":[1-9]' "$R/lead.json" && grep -q '"/camera/image_raw/compressed":[1-9]' "$R/lead.json"; then
  echo "ok   lead --live: the teach's frames and decisions seen"
else
  echo "FAIL lead --live: $(cat "$R/lead.json") $(tail -3 "$R/lead.log")"; FAILS=$((FAILS + 1))
fi

echo "-- the page in Chromium"
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
if [ -z "$CHROMIUM" ]; then
  echo "FAIL no chromium (scripts/setup.sh --test installs it)"; FAILS=$((FAILS + 1))
else
  "$MAPLESS" repeat --route "$R/route" --source $S --seed 2 --log "$R/page.jsonl" \
    --live 127.0.0.1:0 --live-rate 2 >"$R/page_repeat.log" 2>&1 &
  page_repeat=$!; pids+=("$page_repeat")
  PORT=$(port_of "$R/page_repeat.log") || exit 1
  if CHROMIUM=$CHROMIUM timeout 120 node "$WORK/js/page.mjs" "http://127.0.0.1:$PORT/" "$R/page.png" \
    >"$R/page.json" 2>&1; then
    echo "ok   the page: $(cat "$R/page.json")"
  else
    echo "FAIL the page: $(cat "$R/page.json")"; FAILS=$((FAILS + 1))
  fi
  kill -INT "$page_repeat" 2>/dev/null; wait "$page_repeat"
fi
[ "$FAILS" -eq 0 ] || { echo "interop.sh: $FAILS failed"; exit 1; }
echo "interop.sh: all passed"

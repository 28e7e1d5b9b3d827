# Sourced by the ROS 1 test scripts: a private ROS master on loopback for one script.
#   source master.sh NAME   (after `set -uo pipefail` and BIN=...)
# Skips the script (exit 77) without rosmaster. Sets OUT (a fresh temporary directory, removed at
# exit), PORT, ROS_MASTER_URI/ROS_IP/ROS_HOSTNAME/ROS_HOME, and PIDS: every pid added to it is
# killed at exit, the master's first.
NAME=$1
command -v rosmaster >/dev/null 2>&1 ||
  { echo "$NAME: SKIPPED: no rosmaster (scripts/setup.sh --ros)"; exit 77; }
OUT=$(mktemp -d "/tmp/mapless_$NAME.XXXXXX")
PORT=$((20000 + ($$ + ${#NAME} * 7) % 20000))
export ROS_MASTER_URI="http://127.0.0.1:$PORT" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
export ROS_HOME="$OUT/roshome"
PIDS=()
cleanup() { for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; wait "$p" 2>/dev/null; done; rm -rf "$OUT"; }
trap cleanup EXIT INT TERM
rosmaster --core -p "$PORT" >"$OUT/master.log" 2>&1 &
PIDS+=($!)
for _ in $(seq 1 100); do (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null && break; sleep 0.1; done

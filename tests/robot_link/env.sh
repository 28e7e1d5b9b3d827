# Sourced by the robot-link test scripts: a private middleware on loopback for one script.
#   source env.sh NAME MIDDLEWARE    (ros1 or ros2; after `set -uo pipefail`)
# Sets OUT (a fresh temporary directory removed at exit, unless OUT was set: then it is kept) and
# PIDS (every pid
# added to it is killed at exit). ros1: starts a private ROS master (ROS_MASTER_URI etc.); skips
# (exit 77) without rosmaster. ros2: a ROS domain of its own (ROS_DOMAIN_ID from the pid) with
# discovery and data on loopback only (ROS_LOCALHOST_ONLY=1, as a ROS 2 user would set it).
NAME=$1
MIDDLEWARE=$2
if [ -n "${OUT:-}" ]; then
  mkdir -p "$OUT"; OUT=$(realpath "$OUT"); KEEP_OUT=1
else
  OUT=$(mktemp -d "/tmp/mapless_$NAME.XXXXXX")
fi
PIDS=()
cleanup() {
  for p in "${PIDS[@]}"; do kill -9 "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
  [ "${KEEP_OUT:-0}" = 1 ] || rm -rf "$OUT"
}
trap cleanup EXIT INT TERM
case "$MIDDLEWARE" in
  ros1)
    command -v rosmaster >/dev/null 2>&1 ||
      { echo "$NAME: SKIPPED: no rosmaster (scripts/setup.sh --ros)"; exit 77; }
    PORT=$((20000 + ($$ + ${#NAME} * 7) % 20000))
    export ROS_MASTER_URI="http://127.0.0.1:$PORT" ROS_IP=127.0.0.1 ROS_HOSTNAME=127.0.0.1
    export ROS_HOME="$OUT/roshome"
    rosmaster --core -p "$PORT" >"$OUT/master.log" 2>&1 &
    PIDS+=($!)
    for _ in $(seq 1 100); do (exec 3<>"/dev/tcp/127.0.0.1/$PORT") 2>/dev/null && break; sleep 0.1; done
    ;;
  ros2)
    # Domains 1-200: the UDP ports of a domain are 7400 + 250 * id + ..., all below 57,700.
    export ROS_DOMAIN_ID=$((1 + ($$ + ${#NAME} * 13) % 200)) ROS_LOCALHOST_ONLY=1
    unset CYCLONEDDS_URI
    ;;
  *) echo "$NAME: unknown middleware $MIDDLEWARE (ros1, ros2)" >&2; exit 2 ;;
esac

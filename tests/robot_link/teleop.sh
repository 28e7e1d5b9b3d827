#!/usr/bin/env bash
# Teleop on a pseudo-terminal, ended every way a person or the system ends it (issue 67), with no
# camera at all (the robot never sends a frame): the Ctrl-C key, the Ctrl-D key, SIGTERM, SIGHUP,
# the end of standard input, and the terminal closed. Each must end teleop at once (within 3 s of
# the act; the camera's give-up is disabled, so nothing else would end it), with the terminal's
# mode as it was before (`stty -g` before and after, in the same pseudo-terminal), and a zero
# Twist on cmd_vel (the probe's `listen` mode: the first command it sees must be a zero). Exit
# codes: 0 for the keys and the input's end, 143 for SIGTERM, 129 for SIGHUP.
# Exit 77 (skipped) without the middleware or without `script` (util-linux).
#   tests/robot_link/teleop.sh MAPLESS SAFETY_PROBE ros1|ros2
set -uo pipefail
BIN=$1; PROBE=$2; MW=$3
# shellcheck source=env.sh
source "$(dirname "$0")/env.sh" teleop.sh "$MW"
command -v script >/dev/null || { echo "teleop.sh: SKIPPED: no script (util-linux)"; exit 77; }
FAILS=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; FAILS=$((FAILS + 1)); fi; }
# No camera ever; the give-up disabled: only what the case does can end teleop.
printf 'middleware: %s\nname: teleop test\nnode_name: teleop\nsafety: {give_up_without_frames_s: 0}\n' \
  "$MW" >"$OUT/robot.yaml"

# run_case NAME WANT_RC HOW: teleop in `script`'s pseudo-terminal; HOW is key_c, key_d, term, hup,
# eof or close. The inner shell records the terminal's mode before and after.
run_case() {
  local name=$1 want=$2 how=$3
  rm -f "$OUT/before" "$OUT/after" "$OUT/pid" "$OUT/rc"
  rm -f "$OUT/ready" "$OUT/tpid" "$OUT/act" "$OUT/end"
  SAFETY_PROBE_READY="$OUT/ready" timeout 30 "$PROBE" listen 0 20 0 >"$OUT/probe_$how.json" 2>&1 &
  local probe=$!; PIDS+=("$probe")
  sleep 1.5  # the probe's subscription in place (discovery)
  local inner="stty -g >$OUT/before; $BIN teleop --robot $OUT/robot.yaml </dev/tty & t=\$!; echo \$t >$OUT/tpid; wait \$t; echo \$? >$OUT/rc; date +%s.%N >$OUT/end; stty -g >$OUT/after"
  # The act waits for teleop's cmd_vel to be connected to the probe (its ready file), 15 s at
  # most: a fixed delay was too short on a loaded machine (the zero went to no one).
  ready() { for _ in $(seq 1 150); do [ -e "$OUT/ready" ] && return 0; sleep 0.1; done; return 1; }
  act() {  # the act, its time noted
    date +%s.%N >"$OUT/act"
    case "$how" in key_c) printf '\003' ;; key_d) printf '\004' ;; *) kill -"${how^^}" "$(cat "$OUT/tpid")" ;; esac
  }
  case "$how" in
    key_c | key_d | term | hup)
      { ready; sleep 0.3; act; sleep 3.5; } |
        timeout 30 script -q -e -c "$inner" /dev/null >"$OUT/teleop_$how.log" 2>&1
      ;;
    eof)  # not a terminal: standard input a pipe that ends after 2 s
      { ready; sleep 0.3; date +%s.%N >"$OUT/act"; } |
        (timeout 30 "$BIN" teleop --robot "$OUT/robot.yaml" >"$OUT/teleop_$how.log" 2>&1; echo $? >"$OUT/rc"; date +%s.%N >"$OUT/end")
      ;;
    close)  # the terminal goes away: `script` (the pseudo-terminal's master) killed
      { sleep 30; } | timeout 30 script -q -e -c "$inner" /dev/null >"$OUT/teleop_$how.log" 2>&1 &
      local s=$!; ready; sleep 0.3
      date +%s.%N >"$OUT/act"
      pkill -KILL -P "$s" -x script 2>/dev/null; kill -KILL "$s" 2>/dev/null
      local tpid; tpid=$(cat "$OUT/tpid" 2>/dev/null)
      # Ended: gone, or a zombie (its parent shell died with the terminal; a container's init
      # may reap it late).
      gone() { ! kill -0 "$tpid" 2>/dev/null || grep -q '^[0-9]* ([^)]*) Z' "/proc/$tpid/stat" 2>/dev/null; }
      for _ in $(seq 1 50); do gone && break; sleep 0.05; done
      gone && date +%s.%N >"$OUT/end"
      kill -9 "$tpid" 2>/dev/null
      ;;
  esac
  [ -s "$OUT/act" ] && [ -s "$OUT/end" ] &&
    awk -v a="$(cat "$OUT/act")" -v e="$(cat "$OUT/end")" 'BEGIN { printf "  ended %.2f s after the act\n", e - a; exit !(e - a >= 0 && e - a < 3) }'
  check "$name: teleop ended within 3 s" $?
  [ -e "$OUT/ready" ]
  check "$name: teleop's cmd_vel reached the probe before the act" $?
  wait "$probe"; local probe_rc=$?
  echo "  probe: $(cat "$OUT/probe_$how.json")"
  if [ "$how" != close ]; then
    local rc; rc=$(cat "$OUT/rc" 2>/dev/null || echo none)
    [ "$rc" = "$want" ]
    check "$name: exit $want (got $rc)" $?
    if [ "$how" != eof ]; then
      [ -s "$OUT/before" ] && cmp -s "$OUT/before" "$OUT/after"
      check "$name: the terminal's mode restored" $?
    fi
  fi
  [ "$probe_rc" = 0 ]
  check "$name: a zero Twist on cmd_vel" $?
}
run_case "the Ctrl-C key" 0 key_c
run_case "the Ctrl-D key" 0 key_d
run_case "SIGTERM" 143 term
run_case "SIGHUP" 129 hup
run_case "standard input at its end" 0 eof
run_case "the terminal closed" 0 close
echo "teleop.sh: $FAILS failure(s)"
[ "$FAILS" = 0 ]

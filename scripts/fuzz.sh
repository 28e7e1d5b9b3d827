#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang, ASan + UBSan) and runs each one for a fixed
# number of executions or a time limit, whichever comes first.
#
#   scripts/fuzz.sh [-r RUNS] [-t SECONDS] [-f JOBS] [TARGET ...]
#     -r RUNS     executions per target (default 1000000)
#     -t SECONDS  time limit per target (default 600)
#     -f JOBS     libFuzzer's fork mode: JOBS worker processes at a time, each restarted after a
#                 short job, RUNS counted over all of them (default: one process). For a target
#                 that slows down within a process: rosbag, from 442 to 72 executions/s over
#                 500,000 executions (docs/recordings.md)
#     TARGET      route_manifest route_keyframe scenario config calibration flo tum image_folder
#                 video_file scenario_world robot_file appearance_manifest camera_message
#                 fleet_record fleet_follower fleet_view_offer ros2_message mcap rosbag camera_info
#                 live_client live_http live_ws_frames
#                 (default: all)
#
# Each target starts from fuzz/corpus/<target>/ (kept inputs) and grows a working corpus in
# build/fuzz/corpus/<target>/. A crash, sanitizer report, leak or hang stops that target; its input is
# written to build/fuzz/artifacts/<target>/ and the script exits non-zero. Keep such an input as a
# regression test: copy it to fuzz/corpus/<target>/crash-<what> (the ordinary test suite runs every
# kept input through the same harness), fix the parser, and run this script again.
# A summary line per target, with the executions done, ends the output (also in build/fuzz/summary.txt).
set -euo pipefail
cd "$(dirname "$0")/.."

runs=1000000
seconds=600
fork=()
while getopts "r:t:f:" opt; do
  case "$opt" in
    r) runs="$OPTARG" ;;
    t) seconds="$OPTARG" ;;
    f) fork=(-fork="$OPTARG" -ignore_crashes=0) ;;
    *) echo "usage: scripts/fuzz.sh [-r RUNS] [-t SECONDS] [-f JOBS] [TARGET ...]" >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(route_manifest route_keyframe scenario config calibration flo tum image_folder video_file
           scenario_world robot_file appearance_manifest camera_message fleet_record fleet_follower fleet_view_offer ros2_message mcap rosbag
           camera_info live_client live_http live_ws_frames)
fi

bash scripts/setup.sh
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j "$(nproc)"

out=build/fuzz
summary="$out/summary.txt"
: > "$summary"
status=0
for t in "${targets[@]}"; do
  bin="$out/fuzz/fuzz_$t"
  [ -x "$bin" ] || { echo "fuzz.sh: no target '$t'" >&2; exit 2; }
  mkdir -p "$out/corpus/$t" "$out/artifacts/$t"
  log="$out/fuzz_$t.log"
  echo "fuzz.sh: $t (up to $runs executions or $seconds s)"
  set +e
  # Leak checks stay on; -timeout flags a single input that takes over 10 s (a hang);
  # -malloc_limit_mb flags any single allocation over 1 GB. The process limit is 2 GB: over a
  # million executions libFuzzer's and ASan's own memory creeps towards 1 GB (scenario_world: 1 GB
  # after 600,000, while the same harness without them stays at 80 MB; docs/hardening.md).
  "$bin" ${fork[@]+"${fork[@]}"} -runs="$runs" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=1024 \
    -max_len=65536 -print_final_stats=1 -artifact_prefix="$out/artifacts/$t/" \
    "$out/corpus/$t" "fuzz/corpus/$t" >"$log" 2>&1
  rc=$?
  set -e
  done_runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -1 || true)
  secs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*' | tail -1 || true)
  if [ ${#fork[@]} -gt 0 ]; then  # fork mode: "#N: cov: ..." lines and "INFO: exiting: 0 time: Ss"
    done_runs=$(grep -ao '^#[0-9]*:' "$log" | grep -o '[0-9]*' | tail -1 || true)
    secs=$(grep -ao 'INFO: exiting: [0-9]* time: [0-9]*s' "$log" | grep -o '[0-9]*s$' | grep -o '[0-9]*' | tail -1 || true)
  fi
  if [ "$rc" -eq 0 ]; then
    line="$t: ${done_runs:-?} executions in ${secs:-?} s, no crash"
  else
    line="$t: FAILED after ${done_runs:-?} executions (exit $rc); input in $out/artifacts/$t/, log $log"
    status=1
  fi
  echo "$line" | tee -a "$summary"
done
echo "fuzz.sh: summary in $summary"
exit "$status"

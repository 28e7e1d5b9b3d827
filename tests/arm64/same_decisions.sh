#!/usr/bin/env bash
# The same decisions on arm64 as on x86-64 (issue 70): a teach and a repeat of each scenario below
# on the simulator by the x86-64 build and by the arm64 build under qemu, then compared.
#
# What is the same, bit for bit: the route manifest (which frames became keyframes, when), the
# teach line, the keyframe thumbnails, and in every keyframe file all but the tracked feature
# tracks: the keypoints (FAST, the pyramid, the ORB angles: mapless computes cv::fastAtan2 itself,
# features/orb.h), the descriptors, the odometry.
#
# What differs, and its bound: the tracks (segment_start_px/segment_end_px), and the repeat's
# obstacle watch, come from OpenCV's sparse pyramidal Lucas-Kanade (cv::calcOpticalFlowPyrLK),
# whose arm64 build sums its float terms with NEON in another order and with fused
# multiply-adds: tracked points differ by a few hundredths of a pixel, and now and then a track
# passes the forward-backward check in one build only (measured 2026-12-07: ends within 0.062 px,
# 1 track of 6,400 in one build only). A funnel-lane decision that rests on a feature that close
# to a lane's edge goes the other way, and a closed loop carries that on. The bounds, each below
# what the method itself resolves:
#   - tracks paired by their start: at most 1% kept by one build only, and the others' ends
#     within 0.1 px (the accuracy the KLT's own test asks of it,
#     TrackKlt.RecoversASubPixelTranslation);
#   - the repeat: the same outcome (its line without the numbers), as many decisions within 2%,
#     and the final true pose within 0.05 m and 0.02 rad (below the repeat's own final error
#     against the taught route, 0.06-0.08 m on these scenarios).
# The figures are printed: decisions that differ, the largest segment-end difference, the final
# poses. KEEP_TMP=1 keeps the two runs' folders.
# Usage: same_decisions.sh X86_MAPLESS ARM64_MAPLESS SYSROOT [SCENARIO...]
set -uo pipefail
X86=$(realpath "$1")
ARM=$(realpath "$2")
SYSROOT=$(realpath "$3")
shift 3
SCENARIOS=("$@")
[ ${#SCENARIOS[@]} -gt 0 ] || SCENARIOS=(narrow_room_sharp_turn table1_almost_straight)
QEMU=(qemu-aarch64-static -L "$SYSROOT")
TMP=$(mktemp -d /tmp/mapless_same.XXXXXX)
[ -n "${KEEP_TMP:-}" ] || trap 'rm -rf "$TMP"' EXIT
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }
# Two keyframe files: "SAME_OTHERS LARGEST MATCHED ONE_ONLY TRACKS": SAME_OTHERS 1 when every
# section but the tracked segments is the same text; the tracks paired by their start (the
# keypoint they began at), LARGEST the largest |difference| of a pair's ends in px, MATCHED the
# pairs, ONE_ONLY the tracks kept by one build only, TRACKS the first file's.
KEYFRAME_COMPARE='
function section(line) { if (match(line, /^[a-z_]+:/)) cur = substr(line, 1, RLENGTH - 1); return cur }
function numbers(line, name, arr, f,    n, i, v) {
  sub("^" name ":", "", line); gsub(/[][,]/, " ", line)
  n = split(line, v, " ")
  for (i = 1; i <= n; i++) arr[f, ++len[name, f]] = v[i] + 0
}
FNR == 1 { file++; cur = "" }
{
  s = section($0)
  if (s == "segment_start_px") numbers($0, s, starts, file)
  else if (s == "segment_end_px") numbers($0, s, ends, file)
  else { text[file, s] = text[file, s] $0 "\n"; keys[s] = 1 }
}
END {
  same = 1
  for (k in keys) if (text[1, k] != text[2, k]) same = 0
  # The tracks, by their start: those of file 1 looked up among those of file 2 (in order).
  n2 = len["segment_start_px", 2] / 2
  for (j = 1; j <= n2; j++) {
    key = starts[2, 2 * j - 1] "," starts[2, 2 * j]
    at[key, ++many[key]] = j
  }
  n1 = len["segment_start_px", 1] / 2
  big = 0; matched = 0
  for (i = 1; i <= n1; i++) {
    key = starts[1, 2 * i - 1] "," starts[1, 2 * i]
    if (used[key] >= many[key]) continue
    j = at[key, ++used[key]]
    matched++
    for (c = 0; c <= 1; c++) {
      d = ends[1, 2 * i - c] - ends[2, 2 * j - c]; if (d < 0) d = -d
      if (d > big) big = d
    }
  }
  printf "%d %.6f %d %d %d\n", same, big, matched, n1 + n2 - 2 * matched, n1
}
'

run_both() {  # run_both NAME ARGS...: the command on both builds; logs in $TMP/{x86,arm64}/NAME.log
  local name=$1 rc_x rc_a
  shift
  (cd "$W/x86" && "$X86" "$@" >"$name.log" 2>&1); rc_x=$?
  (cd "$W/arm64" && "${QEMU[@]}" "$ARM" "$@" >"$name.log" 2>&1); rc_a=$?
  [ $rc_x -eq 0 ] || tail -3 "$W/x86/$name.log" | sed 's/^/     x86   | /'
  [ $rc_a -eq 0 ] || tail -3 "$W/arm64/$name.log" | sed 's/^/     arm64 | /'
  [ $rc_x -eq 0 ] && [ $rc_a -eq 0 ]
}
# The log's lines without their level ("[info] teach: ...").
outcome() { sed -n "s/^\[[a-z]*\] \($1.*\)/\1/p" "$2"; }
same_files() {  # same_files GLOB: "EQUAL of TOTAL" over the files GLOB names under both routes
  local total=0 equal=0 f
  for f in $W/x86/$1; do
    total=$((total + 1))
    cmp -s "$f" "$W/arm64/${f#"$W"/x86/}" && equal=$((equal + 1))
  done
  echo "$equal of $total"
}

# compare SCENARIO: both builds' runs in $TMP/SCENARIO, the checks printed; returns how many failed.
compare() {
  local s=$1 W="$TMP/$1"
  mkdir -p "$W/x86" "$W/arm64"
  run_both teach teach --source "sim:$s" --out route
  check "$s: the teach exits 0 on both" $?
  x=$(outcome "teach: [0-9]* frames" "$W/x86/teach.log")
  a=$(outcome "teach: [0-9]* frames" "$W/arm64/teach.log")
  echo "     x86:   $x"
  echo "     arm64: $a"
  cmp -s "$W/x86/route/manifest.json" "$W/arm64/route/manifest.json" && [ -n "$x" ] && [ "$x" = "$a" ]
  check "$s: the same keyframes (the same manifest, the same teach line)" $?
  thumbs=$(same_files 'route/keyframes/*.png')
  echo "     equal keyframe files: $(same_files 'route/keyframes/*.yml'), thumbnails: $thumbs"
  [ "${thumbs%% of *}" = "${thumbs##* of }" ]; check "$s: the same keyframe thumbnails" $?
  kf=$(for f in "$W"/x86/route/keyframes/*.yml; do
         awk "$KEYFRAME_COMPARE" "$f" "$W/arm64/${f#"$W"/x86/}"
       done | awk '{ s += $1; n++; if ($2 > big) big = $2; m += $3; one += $4; all += $5 }
                   END { printf "%d %d %.4f %d %d %d\n", s, n, big, m, one, all }')
  read -r same_kf n_kf big_end matched one_only tracks <<<"$kf"
  echo "     tracks: $tracks (x86), $one_only kept by one build only; the ends of the $matched in both within $big_end px"
  [ "$same_kf" = "$n_kf" ] && [ "$n_kf" -gt 0 ]
  check "$s: the same keypoints, descriptors and odometry in all $n_kf keyframes" $?
  awk -v d="$big_end" -v one="$one_only" -v all="$tracks" 'BEGIN { exit !(d <= 0.1 && one <= 0.01 * all) }'
  check "$s: tracks: at most 1% kept by one build only, the others' ends within 0.1 px" $?

  run_both repeat repeat --route route --source "sim:$s" --log repeat.jsonl
  check "$s: the repeat exits 0 on both" $?
  x=$(outcome "repeat: " "$W/x86/repeat.log")
  a=$(outcome "repeat: " "$W/arm64/repeat.log")
  echo "     x86:   $x"
  echo "     arm64: $a"
  words() { sed 's/[-0-9.]\+//g' <<<"$1"; }
  [ -n "$x" ] && [ "$(words "$x")" = "$(words "$a")" ]
  check "$s: the same outcome (its line without the numbers)" $?
  nx=$(wc -l <"$W/x86/repeat.jsonl")
  na=$(wc -l <"$W/arm64/repeat.jsonl")
  [ "$nx" -gt 0 ] && awk -v a="$nx" -v b="$na" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= 0.02 * a) }'
  check "$s: as many decisions within 2% ($nx, $na)" $?
  differ=$(paste -d'\n' "$W/x86/repeat.jsonl" "$W/arm64/repeat.jsonl" | paste - - |
           awk -F'\t' '$1 != $2' | wc -l)
  echo "     decisions that differ in any field: $differ of $nx"
  pose() { tail -1 "$1" | grep -o '"\(x_m\|y_m\|theta_rad\)":[-0-9.e+]*' | cut -d: -f2 | paste -sd' '; }
  px=$(pose "$W/x86/repeat.jsonl")
  pa=$(pose "$W/arm64/repeat.jsonl")
  echo "     final pose x86: $px, arm64: $pa"
  awk -v a="$px" -v b="$pa" 'BEGIN { n = split(a, p, " "); m = split(b, q, " ");
      if (n != 3 || m != 3) exit 1;
      for (i = 1; i <= 3; i++) { d = p[i] - q[i]; if (d < 0) d = -d; if (d > (i < 3 ? 0.05 : 0.02)) exit 1 } }'
  check "$s: the final pose within 0.05 m and 0.02 rad" $?
  return "$failed"
}

# The scenarios side by side (each one core: qemu runs a process on one), then their reports.
pids=()
for s in "${SCENARIOS[@]}"; do
  compare "$s" >"$TMP/$s.out" 2>&1 &
  pids+=($!)
done
for i in "${!SCENARIOS[@]}"; do
  wait "${pids[$i]}"; failed=$((failed + $?))
  cat "$TMP/${SCENARIOS[$i]}.out"
done
echo "$failed failed"
[ "$failed" -eq 0 ]

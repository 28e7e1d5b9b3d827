#!/usr/bin/env bash
# The same decisions on arm64 as on x86-64 (issue 70): a teach and a repeat of each scenario below
# on the simulator by the x86-64 build and by the arm64 build under qemu, then compared:
#   - the keyframes: the route manifests (which frames became keyframes, at which times) are the
#     same file; the keyframes' features (keyframes/*.yml) and thumbnails (*.png) are counted
#     equal or not, and reported;
#   - the repeat: its outcome line ("final error ..., lateral RMS ...", printed to 2 decimals) is
#     the same, its decision log has as many decisions, and the final true pose (x_m, y_m,
#     theta_rad) differs by at most 0.005 m and 0.005 rad (what "%.2f" prints the same, give or
#     take a rounding edge); the number of decisions that differ at all is reported.
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
trap 'rm -rf "$TMP"' EXIT
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }

run_both() {  # run_both NAME ARGS...: the command on both builds; logs in $TMP/{x86,arm64}/NAME.log
  local name=$1 rc_x rc_a
  shift
  (cd "$TMP/x86" && "$X86" "$@" >"$name.log" 2>&1); rc_x=$?
  (cd "$TMP/arm64" && "${QEMU[@]}" "$ARM" "$@" >"$name.log" 2>&1); rc_a=$?
  [ $rc_x -eq 0 ] || tail -3 "$TMP/x86/$name.log" | sed 's/^/     x86   | /'
  [ $rc_a -eq 0 ] || tail -3 "$TMP/arm64/$name.log" | sed 's/^/     arm64 | /'
  [ $rc_x -eq 0 ] && [ $rc_a -eq 0 ]
}
# The log's lines without their level ("[info] teach: ...").
outcome() { sed -n "s/^\[[a-z]*\] \($1.*\)/\1/p" "$2"; }
same_files() {  # same_files GLOB: "EQUAL of TOTAL" over the files GLOB names under both routes
  local total=0 equal=0 f
  for f in $TMP/x86/$1; do
    total=$((total + 1))
    cmp -s "$f" "$TMP/arm64/${f#"$TMP"/x86/}" && equal=$((equal + 1))
  done
  echo "$equal of $total"
}

for s in "${SCENARIOS[@]}"; do
  rm -rf "$TMP/x86" "$TMP/arm64"
  mkdir -p "$TMP/x86" "$TMP/arm64"
  run_both teach teach --source "sim:$s" --out route
  check "$s: the teach exits 0 on both" $?
  x=$(outcome "teach: [0-9]* frames" "$TMP/x86/teach.log")
  a=$(outcome "teach: [0-9]* frames" "$TMP/arm64/teach.log")
  echo "     x86:   $x"
  echo "     arm64: $a"
  cmp -s "$TMP/x86/route/manifest.json" "$TMP/arm64/route/manifest.json" && [ -n "$x" ] && [ "$x" = "$a" ]
  check "$s: the same keyframes (the same manifest, the same teach line)" $?
  echo "     equal keyframe features: $(same_files 'route/keyframes/*.yml'), thumbnails: $(same_files 'route/keyframes/*.png')"

  run_both repeat repeat --route route --source "sim:$s" --log repeat.jsonl
  check "$s: the repeat exits 0 on both" $?
  x=$(outcome "repeat: " "$TMP/x86/repeat.log")
  a=$(outcome "repeat: " "$TMP/arm64/repeat.log")
  echo "     x86:   $x"
  echo "     arm64: $a"
  # The duration is simulated time, so it too must be the same.
  [ -n "$x" ] && [ "$x" = "$a" ]
  check "$s: the same outcome line" $?
  nx=$(wc -l <"$TMP/x86/repeat.jsonl")
  na=$(wc -l <"$TMP/arm64/repeat.jsonl")
  [ "$nx" -gt 0 ] && [ "$nx" -eq "$na" ]; check "$s: as many decisions ($nx, $na)" $?
  differ=$(paste -d'\n' "$TMP/x86/repeat.jsonl" "$TMP/arm64/repeat.jsonl" | paste - - |
           awk -F'\t' '$1 != $2' | wc -l)
  echo "     decisions that differ in any field: $differ of $nx"
  pose() { tail -1 "$1" | grep -o '"\(x_m\|y_m\|theta_rad\)":[-0-9.e+]*' | cut -d: -f2 | paste -sd' '; }
  px=$(pose "$TMP/x86/repeat.jsonl")
  pa=$(pose "$TMP/arm64/repeat.jsonl")
  echo "     final pose x86: $px, arm64: $pa"
  awk -v a="$px" -v b="$pa" 'BEGIN { n = split(a, p, " "); m = split(b, q, " ");
      if (n != 3 || m != 3) exit 1;
      for (i = 1; i <= 3; i++) { d = p[i] - q[i]; if (d < 0) d = -d; if (d > 0.005) exit 1 } }'
  check "$s: the same final pose (within 0.005 m and rad)" $?
done
echo "$failed failed"
[ "$failed" -eq 0 ]

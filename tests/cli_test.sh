#!/usr/bin/env bash
# Integration test of the `mapless` command line: every subcommand answers --help, bad input gives
# one error line and exit code 2, outputs are deterministic and complete.
# Usage: cli_test.sh PATH/TO/mapless SOURCE_TESTS_DIR [SECTION ...]
# Sections (each a ctest entry of its own, cli.SECTION, so that `ctest -j` runs them side by side;
# all of them when none is named): basics navigate localize_eval routes crash bench.
# The demo's files and report are checked by newcomer.demo (tests/report/chromium.sh).
set -u
MAPLESS="$1"
HERE="$2"
shift 2
SECTIONS="${*:-basics navigate localize_eval routes crash bench}"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
passed=0
failed=0

check() {  # check NAME CONDITION-EXIT-CODE
  if [ "$2" -eq 0 ]; then passed=$((passed + 1)); echo "ok   $1"; else failed=$((failed + 1)); echo "FAIL $1"; fi
}

# expect_exit NAME CODE CMD...: runs CMD, checks its exit code, keeps stderr in $TMP/err.
expect_exit() {
  local name="$1" code="$2"
  shift 2
  "$@" >"$TMP/out" 2>"$TMP/err"
  local got=$?
  [ "$got" -eq "$code" ]
  local ok=$?
  [ $ok -ne 0 ] && { echo "     expected exit $code, got $got; stderr:"; sed 's/^/     | /' "$TMP/err"; }
  check "$name" $ok
}

# Fixtures more than one section uses, made on first need.
need_drive() {  # $TMP/d1: a recorded drive of rotation_in_place (frames, poses)
  [ -d "$TMP/d1" ] && return
  expect_exit "drive 1" 0 "$MAPLESS" sim drive --scenario rotation_in_place --out "$TMP/d1" --seed 5
  n_frames=$(ls "$TMP/d1/frames" | wc -l)
}

section_basics() {
  # Every subcommand answers --help with exit 0 and a usage text.
  for sub in "" "demo" "sim" "sim list" "sim render" "sim drive" "sim generate" "eval generated" "bench" "shift" "teach" "repeat" "route" "route info" "route prune" "eval" "eval table1" "eval obstacles" "soak" "flow" "ground" "navigate" "localize" "follow" "sim serve" "teleop" "lead" "fleet"; do
    # shellcheck disable=SC2086
    expect_exit "help: mapless $sub --help" 0 "$MAPLESS" $sub --help
    grep -qi "usage" "$TMP/out"; check "help text: mapless $sub" $?
    ! awk 'length > 100 { bad = 1 } END { exit !bad }' "$TMP/out"; check "help of mapless $sub fits 100 columns" $?
  done

  # The image codecs, video I/O and FFmpeg are opened on first use, not linked: a start of the
  # command does not load their 200 libraries (io/lazy_libraries.h).
  if command -v readelf >/dev/null; then
    ! readelf -d "$MAPLESS" | grep NEEDED | grep -Eq "opencv_imgcodecs|opencv_videoio|libav|libswscale"
    check "mapless links no image codec, video I/O or FFmpeg library" $?
  fi

  # docs/cli.md lists every option a command offers (one meaning per name, issue 42).
  if [ -f "$HERE/../docs/cli.md" ]; then
    missing=""
    for sub in demo "eval shift" "eval localize" "eval ground" "sim render" "sim drive" "sim serve" "sim generate" "eval generated" bench shift teach lead repeat "route info" "eval table1" "eval potential" "eval eigenspace" "eval obstacles" "eval fleet" soak flow ground navigate localize follow teleop "fleet keygen"; do
      # shellcheck disable=SC2086
      for opt in $("$MAPLESS" $sub --help | grep -oE '^  --[a-z0-9-]+' | tr -d ' '); do
        [ "$opt" = --help ] || grep -q "^| \`$opt\` |" "$HERE/../docs/cli.md" || missing="$missing $sub:$opt"
      done
    done
    [ -z "$missing" ]; check "docs/cli.md lists every option${missing:+; missing:$missing}" $?
  fi

  # sim generate: the same seed gives the same file; an existing file is kept unless --overwrite.
  expect_exit "sim generate" 0 "$MAPLESS" sim generate --seed 11 --out "$TMP/g1.yaml"
  expect_exit "sim generate again" 0 "$MAPLESS" sim generate --seed 11 --out "$TMP/g2.yaml"
  cmp -s "$TMP/g1.yaml" "$TMP/g2.yaml"; check "sim generate: the same seed, the same world" $?
  expect_exit "sim generate over a file exits 2" 2 "$MAPLESS" sim generate --seed 12 --out "$TMP/g1.yaml"
  cmp -s "$TMP/g1.yaml" "$TMP/g2.yaml"; check "sim generate: the existing file is kept" $?
  expect_exit "a generated world renders" 0 "$MAPLESS" sim render --scenario "$TMP/g1.yaml" --pose 0,0,0 --out "$TMP/g1.png"
  expect_exit "eval generated, a missing world, exits 2" 2 "$MAPLESS" eval generated --world "$TMP/none.yaml"
  [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "eval generated, a missing world: one error line" $?

  # sim list: one name per line, the paper scenarios among them.
  expect_exit "sim list" 0 "$MAPLESS" sim list
  [ "$(wc -l <"$TMP/out")" -ge 15 ]; check "sim list has >= 15 scenarios" $?
  for s in narrow_room_sharp_turn table1_sharp_turn_low_texture corridor_s_shaped office_aliasing; do
    grep -qx "$s" "$TMP/out"; check "sim list names $s" $?
  done

  # Unknown option, unknown subcommand: usage errors, exit 2, one line.
  expect_exit "unknown option exits 2" 2 "$MAPLESS" sim list --bogus
  [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "unknown option: one error line" $?
  expect_exit "unknown subcommand exits 2" 2 "$MAPLESS" fly

  # Malformed scenario: one line naming the file and the field, exit 2.
  expect_exit "malformed scenario exits 2" 2 "$MAPLESS" sim render --scenario "$HERE/data/bad_scenario_field.yaml" --pose 0,0,0 --out "$TMP/x.png"
  [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "malformed scenario: one error line" $?
  grep -q "bad_scenario_field.yaml:[0-9]*:[0-9]*: world.objects\[1\].radius_m" "$TMP/err"; check "malformed scenario: names file, line and field" $?
  expect_exit "broken YAML exits 2" 2 "$MAPLESS" sim render --scenario "$HERE/data/bad_scenario_syntax.yaml" --pose 0,0,0 --out "$TMP/x.png"
  grep -q "bad_scenario_syntax.yaml:[0-9]*:[0-9]*: malformed YAML" "$TMP/err"; check "broken YAML: names file and line" $?
  expect_exit "missing scenario file exits 2" 2 "$MAPLESS" sim drive --scenario "$TMP/none.yaml" --out "$TMP/d"
  grep -q "none.yaml: cannot open file" "$TMP/err"; check "missing file is named" $?
  expect_exit "unknown built-in exits 2" 2 "$MAPLESS" sim render --scenario nowhere --pose 0,0,0 --out "$TMP/x.png"
  expect_exit "bad pose exits 2" 2 "$MAPLESS" sim render --scenario narrow_room_sharp_turn --pose 1,2 --out "$TMP/x.png"
  grep -q -- "--pose '1,2'" "$TMP/err"; check "bad pose is named" $?
  printf 'render: {edge_supersample: 0}\n' >"$TMP/bad_config.yaml"
  expect_exit "bad config value exits 2" 2 "$MAPLESS" sim drive --scenario rotation_in_place --out "$TMP/d" --config "$TMP/bad_config.yaml"
  grep -q "bad_config.yaml:1:[0-9]*: render: RenderOptions.edge_supersample = 0" "$TMP/err"; check "bad config names file, line and field" $?

  # Render: deterministic bytes for the same scenario, pose and seed.
  expect_exit "render a" 0 "$MAPLESS" sim render --scenario narrow_room_sharp_turn --pose 1.0,0.2,10 --out "$TMP/a.png" --seed 3
  expect_exit "render b" 0 "$MAPLESS" sim render --scenario narrow_room_sharp_turn --pose 1.0,0.2,10 --out "$TMP/b.png" --seed 3
  cmp -s "$TMP/a.png" "$TMP/b.png"; check "render is byte-identical for the same inputs" $?
  expect_exit "render repeat variant" 0 "$MAPLESS" sim render --scenario outdoor_loop_cars_removed --pose 0,0,0 --out "$TMP/v.png" --repeat-variant
  expect_exit "render teach world" 0 "$MAPLESS" sim render --scenario outdoor_loop_cars_removed --pose 0,0,0 --out "$TMP/t.png"
  ! cmp -s "$TMP/v.png" "$TMP/t.png"; check "repeat variant differs from the teach world" $?

  # Drive: frames, TUM poses, top-down picture; identical poses for the same seed.
  need_drive
  expect_exit "drive 2" 0 "$MAPLESS" sim drive --scenario rotation_in_place --out "$TMP/d2" --seed 5
  for f in groundtruth.tum odometry.tum topdown.png summary.json frames.csv frames/000000.png; do
    [ -s "$TMP/d1/$f" ]; check "drive writes $f" $?
  done
  n_frames=$(ls "$TMP/d1/frames" | wc -l)
  n_poses=$(grep -vc '^#' "$TMP/d1/groundtruth.tum")
  [ "$n_frames" -eq "$n_poses" ] && [ "$n_frames" -gt 50 ]; check "one pose per frame ($n_frames frames)" $?
  cmp -s "$TMP/d1/groundtruth.tum" "$TMP/d2/groundtruth.tum"; check "drive poses identical for the same seed" $?
  cmp -s "$TMP/d1/frames/000040.png" "$TMP/d2/frames/000040.png"; check "drive frames identical for the same seed" $?
  ls "$TMP/d1" "$TMP/d1/frames" | grep -q '\.tmp\.' && r=1 || r=0; check "no temporary files left" $r

  # Shift: JSON with the documented fields; the sign follows dx = x_current - x_reference.
  S="$HERE/data/stromovka"
  expect_exit "shift --json" 0 "$MAPLESS" shift "$S/0101.png" "$S/1201.png" --json
  grep -q '"dx_px":' "$TMP/out" && grep -q '"matches":' "$TMP/out" && grep -q '"ok":true' "$TMP/out"; check "shift JSON has dx_px, matches, ok" $?
  dx=$(sed 's/.*"dx_px":\([-0-9.e]*\).*/\1/' "$TMP/out")
  awk -v d="$dx" 'BEGIN { exit !(d > 40.5 - 17.5 && d < 40.5 + 17.5) }'; check "shift of Stromovka place 1, session 12 vs 01 is 40.5 +- 17.5 px (got $dx)" $?
  expect_exit "shift of a missing image exits 2" 2 "$MAPLESS" shift "$S/0101.png" "$TMP/none.png"
  grep -q "none.png: cannot open file" "$TMP/err"; check "shift names the missing image" $?

  # Optical flow and the dominant plane on two simulator frames of the downward-looking corridor.
  expect_exit "render f0" 0 "$MAPLESS" sim render --scenario corridor_straight_3p5m --pose 0,0,0 --out "$TMP/f0.png"
  expect_exit "render f1" 0 "$MAPLESS" sim render --scenario corridor_straight_3p5m --pose 0.05,0,0 --out "$TMP/f1.png"
  expect_exit "flow --out" 0 "$MAPLESS" flow "$TMP/f0.png" "$TMP/f1.png" --out "$TMP/f.flo" --flow lk
  expect_exit "flow against its own output" 0 "$MAPLESS" flow "$TMP/f0.png" "$TMP/f1.png" --method lk --gt "$TMP/f.flo"
  grep -q -- "--method is now --flow here" "$TMP/err"; check "flow --method still works and says it is now --flow" $?
  grep -q '"epe_px":0' "$TMP/out"; check "flow EPE against its own output is 0" $?
  head -c 100 "$TMP/f.flo" > "$TMP/short.flo"
  expect_exit "truncated .flo exits 2" 2 "$MAPLESS" flow "$TMP/f0.png" "$TMP/f1.png" --gt "$TMP/short.flo"
  grep -q "short.flo: truncated" "$TMP/err"; check "flow names the truncated .flo" $?
  expect_exit "unknown flow method exits 2" 2 "$MAPLESS" flow "$TMP/f0.png" "$TMP/f1.png" --out "$TMP/g.flo" --flow magic
  grep -q "unknown flow method 'magic'" "$TMP/err"; check "flow names the unknown method" $?
  expect_exit "ground --out" 0 "$MAPLESS" ground "$TMP/f0.png" "$TMP/f1.png" --out "$TMP/ground.png" --roi-top 0
  [ -s "$TMP/ground.png" ]; check "ground wrote a mask" $?
  expect_exit "ground of a missing frame exits 2" 2 "$MAPLESS" ground "$TMP/f0.png" "$TMP/none.png" --out "$TMP/g.png"
  grep -q "none.png: cannot open file" "$TMP/err"; check "ground names the missing frame" $?
}

section_navigate() {
  # Visual-potential navigation: reach a destination, keep the calibration, log every frame.
  expect_exit "navigate to a destination" 0 "$MAPLESS" navigate --scenario obstacle_field --destination-index 1 --save-calibration "$TMP/cal.yaml" --log "$TMP/nav.jsonl"
  grep -q "mapless-planar-flow-calibration" "$TMP/cal.yaml"; check "navigate saved the calibration" $?
  tail -1 "$TMP/nav.jsonl" | grep -q '"status":"arrived"'; check "navigate log ends arrived" $?
  expect_exit "navigate with a bad destination exits 2" 2 "$MAPLESS" navigate --scenario obstacle_field --destination 1,x
  grep -q "destination '1,x': expected X,Y" "$TMP/err"; check "navigate names the bad destination" $?
  expect_exit "navigate --homing without a destination exits 2" 2 "$MAPLESS" navigate --scenario obstacle_field --homing
  sed 's/^width: 320/width: 64/' "$TMP/cal.yaml" > "$TMP/cal64.yaml"
  expect_exit "navigate with a calibration for another camera exits 2" 2 "$MAPLESS" navigate --scenario obstacle_field --calibration "$TMP/cal64.yaml"
  grep -q "cal64.yaml: calibrated for 64x240" "$TMP/err"; check "navigate names the mismatched calibration" $?
  head -c 120 "$TMP/cal.yaml" > "$TMP/calcut.yaml"
  expect_exit "navigate with a truncated calibration exits 2" 2 "$MAPLESS" navigate --scenario obstacle_field --calibration "$TMP/calcut.yaml"
  grep -q "calcut.yaml" "$TMP/err"; check "navigate names the truncated calibration" $?
}

section_localize_eval() {
  # localize: Nordland winter queries on the summer route (100 places, tests/data/nordland).
  NL="$HERE/data/nordland"
  within5() { awk -F'"index":' '{split($2,a,","); d=a[1]-(NR-1); if (d<0) d=-d; if (d<=5) ok++} END {print ok+0}' "$1"; }
  expect_exit "localize markov" 0 "$MAPLESS" localize --database "$NL/summer" --query "$NL/winter" --localizer markov --json
  cp "$TMP/out" "$TMP/loc_markov.jsonl"
  [ "$(wc -l <"$TMP/loc_markov.jsonl")" -eq 100 ]; check "localize: one line per query" $?
  head -1 "$TMP/loc_markov.jsonl" | grep -Eq '^\{"query":"images-04010.png","index":[0-9]+,"probability":[0-9.e-]+\}$'; check "localize: query, index, probability" $?
  expect_exit "localize nn" 0 "$MAPLESS" localize --database "$NL/summer" --query "$NL/winter" --localizer nn --json
  cp "$TMP/out" "$TMP/loc_nn.jsonl"
  m5=$(within5 "$TMP/loc_markov.jsonl"); n5=$(within5 "$TMP/loc_nn.jsonl")
  echo "     localize within +-5 places: markov $m5/100, nn $n5/100"
  [ "$m5" -ge 90 ] && [ "$m5" -gt "$n5" ]; check "localize: markov >= 90/100 within 5 places and better than nn" $?
  expect_exit "localize (the sequence filter, the default)" 0 "$MAPLESS" localize --database "$NL/summer" --query "$NL/winter" --json
  s5=$(within5 "$TMP/out")
  echo "     localize within +-5 places: sequence $s5/100"
  [ "$s5" -ge 95 ]; check "localize: the default sequence filter >= 95/100 within 5 places" $?
  expect_exit "localize with a missing folder exits 2" 2 "$MAPLESS" localize --database "$TMP/none" --query "$NL/winter"
  grep -q -- "--database $TMP/none: not a folder of images" "$TMP/err"; check "localize names the missing folder" $?
  expect_exit "localize with a bad method exits 2" 2 "$MAPLESS" localize --database "$NL/summer" --query "$NL/winter" --localizer best
  grep -q "'best' is unknown" "$TMP/err"; check "localize names the bad method" $?

  # eval experiences (issue 45) on the bundled Stromovka subset: two places, sessions 01, 06, 12.
  expect_exit "eval experiences --json" 0 "$MAPLESS" eval experiences --sessions "$HERE/data/stromovka" --json
  grep -Eq '"single_fraction":[0-9.]+' "$TMP/out" && grep -Eq '"experiences_fraction":[0-9.]+' "$TMP/out" && [ "$(grep -o '"place":' "$TMP/out" | wc -l)" -eq 2 ]; check "eval experiences: both fractions, one row per place" $?
  # eval shift and eval localize (issue 66): mapless and the stock baselines of the same run.
  expect_exit "eval shift --json" 0 "$MAPLESS" eval shift --sessions "$HERE/data/stromovka" --json
  grep -q '"method":"mapless"' "$TMP/out" && grep -q '"method":"fast_sift"' "$TMP/out" && grep -q '"pairs":12' "$TMP/out"; check "eval shift: mapless and the baselines over 12 pairs" $?
  expect_exit "eval shift on a folder with neither list exits 2" 2 "$MAPLESS" eval shift --sessions "$NL/summer"
  grep -q "dx.txt" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "eval shift names the missing list in one line" $?
  expect_exit "eval localize --json" 0 "$MAPLESS" eval localize --database "$NL/summer" --query "$NL/winter" --json
  grep -q '"method":"seqslam"' "$TMP/out" && grep -Eq '"within5":[0-9.]+' "$TMP/out"; check "eval localize: mapless and the baselines" $?
  expect_exit "eval ground on folders with no labelled pair exits 2" 2 "$MAPLESS" eval ground --frames "$NL/summer" --masks "$HERE/data/stromovka"
  grep -q "no mask has the name of a frame" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "eval ground says why in one line" $?
  expect_exit "eval experiences on a folder without offsets.txt exits 2" 2 "$MAPLESS" eval experiences --sessions "$NL/summer"
  grep -q "$NL/summer/offsets.txt" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "eval experiences names the missing offsets.txt in one line" $?

  expect_exit "eval eigenspace with an unknown scenario exits 2" 2 "$MAPLESS" eval eigenspace --only nowhere --runs 1
  grep -q "'nowhere': not a scenario of suite eigenspace" "$TMP/err"; check "eval eigenspace names the unknown scenario" $?
  expect_exit "eval with an unknown switching rule exits 2" 2 "$MAPLESS" eval table1 --runs 1 --switching sideways
  grep -q "unknown switching rule 'sideways'" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "eval names the unknown switching rule in one line" $?
  # eval --report: per entry the world from above, the error along the path, and the first run frame
  # by frame (commands; the slopes only for the sloped funnel lane; chosen frames).
  expect_exit "eval table1 --report" 0 "$MAPLESS" eval table1 --runs 1 --only table1_almost_straight --jobs 2 --report "$TMP/evalreport"
  [ "$(grep -o 'Commands over time' "$TMP/evalreport/index.html" | wc -l)" -eq 2 ] && [ "$(grep -o 'Funnel-lane slopes' "$TMP/evalreport/index.html" | wc -l)" -eq 1 ] && [ "$(grep -o '<img' "$TMP/evalreport/index.html" | wc -l)" -ge 4 ] && [ -s "$TMP/evalreport/table1_almost_straight_sloped_plot3.png" ]; check "eval report: commands of both, slopes of the sloped run, chosen frames, PNGs" $?
  expect_exit "eval potential refuses --end" 2 "$MAPLESS" eval potential --runs 1 --end switching
  grep -q "not expected: .*--end" "$TMP/err"; check "eval potential has no --end (each suite has its own options)" $?
}

section_routes() {
  need_drive
  # Teach from a recorded image folder, inspect, repeat open loop: one JSON line per frame.
  expect_exit "teach from an image folder" 0 "$MAPLESS" teach --source "$TMP/d1/frames" --out "$TMP/route"
  expect_exit "route info --json" 0 "$MAPLESS" route info "$TMP/route" --json
  grep -q '"complete":true' "$TMP/out" && grep -Eq '"keyframes":([2-9]|[1-9][0-9]+)[,}]' "$TMP/out"; check "route is complete with >= 2 keyframes" $?
  expect_exit "teach refuses to overwrite" 2 "$MAPLESS" teach --source "$TMP/d1/frames" --out "$TMP/route"
  grep -q "already holds a route" "$TMP/err"; check "overwrite refusal is explained" $?
  expect_exit "repeat open loop" 0 "$MAPLESS" repeat --route "$TMP/route" --source "$TMP/d1/frames" --log "$TMP/rep.jsonl"
  [ "$(wc -l <"$TMP/rep.jsonl")" -eq "$n_frames" ]; check "one decision line per frame" $?
  head -1 "$TMP/rep.jsonl" | grep -q '"destination":' && head -1 "$TMP/rep.jsonl" | grep -q '"v_mps":'; check "decision lines carry segment and command" $?
  expect_exit "route prune to the taught views" 0 "$MAPLESS" route prune "$TMP/route" --max-views 1
  grep -q "route: 0 learned views pruned, 0 left" "$TMP/out"; check "route prune says what it pruned" $?
  expect_exit "route prune --max-views 0 exits 2" 2 "$MAPLESS" route prune "$TMP/route" --max-views 0
  # Views learned by another copy of the route (issue 45): merged; the route itself and a route
  # taught otherwise refused; each keyframe's views listed.
  cp -r "$TMP/route" "$TMP/route_copy" && rm -f "$TMP/route_copy/.lock"
  expect_exit "repeat --learn on the copy" 0 "$MAPLESS" repeat --route "$TMP/route_copy" --source "$TMP/d1/frames" --learn
  expect_exit "route merge of the copy" 0 "$MAPLESS" route merge "$TMP/route" "$TMP/route_copy"
  grep -Eq "route: [0-9]+ learned views? merged from .*route_copy, [0-9]+ in all" "$TMP/out"; check "route merge says what it merged" $?
  expect_exit "route info --views --json" 0 "$MAPLESS" route info "$TMP/route" --views --json
  grep -q '"visits":1' "$TMP/out" && grep -q '"views":\[\[' "$TMP/out"; check "route info lists the views per keyframe, the copy's visit counted" $?
  expect_exit "route merge of the route itself exits 2" 2 "$MAPLESS" route merge "$TMP/route" "$TMP/route/"
  grep -q "is the route itself" "$TMP/err"; check "merging a route into itself is refused" $?
  mkdir -p "$TMP/half" && find "$TMP/d1/frames" -name '*.png' | sort | head -n $((n_frames / 2)) | xargs cp -t "$TMP/half"
  expect_exit "teach half of the drive" 0 "$MAPLESS" teach --source "$TMP/half" --out "$TMP/route_other"
  expect_exit "route merge of another route exits 2" 2 "$MAPLESS" route merge "$TMP/route" "$TMP/route_other"
  grep -q "were not taught together" "$TMP/err"; check "merging a route taught otherwise is refused" $?
  # An image folder with TUM poses as its odometry (--poses): the eigenspace teach needs odometry.
  expect_exit "eigenspace teach of a folder without poses exits 2" 2 "$MAPLESS" teach --method eigenspace --source "$TMP/d1/frames" --out "$TMP/eroute0"
  grep -q "with --poses FILE.tum" "$TMP/err"; check "eigenspace teach asks for --poses" $?
  expect_exit "eigenspace teach of a folder with poses" 0 "$MAPLESS" teach --method eigenspace --source "$TMP/d1/frames" --poses "$TMP/d1/odometry.tum" --out "$TMP/eroute"
  expect_exit "route info of an appearance route" 0 "$MAPLESS" route info "$TMP/eroute" --json
  grep -q '"kind":"appearance"' "$TMP/out" && grep -q '"complete":true' "$TMP/out" && grep -Eq '"images":([1-9][0-9]+)[,}]' "$TMP/out"; check "eigenspace route from a folder with poses is complete, >= 10 images" $?
  expect_exit "poses with a recording exits 2" 2 "$MAPLESS" teach --source "$TMP/none.mcap" --poses "$TMP/d1/odometry.tum" --out "$TMP/eroute1"
  grep -q "has its own odometry topic" "$TMP/err"; check "--poses with a recording is refused" $?
  printf 'image_width: 320\nimage_height: 240\ncamera_matrix: {rows: 3, cols: 2, data: [1, 0, 0, 1, 0, 0]}\n' > "$TMP/cam.yaml"
  expect_exit "a 3x2 camera matrix exits 2" 2 "$MAPLESS" teach --source sim:rotation_in_place --out "$TMP/camroute" --record "$TMP/cam.mcap" --camera-info "$TMP/cam.yaml"
  grep -q "cam.yaml:3:.*camera_matrix.*expected 3 x 3" "$TMP/err" && [ ! -e "$TMP/cam.mcap" ] && [ ! -e "$TMP/camroute" ]; check "camera_info YAML errors name the file, line and field; nothing written" $?
  # ground on a source: one JSON line and one mask per frame that has a frame --step later.
  expect_exit "ground --source" 0 "$MAPLESS" ground --source "$TMP/d1/frames" --max-frames 4 --step 2 --out-dir "$TMP/masks" --log "$TMP/ground.jsonl"
  [ "$(wc -l <"$TMP/ground.jsonl")" -eq 4 ] && [ "$(ls "$TMP/masks" | grep -c '\.png$')" -eq 4 ] && grep -q '"plane_fraction":' "$TMP/ground.jsonl"; check "ground --source: 4 lines, 4 masks" $?
  expect_exit "ground with F0 and --source exits 2" 2 "$MAPLESS" ground "$TMP/f0.png" --source "$TMP/d1/frames"
  grep -q "not both" "$TMP/err"; check "ground says F0 F1 or --source" $?
  # The route's end: the local scale by default, the paper's StdRatio with --end switching.
  expect_exit "teach on the simulator" 0 "$MAPLESS" teach --source sim:rotation_in_place --out "$TMP/simroute"
  expect_exit "repeat with the paper's end rule" 0 "$MAPLESS" repeat --route "$TMP/simroute" --source sim:rotation_in_place --end switching --log "$TMP/rep2.jsonl"
  tail -1 "$TMP/rep2.jsonl" | grep -q '"status":"completed"' && ! grep -q '"local_scale":' "$TMP/rep2.jsonl"; check "--end switching completes without the local scale" $?
  # A teach with odometry (the simulator) stores each keyframe's pose; one from a folder without
  # poses does not (carrying on needs it).
  grep -q "^odometry: " "$TMP/simroute/keyframes/000001.yml" && ! grep -q "^odometry: " "$TMP/route/keyframes/000001.yml"; check "keyframes keep the teach's odometry when it had any" $?
  expect_exit "a negative --carry-on-m exits 2" 2 "$MAPLESS" repeat --route "$TMP/route" --source "$TMP/d1/frames" --carry-on-m -1
  grep -q -- "--carry-on-m" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "a bad --carry-on-m is named in one line" $?
  expect_exit "eval potential refuses --carry-on-m" 2 "$MAPLESS" eval potential --runs 1 --carry-on-m 2
  # --on-obstacle avoid: teach & repeat only; the follower refuses it in one line.
  expect_exit "follow refuses --on-obstacle avoid" 2 "$MAPLESS" follow --route "$TMP/eroute" --source "$TMP/d1/frames" --poses "$TMP/d1/odometry.tum" --on-obstacle avoid
  grep -q -- "--on-obstacle.*avoid" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "follow names --on-obstacle avoid in one line" $?
  "$MAPLESS" follow --help >"$TMP/out" 2>&1
  ! grep -A2 -- "--on-obstacle" "$TMP/out" | grep -q "avoid"; check "follow --help does not offer --on-obstacle avoid" $?
  expect_exit "follow: a negative --carry-on-m exits 2" 2 "$MAPLESS" follow --route "$TMP/eroute" --source "$TMP/d1/frames" --poses "$TMP/d1/odometry.tum" --carry-on-m -1
  grep -q -- "--carry-on-m" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "follow names a bad --carry-on-m in one line" $?
  expect_exit "an unknown --on-obstacle exits 2" 2 "$MAPLESS" repeat --route "$TMP/route" --source "$TMP/d1/frames" --on-obstacle swerve
  expect_exit "repeat with --on-obstacle avoid and nothing in the way" 0 "$MAPLESS" repeat --route "$TMP/simroute" --source sim:rotation_in_place --on-obstacle avoid --log "$TMP/rep3.jsonl"
  tail -1 "$TMP/rep3.jsonl" | grep -q '"status":"completed"' && ! grep -q '"avoiding":' "$TMP/rep3.jsonl"; check "avoid with nothing in the way: completed, never went round" $?
  expect_exit "unknown --end exits 2" 2 "$MAPLESS" repeat --route "$TMP/route" --source "$TMP/d1/frames" --end sideways
  grep -q "\-\-end 'sideways'" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "unknown --end names the value in one line" $?

  # Bad routes: one line naming the file, exit 2, never a crash.
  expect_exit "missing route exits 2" 2 "$MAPLESS" repeat --route "$TMP/nothing" --source "$TMP/d1/frames"
  grep -q "manifest.json is missing" "$TMP/err"; check "missing route is named" $?
  cp -r "$TMP/route" "$TMP/broken"
  printf 'format: mapless-keyframe\nversion: 1\nkeypo' > "$TMP/broken/keyframes/000001.yml"
  expect_exit "truncated keyframe exits 2" 2 "$MAPLESS" route info "$TMP/broken"
  grep -q "000001.yml" "$TMP/err" && [ "$(wc -l <"$TMP/err")" -eq 1 ]; check "truncated keyframe: one line naming the file" $?
  head -c 100 "$TMP/route/manifest.json" > "$TMP/broken/manifest.json"
  expect_exit "truncated manifest exits 2" 2 "$MAPLESS" route info "$TMP/broken"
  grep -q "manifest.json: corrupt manifest" "$TMP/err"; check "truncated manifest is named" $?
}

section_crash() {
  # A teach killed with SIGKILL leaves a route that loads, with every keyframe completed before.
  "$MAPLESS" teach --source sim:outdoor_70m --out "$TMP/killed" >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 400); do [ -f "$TMP/killed/keyframes/000002.png" ] && break; sleep 0.05; done
  if kill -9 "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null
    expect_exit "killed teach: route loads" 0 "$MAPLESS" route info "$TMP/killed" --json
    grep -q '"complete":false' "$TMP/out" && grep -q '"keyframes":[1-9]' "$TMP/out"; st=$?; check "killed teach keeps its completed keyframes ($(cat "$TMP/out"))" $st
  else
    wait "$pid"; check "teach was still running when killed (machine too fast?)" 1
  fi

  # A recording killed with SIGKILL keeps every frame it finished: listed, with whole poses.
  "$MAPLESS" sim drive --scenario outdoor_70m --out "$TMP/killedrec" >/dev/null 2>&1 &
  pid=$!
  for _ in $(seq 1 400); do [ -f "$TMP/killedrec/frames/000020.png" ] && break; sleep 0.05; done
  if kill -9 "$pid" 2>/dev/null; then
    wait "$pid" 2>/dev/null
    [ ! -f "$TMP/killedrec/summary.json" ]; check "killed recording: it was killed before its end" $?
    bad=$(awk 'FNR > 1 && NF != 8' "$TMP/killedrec/groundtruth.tum" "$TMP/killedrec/odometry.tum" | wc -l)
    [ "$bad" -eq 0 ]; check "killed recording: every TUM record is whole ($bad bad)" $?
    listed=$(($(wc -l < "$TMP/killedrec/frames.csv") - 1))
    poses=$(($(wc -l < "$TMP/killedrec/groundtruth.tum") - 1))
    [ "$listed" -ge 20 ] && [ $((listed - poses)) -le 1 ] && [ $((listed - poses)) -ge 0 ]
    check "killed recording: $listed frames listed, $poses poses" $?
    missing=0
    while IFS=, read -r _ _ file; do [ -f "$TMP/killedrec/$file" ] || missing=$((missing + 1)); done < <(tail -n +2 "$TMP/killedrec/frames.csv")
    [ "$missing" -eq 0 ]; check "killed recording: every listed frame is on disk ($missing missing)" $?
  else
    wait "$pid"; check "recording was still running when killed (machine too fast?)" 1
  fi
}

section_bench() {
  # Bench: one JSON object with the render stage and its reference.
  # Every stage, on the smallest work that runs it (one scenario, 160x120): a check of the
  # command and its JSON, not a measurement (README's figures: `mapless bench --repeats 30`).
  expect_exit "bench --json" 0 "$MAPLESS" bench --json --repeats 3 --scenario narrow_room_sharp_turn --size 160x120
  grep -q '"sim_render_320x240_ms":[0-9.]*' "$TMP/out" && grep -q '"opencv_dis_fast_320x240_ms"' "$TMP/out"; check "bench JSON has the render stage and DIS reference" $?
  grep -q '"dominant_plane_step_ms":[0-9.]*' "$TMP/out" && grep -q '"opencv_dis_fast_ground_320x240_ms"' "$TMP/out"; check "bench JSON has the potential step and its DIS reference" $?
  grep -q '"repeat_step_default_over_orb_interleaved":[0-9.]*' "$TMP/out" && grep -q '"orb_detector_over_opencv_same_settings":[0-9.]*' "$TMP/out"; check "bench JSON has the default step against ORB-500 timed after each step, and OrbDetector against OpenCV's ORB" $?
  grep -Eq '"repeat_step_5_views_over_1":[0-9.]+' "$TMP/out"; check "bench JSON has the step with 5 views against 1 (issue 45)" $?
  [ "$(wc -l <"$TMP/out")" -eq 1 ]; check "bench JSON is one line" $?
  grep -q '"frame":"160x120"' "$TMP/out" && grep -q '"scenarios":\["narrow_room_sharp_turn"\]' "$TMP/out"; check "bench JSON says the frame size and scenario it ran" $?
}

for section in $SECTIONS; do
  declare -F "section_$section" >/dev/null || { echo "cli_test.sh: unknown section $section" >&2; exit 2; }
  "section_$section"
done
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]

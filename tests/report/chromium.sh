#!/usr/bin/env bash
# The report opens in a browser (issue 20): the report `mapless demo` wrote (newcomer.demo, whose
# output this reads) opens in headless Chromium with no console error and no failed request, and
# its screenshot shows the plots (screenshot_check: the path and command colours are there). A
# broken copy of the report (a missing image, a script error) must be caught by the same checks.
# Exit 77 (skipped) without Chromium (scripts/setup.sh --test installs it).
#   tests/report/chromium.sh DEMO_OUT SCREENSHOT_CHECK
set -uo pipefail
DEMO=$1; CHECK=$2
CHROMIUM=$(command -v chromium || command -v chromium-browser || true)
[ -n "$CHROMIUM" ] || { echo "chromium.sh: SKIPPED: no chromium (scripts/setup.sh --test)"; exit 77; }
OUT=$(mktemp -d /tmp/mapless_report.XXXXXX)
trap 'rm -rf "$OUT"' EXIT

REPORT="$DEMO/report/index.html"
[ -s "$REPORT" ] || { echo "FAIL no $REPORT (newcomer.demo writes it)"; exit 1; }

# Opens a page headless, its console and network errors in $OUT/NAME.log; screenshot NAME.png.
# --enable-logging=stderr prints console messages ("CONSOLE(...)") and failed loads.
open_page() {
  timeout 120 "$CHROMIUM" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --no-first-run --user-data-dir="$OUT/profile" --window-size=1200,2600 \
    --enable-logging=stderr --v=0 --screenshot="$OUT/$2.png" "file://$1" >"$OUT/$2.log" 2>&1
}
page_errors() {
  grep -E 'CONSOLE|Failed to load resource|ERR_FILE_NOT_FOUND|net::ERR_|Uncaught' "$OUT/$1.log"
}

FAILS=0
open_page "$REPORT" report
if [ -s "$OUT/report.png" ] && ! page_errors report >/dev/null; then
  echo "ok   the report opens: no console error, no failed request"
else
  echo "FAIL the report: errors or no screenshot"; page_errors report | head -5; FAILS=$((FAILS + 1))
fi
if "$CHECK" "$OUT/report.png"; then
  echo "ok   the screenshot shows the plots"
else
  echo "FAIL the screenshot does not show the plots"; FAILS=$((FAILS + 1))
fi
# What the browser made of the page (its DOM after parsing), for the checks of issue 42.
timeout 120 "$CHROMIUM" --headless --no-sandbox --disable-gpu --no-first-run \
  --user-data-dir="$OUT/profile" --dump-dom "file://$REPORT" >"$OUT/dom.html" 2>/dev/null
DOM="$OUT/dom.html"
# Under the title: the mapless version, the date and the command line.
if grep -Eq '<p class="byline">mapless [0-9][^,]*, 20[0-9-]+ [0-9:]+ UTC: mapless demo( |<)' "$DOM"; then
  echo "ok   the header names the version, the date and the command line"
else
  echo "FAIL no byline with the version and command line"; FAILS=$((FAILS + 1))
fi
# Every path on the maps has its own legend entry: as many entries with a path's line as paths.
PATHS=$(grep -o '<polyline' "$DOM" | wc -l)
ENTRIES=$(grep -o '<g class="legend-entry" data-kind="path">' "$DOM" | wc -l)
if [ "$PATHS" -gt 0 ] && [ "$PATHS" = "$ENTRIES" ]; then
  echo "ok   each of the $PATHS paths drawn has its own legend entry"
else
  echo "FAIL $PATHS paths drawn, $ENTRIES legend entries for paths"; FAILS=$((FAILS + 1))
fi
# Nothing outside the file: no http(s) link but the SVG namespace, no script.
if grep -o 'https\?://[^"]*' "$REPORT" | grep -qv '^http://www.w3.org/2000/svg$' ||
   grep -q '<script' "$REPORT"; then
  echo "FAIL the report links outside itself or has a script"; FAILS=$((FAILS + 1))
else
  echo "ok   self-contained (no external link, no script)"
fi
# The checks can fail: a copy with a missing image and a script error is caught.
sed 's|</body>|<img src="missing.png"><script>undefined_function();</script></body>|' "$REPORT" \
  >"$OUT/broken.html"
open_page "$OUT/broken.html" broken
if page_errors broken >/dev/null; then
  echo "ok   a broken copy is caught: $(page_errors broken | head -1 | cut -c1-100)"
else
  echo "FAIL a broken copy passed the checks"; FAILS=$((FAILS + 1))
fi
[ "$FAILS" = 0 ]

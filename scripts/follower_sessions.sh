#!/usr/bin/env bash
# Issue 45's question for the appearance follower: would route images from later sessions help?
# On one changing world of the simulator, follows session S (1..20) once with the route taught on
# session 0 and once with a route taught afresh on session S-1 (the most a follower that learned
# every image of the session before could know), and prints where each ended.
#
#   bash scripts/follower_sessions.sh [MAPLESS] [WORLD]    (default: build/release/apps/mapless,
#                                                           lifelong_indoor; about 2 minutes)
set -euo pipefail
mapless=${1:-build/release/apps/mapless}
world=${2:-lifelong_indoor}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
outcome() {  # the follower's last line: how it ended and how far from the route's end
  "$mapless" follow --route "$1" --source "sim:$world@$2" 2>&1 | grep 'follow: ' | tail -1 |
    sed 's/.*follow: //'
}
"$mapless" teach --method eigenspace --source "sim:$world@0" --out "$work/0" >/dev/null 2>&1
printf '%-3s | %-60s | %s\n' S 'route taught on session 0' 'route taught on session S-1'
for s in $(seq 1 20); do
  "$mapless" teach --method eigenspace --source "sim:$world@$((s - 1))" --out "$work/$s" \
    >/dev/null 2>&1
  printf '%-3s | %-60s | %s\n' "$s" "$(outcome "$work/0" "$s")" "$(outcome "$work/$s" "$s")"
  rm -rf "${work:?}/$s"
done

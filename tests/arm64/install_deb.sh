#!/usr/bin/env bash
# The arm64 package in a clean arm64 Debian 12 root (issue 70): cpack packs the cross build
# (preset arm64), mmdebstrap makes a root from Debian 12's arm64 packages with the .deb and what
# its Depends pull in, and the packaged mapless runs there under qemu user-mode emulation.
#   - When this machine runs arm64 programs (qemu's binfmt handler registered, as systemd-binfmt
#     or update-binfmts do where qemu-user-static is installed), the root is a real install:
#     `--variant=apt`, every package configured by its own scripts, then mapless run in a chroot.
#   - Otherwise `--variant=extract`: apt resolves the package's Depends against Debian 12 arm64
#     exactly as for an install and unpacks all of them, none configured (mapless's package has no
#     scripts of its own); mapless runs as `qemu-aarch64-static -L ROOT ROOT/usr/bin/mapless`,
#     so that it finds only the root's libraries.
# What runs there: `mapless --version`, `mapless demo --help`, and with --short a teach and a
# repeat of table1_almost_straight; with --demo the whole `mapless demo` to its report.
# Usage: install_deb.sh ARM64_BUILD_DIR [--short|--demo]
set -uo pipefail
BUILD=$(realpath "$1")
WHAT=${2:---short}
TMP=$(mktemp -d /tmp/mapless_deb_arm64.XXXXXX)
# Unmounts whatever is still mounted under TMP before removing it (never follows a bind mount).
cleanup() {
  grep -o " $TMP/[^ ]*" /proc/mounts | sort -r | while read -r m; do umount -l "$m"; done
  rm -rf --one-file-system "$TMP"
}
trap cleanup EXIT
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }
elapsed() { echo "$(($(date +%s) - $1)) s"; }

(cd "$TMP" && cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$TMP/deb") >"$TMP/cpack.log" 2>&1
ok=$?
[ $ok -ne 0 ] && sed 's/^/     | /' "$TMP/cpack.log" | tail -20
check "cpack -G DEB exits 0 on the arm64 build" $ok
deb=$(ls "$TMP"/deb/mapless_*_arm64.deb 2>/dev/null | head -1)
[ -n "$deb" ]; st=$?; check "a mapless_*_arm64.deb was written ($(basename "${deb:-none}"))" $st
[ -n "$deb" ] || { echo "$failed failed"; exit 1; }
[ "$(dpkg-deb -f "$deb" Architecture)" = arm64 ]; check "its Architecture is arm64" $?
depends=$(dpkg-deb -f "$deb" Depends)
echo "     Depends: $depends"
grep -q "libopencv-core406" <<<"$depends" && grep -q "libyaml-cpp0.7" <<<"$depends" &&
  grep -q "libzmq5" <<<"$depends" && grep -q "libc6" <<<"$depends" &&
  grep -q "libopencv-imgcodecs406" <<<"$depends" && grep -q "libavformat59" <<<"$depends"
check "Depends names the runtime packages, those opened on first use too" $?
dpkg-deb --fsys-tarfile "$deb" | tar -xO ./usr/bin/mapless >"$TMP/mapless.bin"
file_of_binary=$(head -c 20 "$TMP/mapless.bin" | od -An -tx1 | tr -d ' \n')
# ELF, 64-bit, little endian; e_machine 0xb7 (AArch64) at offset 18.
[ "${file_of_binary:36:4}" = "b700" ]; check "the packaged mapless is an AArch64 program" $?

sources=()
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
  [ -s "$f" ] && sources+=("$f")
done
ROOT="$TMP/root"
if [ -e /proc/sys/fs/binfmt_misc/qemu-aarch64 ] && grep -qx enabled /proc/sys/fs/binfmt_misc/qemu-aarch64; then
  variant=apt
  run() { chroot "$ROOT" /usr/bin/env -i PATH=/usr/bin:/bin HOME=/root sh -c 'cd /root && "$@"' sh "$@"; }
else
  variant=extract
  run() { (cd "$ROOT/root" && qemu-aarch64-static -L "$ROOT" "$ROOT/usr/bin/$1" "${@:2}"); }
fi
run_in="$ROOT/root"  # where a run's files are, seen from here (the chroot's /root)
# apt hands the .deb's path to dpkg inside the root: it is copied there at the same path first,
# and removed before the root is used.
debdir=$(dirname "$deb")
hooks=(--setup-hook="mkdir -p \"\$1$debdir\" && cp \"$deb\" \"\$1$debdir/\""
       --customize-hook="rm -rf \"\$1$TMP\"")
start=$(date +%s)
mmdebstrap --quiet --arch=arm64 --variant=$variant --include="$deb" "${hooks[@]}" \
  bookworm "$ROOT" "${sources[@]}" >"$TMP/mmdebstrap.log" 2>&1
ok=$?
[ $ok -ne 0 ] && tail -20 "$TMP/mmdebstrap.log" | sed 's/^/     | /'
check "mmdebstrap --variant=$variant makes an arm64 Debian 12 root with the package ($(elapsed "$start"), $(du -sh "$ROOT" 2>/dev/null | cut -f1))" $ok
[ -x "$ROOT/usr/bin/mapless" ]; check "the root has /usr/bin/mapless" $?
if [ $variant = extract ]; then
  # BLAS and LAPACK are reached through Debian's alternatives, which their packages' scripts set
  # up when configured; unpacked only, the links those scripts would make are made here.
  for lib in blas lapack; do
    a="$ROOT/usr/lib/aarch64-linux-gnu"
    [ -e "$a/lib$lib.so.3" ] || [ ! -e "$a/$lib/lib$lib.so.3" ] || ln -s "$lib/lib$lib.so.3" "$a/lib$lib.so.3"
  done
fi
mkdir -p "$ROOT/root"

run mapless --version >"$TMP/version" 2>&1
ok=$?
check "mapless --version in the root ($(tr '\n' ' ' <"$TMP/version" | cut -c1-80))" $ok
grep -q "^robot links: ros1, ros2" "$TMP/version"; check "it has both robot links" $?
run mapless demo --help >"$TMP/help" 2>&1 && grep -q -- "--scenario" "$TMP/help"
check "mapless demo --help" $?
if [ "$WHAT" = --short ]; then
  start=$(date +%s)
  run mapless teach --source sim:table1_almost_straight --out route >"$TMP/teach.log" 2>&1
  ok=$?
  [ $ok -ne 0 ] && tail -3 "$TMP/teach.log" | sed 's/^/     | /'
  check "a teach of table1_almost_straight ($(grep -o 'teach: [0-9]* frames.*' "$TMP/teach.log" | head -1); $(elapsed "$start") emulated)" $ok
  start=$(date +%s)
  run mapless repeat --route route --source sim:table1_almost_straight --log repeat.jsonl >"$TMP/repeat.log" 2>&1 &&
    tail -1 "$run_in/repeat.jsonl" 2>/dev/null | grep -q '"status":"completed"'
  ok=$?
  [ $ok -ne 0 ] && tail -3 "$TMP/repeat.log" | sed 's/^/     | /'
  check "its repeat completes ($(grep -o 'repeat: .*final error.*' "$TMP/repeat.log" | head -1); $(elapsed "$start") emulated)" $ok
elif [ "$WHAT" = --demo ]; then
  start=$(date +%s)
  run mapless demo --out demo >"$TMP/demo.log" 2>&1
  ok=$?
  [ $ok -ne 0 ] && tail -5 "$TMP/demo.log" | sed 's/^/     | /'
  check "mapless demo runs to its report ($(elapsed "$start") emulated)" $ok
  [ -s "$run_in/demo/report/index.html" ] && [ "$(grep -c '"success": true' "$run_in/demo/summary.json")" -eq 3 ]
  check "the report is written and all three methods succeeded ($(grep -c '"success": true' "$run_in/demo/summary.json" 2>/dev/null) of 3)" $?
fi
echo "$failed failed"
[ "$failed" -eq 0 ]

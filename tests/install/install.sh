#!/usr/bin/env bash
# mapless installs as a library and a package (issue 39):
#   1. `cmake --install BUILD --prefix P` puts the command, the libraries, the headers and the CMake
#      package under P; a program outside the tree (consumer/: the sloped funnel lane's command for
#      two images) is configured with find_package(mapless), built against P and run on two
#      simulator frames rendered by the installed command.
#   2. `cpack -G DEB` packs the build; the package's Depends names the runtime libraries' Debian
#      packages; unpacked with `dpkg-deb -x` (never installed on this machine), its `mapless
#      --version` and `mapless sim list` run.
# Usage: install.sh BUILD_DIR SOURCE_DIR [install|deb]   (both when the last argument is absent)
set -uo pipefail
BUILD=$(realpath "$1")
SRC=$(realpath "$2")
WHAT="${3:-all}"
TMP=$(mktemp -d /tmp/mapless_install.XXXXXX)
trap 'rm -rf "$TMP"' EXIT
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }

if [ "$WHAT" = all ] || [ "$WHAT" = install ]; then
  P="$TMP/prefix"
  cmake --install "$BUILD" --prefix "$P" >"$TMP/install.log" 2>&1
  check "cmake --install exits 0" $?
  [ -x "$P/bin/mapless" ] && [ -f "$P/include/mapless/control/funnel_lane.h" ] \
    && [ -f "$P/lib/cmake/mapless/maplessConfig.cmake" ] && ls "$P"/lib/libmapless_*.a >/dev/null 2>&1
  check "the prefix has bin/mapless, the headers, the libraries and the CMake package" $?
  ! find "$P/include" -name '*_test*' | grep -q .; check "no test headers installed" $?
  cmake -S "$SRC/tests/install/consumer" -B "$TMP/consumer" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$P" >"$TMP/consumer.log" 2>&1 \
    && cmake --build "$TMP/consumer" >>"$TMP/consumer.log" 2>&1
  ok=$?
  [ $ok -ne 0 ] && sed 's/^/     | /' "$TMP/consumer.log" | tail -30
  check "a program outside the tree builds with find_package(mapless)" $ok
  # The keyframe 1 m ahead on the route; the current view from the start, turned 15 degrees left:
  # the funnel lane must turn the robot right, back towards the keyframe's view.
  "$P/bin/mapless" sim render --scenario table1_almost_straight --pose 1,0,0 --out "$TMP/keyframe.png" \
    && "$P/bin/mapless" sim render --scenario table1_almost_straight --pose 0,0,15 --out "$TMP/current.png"
  check "the installed mapless renders two frames" $?
  out=$("$TMP/consumer/funnel_lane_command" "$TMP/keyframe.png" "$TMP/current.png")
  echo "     funnel_lane_command: $out"
  matches=$(sed -n 's/.*matches \([0-9]*\).*/\1/p' <<<"$out")
  [ "${matches:-0}" -ge 20 ] && grep -q "command right" <<<"$out"
  check "the installed library's sloped funnel lane turns right, on >= 20 matches" $?
fi

if [ "$WHAT" = all ] || [ "$WHAT" = deb ]; then
  (cd "$TMP" && cpack -G DEB --config "$BUILD/CPackConfig.cmake" -B "$TMP/deb") >"$TMP/cpack.log" 2>&1
  ok=$?
  [ $ok -ne 0 ] && sed 's/^/     | /' "$TMP/cpack.log" | tail -30
  check "cpack -G DEB exits 0" $ok
  deb=$(ls "$TMP"/deb/mapless_*.deb 2>/dev/null | head -1)
  [ -n "$deb" ]; st=$?; check "a .deb was written ($(basename "${deb:-none}"))" $st
  if [ -n "$deb" ]; then
    depends=$(dpkg-deb -f "$deb" Depends)
    echo "     Depends: $depends"
    grep -q "libopencv-core" <<<"$depends" && grep -q "libyaml-cpp" <<<"$depends" \
      && grep -q "libzmq" <<<"$depends" && grep -q "libc6" <<<"$depends"
    check "Depends names the runtime packages (OpenCV, yaml-cpp, ZeroMQ, libc)" $?
    # Opened on first use (io/lazy_libraries.h), so named by the build rather than found.
    grep -q "libopencv-imgcodecs" <<<"$depends" && grep -q "libopencv-videoio" <<<"$depends" \
      && grep -q "libavformat" <<<"$depends" && grep -q "libswscale" <<<"$depends"
    check "Depends names the libraries opened on first use (image codecs, video I/O, FFmpeg)" $?
    dpkg-deb -x "$deb" "$TMP/root"
    check "dpkg-deb -x unpacks it" $?
    "$TMP/root/usr/bin/mapless" --version >"$TMP/version" 2>&1
    check "the packaged mapless --version exits 0" $?
    head -1 "$TMP/version" | grep -q "^mapless [0-9]" && grep -q "^robot links: " "$TMP/version"
    st=$?; check "it names its version and its robot links ($(tr '\n' ' ' <"$TMP/version"))" $st
    "$TMP/root/usr/bin/mapless" sim list >"$TMP/list" 2>&1 && grep -qx "narrow_room_sharp_turn" "$TMP/list"
    check "the packaged mapless sim list names the built-in scenarios" $?
    [ -f "$TMP/root/usr/lib/cmake/mapless/maplessConfig.cmake" ] || \
      ls "$TMP"/root/usr/lib/*/cmake/mapless/maplessConfig.cmake >/dev/null 2>&1
    check "the package carries the CMake package" $?
  fi
fi

echo "$failed failed"
[ "$failed" -eq 0 ]

#!/usr/bin/env bash
# Installs every Debian package mapless needs. Idempotent: packages already installed are
# skipped; nothing is done when all are present.
# Usage: scripts/setup.sh            build and run mapless on the simulator, recordings, videos and
#                                    cameras (README command 1; as root, or with sudo available)
#        scripts/setup.sh --ros      also ROS 1 (roscpp, the message packages, roscore, rosbag) and
#                                    Cyclone DDS for ROS 2: the robot links over ROS 1 and ROS 2 are
#                                    built when they are present (about 180 Debian packages, so
#                                    the demo does without)
#        scripts/setup.sh --test     --ros and what the test command (README command 2) uses
#                                    besides: Chromium (the report opened headless), clang (the
#                                    sanitizer build, with its runtimes), clang-format (the style
#                                    check), dpkg-dev and file (the .deb's dependencies), and
#                                    Node.js with npm where there is none (the interop tests)
#        scripts/setup.sh --arm64    also the arm64 cross build's tools: Debian's cross GCC,
#                                    mmdebstrap (scripts/sysroot_arm64.sh) and qemu user-mode
#                                    emulation (docs/arm64.md); combines with the others
set -euo pipefail
WITH_ROS=0
WITH_TEST=0
WITH_ARM64=0
for arg in "$@"; do
  case "$arg" in
    --ros) WITH_ROS=1 ;;
    --test) WITH_ROS=1; WITH_TEST=1 ;;
    --arm64) WITH_ARM64=1 ;;
    *) echo "setup: unknown option $arg (known: --ros, --test, --arm64)" >&2; exit 2 ;;
  esac
done

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libopencv-dev          # images, features, optical flow (Debian's build: no SURF)
  libavformat-dev libavcodec-dev libswscale-dev libavutil-dev   # video files, decoded with FFmpeg
  libeigen3-dev          # linear algebra (PCA, least squares)
  libyaml-cpp-dev        # scenario, world and configuration files
  libcli11-dev           # the `mapless` command line
  libspdlog-dev libfmt-dev   # logging in apps (library code does not log)
  nlohmann-json3-dev     # JSON output (bench, eval, localize)
  libgtest-dev libgmock-dev  # unit and integration tests
  libbenchmark-dev       # micro benchmarks
  libzmq3-dev cppzmq-dev # fleet messaging (leader/follower)
  libzstd-dev liblz4-dev zlib1g-dev   # MCAP recordings: zstd and lz4 chunks, CRC-32
  libwebsocketpp-dev libasio-dev   # the live view (--live): the Foxglove WebSocket protocol
)
if [ "$WITH_ROS" = "1" ]; then
  PACKAGES+=(
    libroscpp-dev          # ROS 1 client library (Noetic level in Debian 12)
    libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libstd-msgs-dev
    ros-core-dev           # roscore / rosmaster, for `mapless sim serve` and the tests
    # The message packages' Python side, for the ROS tools a robot owner looks with (`rostopic
    # echo /cmd_vel` said "Cannot load message class" without them; ros-core-dev has rostopic).
    python3-geometry-msgs python3-sensor-msgs python3-nav-msgs python3-std-msgs
    cyclonedds-dev cyclonedds-tools   # ROS 2 over DDS (Cyclone 0.10, as in Humble and Jazzy)
    libsodium-dev          # SHA-256 of the ROS 2 type descriptions (the RIHS01 type hash)
    librosbag-storage-dev libbz2-dev  # reading ROS 1 bags (recordings as sources; bz2 chunks checked)
  )
fi
if [ "$WITH_TEST" = "1" ]; then
  PACKAGES+=(
    chromium               # the HTML report opened headless (no console error, a screenshot)
    clang                  # the sanitizer build (docs/ci.md: 0.6x GCC's compile time under ASan)
    libclang-rt-14-dev     # ... its ASan and UBSan runtimes (only a Recommends of clang)
    clang-format           # the style check (scripts/check_format.sh)
    dpkg-dev file          # dpkg-shlibdeps and file: the Depends of the .deb (cpack)
  )
  # The interoperability tests' reference clients (npm packages pinned in the tests' folders):
  # Debian's Node.js where the machine has none (18 in Debian 12; the live page's check needs 20
  # and is skipped, saying so, on 18). A Node.js installed otherwise (NodeSource's, nvm) is kept.
  if ! command -v node >/dev/null 2>&1; then
    PACKAGES+=(nodejs npm ca-certificates)
  fi
  if [ "$WITH_ROS" = "1" ]; then
    # A real ROS 2 middleware on the other end (tests/ros2/fastdds): eProsima Fast DDS, the default
    # of ROS 2 Humble and Jazzy, and its type generator (Java).
    PACKAGES+=(libfastrtps-dev fastddsgen)
  fi
fi
if [ "$WITH_ARM64" = "1" ]; then
  PACKAGES+=(crossbuild-essential-arm64 mmdebstrap arch-test qemu-user-static
             cyclonedds-tools)  # idlc runs on the build machine for the arm64 ROS 2 link
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || { echo "setup: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  SUDO="sudo"
fi

echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -q
$SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"

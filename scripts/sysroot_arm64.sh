#!/usr/bin/env bash
# Makes the arm64 sysroot the cross build links against (cmake --preset arm64, docs/arm64.md):
# Debian 12's arm64 builds of every library mapless uses, unpacked (never installed: nothing of
# theirs runs) by mmdebstrap from this machine's own apt sources, into build/sysroot-arm64.
# It also writes the sysroot's shared-library index (mapless/shlibs.tsv inside it: soname, the
# package that ships it and the dependency its shlibs file asks for), from which the arm64 .deb's
# Depends are computed (cmake/MaplessCrossDepends.cmake). Kept between runs: made again only when the
# package list below changes. Usage: scripts/sysroot_arm64.sh [DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
DIR=$(realpath -m "${1:-build/sysroot-arm64}")
# The arm64 side of scripts/setup.sh --ros (the libraries, headers and CMake packages; not the
# tools, which run on the build machine), and the C/C++ runtime and headers of Debian's GCC 12.
PACKAGES=(
  libc6-dev libstdc++-12-dev
  libopencv-dev libavformat-dev libavcodec-dev libswscale-dev libavutil-dev
  libeigen3-dev libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libzmq3-dev cppzmq-dev libzstd-dev liblz4-dev zlib1g-dev libwebsocketpp-dev libasio-dev
  libroscpp-dev libsensor-msgs-dev libgeometry-msgs-dev libnav-msgs-dev libstd-msgs-dev
  librosbag-storage-dev libbz2-dev cyclonedds-dev libsodium-dev
)
stamp="$DIR/mapless/packages.txt"
want=$(printf '%s\n' "${PACKAGES[@]}")
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ] && [ -f "$DIR/mapless/shlibs.tsv" ]; then
  echo "sysroot_arm64: $DIR is up to date"
  exit 0
fi
for tool in mmdebstrap dpkg-deb; do
  command -v "$tool" >/dev/null ||
    { echo "sysroot_arm64: $tool not found (scripts/setup.sh --arm64 installs it)" >&2; exit 1; }
done
# This machine's apt sources (one-line or deb822 files), as apt itself reads them.
sources=()
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
  [ -s "$f" ] && sources+=("$f")
done
[ ${#sources[@]} -gt 0 ] || { echo "sysroot_arm64: no apt sources in /etc/apt" >&2; exit 1; }
rm -rf "$DIR.new"
mkdir -p "$DIR.new"
include=$(IFS=,; echo "${PACKAGES[*]}")
echo "sysroot_arm64: unpacking ${#PACKAGES[@]} packages and their dependencies into $DIR"
# extract: the packages are unpacked, none is configured; the downloaded .debs are kept for the
# index, then removed.
mmdebstrap --quiet --arch=arm64 --variant=extract --include="$include" \
  --skip=check/empty --skip=cleanup/apt/cache bookworm "$DIR.new" "${sources[@]}"
debs="$DIR.new/var/cache/apt/archives"
# Absolute links (libz.so -> /lib/...) would point into the build machine: made relative.
find "$DIR.new/usr" "$DIR.new/etc" -type l -lname '/*' | while read -r link; do
  target=$(readlink "$link")
  ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$DIR.new$target")" "$link"
done
# BLAS and LAPACK (OpenCV links them) are reached through Debian's alternatives, which the
# packages' scripts set up when installed; unpacked only, the reference builds are linked here.
arch_lib="$DIR.new/usr/lib/aarch64-linux-gnu"
for lib in blas lapack; do
  if [ ! -e "$arch_lib/lib$lib.so.3" ] && [ -e "$arch_lib/$lib/lib$lib.so.3" ]; then
    ln -sfn "$lib/lib$lib.so.3" "$arch_lib/lib$lib.so.3"
  fi
done
mkdir -p "$DIR.new/mapless"
index="$DIR.new/mapless/shlibs.tsv"
: >"$index"
for deb in "$debs"/*.deb; do
  pkg=$(dpkg-deb -f "$deb" Package)
  version=$(dpkg-deb -f "$deb" Version)
  shlibs=$(dpkg-deb -I "$deb" shlibs 2>/dev/null || true)
  # Every shared library the package ships, by file name.
  dpkg-deb -c "$deb" | awk '{print $6}' | sed -n 's#.*/\(lib[^/]*\.so[^/]*\)$#\1#p' | sort -u |
    while read -r so; do
      dep=""
      # shlibs lines: "libname soversion package (>= version)"; the soname is libname.so.soversion.
      if [ -n "$shlibs" ]; then
        dep=$(awk -v so="$so" 'NF >= 3 && $1 !~ /:$/ {
                name = $1 ".so." $2; alt = $1 "-" $2 ".so";
                if (so == name || so == alt) { $1 = ""; $2 = ""; sub(/^  */, ""); print; exit } }' \
              <<<"$shlibs")
      fi
      [ -n "$dep" ] || dep="$pkg (>= ${version%%-*})"
      printf '%s\t%s\t%s\n' "$so" "$pkg" "$dep" >>"$index"
    done
done
rm -f "$debs"/*.deb
printf '%s\n' "${PACKAGES[@]}" >"$DIR.new/mapless/packages.txt"
rm -rf "$DIR"
mv "$DIR.new" "$DIR"
echo "sysroot_arm64: $DIR ready ($(du -sh "$DIR" | cut -f1), $(wc -l <"$DIR/mapless/shlibs.tsv") shared libraries indexed)"

#!/usr/bin/env bash
# README's quick start on a fresh Debian 12, as a newcomer's machine is: no ROS, no compiler, no
# library of mapless's. Makes a minimal Debian 12 (debootstrap --variant=minbase) in DIR, clones
# this repository's HEAD into it, and runs README command 1 (`bash scripts/demo.sh`) there under
# chroot, then checks that the build has no robot link and that the demo wrote its report; with
# --test, also command 2 (`bash .ci/run`, which installs ROS 1, Cyclone DDS and the test tools
# first). Prints each command's time. Not run by ctest: it needs root, a Debian mirror and about
# 6 minutes for command 1 (docs/ci.md, "A fresh machine").
#   sudo tests/newcomer/fresh_machine.sh DIR [--test]
# DIR must not exist or be empty; it is left in place (remove it with rm -rf after); the mounts
# made in it are always undone.
set -euo pipefail
DIR=${1:?usage: fresh_machine.sh DIR [--test]}
WITH_TEST=${2:-}
[ "$(id -u)" -eq 0 ] || { echo "fresh_machine: run as root (debootstrap, chroot)" >&2; exit 1; }
[ ! -e "$DIR" ] || [ -z "$(ls -A "$DIR")" ] || { echo "fresh_machine: $DIR is not empty" >&2; exit 1; }
REPO=$(cd "$(dirname "$0")/../.." && pwd)
MIRROR=${MIRROR:-http://deb.debian.org/debian}

command -v debootstrap >/dev/null || apt-get install -y debootstrap >/dev/null
mounted=()
cleanup() {
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do
    mount --make-rslave "${mounted[$i]}" 2>/dev/null || true
    umount -R "${mounted[$i]}" 2>/dev/null || umount -lR "${mounted[$i]}" 2>/dev/null || true
  done
}
trap cleanup EXIT

mkdir -p "$DIR"
echo "fresh_machine: debootstrap bookworm (minbase) into $DIR"
debootstrap --variant=minbase bookworm "$DIR" "$MIRROR" >"$DIR.debootstrap.log" 2>&1 ||
  { tail -20 "$DIR.debootstrap.log"; exit 1; }
cat >"$DIR/etc/apt/sources.list" <<EOF
deb $MIRROR bookworm main
deb $MIRROR bookworm-updates main
deb http://deb.debian.org/debian-security bookworm-security main
EOF
cp /etc/resolv.conf "$DIR/etc/resolv.conf"
# Behind a proxy that signs with its own CA (NODE_EXTRA_CA_CERTS on this host), npm inside needs it.
extra_ca=()
if [ -n "${NODE_EXTRA_CA_CERTS:-}" ] && [ -f "$NODE_EXTRA_CA_CERTS" ]; then
  mkdir -p "$DIR$(dirname "$NODE_EXTRA_CA_CERTS")"
  cp "$NODE_EXTRA_CA_CERTS" "$DIR$NODE_EXTRA_CA_CERTS.proxy"
  extra_ca=(NODE_EXTRA_CA_CERTS="$NODE_EXTRA_CA_CERTS.proxy")
fi
git clone -q "$REPO" "$DIR/root/mapless"
git -C "$DIR/root/mapless" checkout -q "$(git -C "$REPO" rev-parse HEAD)"
mount -t proc proc "$DIR/proc" && mounted+=("$DIR/proc")
mount -t sysfs sys "$DIR/sys" && mounted+=("$DIR/sys")
mount --rbind /dev "$DIR/dev" && mount --make-rslave "$DIR/dev" && mounted+=("$DIR/dev")

in_chroot() {  # in_chroot LOG COMMAND: runs COMMAND in the repository inside DIR, as root
  local log=$1 start rc=0
  shift
  start=$(date +%s)
  chroot "$DIR" /usr/bin/env -i HOME=/root TERM=dumb CI=true "${extra_ca[@]}" \
    PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    bash -c "cd /root/mapless && $*" >"$log" 2>&1 || rc=$?
  echo "fresh_machine: '$*' exit $rc after $(($(date +%s) - start)) s (log: $log)"
  return $rc
}

set +e
failed=0
check() { if [ "$2" -eq 0 ]; then echo "ok   $1"; else echo "FAIL $1"; failed=$((failed + 1)); fi; }
in_chroot "$DIR.command1.log" bash scripts/demo.sh
check "README command 1 exits 0" $?
grep -q "mapless: ROS 1 robot link: NOT built" "$DIR.command1.log" &&
  grep -q "mapless: ROS 2 robot link: NOT built" "$DIR.command1.log"
check "the newcomer's build has no robot link (no ROS installed)" $?
[ -s "$DIR/root/mapless/demo_out/report/index.html" ]
check "the demo wrote demo_out/report/index.html" $?
if [ "$WITH_TEST" = --test ]; then
  in_chroot "$DIR.command2.log" bash .ci/run
  check "README command 2 exits 0" $?
fi
echo "fresh_machine: $failed failed"
[ "$failed" -eq 0 ]

# Sourced by the npm interoperability tests (tests/recording/interop.sh, tests/live/interop.sh):
#   npm_folder SRC_DIR WORK_DIR: copies SRC_DIR's package.json, package-lock.json and *.mjs to
#   WORK_DIR/js and installs the pinned packages there with `npm ci` (again only when the lock
#   changed); exits 1 with npm's last lines when that fails.
npm_folder() {
  local src=$1 work=$2
  mkdir -p "$work/js"
  cp "$src/package.json" "$src/package-lock.json" "$src/"*.mjs "$work/js/"
  if ! cmp -s "$src/package-lock.json" "$work/js/node_modules/.package-lock.json.installed" 2>/dev/null; then
    (cd "$work/js" && npm ci --no-audit --no-fund --loglevel=error) >"$work/npm.log" 2>&1 ||
      { echo "interop.sh: npm ci failed:"; tail -5 "$work/npm.log"; exit 1; }
    cp "$src/package-lock.json" "$work/js/node_modules/.package-lock.json.installed"
  fi
}

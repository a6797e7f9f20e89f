#!/usr/bin/env bash
# The MCAP interoperability tests (mcap_interop.cjs) and their npm packages.
#   mcap_interop_test.sh npm-ci SOURCE_DIR NPM_DIR
#     installs package-lock.json's packages into NPM_DIR/node_modules with `npm ci` (only from the
#     npm registry); a second run with the same lock file does nothing (a stamp holds the lock's hash)
#   mcap_interop_test.sh MODE SOURCE_DIR NPM_DIR TOOL WORK_DIR
#     runs mcap_interop.cjs MODE (npm-reads-cosmic, cosmic-reads-npm) against those packages
# Exit status: 0 passed, 1 failed, 77 skipped (no node or npm on this machine).
set -euo pipefail

mode=${1:?mode}
source_dir=${2:?source dir}
npm_dir=${3:?npm dir}
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "mcap interop: node and npm are not installed (Debian package nodejs): skipped"
  exit 77
fi

if [ "$mode" = npm-ci ]; then
  mkdir -p "$npm_dir"
  hash=$(sha256sum "$source_dir/package.json" "$source_dir/package-lock.json" | sha256sum | cut -d' ' -f1)
  if [ -d "$npm_dir/node_modules" ] && [ "$(cat "$npm_dir/.installed" 2>/dev/null)" = "$hash" ]; then
    echo "mcap interop: npm packages already installed in $npm_dir"
    exit 0
  fi
  cp "$source_dir/package.json" "$source_dir/package-lock.json" "$npm_dir/"
  rm -f "$npm_dir/.installed"
  (cd "$npm_dir" && npm ci --ignore-scripts --no-audit --no-fund --prefer-offline)
  echo "$hash" >"$npm_dir/.installed"
  exit 0
fi

tool=${4:?tool}
work=${5:?work dir}
[ -d "$npm_dir/node_modules" ] || { echo "mcap interop: no $npm_dir/node_modules (run the npm-ci step first)" >&2; exit 1; }
rm -rf "$work"
NODE_PATH="$npm_dir/node_modules" node "$source_dir/mcap_interop.cjs" "$mode" "$tool" "$work"

#!/usr/bin/env bash
# run_ajv.sh CASES_TOOL SOURCE_DIR WORK_DIR: the JSON Schemas of cosmic::json_schema() against ajv
# (validate.cjs says what is checked). ajv comes from npm, as package-lock.json pins it, installed
# with `npm ci` into WORK_DIR/npm (the build tree; node_modules is never committed) and installed
# again only when the lock file changed. Exit 77 (ctest: skipped) when node or npm is missing.
set -euo pipefail
tool=$1 source_dir=$2 work=$3
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "SKIP: node and npm are needed to run ajv"
  exit 77
fi
mkdir -p "$work/npm"
if ! cmp -s "$source_dir/package-lock.json" "$work/npm/package-lock.json" || [ ! -d "$work/npm/node_modules/ajv" ]; then
  cp "$source_dir/package.json" "$source_dir/package-lock.json" "$work/npm/"
  (cd "$work/npm" && npm ci --no-audit --no-fund --ignore-scripts)
fi
rm -rf "$work/cases"
mkdir -p "$work/cases"
"$tool" "$work/cases"
node "$source_dir/validate.cjs" "$work/npm" "$work/cases"

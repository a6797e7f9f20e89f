# Shared by the cosmicctl CLI tests (sourced): arguments, a work directory, and checks that count
# failures instead of stopping, so one run reports every broken expectation.
# The sourcing script is called as: SCRIPT PATH_TO_cosmicctl PROJECT_SOURCE_DIR
CTL=${1:?path to cosmicctl}
SRC=${2:?project source dir}
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
FAILURES=0

fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}

# run NAME EXPECTED_EXIT ARGS...: runs cosmicctl, keeps stdout/stderr in $WORK/NAME.{out,err}.
run() {
  local name=$1 expected=$2
  shift 2
  "$CTL" "$@" >"$WORK/$name.out" 2>"$WORK/$name.err"
  local code=$?
  if [ "$code" -ne "$expected" ]; then
    fail "$name: exit $code, expected $expected (cosmicctl $*)"
    sed 's/^/    /' "$WORK/$name.out" "$WORK/$name.err" >&2
  fi
}

# json_check NAME PYTHON_EXPRESSIONS: every line of the script must hold for `d`, the parsed output.
json_check() {
  local name=$1 script=$2
  if ! python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
for line in sys.argv[2].strip().splitlines():
    line = line.strip()
    if line and not eval(line, {"d": d, "all": all, "any": any, "set": set, "len": len, "isinstance": isinstance}):
        sys.exit("does not hold: " + line)
' "$WORK/$name.out" "$script"; then
    fail "$name: JSON check"
  fi
}

contains() {  # contains NAME out|err TEXT
  if ! grep -qF -- "$3" "$WORK/$1.$2"; then
    fail "$1: $2 lacks '$3'"
    sed 's/^/    /' "$WORK/$1.$2" >&2
  fi
}

finish() {  # finish WHAT: the exit status of the test
  if [ "$FAILURES" -ne 0 ]; then
    echo "$FAILURES check(s) failed" >&2
    exit 1
  fi
  echo "$1: all checks passed"
}

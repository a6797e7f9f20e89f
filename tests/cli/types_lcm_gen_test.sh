#!/usr/bin/env bash
# `cosmicctl types FILE.lcm` against lcm-gen (issue 35): for every struct of an LCM type file, the
# fingerprint cosmicctl computes is the one lcm-gen's generated Python code computes
# (_get_hash_recursive, rotated, as every LCM message of the type starts with), and the fields are
# the struct's members in order.
# Usage: types_lcm_gen_test.sh PATH_TO_cosmicctl PROJECT_SOURCE_DIR
set -u

. "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"
LCM=$SRC/tests/cli/types/robot_types.lcm
command -v lcm-gen >/dev/null || { echo "FAIL: lcm-gen not found (scripts/setup installs liblcm-bin)"; exit 1; }
python=/usr/bin/python3
[ -x "$python" ] || python=$(command -v python3)

(cd "$WORK" && lcm-gen -p "$LCM" >/dev/null) || fail "lcm-gen -p $LCM failed"
run json 0 --json types "$LCM"
if ! PYTHONPATH=$WORK "$python" - "$WORK/json.out" <<'PY'; then
import importlib, json, sys
d = json.load(open(sys.argv[1]))
problems = []
names = [t["name"] for t in d["types"]]
if names != ["robot.vector3_t", "robot.twist_t", "robot.laser_scan_t", "robot.path_t"]:
    problems.append("structs %s" % names)
for t in d["types"]:
    package, name = t["name"].split(".")
    generated = getattr(importlib.import_module(package + "." + name), name)
    theirs = "0x%016x" % int.from_bytes(generated._get_packed_fingerprint(), "big")
    if t["fingerprint"] != theirs:
        problems.append("%s: cosmicctl %s, lcm-gen %s" % (t["name"], t["fingerprint"], theirs))
    members = list(generated.__slots__)
    if [f["name"] for f in t["fields"]] != members:
        problems.append("%s: fields %s, lcm-gen members %s" % (t["name"], [f["name"] for f in t["fields"]], members))
for p in problems:
    print("FAIL:", p)
sys.exit(1 if problems else 0)
PY
  fail "cosmicctl's fingerprints or fields differ from lcm-gen's"
fi

run text 0 types "$LCM"
contains text out "robot_types.lcm: LCM, 4 structs"
contains text out "  const int8_t MODE_RUN = 1"
contains text out "  ranges: sequence<float32, 65536>"
contains text out "  covariance: float64[6][6]"
contains text out "  labels: sequence<string<=65536>[2], 127>"
contains text out "  command: {linear: {x: float64, y: float64, z: float64}, angular: {x: float64, y: float64, z: float64}}"
# Unbounded arrays count at their limit: a type once max_length bounds them.
contains text out "  not a type as it stands: line 18:1: robot.laser_scan_t: its largest value holds more than 65536 scalars (max_length: {MEMBER: N} bounds a variable-length array)"

printf 'struct t { int32_t a; int16_t b[n]; }\n' >"$WORK/bad.lcm"
run bad 2 types "$WORK/bad.lcm"
contains bad err "$WORK/bad.lcm:1:31: the size of b, 'n', is not an integer member declared before it"

finish "cosmicctl types (LCM) against lcm-gen"

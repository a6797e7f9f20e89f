"""The generated C++ structs of typed_gen.yaml against the Python package's own compact layout
(cosmic._typed, written apart from cosmicctl gen): bytes Python encodes decode in C++ to the same
values and encode again to the same bytes, Python decodes what C++ encoded, and C++ refuses what is
not an event of the type.

Usage: typed_roundtrip.py CONFIG ROUNDTRIP_BINARY...   (PYTHONPATH: the built package `cosmic`)
"""
from __future__ import annotations

import json
import struct
import subprocess
import sys

import cosmic

SCAN_CASES = [
    {"flag": True, "i8": -100, "i16": -32768, "i32": 123456, "i64": -(2**63), "u8": 200, "u16": 65535,
     "u32": 2**32 - 1, "u64": 2**64 - 1, "distance": 12.5, "heading": -3.141592653589793, "state": "FAULT",
     "label": "h\u00e9llo", "ranges": [0.5, 99.25, 3.0], "corners": [-1, 2], "flags": [True, False, True],
     "names": ["ab", "wxyz"], "grid": [[1, 2], [3, 4]], "pose": {"x": 1.25, "Pose": -7, "mode": "MOVING"},
     "track": [{"x": 2.5, "tags": [1, 65535]}, {"x": -0.0, "tags": []}], "class": 255},
    # Empty strings and sequences, and an enumeration's value it does not name.
    {"flag": False, "i8": 100, "i16": 1, "i32": -1, "i64": 2**63 - 1, "u8": 0, "u16": 0, "u32": 0, "u64": 0,
     "distance": 40.0, "heading": 1e300, "state": 7, "label": "", "ranges": [], "corners": [0, 0], "flags": [],
     "names": ["", ""], "grid": [[0, 0], [0, 255]], "pose": {"x": 0.0, "Pose": 0, "mode": "IDLE"}, "track": [],
     "class": 0},
]
DIAGNOSTICS_CASES = [
    {"Mode": 0, "Dtc": 513, "Voltage": 12.5, "Ignition": "Run"},
    {"Mode": 2, "Level": 150, "Voltage": 0.01, "Ignition": "class"},
    {"Mode": 5, "Voltage": 655.35, "Ignition": 0},  # neither conditional field selected: zeros
]

# What C++ must refuse, by the encode() refusals the program runs itself.
EXPECTED_REFUSALS = {
    "ranges_over_bound": "over_bound ranges",
    "label_over_bound": "over_bound label",
    "tags_over_bound": "over_bound track[].tags",
    "track_over_bound": "over_bound track",
    "distance_above": "out_of_range distance",
    "distance_nan": "out_of_range distance",
    "i8_below": "out_of_range i8",
    "u8_above": "out_of_range u8",
    "range_element": "out_of_range ranges[]",
    "within_bounds": "ok -",
    "buffer_too_small": "buffer_too_small i64",  # 10 bytes: flag, i8, i16 and i32 fit
    "dtc_not_selected": "not_selected Dtc",
    "level_above": "out_of_range Level",
}

failures: list[str] = []


def fail(what: str) -> None:
    failures.append(what)
    print("FAIL:", what, file=sys.stderr)


def integers(fields: list[dict], value: dict) -> dict:
    """The dict with each enumeration's name as its integer, as the C++ side prints it."""
    out = {}
    for f in fields:
        if f["name"] in value:
            out[f["name"]] = _integers(f["type"], value[f["name"]])
    return out


def _integers(t: dict, value):
    if t["kind"] == "enum":
        return t["values"].get(value, value) if isinstance(value, str) else value
    if t["kind"] in ("array", "sequence"):
        return [_integers(t["element"], v) for v in value]
    if t["kind"] == "record":
        return integers(t["fields"], value)
    return value


def run(binary: str, lines: list[str], *args: str) -> list[str]:
    done = subprocess.run([binary, *args], input="".join(lines), capture_output=True, text=True, check=False)
    if done.returncode != 0:
        fail(f"{binary} {' '.join(args)} exited {done.returncode}: {done.stderr}")
    return done.stdout.splitlines()


def check_round_trips(binary: str, types: dict) -> None:
    cases = [("scan", c) for c in SCAN_CASES] + [("diagnostics", c) for c in DIAGNOSTICS_CASES]
    encoded = [types[name].encode(values) for name, values in cases]
    answers = run(binary, [f"{name} {data.hex()}\n" for (name, _), data in zip(cases, encoded)])
    for (name, values), data, answer in zip(cases, encoded, answers + [""] * len(cases)):
        words = answer.split(" ")
        if words[0] != "ok" or len(words) != 3:
            fail(f"{binary}: {name} {values}: {answer!r}")
            continue
        ctype = types[name]
        expected = integers(ctype.fields, ctype.decode(data))
        if json.loads(words[1]) != expected:
            fail(f"{binary}: {name}: C++ decoded {words[1]}, Python {expected}")
        if words[2] != data.hex():
            fail(f"{binary}: {name}: C++ encoded {words[2]}, Python {data.hex()}")
        try:
            same = ctype.decode(bytes.fromhex(words[2])) == ctype.decode(data)
        except cosmic.InvalidError as e:
            same = False
            fail(f"{binary}: {name}: Python refuses C++'s bytes: {e}")
        if not same:
            fail(f"{binary}: {name}: Python does not decode C++'s bytes to the same values")


def check_malformed(binary: str, types: dict) -> None:
    scan = types["scan"].encode(SCAN_CASES[1])
    over = bytearray(scan)
    struct.pack_into("<I", over, 45 + 4, 4)  # ranges' count (after 45 bytes of scalars and label ""): 4 > 3
    bad_bool = bytes([2]) + scan[1:]
    diagnostics = types["diagnostics"].encode(DIAGNOSTICS_CASES[0])
    cases = {
        "scan short": (f"scan {scan[:-1].hex()}\n", "refused short_event class"),
        "scan empty": ("scan -\n", "refused short_event flag"),
        "scan over bound": (f"scan {bytes(over).hex()}\n", "refused over_bound ranges"),
        "scan bad bool": (f"scan {bad_bool.hex()}\n", "refused bad_bool flag"),
        "scan trailing": (f"scan {scan.hex()}00\n", "refused trailing_bytes -"),
        "diagnostics short": (f"diagnostics {diagnostics[:-1].hex()}\n", "refused short_event Ignition"),
    }
    answers = run(binary, [line for line, _ in cases.values()])
    for (what, (_, expected)), answer in zip(cases.items(), answers + [""] * len(cases)):
        if answer != expected:
            fail(f"{binary}: {what}: {answer!r}, expected {expected!r}")


def check_refusals(binary: str) -> None:
    answers = dict(line.split(" ", 1) for line in run(binary, [], "refusals"))
    if answers != EXPECTED_REFUSALS:
        fail(f"{binary}: encode refusals {answers}, expected {EXPECTED_REFUSALS}")


def main() -> int:
    config, binaries = sys.argv[1], sys.argv[2:]
    types = {name: cosmic.load_channel(config, name).type for name in ("scan", "diagnostics")}
    for binary in binaries:
        check_round_trips(binary, types)
        check_malformed(binary, types)
        check_refusals(binary)
    print(f"typed_roundtrip: {len(binaries)} build(s), {len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

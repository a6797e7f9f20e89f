#!/usr/bin/env python3
"""The gateway's LCM representation against lcm-gen's generated code, an implementation we did not write.

  lcm_gen_test.py PEER C_COMPILER SOURCE_DIR

PEER is cosmic-lcm-encoding-peer (tests/peers/lcm_encoding_peer.cpp), which answers JSON requests with
cosmic::LcmRepresentation for crosscheck.sample_t of SOURCE_DIR/cross_types.lcm (every primitive,
strings, fixed and variable dimensions, nested structs, a 2-D array with one variable dimension).
lcm-gen -c and -p write their code for that file into a scratch directory; the C code is built with
C_COMPILER and liblcm-dev's headers together with lcm_gen_check.c. Then:
  1. two known values (written out in lcm_gen_check.c and below), encoded by the generated C code:
     cosmic reads each message as exactly those values; cosmic writes those values as exactly the C
     code's bytes, which its decode() reads back as the same values; the generated Python code
     writes the same bytes too;
  2. random values (fixed seed) encoded by the generated Python code: cosmic reads the values, and
     writes them back as the same bytes, which the Python code decodes to the same values;
  3. a message cut short, one with a byte too many and one of another fingerprint are refused.
The generated Python code needs nothing beyond the standard library (Debian has no python3-lcm).
Exit status 0 when everything agrees; otherwise each disagreement is printed.
"""
import json
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile

SEED = 20261130
RANDOM_MESSAGES = 300
MAX_LENGTH = {"ranges": 8, "grid": 4, "columns": 8, "path": 3, "words": 4}

# The values lcm_gen_check.c's known() gives, as cosmic's JSON shows them.
KNOWN = [
    {"timestamp": -0x0123456789ABCDEF, "small": -128, "flag": True, "name": "gateway", "fixed": [1, -2, 32767],
     "num": 3, "ranges": [1.5, -0.25, 65504.0],
     "points": [{"id": 7, "label": "a", "xy": [0.5, -1.0]}, {"id": -8, "label": "", "xy": [1e300, -2.5]}],
     "rows": 2, "grid": [[1, 2, 3], [250, 251, 255]], "columns": [[0.125, 2.0, -3.5], [4.0, 5.5, -6.75]],
     "n_path": 1, "path": [{"id": 42, "label": "node", "xy": [9.0, 10.0]}], "tags": ["x", "yz"],
     "n_words": 2, "words": ["hello", "world!"], "flags": [False, True]},
    {"timestamp": 0x7FFFFFFFFFFFFFFF, "small": 127, "flag": False, "name": "", "fixed": [0, 0, -32768],
     "num": 0, "ranges": [],
     "points": [{"id": 0, "label": "", "xy": [0.0, 0.0]}, {"id": 0, "label": "", "xy": [0.0, 0.0]}],
     "rows": 0, "grid": [], "columns": [[], []], "n_path": 0, "path": [], "tags": ["", ""],
     "n_words": 0, "words": [], "flags": [True, True]},
]


class Peer:
    def __init__(self, path, lcm_file):
        bounds = ["%s=%d" % item for item in sorted(MAX_LENGTH.items())]
        self.process = subprocess.Popen([path, lcm_file, "crosscheck.sample_t"] + bounds, stdin=subprocess.PIPE,
                                        stdout=subprocess.PIPE, text=True)

    def ask(self, request):
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            sys.exit("cosmic-lcm-encoding-peer ended (exit %s)" % self.process.wait())
        return json.loads(line)

    def close(self):
        self.process.stdin.close()
        return self.process.wait(timeout=30)


def generate(work, source_dir, compiler):
    """lcm-gen's C and Python code for cross_types.lcm in `work`, and lcm_gen_check built on the C code."""
    lcm_file = os.path.join(source_dir, "cross_types.lcm")
    subprocess.run(["lcm-gen", "-c", "--c-cpath", work, "--c-hpath", work, lcm_file], check=True, cwd=work,
                   stdout=subprocess.DEVNULL)
    subprocess.run(["lcm-gen", "-p", "--ppath", work, lcm_file], check=True, cwd=work, stdout=subprocess.DEVNULL)
    flags = subprocess.run(["pkg-config", "--cflags", "--libs", "lcm"], check=True, capture_output=True,
                           text=True).stdout.split()
    sources = [os.path.join(work, f) for f in os.listdir(work) if f.endswith(".c")]
    program = os.path.join(work, "lcm_gen_check")
    subprocess.run([compiler, "-std=gnu11", "-O1", "-I", work, os.path.join(source_dir, "lcm_gen_check.c")] + sources +
                   ["-o", program] + flags, check=True)
    sys.path.insert(0, work)
    return program


def to_python(module, values):
    """The values as an object of lcm-gen's Python class."""
    sample, point = module.sample_t(), module.point_t()
    for name in sample.__slots__:
        setattr(sample, name, values[name])
    for name in ("points", "path"):
        objects = []
        for p in values[name]:
            o = type(point)()
            o.id, o.label, o.xy = p["id"], p["label"], list(p["xy"])
            objects.append(o)
        setattr(sample, name, objects)
    sample.grid = [bytes(row) for row in values["grid"]]
    return sample


def from_python(sample):
    """lcm-gen's Python object as the values, shown as cosmic's JSON shows them."""
    values = {name: getattr(sample, name) for name in sample.__slots__}
    for name in ("fixed", "ranges", "tags", "words"):
        values[name] = list(values[name])
    values["flags"] = [bool(f) for f in values["flags"]]
    values["grid"] = [list(row) for row in values["grid"]]
    values["columns"] = [list(c) for c in values["columns"]]
    for name in ("points", "path"):
        values[name] = [{"id": p.id, "label": p.label, "xy": list(p.xy)} for p in values[name]]
    return values


def float32(value):
    return struct.unpack(">f", struct.pack(">f", value))[0]


def random_text(rng, longest):
    return "".join(chr(rng.randrange(0x20, 0x7F)) for _ in range(rng.randrange(longest + 1)))


def random_point(rng):
    return {"id": rng.randrange(-32768, 32768), "label": random_text(rng, 12),
            "xy": [rng.uniform(-1e6, 1e6), rng.choice([0.0, -0.0, 1e-300, rng.random()])]}


def random_values(rng):
    num, rows = rng.randrange(MAX_LENGTH["ranges"] + 1), rng.randrange(MAX_LENGTH["grid"] + 1)
    n_path, n_words = rng.randrange(MAX_LENGTH["path"] + 1), rng.randrange(MAX_LENGTH["words"] + 1)
    return {
        "timestamp": rng.randrange(-2**63, 2**63), "small": rng.randrange(-128, 128), "flag": rng.random() < 0.5,
        "name": random_text(rng, 40), "fixed": [rng.randrange(-32768, 32768) for _ in range(3)],
        "num": num, "ranges": [float32(rng.uniform(-1e30, 1e30)) for _ in range(num)],
        "points": [random_point(rng) for _ in range(2)], "rows": rows,
        "grid": [[rng.randrange(256) for _ in range(3)] for _ in range(rows)],
        "columns": [[rng.uniform(-1e300, 1e300) for _ in range(num)] for _ in range(2)],
        "n_path": n_path, "path": [random_point(rng) for _ in range(n_path)],
        "tags": [random_text(rng, 5) for _ in range(2)], "n_words": n_words,
        "words": [random_text(rng, 20) for _ in range(n_words)], "flags": [rng.random() < 0.5 for _ in range(2)],
    }


def check_known(peer, program, module, problems):
    for n, values in enumerate(KNOWN):
        c_hex = subprocess.run([program, "encode", str(n)], check=True, capture_output=True, text=True).stdout.strip()
        if to_python(module, values).encode().hex() != c_hex:
            problems.append("known value %d: lcm-gen's C and Python code write different bytes" % n)
        decoded = peer.ask({"decode": c_hex})
        if decoded.get("event") != values:
            problems.append("known value %d: cosmic read the C code's message as %s" % (n, decoded))
        encoded = peer.ask({"encode": values})
        if encoded.get("data") != c_hex:
            problems.append("known value %d: cosmic wrote %s, the C code %s" % (n, encoded, c_hex))
            continue
        checked = subprocess.run([program, "check", str(n), encoded["data"]], capture_output=True, text=True)
        if checked.returncode != 0:
            problems.append("known value %d: %s" % (n, checked.stdout.strip() or checked.stderr.strip()))


def check_random(peer, module, problems):
    rng = random.Random(SEED)
    for i in range(RANDOM_MESSAGES):
        values = random_values(rng)
        message = to_python(module, values).encode()
        decoded = peer.ask({"decode": message.hex()})
        if decoded.get("event") != values:
            problems.append("random message %d: cosmic read %s as %s" % (i, values, decoded))
            continue
        encoded = peer.ask({"encode": values})
        if encoded.get("data") != message.hex():
            problems.append("random message %d: cosmic wrote %s, lcm-gen's Python code %s" % (i, encoded, message.hex()))
            continue
        back = from_python(module.sample_t.decode(bytes.fromhex(encoded["data"])))
        if back != values:
            problems.append("random message %d: lcm-gen's Python code read cosmic's bytes as %s" % (i, back))


def check_refusals(peer, module, problems):
    message = to_python(module, KNOWN[0]).encode()
    another = bytearray(message)
    another[0] ^= 0x80
    for name, data in (("cut short", message[:-1]), ("a byte too many", message + b"\0"),
                       ("another fingerprint", bytes(another))):
        answer = peer.ask({"decode": data.hex()})
        if answer.get("error") != "malformed":
            problems.append("a message %s: cosmic answered %s, not malformed" % (name, answer))


def main():
    if len(sys.argv) != 4:
        sys.exit("usage: lcm_gen_test.py PEER C_COMPILER SOURCE_DIR")
    peer_path, compiler, source_dir = os.path.abspath(sys.argv[1]), sys.argv[2], os.path.abspath(sys.argv[3])
    if shutil.which("lcm-gen") is None:
        sys.exit("lcm-gen not found (scripts/setup installs liblcm-bin)")
    problems = []
    with tempfile.TemporaryDirectory(prefix="lcm_gen_test.") as work:
        program = generate(work, source_dir, compiler)
        import crosscheck  # noqa: E402 (generated above; its __init__ names the classes)
        peer = Peer(peer_path, os.path.join(source_dir, "cross_types.lcm"))
        describe = peer.ask({"fingerprint": True})
        theirs = "0x%016x" % int.from_bytes(crosscheck.sample_t._get_packed_fingerprint(), "big")
        if describe != {"fingerprint": theirs, "describe": "LCM crosscheck.sample_t"}:
            problems.append("cosmic: %s, lcm-gen's fingerprint %s" % (describe, theirs))
        check_known(peer, program, crosscheck, problems)
        check_random(peer, crosscheck, problems)
        check_refusals(peer, crosscheck, problems)
        if peer.close() != 0:
            problems.append("cosmic-lcm-encoding-peer did not exit 0")
    for p in problems[:20]:
        print("FAIL:", p)
    if problems:
        sys.exit("%d disagreements between cosmic's LCM representation and lcm-gen's code" % len(problems))
    print("cosmic's LCM representation agrees with lcm-gen's C and Python code: %d known values, %d random "
          "messages, 3 refusals" % (len(KNOWN), RANDOM_MESSAGES))


if __name__ == "__main__":
    main()

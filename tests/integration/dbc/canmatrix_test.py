#!/usr/bin/env python3
"""The gateway's DBC reader and codec against python3-canmatrix, an implementation we did not write.

  canmatrix_test.py PEER DBC_FILE

PEER is cosmic-dbc-codec-peer (tests/peers/dbc_codec_peer.cpp), which answers JSON requests with
cosmic's codec. For every message of DBC_FILE (Intel and Motorola, signed, scaled, IEEE float,
multiplexed, 64-bit, a 64-byte CAN FD frame), with a fixed seed:
  1. frames of random bytes decoded by both: the same signals present, the same physical values;
  2. random raw values of every signal (for a multiplexed message, one switch value a frame):
     packed by canmatrix (its Frame.encode takes raw values), decoded by cosmic to the physical
     values; the physical values packed by cosmic (which rounds to the nearest raw value) to the same
     bytes, decoded by canmatrix to the same values.
  3. the same through a typed channel's representations: a frame to the compact layout to JSON
     gives canmatrix's physical values (an enumeration the identifier of canmatrix's value name,
     by the rule of docs/yaml-reference.md), and fields packed through the compact layout give
     canmatrix's bytes.
Exit status 0 when everything agrees; otherwise each disagreement is printed.
"""
import json
import math
import random
import struct
import subprocess
import sys

import canmatrix.formats

FRAMES_PER_MESSAGE = 300
SEED = 20261129


class Peer:
    def __init__(self, path, dbc):
        self.process = subprocess.Popen([path, dbc], stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)

    def ask(self, request):
        self.process.stdin.write(json.dumps(request) + "\n")
        self.process.stdin.flush()
        line = self.process.stdout.readline()
        if not line:
            sys.exit("cosmic-dbc-codec-peer ended (exit %s)" % self.process.wait())
        return json.loads(line)

    def close(self):
        self.process.stdin.close()
        return self.process.wait(timeout=30)


def physical(value):
    """canmatrix's Decimal or float as a float; None (cosmic's JSON for NaN and infinities) as NaN."""
    return float("nan") if value is None else float(value)


def same(a, b):
    a, b = physical(a), physical(b)
    if math.isnan(a) or math.isnan(b) or math.isinf(a) or math.isinf(b):
        # JSON carries neither NaN nor infinity: cosmic's peer writes null for both.
        return (math.isnan(a) or math.isinf(a)) and (math.isnan(b) or math.isinf(b))
    return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-9)


def canmatrix_values(frame, data):
    return {name: decoded.phys_value for name, decoded in frame.decode(bytearray(data)).items()}


def raw_range(signal):
    size = int(signal.size)
    if signal.is_signed:
        return -(1 << (size - 1)), (1 << (size - 1)) - 1
    return 0, (1 << size) - 1


def random_values(rng, frame):
    """Raw and physical values of one frame's worth of signals (canmatrix's Frame.encode takes raw
    values, cosmic's peer physical ones); a multiplexed message picks its switch value."""
    selector = next((s for s in frame.signals if s.is_multiplexer), None)
    chosen = None
    if selector is not None:
        choices = sorted({int(s.mux_val) for s in frame.signals if s.mux_val is not None})
        chosen = rng.choice(choices)
    raws, values = {}, {}
    for s in frame.signals:
        if s.mux_val is not None and int(s.mux_val) != chosen:
            continue
        if s is selector:
            raw = chosen
        elif s.is_float:
            raw = rng.uniform(-1e6, 1e6)
            if int(s.size) == 32:  # a value a float holds exactly
                raw = struct.unpack("<f", struct.pack("<f", raw))[0]
        else:
            low, high = raw_range(s)
            # Exact in a double: at most 53 bits of raw value (wider signals: their top and bottom).
            if high - low >= 1 << 53:
                raw = rng.choice([0, rng.randrange(-(1 << 52) if s.is_signed else 0, 1 << 52)])
            else:
                raw = rng.randint(low, high)
        raws[s.name] = raw
        values[s.name] = raw * float(s.factor) + float(s.offset)
    return raws, values


def value_identifier(description, value):
    """cosmic::dbc_value_identifier, written again from its documentation."""
    name = ""
    for c in description:
        if c.isascii() and c.isalnum():
            name += c
        elif name and not name.endswith("_"):
            name += "_"
    name = name.rstrip("_")
    if not name:
        return "v%d" % abs(value)
    if not name[0].isalpha():
        name = "v" + name
    return name[:64].rstrip("_")


def whole(number):
    return float(number) == int(number)


def typed_fields(frame, raws):
    """The fields a typed channel's event holds for these raw values: an enumeration or a bool its
    raw value, an integer field raw * factor + offset in whole numbers, a float field its physical value."""
    fields = {}
    for s in frame.signals:
        if s.name not in raws:
            continue
        raw = raws[s.name]
        if s.values or s.is_float:
            fields[s.name] = raw
        elif whole(s.factor) and whole(s.offset):
            fields[s.name] = raw * int(s.factor) + int(s.offset)
        else:
            fields[s.name] = raw * float(s.factor) + float(s.offset)
    return fields


def check_typed(peer, frame, data, raws, problems):
    name = frame.name
    decoded = frame.decode(bytearray(data))
    event = peer.ask({"json": name, "data": data.hex()})
    if "error" in event:
        problems.append("%s %s: no JSON event: %s" % (name, data.hex(), event["error"]))
        return
    event = event["json"]
    if set(event) != set(decoded):
        problems.append("%s %s: JSON has %s, canmatrix %s" % (name, data.hex(), sorted(event), sorted(decoded)))
        return
    for signal_name, signal_value in decoded.items():
        ours, signal = event[signal_name], signal_value.signal
        if isinstance(ours, str):
            expected = value_identifier(signal.values.get(int(signal_value.raw_value), ""), int(signal_value.raw_value))
            if ours != expected:
                problems.append("%s %s: %s JSON %r, canmatrix names %r" % (name, data.hex(), signal_name, ours, expected))
        elif isinstance(ours, bool) or signal.values:
            if int(ours) != int(signal_value.raw_value):
                problems.append("%s %s: %s JSON %r, canmatrix raw %r" % (name, data.hex(), signal_name, ours,
                                                                         signal_value.raw_value))
        elif not same(ours, signal_value.phys_value):
            problems.append("%s %s: %s JSON %r, canmatrix %r" % (name, data.hex(), signal_name, ours,
                                                                 signal_value.phys_value))
    packed = peer.ask({"pack": name, "fields": typed_fields(frame, raws)})
    expected = bytes(frame.encode(raws)).hex()
    if packed.get("data") != expected:
        problems.append("%s %r: the typed path packs %s, canmatrix %s" % (name, raws, packed, expected))


def check_message(peer, frame, rng, problems):
    name = frame.name
    length = int(frame.size)
    # 1. Random frames, decoded by both.
    for _ in range(FRAMES_PER_MESSAGE):
        data = bytes(rng.getrandbits(8) for _ in range(length))
        theirs = canmatrix_values(frame, data)
        ours = peer.ask({"decode": name, "data": data.hex()})["values"]
        if set(theirs) != set(ours):
            problems.append("%s %s: canmatrix decodes %s, cosmic %s" % (name, data.hex(), sorted(theirs), sorted(ours)))
            continue
        for signal, value in theirs.items():
            if not same(value, ours[signal]):
                problems.append("%s %s: %s canmatrix %r, cosmic %r" % (name, data.hex(), signal, value, ours[signal]))
    # 2. Random values, packed by each and decoded by the other.
    for _ in range(FRAMES_PER_MESSAGE):
        raws, values = random_values(rng, frame)
        packed_by_canmatrix = bytes(frame.encode(raws))
        answer = peer.ask({"encode": name, "values": values})
        if "error" in answer:
            problems.append("%s: cosmic cannot pack %r: %s" % (name, values, answer["error"]))
            continue
        packed_by_cosmic = bytes.fromhex(answer["data"])
        if packed_by_cosmic != packed_by_canmatrix:
            problems.append("%s %r: cosmic packs %s, canmatrix %s" % (name, values, packed_by_cosmic.hex(),
                                                                      packed_by_canmatrix.hex()))
        check_typed(peer, frame, packed_by_canmatrix, raws, problems)
        decoded_by_cosmic = peer.ask({"decode": name, "data": packed_by_canmatrix.hex()})["values"]
        decoded_by_canmatrix = canmatrix_values(frame, packed_by_cosmic)
        for signal, value in values.items():
            if not same(value, decoded_by_cosmic.get(signal)):
                problems.append("%s: %s packed by canmatrix as %r, cosmic reads %r" % (name, signal, value,
                                                                                      decoded_by_cosmic.get(signal)))
            if not same(value, decoded_by_canmatrix.get(signal)):
                problems.append("%s: %s packed by cosmic as %r, canmatrix reads %r" % (name, signal, value,
                                                                                      decoded_by_canmatrix.get(signal)))


def main():
    peer_path, dbc = sys.argv[1], sys.argv[2]
    matrix = canmatrix.formats.loadp_flat(dbc)
    rng = random.Random(SEED)
    peer = Peer(peer_path, dbc)
    problems = []
    names = []
    for frame in matrix.frames:
        names.append(frame.name)
        check_message(peer, frame, rng, problems)
    status = peer.close()
    if status != 0:
        problems.append("cosmic-dbc-codec-peer exited %d" % status)
    for p in problems[:40]:
        print("DISAGREE:", p)
    if problems:
        sys.exit("%d disagreements between cosmic and canmatrix" % len(problems))
    print("cosmic and canmatrix agree on %d messages (%s), %d frames each way" % (
        len(names), ", ".join(names), FRAMES_PER_MESSAGE))


if __name__ == "__main__":
    main()

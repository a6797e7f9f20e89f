#!/usr/bin/env python3
"""CAN frame helpers for the end-to-end test, written from docs/can-wire-format.md alone.

    canlog.py id PRIO NODE ETAG                 29-bit identifier (section 1), 8 hex digits
    canlog.py payload KIND SIZE [K]             test payload as hex:
                                                  lcm K: byte i = (K*31 + i) & 0xff (cosmic-lcm-peer)
                                                  dds K: byte i = (K + i) & 0xff    (cosmic-dds-peer)
                                                  dev K: byte i = (K*7 + 3*i) & 0xff (our CAN device)
    canlog.py fragment ID SEQ HEX [IFACE]       canplayer log of one event as classic fragments
                                                (section 6, sender rules)
    canlog.py frames LOG [ID]                   "ID DATA" per data frame of a candump -L log
                                                (optionally only identifier ID; 11-bit frames and
                                                the test's sync marker are skipped)
    canlog.py reassemble LOG ID FIRST_SEQ       checks that the frames of ID in LOG follow the
                                                classic-CAN sender rules of section 6 strictly and
                                                prints each event's bytes as hex, one per line
    canlog.py pass-filter LOG ETAG[,ETAG...]    number of frames in LOG that a receive filter on
                                                these etags (29-bit data or remote frames) passes
"""
import re
import sys

LINE = re.compile(r"^\((?P<ts>[0-9.]+)\)\s+(?P<ifc>\S+)\s+(?P<id>[0-9A-Fa-f]+)#(?P<rest>.*)$")
CLASSIC_FRAGMENT_DATA = 6


def die(msg):
    print("canlog.py: " + msg, file=sys.stderr)
    sys.exit(1)


def can_id(prio, node, etag):
    assert 0 <= prio <= 0xFF and 0 <= node <= 0x7F and 0 <= etag <= 0x3FFF
    return (prio << 21) | (node << 14) | etag


def payload(kind, size, k):
    if kind == "lcm":
        return bytes((k * 31 + i) & 0xFF for i in range(size))
    if kind == "dds":
        return bytes((k + i) & 0xFF for i in range(size))
    if kind == "dev":
        return bytes((k * 7 + 3 * i) & 0xFF for i in range(size))
    die("unknown payload kind " + kind)
    return b""


def fragments(data, seq):
    """Section 6: 2-byte header (seq << 12 | last << 11 | index), then up to 6 bytes."""
    chunks = [data[i:i + CLASSIC_FRAGMENT_DATA] for i in range(0, len(data), CLASSIC_FRAGMENT_DATA)] or [b""]
    out = []
    for index, chunk in enumerate(chunks):
        last = index == len(chunks) - 1
        header = ((seq & 0xF) << 12) | (0x800 if last else 0) | index
        out.append(header.to_bytes(2, "big") + chunk)
    return out


def read_frames(path):
    """Data and remote frames of a candump -L log: (id, is_eff, is_rtr, is_fd, data)."""
    frames = []
    with open(path, encoding="ascii", errors="replace") as f:
        for line in f:
            m = LINE.match(line.strip())
            if not m:
                continue
            ident = m.group("id")
            rest = m.group("rest")
            eff = len(ident) == 8
            value = int(ident, 16)
            if rest.startswith("R"):
                frames.append((value, eff, True, False, b""))
            elif rest.startswith("#"):  # CAN FD: ##<flags nibble><data>
                frames.append((value, eff, False, True, bytes.fromhex(rest[2:])))
            else:
                frames.append((value, eff, False, False, bytes.fromhex(rest)))
    return frames


def cmd_frames(path, ident=None):
    for value, eff, rtr, fd, data in read_frames(path):
        if not eff:
            continue
        if ident is not None and value != ident:
            continue
        print("%08X %s%s" % (value, "R" if rtr else "", data.hex().upper()))


def cmd_reassemble(path, ident, first_seq):
    frames = [(data, rtr, fd) for value, eff, rtr, fd, data in read_frames(path) if eff and value == ident]
    if not frames:
        die("no frame with identifier %08X" % ident)
    seq = first_seq & 0xF
    expect_index = 0
    event = bytearray()
    for n, (data, rtr, fd) in enumerate(frames):
        where = "frame %d of %08X (%s)" % (n, ident, data.hex().upper())
        if rtr or fd:
            die(where + ": remote or FD frame on a classic fragmented channel")
        if len(data) < 2:
            die(where + ": shorter than the 2-byte fragment header")
        header = int.from_bytes(data[:2], "big")
        f_seq, f_last, f_index = header >> 12, bool(header & 0x800), header & 0x7FF
        body = data[2:]
        if f_seq != seq:
            die(where + ": sequence %d, expected %d" % (f_seq, seq))
        if f_index != expect_index:
            die(where + ": index %d, expected %d" % (f_index, expect_index))
        if not f_last and len(body) != CLASSIC_FRAGMENT_DATA:
            die(where + ": a fragment before the last must carry %d bytes" % CLASSIC_FRAGMENT_DATA)
        event += body
        if f_last:
            print(event.hex())
            event = bytearray()
            expect_index = 0
            seq = (seq + 1) & 0xF
        else:
            expect_index += 1
    if expect_index != 0:
        die("the last event of %08X is incomplete (%d fragments, no last bit)" % (ident, expect_index))


def cmd_pass_filter(path, etags):
    wanted = {int(e, 0) for e in etags.split(",")}
    print(sum(1 for value, eff, rtr, fd, data in read_frames(path) if eff and not fd and (value & 0x3FFF) in wanted))


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 64
    cmd, args = argv[1], argv[2:]
    if cmd == "id" and len(args) == 3:
        print("%08X" % can_id(*(int(a, 0) for a in args)))
    elif cmd == "payload" and len(args) in (2, 3):
        print(payload(args[0], int(args[1], 0), int(args[2], 0) if len(args) == 3 else 1).hex())
    elif cmd == "fragment" and len(args) in (3, 4):
        ident, seq, data = int(args[0], 16), int(args[1], 0), bytes.fromhex(args[2])
        iface = args[3] if len(args) == 4 else "vcan0"
        for n, frame in enumerate(fragments(data, seq)):
            print("(%d.%06d) %s %08X#%s" % (n // 1000, (n % 1000) * 1000, iface, ident, frame.hex().upper()))
    elif cmd == "frames" and len(args) in (1, 2):
        cmd_frames(args[0], int(args[1], 16) if len(args) == 2 else None)
    elif cmd == "reassemble" and len(args) == 3:
        cmd_reassemble(args[0], int(args[1], 16), int(args[2], 0))
    elif cmd == "pass-filter" and len(args) == 2:
        cmd_pass_filter(args[0], args[1])
    else:
        print(__doc__, file=sys.stderr)
        return 64
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

"""CAN frame helpers of the end-to-end test, written from docs/can-wire-format.md alone.

As a module: can_id, payload, fragments, fragment_lines (canplayer input), read_frames (candump -L
output), reassemble (the classic-CAN sender rules of section 6, strictly). As a command, for
poking at the bus by hand:

    python3 canlog.py id PRIO NODE ETAG            the 29-bit identifier, 8 hex digits
    python3 canlog.py fragment ID SEQ HEX          canplayer input for one fragmented event
    python3 canlog.py reassemble LOG ID SEQ        events of ID in a candump -L log, as hex
"""
import collections
import re
import sys

CLASSIC_FRAGMENT_DATA = 6  # event bytes per classic fragment (8 - 2 header bytes)
FD_FRAGMENT_DATA = 62      # event bytes per CAN FD fragment (64 - 2 header bytes)
# One frame of a candump -L log; fd_flags is None for a classic frame, else the FD flags nibble
# (BRS = 1, ESI = 2, FDF = 4 on newer kernels).
Frame = collections.namedtuple("Frame", "id eff rtr fd_flags data")
_LINE = re.compile(r"^\((?P<ts>[0-9.]+)\)\s+(?P<ifc>\S+)\s+(?P<id>[0-9A-Fa-f]+)#(?P<rest>.*)$")


def can_id(prio, node, etag):
    """Section 1: priority (8 bits) | TxNode (7 bits) | etag (14 bits)."""
    if not (0 <= prio <= 0xFF and 0 <= node <= 0x7F and 0 <= etag <= 0x3FFF):
        raise ValueError("field out of range: priority %r, TxNode %r, etag %r" % (prio, node, etag))
    return (prio << 21) | (node << 14) | etag


def payload(kind, size, k=1):
    """Test payloads: lcm = cosmic-lcm-peer's message k, dds = cosmic-dds-peer's event k, dev = ours."""
    if kind == "lcm":
        return bytes((k * 31 + i) & 0xFF for i in range(size))
    if kind == "dds":
        return bytes((k + i) & 0xFF for i in range(size))
    if kind == "dev":
        return bytes((k * 7 + 3 * i) & 0xFF for i in range(size))
    raise ValueError("unknown payload kind " + kind)


def fragments(data, seq):
    """Section 6: big-endian header sequence (4 bits) | last (1) | index (11), then up to 6 bytes;
    every fragment full but the last; an empty event is one header-only fragment."""
    chunks = [data[i:i + CLASSIC_FRAGMENT_DATA] for i in range(0, len(data), CLASSIC_FRAGMENT_DATA)] or [b""]
    out = []
    for index, chunk in enumerate(chunks):
        header = ((seq & 0xF) << 12) | (0x800 if index == len(chunks) - 1 else 0) | index
        out.append(header.to_bytes(2, "big") + chunk)
    return out


def fragment_lines(ident, seq, data, iface="vcan0"):
    """canplayer input (candump -L format) sending one event as fragments on identifier IDENT."""
    return ["(%d.%06d) %s %08X#%s" % (n // 1000, (n % 1000) * 1000, iface, ident, f.hex().upper())
            for n, f in enumerate(fragments(data, seq))]


def read_frames(path):
    """Frames of a candump -L log (Frame tuples), in order."""
    frames = []
    try:
        f = open(path, encoding="ascii", errors="replace")
    except FileNotFoundError:
        return frames
    with f:
        for line in f:
            m = _LINE.match(line.strip())
            if not m:
                continue
            ident, rest = m.group("id"), m.group("rest")
            value, eff = int(ident, 16), len(ident) == 8
            try:
                if rest.startswith("R"):
                    frames.append(Frame(value, eff, True, None, b""))
                elif rest.startswith("#"):  # CAN FD: ##<flags nibble><data>
                    frames.append(Frame(value, eff, False, int(rest[1], 16), bytes.fromhex(rest[2:])))
                else:
                    frames.append(Frame(value, eff, False, None, bytes.fromhex(rest)))
            except (ValueError, IndexError):
                pass  # a line still being written
    return frames


def reassemble(datas, first_seq, fragment_data=CLASSIC_FRAGMENT_DATA):
    """Events carried by consecutive fragments (the data of each frame, in order; classic, or CAN FD
    with fragment_data=FD_FRAGMENT_DATA), checked against the sender rules of section 6: sequences
    first_seq, first_seq + 1, ... (mod 16), indexes 0, 1, ... with the last bit on the final one,
    all but the last fragment full. On CAN FD the last fragment's padding stays on the event (the
    receiver cuts it at the channel's payload). Raises ValueError naming the first violation."""
    seq, expect_index, event, events = first_seq & 0xF, 0, bytearray(), []
    for n, data in enumerate(datas):
        where = "fragment %d (%s)" % (n, data.hex().upper())
        if len(data) < 2:
            raise ValueError(where + ": shorter than the 2-byte header")
        header = int.from_bytes(data[:2], "big")
        f_seq, last, index, body = header >> 12, bool(header & 0x800), header & 0x7FF, data[2:]
        if f_seq != seq:
            raise ValueError(where + ": sequence %d, expected %d" % (f_seq, seq))
        if index != expect_index:
            raise ValueError(where + ": index %d, expected %d" % (index, expect_index))
        if not last and len(body) != fragment_data:
            raise ValueError(where + ": a fragment before the last carries %d bytes, not %d"
                             % (len(body), fragment_data))
        event += body
        if last:
            events.append(bytes(event))
            seq, expect_index, event = (seq + 1) & 0xF, 0, bytearray()
        else:
            expect_index += 1
    if expect_index:
        raise ValueError("the last event is incomplete (%d fragments, no last bit)" % expect_index)
    return events


def main(argv):
    cmd, args = (argv[1], argv[2:]) if len(argv) > 1 else ("", [])
    if cmd == "id" and len(args) == 3:
        print("%08X" % can_id(*(int(a, 0) for a in args)))
    elif cmd == "fragment" and len(args) == 3:
        print("\n".join(fragment_lines(int(args[0], 16), int(args[1], 0), bytes.fromhex(args[2]))))
    elif cmd == "reassemble" and len(args) == 3:
        ident = int(args[1], 16)
        datas = [f.data for f in read_frames(args[0]) if f.eff and f.id == ident]
        for event in reassemble(datas, int(args[2], 0)):
            print(event.hex())
    else:
        print(__doc__, file=sys.stderr)
        return 64
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

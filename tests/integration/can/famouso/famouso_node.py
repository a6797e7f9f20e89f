"""A FAMOUSO-behaving CAN node, written from FAMOUSO's sources (steup/FAMOUSO: canID_LE_PC.h,
canETAGS.h, ccp/Client.h, etagBP/Client.h, anl/AbstractNetworkLayer.h, afp/), independently of
cosmicd's code: its identifier layout, the CCP client, the etag-4 binding client and AFP on CAN
(basic header only, in order). Python's AF_CAN sockets, classic frames only."""
import socket
import struct
import time

CCP_SSI, CCP_RSI, GET_ETAG, SUPPLY_ETAG, SUPPLY_ETAG_NEW_BP = range(5)
BROKER_NODE = 0x7F
PRIO = 0xFD                      # everything a FAMOUSO node sends: prio(0xfd)
SUBSCRIBE = b"SUBSCRIB"          # Subject("SUBSCRIBE"): the first 8 characters
EFF = socket.CAN_EFF_FLAG


def famouso_id(prio, fragment, node, etag):
    """canID_LE_PC.h: etag 14 | tx_node 7 | fragment 1 | prio lo 2 | prio hi 5 (the setter keeps
    p & 3 and p >> 2, so only 7 bits of the priority survive)."""
    return ((prio & 0x7F) << 22) | (int(bool(fragment)) << 21) | ((node & 0x7F) << 14) | (etag & 0x3FFF)


def split_id(ident):
    return {"prio": (ident >> 22) & 0x7F, "fragment": bool((ident >> 21) & 1), "node": (ident >> 14) & 0x7F,
            "etag": ident & 0x3FFF}


def afp_header(remaining, first):
    """AFP basic header (NoFECFragmenter::get_header): fseq = fragments still to come."""
    length = 1
    while remaining >= 1 << (7 * length - 2):
        length += 1
    out = bytearray(remaining.to_bytes(length, "big"))
    out[0] |= ((0xF8 | (1 if first else 0)) << (6 - length)) & 0xFF
    return bytes(out)


def afp_fragments(data, mtu=8):
    """Cuts like AFP: the last 32 fragments have a 1-byte header, earlier ones 2 bytes."""
    count, rest = 0, len(data)
    if rest <= 32 * (mtu - 1):
        count = -(-rest // (mtu - 1))
    else:
        count = 32 + -(-(rest - 32 * (mtu - 1)) // (mtu - 2))
    frags, pos = [], 0
    for remaining in range(count - 1, -1, -1):
        h = afp_header(remaining, pos == 0)
        take = min(mtu - len(h), len(data) - pos)
        frags.append(h + data[pos:pos + take])
        pos += take
    return frags


def parse_afp(frame):
    """(first, remaining, payload) of one fragment (defrag/Headers.h)."""
    h, length = frame[0], 1
    while h & 0x80:
        length += 1
        h = (h << 1) & 0xFF
    if h & 0x40:
        raise ValueError("extension header on CAN")
    remaining = frame[0] & (0x3F >> length)
    for b in frame[1:length]:
        remaining = (remaining << 8) | b
    return bool(h & 0x20), remaining, frame[length:]


class Node:
    def __init__(self, iface, uid):
        self.uid = uid
        self.node = None
        self.s = socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)
        self.s.bind((iface,))
        self.log = []  # every frame received: (id, data)

    def close(self):
        self.s.close()

    def send(self, ident, data=b""):
        self.s.send(struct.pack("=IB3x8s", ident | EFF, len(data), data.ljust(8, b"\0")))

    def recv(self, deadline):
        """The next 29-bit frame (id, data), or None at the deadline."""
        while True:
            left = deadline - time.monotonic()
            if left <= 0:
                return None
            self.s.settimeout(left)
            try:
                raw = self.s.recv(16)
            except socket.timeout:
                return None
            ident, dlc = struct.unpack("=IB3x", raw[:8])
            if ident & EFF and not ident & socket.CAN_RTR_FLAG:
                frame = (ident & socket.CAN_EFF_MASK, raw[8:8 + dlc])
                self.log.append(frame)
                return frame

    # --- CCP client (ccp/Client.h): one nibble of the UID per stage, 15 down to 0
    def _nibble(self, stage):
        b = self.uid[(15 - stage) >> 1]
        return b >> 4 if stage % 2 else b & 0xF

    def _matches(self, data, down_to):
        return all(self._nibble(s) == ((data[(15 - s) >> 1] >> 4) if s % 2 else (data[(15 - s) >> 1] & 0xF))
                   for s in range(15, down_to - 1, -1))

    def configure(self, timeout=60):
        deadline = time.monotonic() + timeout
        stage = 15
        while True:
            self.send((PRIO & 0x7F) << 22 | (stage << 18) | (self._nibble(stage) << 14) | CCP_RSI)
            while True:
                frame = self.recv(deadline)
                if frame is None:
                    raise TimeoutError("CCP: no TxNode after %d s (stage %d)" % (timeout, stage))
                ident, data = frame
                if ident & 0x3FFF != CCP_SSI or len(data) != 8:
                    continue
                node = split_id(ident)["node"]
                if node == BROKER_NODE:
                    if data == bytes(8):
                        stage = 15
                        break
                    if stage == data[7] & 0xF and self._matches(data, stage):
                        stage -= 1
                        break
                    continue  # an answer for a node that won arbitration: wait
                if self._matches(data, 0):
                    self.node = node
                    return node
                stage = 15
                break

    # --- etag binding client (etagBP/Client.h): asks once, waits for both halves on etag 4
    def bind(self, subject, timeout=30):
        self.request(subject)
        return self.await_etag(subject, timeout)

    def request(self, subject):
        self.send(famouso_id(PRIO, False, self.node, GET_ETAG), subject)

    def await_etag(self, subject, timeout):
        deadline = time.monotonic() + timeout
        rnd = 0
        while True:
            frame = self.recv(deadline)
            if frame is None:
                raise TimeoutError("no etag for %s after %d s" % (subject.hex(), timeout))
            ident, data = frame
            if ident & 0x3FFF != SUPPLY_ETAG_NEW_BP or len(data) < 8:
                continue
            index = data[1] << 2
            if rnd << 2 == index:
                if subject[index:index + 4] != data[4:8]:
                    rnd = 0
                    continue
                rnd += 1
            if rnd == 2:
                return ((data[2] & 0x3F) << 8) + data[3]  # etag from frame 1; byte 0 ignored

    def start(self):
        """CANNL::init + AbstractNetworkLayer::init: CCP, then bind the SUBSCRIBE subject."""
        self.configure()
        self.subscribe_etag = self.bind(SUBSCRIBE)
        return self.node

    def subscribe(self, subject):
        etag = self.bind(subject)
        self.send(famouso_id(PRIO, False, self.node, self.subscribe_etag), subject)
        return etag

    def publish(self, etag, data):
        """AbstractNetworkLayer::publish + CANNL::deliver: one frame up to 8 bytes, else AFP."""
        if len(data) <= 8:
            self.send(famouso_id(PRIO, False, self.node, etag), data)
            return 1
        frags = afp_fragments(data)
        for f in frags:
            self.send(famouso_id(PRIO, True, self.node, etag), f)
        return len(frags)

    def receive_event(self, etag, timeout=20):
        """The next event of ETAG: a plain frame, or AFP fragments reassembled in order.
        Returns (identifier of its frames, event bytes, header lengths)."""
        deadline = time.monotonic() + timeout
        buf, expect, headers = None, None, []
        while True:
            frame = self.recv(deadline)
            if frame is None:
                raise TimeoutError("no event on etag %d after %d s" % (etag, timeout))
            ident, data = frame
            if ident & 0x3FFF != etag:
                continue
            if not split_id(ident)["fragment"]:
                return ident, data, []
            first, remaining, payload = parse_afp(data)
            headers.append(len(data) - len(payload))
            if first:
                buf, headers = bytearray(payload), [len(data) - len(payload)]
            elif buf is None or remaining != expect:
                raise ValueError("AFP fragment out of order: %d, expected %r" % (remaining, expect))
            else:
                buf += payload
            expect = remaining - 1
            if remaining == 0:
                return ident, bytes(buf), headers

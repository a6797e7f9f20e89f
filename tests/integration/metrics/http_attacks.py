#!/usr/bin/env python3
"""The hostile HTTP clients of issue 22 item 3, against cosmicd's metrics endpoint.

  http_attacks.py slowloris HOST PORT COUNT SECONDS OUT
      COUNT connections each send one byte of an endless request head every 2 s for at most
      SECONDS; OUT says "open N closed M": N connected, M of them closed by the endpoint so far.
  http_attacks.py idle HOST PORT COUNT SECONDS OUT
      COUNT connections that send nothing, held for SECONDS; OUT gets "open N" once the connects
      were started and N of them completed.
  http_attacks.py range HOST PORT COUNT
      GET /metrics with a Range of COUNT times "0-"; prints "STATUS BODY_BYTES CONTENT_LENGTH
      HELP_LINES CONTENT_TYPE" (HELP_LINES: how often the document's first line occurs).
  http_attacks.py head HOST PORT BYTES [RANGE]
      GET /metrics with a head of BYTES bytes (filler fields; RANGE: a Range field to add);
      prints the status, or "closed" when the endpoint closed or reset without an answer.
"""
import os
import select
import socket
import sys
import time


def write_status(path, text):
    with open(path + ".tmp", "w") as f:
        f.write(text + "\n")
    os.replace(path + ".tmp", path)


def connect_all(host, port, count):
    socks = []
    for _ in range(count):
        s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        s.setblocking(False)
        try:
            s.connect((host, port))
        except BlockingIOError:
            pass
        socks.append(s)
    deadline = time.monotonic() + 10
    pending = set(socks)
    while pending and time.monotonic() < deadline:
        _, writable, _ = select.select([], list(pending), [], 0.2)
        pending -= set(writable)
    return socks, len(socks) - len(pending)


def slowloris(host, port, count, seconds, out):
    socks, connected = connect_all(host, port, count)
    write_status(out, f"open {connected} closed 0")
    head = b"GET /metrics HTTP/1.1\r\nHost: x\r\nX-Slow: " + b"a" * 100000
    sent = 0
    closed = set()
    end = time.monotonic() + seconds
    while time.monotonic() < end and len(closed) < len(socks):
        for s in socks:
            if s in closed:
                continue
            try:
                s.send(head[sent:sent + 1])
            except OSError:
                closed.add(s)
                continue
            readable, _, _ = select.select([s], [], [], 0)
            if readable:  # an answer (408) or the close: either way the endpoint gave up on it
                try:
                    s.recv(4096)
                except OSError:
                    pass
                closed.add(s)
        sent += 1
        write_status(out, f"open {connected} closed {len(closed)}")
        time.sleep(2)
    for s in socks:
        s.close()


def idle(host, port, count, seconds, out):
    socks, connected = connect_all(host, port, count)
    write_status(out, f"open {connected}")
    time.sleep(seconds)
    for s in socks:
        s.close()


def request(host, port, head, timeout=10):
    """Sends `head`, reads the answer until the endpoint closes or a whole response arrived."""
    s = socket.create_connection((host, port), timeout=timeout)
    data = b""
    try:
        try:
            s.sendall(head)
        except OSError:
            pass  # the endpoint may refuse before reading it all: read what it said
        while True:
            try:
                chunk = s.recv(65536)
            except OSError:
                break
            if not chunk:
                break
            data += chunk
            headers, sep, body = data.partition(b"\r\n\r\n")
            if sep:
                length = [l for l in headers.split(b"\r\n") if l.lower().startswith(b"content-length:")]
                if length and len(body) >= int(length[0].split(b":")[1]):
                    break
    finally:
        s.close()
    return data


def split_response(data):
    headers, _, body = data.partition(b"\r\n\r\n")
    lines = headers.split(b"\r\n")
    status = lines[0].split(b" ")[1].decode() if lines and len(lines[0].split(b" ")) > 1 else "closed"
    fields = {}
    for line in lines[1:]:
        name, _, value = line.partition(b":")
        fields[name.strip().lower().decode()] = value.strip().decode()
    return status, fields, body


def ranges(host, port, count):
    head = (b"GET /metrics HTTP/1.1\r\nHost: x\r\nRange: bytes=" + b",".join([b"0-"] * count) +
            b"\r\nConnection: close\r\n\r\n")
    status, fields, body = split_response(request(host, port, head))
    first = body.split(b"\n", 1)[0]
    print(status, len(body), fields.get("content-length", "-"), body.count(first) if first else 0,
          fields.get("content-type", "-").replace(" ", ""))


def big_head(host, port, size, range_field=None):
    head = b"GET /metrics HTTP/1.1\r\nHost: x\r\n"
    if range_field:
        head += b"Range: " + range_field.encode() + b"\r\n"
    n = 0
    while len(head) + 2 < size:
        field = b"X-Filler-%d: " % n
        room = size - len(head) - len(field) - 4
        head += field + b"f" * max(0, min(90, room)) + b"\r\n"
        n += 1
    head += b"\r\n"
    status, _, _ = split_response(request(host, port, head))
    print(status)


def main(argv):
    what, host, port = argv[1], argv[2], int(argv[3])
    if what == "slowloris":
        slowloris(host, port, int(argv[4]), float(argv[5]), argv[6])
    elif what == "idle":
        idle(host, port, int(argv[4]), float(argv[5]), argv[6])
    elif what == "range":
        ranges(host, port, int(argv[4]))
    elif what == "head":
        big_head(host, port, int(argv[4]), argv[5] if len(argv) > 5 else None)
    else:
        print(__doc__, file=sys.stderr)
        return 64
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

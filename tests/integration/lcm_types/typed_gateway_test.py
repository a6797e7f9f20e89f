#!/usr/bin/env python3
"""A typed LCM channel through a running cosmicd (issue 35), against lcm-gen's generated Python code.

  typed_gateway_test.py COSMICD COSMICCTL LCM_GEN SOURCE_DIR     (inside scripts/netns-run)

cosmicd reads demo.pose_t (pose.lcm) messages on LCM group A, channel POSE, and forwards each event
in two forms: on group B, channel POSE_JSON, as JSON for tools (representation: json), and on group
C, channel POSE_OUT, in the LCM type's own encoding. The messages are encoded by lcm-gen's Python
code (an implementation we did not write) and sent as LCM UDPM datagrams by this script; what comes
out on B and C is received by this script's own sockets. Checked:
  - every message leaves on C byte for byte as it came, and lcm-gen's decode() reads the sent values;
  - every message leaves on B as one JSON object with exactly the sent values (floats as the double
    they are exactly), the fields in the struct's order;
  - a message of another fingerprint and one cut short are dropped and counted as decode_error;
  - `cosmicctl channel pose` names each hop's representation;
  - `cosmicctl echo pose --json` prints the first events with their decoded fields.
Then the other way (issue 37): python3's json module (a JSON writer we did not write) sends each
message's values as one JSON text on group D, channel POSE_JSON_IN (representation: json; every
other text with its keys sorted, not in the struct's order, with json.dumps's ", " and ": " and
ASCII-only \\u escapes), and the channel pose_in leaves on group C, channel POSE_FROM_JSON, in the LCM encoding:
  - every text arrives as exactly the message lcm-gen's encode() gives for the same values;
  - a text missing a field and one with a value beyond its kind are counted as decode_error.
"""
import json
import os
import random
import socket
import struct
import subprocess
import sys
import tempfile
import time

COSMICD, COSMICCTL, LCM_GEN, SOURCE_DIR = sys.argv[1:5]
GROUP = "239.255.76.67"
PORT_IN, PORT_JSON, PORT_OUT, PORT_JSON_IN = 7931, 7932, 7933, 7934
COUNT = 40
LCM_MAGIC = 0x4C433032  # "LC02": a small LCM UDPM message

failures = []


def check(condition, what):
    if not condition:
        failures.append(what)
        print("FAIL: " + what, file=sys.stderr)
    return condition


def lcm_datagram(channel, payload, seq):
    return struct.pack(">II", LCM_MAGIC, seq) + channel.encode() + b"\0" + payload


def parse_datagram(data):
    magic, _ = struct.unpack_from(">II", data)
    if magic != LCM_MAGIC:
        return None, None
    end = data.index(b"\0", 8)
    return data[8:end].decode(), data[end + 1:]


def receiver(port):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    s.bind(("", port))
    s.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, socket.inet_aton(GROUP) + socket.inet_aton("0.0.0.0"))
    s.settimeout(0.2)
    return s


def collect(sock, channel, want, deadline):
    got = []
    while len(got) < want and time.monotonic() < deadline:
        try:
            data = sock.recv(70000)
        except socket.timeout:
            continue
        name, payload = parse_datagram(data)
        if name == channel:
            got.append(payload)
    return got


def ctl(sock_path, *args):
    return subprocess.run([COSMICCTL, "--socket", sock_path] + list(args), capture_output=True, text=True)


def main():
    work = tempfile.mkdtemp(prefix="cosmic-typed-lcm-")
    subprocess.run([LCM_GEN, "-p", "--ppath", work, os.path.join(SOURCE_DIR, "pose.lcm")], check=True)
    sys.path.insert(0, work)
    from demo import pose_t  # noqa: E402  (generated above)
    from demo import point_t  # noqa: E402

    config = os.path.join(work, "gw.yaml")
    with open(config, "w") as f:
        f.write(f"""gateway: {{name: gw-typed-lcm}}
segments:
  - {{name: a, type: lcm, url: "udpm://{GROUP}:{PORT_IN}?ttl=0", latency_bound: 2ms}}
  - {{name: b, type: lcm, url: "udpm://{GROUP}:{PORT_JSON}?ttl=0", latency_bound: 2ms}}
  - {{name: c, type: lcm, url: "udpm://{GROUP}:{PORT_OUT}?ttl=0", latency_bound: 2ms}}
  - {{name: d, type: lcm, url: "udpm://{GROUP}:{PORT_JSON_IN}?ttl=0", latency_bound: 2ms}}
channels:
  - name: pose
    subject: 0x51
    class: nrt
    type: {{lcm: {os.path.join(SOURCE_DIR, "pose.lcm")}, name: demo.pose_t, max_length: {{ranges: 8}}}}
    publishers: [a]
    subscribers: [b, c]
    native:
      a: {{channel: POSE}}
      b: {{channel: POSE_JSON, representation: json}}
      c: {{channel: POSE_OUT}}
  - name: pose_in
    subject: 0x52
    class: nrt
    type: {{lcm: {os.path.join(SOURCE_DIR, "pose.lcm")}, name: demo.pose_t, max_length: {{ranges: 8}}}}
    publishers: [d]
    subscribers: [c]
    native:
      d: {{channel: POSE_JSON_IN, representation: json}}
      c: {{channel: POSE_FROM_JSON}}
""")
    sock_path = os.path.join(work, "gw.sock")
    log = open(os.path.join(work, "gw.log"), "w")
    daemon = subprocess.Popen([COSMICD, "--config", config, "--socket", sock_path, "--state-file",
                               os.path.join(work, "gw.state"), "--log-level", "debug"], stderr=log)
    try:
        deadline = time.monotonic() + 30
        while not os.path.exists(sock_path) or ctl(sock_path, "status").returncode != 0:
            if time.monotonic() > deadline or daemon.poll() is not None:
                print(open(os.path.join(work, "gw.log")).read(), file=sys.stderr)
                check(False, "cosmicd did not start")
                return
            time.sleep(0.05)
        run(sock_path, pose_t, point_t)
        run_json_in(sock_path, pose_t, point_t)
    finally:
        daemon.terminate()
        daemon.wait(10)


def sample(pose_t, point_t, i, rng):
    m = pose_t()
    m.stamp = 1_700_000_000_000_000_000 + i
    m.flags = rng.randint(-128, 127)
    m.position = point_t()
    m.position.x = rng.uniform(-1e6, 1e6)
    m.position.y = float(i) / 3.0
    m.frame = "map" if i % 2 else "odom/\u00e9"
    m.covariance = [struct.unpack("<f", struct.pack("<f", rng.uniform(-10, 10)))[0] for _ in range(3)]
    m.n = i % 9
    m.ranges = [struct.unpack("<f", struct.pack("<f", rng.uniform(0, 100)))[0] for _ in range(m.n)]
    m.valid = bool(i % 3)
    return m


def as_json_values(m):
    return {"stamp": m.stamp, "flags": m.flags, "position": {"x": m.position.x, "y": m.position.y},
            "frame": m.frame, "covariance": list(m.covariance), "n": m.n, "ranges": list(m.ranges),
            "valid": m.valid}


def run(sock_path, pose_t, point_t):
    rng = random.Random(20261129)
    json_sock, out_sock = receiver(PORT_JSON), receiver(PORT_OUT)
    send = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    # cosmicctl echo: the first events the gateway takes in, decoded (the malformed two are not
    # taken in, so the tap starts with message 0). It says on stderr when its tap is open.
    echo_err_path = os.path.join(os.path.dirname(sock_path), "echo.err")
    echo_err_file = open(echo_err_path, "w")
    echo = subprocess.Popen([COSMICCTL, "--socket", sock_path, "--json", "echo", "pose", "--count", "5", "--timeout",
                             "30"], stdout=subprocess.PIPE, stderr=echo_err_file, text=True)
    deadline = time.monotonic() + 20
    while "echo pose:" not in open(echo_err_path).read() and echo.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    check("echo pose:" in open(echo_err_path).read(), "cosmicctl echo did not open its tap")
    messages = [sample(pose_t, point_t, i, rng) for i in range(COUNT)]
    encoded = [m.encode() for m in messages]
    # Two that are not pose_t: another fingerprint, and a message cut short.
    foreign = b"\x01" * 8 + encoded[0][8:]
    for seq, payload in enumerate([foreign, encoded[1][:-3]] + encoded):
        send.sendto(lcm_datagram("POSE", payload, seq), (GROUP, PORT_IN))
        time.sleep(0.002)
    deadline = time.monotonic() + 20
    out = collect(out_sock, "POSE_OUT", COUNT, deadline)
    texts = collect(json_sock, "POSE_JSON", COUNT, deadline)
    check(len(out) == COUNT, f"{len(out)} messages on POSE_OUT, expected {COUNT}")
    check(len(texts) == COUNT, f"{len(texts)} messages on POSE_JSON, expected {COUNT}")
    for i, (payload, m) in enumerate(zip(out, encoded)):
        check(payload == m, f"POSE_OUT message {i}: {payload.hex()} differs from what was sent {m.hex()}")
        decoded = pose_t.decode(payload)
        check(as_json_values(decoded) == as_json_values(messages[i]), f"POSE_OUT message {i}: lcm-gen decodes other values")
    for i, (text, m) in enumerate(zip(texts, messages)):
        got = json.loads(text.decode())
        check(list(got) == ["stamp", "flags", "position", "frame", "covariance", "n", "ranges", "valid"],
              f"POSE_JSON message {i}: fields {list(got)}")
        check(got == as_json_values(m), f"POSE_JSON message {i}: {got} != {as_json_values(m)}")
    echo_out, _ = echo.communicate(timeout=40)
    check(echo.returncode == 0, f"cosmicctl echo exited {echo.returncode}: {open(echo_err_path).read()}")
    echoed = [json.loads(line) for line in echo_out.splitlines() if line.strip()]
    check(len(echoed) == 5, f"cosmicctl echo printed {len(echoed)} events, expected 5")
    for i, event in enumerate(echoed):
        check(event.get("channel") == "pose" and event.get("contents") == as_json_values(messages[i]),
              f"cosmicctl echo event {i}: {event}")
    answer = json.loads(ctl(sock_path, "--json", "channel", "pose").stdout)
    hops = {s["segment"]: s for s in answer["channel"]["segments"]}
    check(hops["a"]["dropped"]["decode_error"] == 2, f"decode_error on a: {hops['a']['dropped']['decode_error']}, expected 2")
    check(hops["a"]["representation"] == "LCM demo.pose_t", f"representation on a: {hops['a']['representation']}")
    check(hops["b"]["representation"] == "JSON", f"representation on b: {hops['b']['representation']}")
    check(hops["c"]["representation"] == "LCM demo.pose_t", f"representation on c: {hops['c']['representation']}")
    if not failures:
        print(f"checked: {COUNT} demo.pose_t messages from lcm-gen's Python code crossed cosmicd, byte for byte in "
              f"the LCM encoding and with the exact values as JSON; 2 malformed counted as decode_error")


def run_json_in(sock_path, pose_t, point_t):
    rng = random.Random(20270412)
    out_sock = receiver(PORT_OUT)
    send = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
    send.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, 0)
    messages = [sample(pose_t, point_t, i, rng) for i in range(COUNT)]
    texts = [json.dumps(as_json_values(m), sort_keys=bool(i % 2)) for i, m in enumerate(messages)]
    missing = dict(as_json_values(messages[0]))
    del missing["valid"]
    beyond = dict(as_json_values(messages[0]), flags=128)  # flags is an int8_t
    for seq, text in enumerate([json.dumps(missing), json.dumps(beyond)] + texts):
        send.sendto(lcm_datagram("POSE_JSON_IN", text.encode(), seq), (GROUP, PORT_JSON_IN))
        time.sleep(0.002)
    got = collect(out_sock, "POSE_FROM_JSON", COUNT, time.monotonic() + 20)
    check(len(got) == COUNT, f"{len(got)} messages on POSE_FROM_JSON, expected {COUNT}")
    for i, (payload, m) in enumerate(zip(got, messages)):
        check(payload == m.encode(), f"POSE_FROM_JSON message {i}: {payload.hex()} is not lcm-gen's {m.encode().hex()} "
              f"for {texts[i]}")
    answer = json.loads(ctl(sock_path, "--json", "channel", "pose_in").stdout)
    hops = {s["segment"]: s for s in answer["channel"]["segments"]}
    check(hops["d"]["representation"] == "JSON", f"representation on d: {hops['d']['representation']}")
    check(hops["d"]["dropped"]["decode_error"] == 2,
          f"decode_error on d: {hops['d']['dropped']['decode_error']}, expected 2")
    if not failures:
        print(f"checked: {COUNT} JSON texts from python3's json module crossed cosmicd into exactly lcm-gen's "
              f"demo.pose_t encoding; a text missing a field and one beyond int8 counted as decode_error")


if __name__ == "__main__":
    main()
    sys.exit(1 if failures else 0)

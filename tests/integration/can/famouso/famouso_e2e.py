"""FAMOUSO interoperability end to end (driver of ../famouso_e2e_test.sh): FAMOUSO-behaving nodes
(famouso_node.py) on vcan0 <-> cosmicd (segment profile famouso) <-> cosmic-lcm-peer and
cosmic-dds-peer. One cosmicd (gateway.yaml here) for all scenarios, in one VM boot:
  ccp            two nodes starting together get distinct TxNodes from cosmicd (CCP broker);
                 neither is the gateway's 9 nor the broker's 0x7F; a restarted node gets its own
                 again; each then binds FAMOUSO's SUBSCRIBE subject (answered on etag 4)
  bind           a node binds the channels' subjects with GET_ETAG and gets their etags from the
                 etag-4 answers (frame 1); a subject bound only later is answered once bound
  up_single      a node publishes a 4-byte event (one frame) -> LCM and DDS subscribers
  up_afp         a node publishes a 100-byte event as AFP fragments -> LCM and DDS, one event
  down_single    LCM and DDS events -> the node: FAMOUSO identifier (7-bit priority 0x10, no
                 fragment flag, TxNode 9), payload
  down_afp       a 300-byte LCM event -> the node: 45 AFP fragments with the fragment flag,
                 2-byte headers first, reassembled by the node
  (up_*, down_*: the identifier `cosmicctl channel` reports, in FAMOUSO's layout, is the one on
                 the wire: the node's 0x7D for what it publishes, the gateway's frames' for the rest)
  rate_limit     a flood of GET_ETAGs from one node: a few answered, the rest refused and counted
                 (receive errors and the adapter's binding_requests_over_limit)
Expected identifiers and bytes come from FAMOUSO's rules (famouso_node.py) and
docs/can-wire-format.md, never from cosmicd's output. Every wait has a deadline; no fixed sleeps.
"""
import os
import subprocess
import sys
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "e2e"))
import canlog  # noqa: E402
import e2e_test as e2e  # noqa: E402
import famouso_node as fn  # noqa: E402

e2e.CONFIG = os.path.join(HERE, "gateway.yaml")
e2e.LCM_URL = "udpm://239.255.76.67:7673?ttl=0"
e2e.DOMAIN = "58"
e2e.SUBJ = {"sensor": 0x1000000A1, "command": 0x1000000B2, "bulk_down": 0x1000000C4, "late": 0x1000000E7}
ETAG = {"sensor": 16383, "command": 300, "bulk_down": 202}
GW_NODE = 9
SUBSCRIBE_ETAG = 5               # docs/can-wire-format.md: the SUBSCRIBE subject's protocol etag
IF = "vcan0"
Fail, check, expect_eq, wait_until = e2e.Fail, e2e.check, e2e.expect_eq, e2e.wait_until
NODES = {}


def subject_bytes(name):
    return e2e.SUBJ[name].to_bytes(8, "big")


def scenario_ccp(s):
    results, errors = {}, []

    def start(name, uid):
        try:
            node = fn.Node(IF, uid)
            results[name] = (node, node.start())
        except Exception as ex:  # noqa: BLE001 - reported below
            errors.append("%s: %s" % (name, ex))

    threads = [threading.Thread(target=start, args=(n, u)) for n, u in
               (("a", b"Schulze\0"), ("b", b"Schulze\1"))]
    for t in threads:
        t.start()
    for t in threads:
        t.join(90)
    check(not errors, "; ".join(errors))
    a, b = results["a"][1], results["b"][1]
    check(a != b, "distinct TxNodes (%d, %d)" % (a, b))
    for n in (a, b):
        check(n not in (GW_NODE, 0x7F), "TxNode %d is neither the gateway's nor the broker's" % n)
    expect_eq("etag of SUBSCRIBE", results["a"][0].subscribe_etag, SUBSCRIBE_ETAG)
    results["a"][0].close()
    again = fn.Node(IF, b"Schulze\0")
    expect_eq("TxNode of the restarted node", again.start(), a)
    NODES["a"], NODES["b"] = again, results["b"][0]
    s.notes.append("TxNodes %d and %d" % (a, b))


def scenario_bind(s):
    node = NODES["a"]
    for name in ("sensor", "command", "bulk_down"):
        expect_eq("etag of " + name, node.bind(subject_bytes(name)), ETAG[name])
    # FAMOUSO's client asks once: the answer must come when the channel is bound later.
    result = {}
    late = fn.Node(IF, b"LateNode")
    late.node = NODES["b"].node
    late.request(subject_bytes("late"))  # before the bind; cosmicd handles frames in order
    t = threading.Thread(target=lambda: result.update(etag=late.await_etag(subject_bytes("late"), 60)))
    t.start()
    bind_file = s.path("late.yaml")
    with open(bind_file, "w") as f:
        f.write("name: late\nsubject: 0x%016X\nclass: nrt\nomission_degree: 5\npayload: 4B\n"
                "publishers: [bus]\nsubscribers: [viz]\n" % e2e.SUBJ["late"])
    s.t.gw.ctl("bind", bind_file)
    t.join(60)
    late.close()
    check("etag" in result, "an answer once the channel was bound")
    check(100 < result["etag"] <= 16383, "a channel etag (%d)" % result["etag"])


def expect_admission_id(gw, channel, ident):
    """cosmicctl channel CHANNEL shows IDENT, in FAMOUSO's layout, as the channel's identifier on
    the bus (JSON: layout, can_id and its fields; text: the fields spelled out)."""
    can = gw.can_hop(channel)
    parts = fn.split_id(ident)
    expect_eq(channel + ": layout", can["layout"], "famouso")
    expect_eq(channel + ": admission's identifier", "%08X" % can["can_id"], "%08X" % ident)
    expect_eq(channel + ": admission's priority (7 bits)", can["priority"], parts["prio"])
    expect_eq(channel + ": fragment flag", can["fragment"], parts["fragment"])
    expect_eq(channel + ": TxNode", can["tx_node"], parts["node"])
    r = subprocess.run([gw.cosmicctl, "--socket", gw.sock, "channel", channel], capture_output=True, text=True)
    text = "can_id 0x%08X (FAMOUSO layout: priority 0x%02X, fragment %d, TxNode %d, etag %d)" % (
        ident, parts["prio"], int(parts["fragment"]), parts["node"], parts["etag"])
    check(text in r.stdout, "cosmicctl channel %s shows %r: %s" % (channel, text, r.stdout))


def scenario_up_single(s):
    gw = s.t.gw
    lcm = s.lcm_sub("lcm", "sensor")
    dds = s.dds_sub("dds", "sensor")
    NODES["a"].publish(ETAG["sensor"], bytes.fromhex("deadbeef"))
    s.received("LCM subscriber", lcm, "deadbeef", "sensor")
    s.received("DDS subscriber", dds, "deadbeef", "sensor")
    check(gw.hop("sensor", "bus")["rx"] >= 1, "received on bus")
    # The node publishes at its own prio(0xFD) (docs/can-wire-format.md section 8): admission
    # analyses `sensor` (100 B: its largest events are AFP fragments, flag set) at that priority,
    # as the last TxNode the broker assigns.
    expect_admission_id(gw, "sensor", fn.famouso_id(fn.PRIO, True, 0x7E, ETAG["sensor"]))


def scenario_up_afp(s):
    lcm = s.lcm_sub("lcm", "sensor")
    dds = s.dds_sub("dds", "sensor")
    event = canlog.payload("dev", 100, 4)
    frames = NODES["a"].publish(ETAG["sensor"], event)
    expect_eq("AFP fragments of 100 bytes", frames, 15)
    s.received("LCM subscriber", lcm, event.hex(), "sensor")
    s.received("DDS subscriber", dds, event.hex(), "sensor")


def scenario_down_single(s):
    node = NODES["a"]
    expected_id = fn.famouso_id(0x10, False, GW_NODE, ETAG["command"])
    s.lcm_pub("command", 6)
    ident, data, _ = node.receive_event(ETAG["command"])
    expect_eq("identifier", "%08X" % ident, "%08X" % expected_id)
    expect_eq("LCM event on the node", data, canlog.payload("lcm", 6, 1))
    pub = s.dds_pub("ddspub", "command", 6)
    ident, data, _ = node.receive_event(ETAG["command"], timeout=40)
    expect_eq("DDS event on the node", data, canlog.payload("dds", 6, 1))
    expect_eq("DDS publisher exit status", pub.wait(30), 0)
    expect_admission_id(s.t.gw, "command", ident)
    s.notes.append("identifier %08X (7-bit priority 0x10, TxNode 9, etag 300)" % expected_id)


def scenario_down_afp(s):
    node = NODES["a"]
    s.lcm_pub("bulk_down", 300)
    ident, data, headers = node.receive_event(ETAG["bulk_down"])
    parts = fn.split_id(ident)
    check(parts["fragment"] and parts["node"] == GW_NODE and parts["prio"] >= 0x78,
          "fragment flag, TxNode 9, an NRT priority (%r)" % parts)
    expect_eq("AFP fragments", len(headers), 45)
    expect_eq("header lengths", headers, [2] * 13 + [1] * 32)
    expect_eq("reassembled event", data, canlog.payload("lcm", 300, 1))
    expect_admission_id(s.t.gw, "bulk_down", ident)


def scenario_rate_limit(s):
    gw = s.t.gw
    node = NODES["b"]
    adapter0 = gw.segments()["bus"]["adapter"]
    errors0, over0 = adapter0["receive_errors"], adapter0["binding_requests_over_limit"]
    check(isinstance(over0, int), "binding_requests_over_limit in the adapter counters (%r)" % over0)
    for _ in range(50):
        node.send(fn.famouso_id(fn.PRIO, False, node.node, fn.GET_ETAG), subject_bytes("sensor"))

    def counted():
        a = gw.segments()["bus"]["adapter"]
        return a["receive_errors"] - errors0 >= 40 and a["binding_requests_over_limit"] - over0 >= 40
    wait_until("the requests over the limit counted", 20, counted, interval=0.2)
    adapter = gw.segments(cli=True)["bus"]["adapter"]  # as cosmicctl segments --json shows it
    refused = adapter["receive_errors"] - errors0
    over = adapter["binding_requests_over_limit"] - over0
    check(40 <= refused <= 50, "refused requests counted (%d)" % refused)
    # Each request over the limit is also a receive error; nothing else counts as one.
    check(40 <= over <= refused, "binding_requests_over_limit (cosmicctl segments --json) %d of %d receive errors"
          % (over, refused))
    # Each admitted request is two answer frames; at most the node's burst (4) plus what it earned.
    deadline = time.monotonic() + 3
    while node.recv(deadline) is not None:
        pass
    answers = sum(1 for i, d in node.log if i & 0x3FFF == fn.SUPPLY_ETAG_NEW_BP and d[4:8] == subject_bytes("sensor")[:4])
    check(answers <= 10, "answered at most the node's burst (%d)" % answers)
    s.notes.append("%d refused (binding_requests_over_limit %d), %d answered" % (refused, over, answers))


SCENARIOS = [scenario_ccp, scenario_bind, scenario_up_single, scenario_up_afp, scenario_down_single,
             scenario_down_afp, scenario_rate_limit]


class Test(e2e.Test):
    def main(self):
        self.gw.start()

        def ready():
            check(self.gw.alive(), "cosmicd exited: %s" % e2e.read_text(self.gw.log))
            st = self.gw.try_query("status")
            return st if st and st["segments"]["up"] == 3 and st["channels"]["bound"] == len(ETAG) else None
        try:
            st = wait_until("cosmicd up with its channels bound", 30, ready, interval=0.1)
        except Fail as ex:
            print("FAIL startup: %s" % ex)
            self.tail(self.gw.log, 30)
            return 1
        self.gateway_id = int(st["gateway"]["id"], 16)
        results = []
        for scenario in SCENARIOS:
            ok = self.run(scenario)
            results.append(ok)
            if not ok and scenario in (scenario_ccp, scenario_bind):
                break  # the rest needs configured nodes
        for node in NODES.values():
            node.close()
        rc = self.gw.stop()
        results.append(rc == 0)
        print(("PASS" if rc == 0 else "FAIL") + " shutdown (exit status %r)" % rc)
        failed = results.count(False) + len(SCENARIOS) + 1 - len(results)
        print("%d passed, %d failed" % (len(results) - results.count(False), failed))
        return 1 if failed else 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        print("usage: famouso_e2e.py COSMICD COSMICCTL DDS_PEER LCM_PEER", file=sys.stderr)
        sys.exit(64)
    test = Test(*sys.argv[1:])
    try:
        sys.exit(test.main())
    finally:
        test.cleanup()

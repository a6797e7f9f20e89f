#!/usr/bin/env python3
"""Evaluate a Python expression against cosmicctl --json output read from stdin.

    cosmicctl --json channels | q.py 'hop("sensor", "viz")["tx"]'        prints the value
    cosmicctl --json segments | q.py -t 'seg("bus")["health"] == "down"'  exit 0 if true, else 1

Names available in EXPR: d (the whole answer), ch(NAME) (a channel of `channels`), seg(NAME) (a
segment of `segments`), hop(CHANNEL, SEGMENT) (a channel's per-segment entry), drops(CHANNEL,
SEGMENT, REASON). A missing name, malformed JSON or "ok": false makes -t false and the print mode
exit 2, so callers can poll with it while cosmicd starts or goes away.
"""
import json
import sys


def main() -> int:
    args = sys.argv[1:]
    test = bool(args) and args[0] == "-t"
    if test:
        args = args[1:]
    if len(args) != 1:
        print("usage: q.py [-t] EXPR < json", file=sys.stderr)
        return 64
    try:
        d = json.load(sys.stdin)
        if not d.get("ok", False):
            raise ValueError("answer is not ok: %s" % d.get("error"))

        def ch(name):
            return next(c for c in d["channels"] if c["name"] == name)

        def seg(name):
            return next(s for s in d["segments"] if s["name"] == name)

        def hop(channel, segment):
            return next(h for h in ch(channel)["segments"] if h["segment"] == segment)

        def drops(channel, segment, reason):
            return hop(channel, segment)["dropped"][reason]

        value = eval(args[0], {"d": d, "ch": ch, "seg": seg, "hop": hop, "drops": drops})
    except Exception as e:  # noqa: BLE001 - any failure is "not (yet) true"
        if not test:
            print("q.py: %s: %s" % (args[0], e), file=sys.stderr)
        return 1 if test else 2
    if test:
        return 0 if value else 1
    print(json.dumps(value) if isinstance(value, (dict, list)) else value)
    return 0


if __name__ == "__main__":
    sys.exit(main())

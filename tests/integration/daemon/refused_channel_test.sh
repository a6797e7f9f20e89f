#!/usr/bin/env bash
# A channel a segment's transport refuses is a visible verdict, never `bound` and silent (issue 9,
# item 10), end to end over real Fast DDS and LCM: two channel names that map to one DDS topic
# ('-' and '.' become '_') make the DDS adapter refuse the second of them at start. One
# configure() contract for every adapter (issue 22, item 12): the refusal names that channel
# alone, and the segment carries the rest.
#   - cam.pose is `failed` with the adapter's reason in `cosmicctl channels`, `channel` (text and
#     --json), `status`, the start-up verdict lines and one error line; cam-pose, on the same topic,
#     is bound and carried;
#   - a channel on other segments only is untouched, and a new channel binds on the segment;
#   - a bind of a third name on that topic is refused with the reason and changes nothing;
#   - once cam.pose is unbound nothing is refused, and an event flows DDS -> cosmicd -> LCM on
#     cam-pose.
#   refused_channel_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER COSMIC_DDS_PEER
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3 DDS_PEER=$4
WORK=$(mktemp -d /tmp/cosmic-refused.XXXXXX)
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"
trap 'cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

LCM_VIZ="udpm://239.255.76.67:7831?ttl=0"
LCM_LOG="udpm://239.255.76.67:7832?ttl=0"
TOPIC_CLASH="channels 'cam-pose' and 'cam.pose' both map to DDS topic cosmic/cam_pose ('-' and '.' become '_'); rename one of them"

cat >"$WORK/g.yaml" <<YAML
gateway: {name: gw-refused}
segments:
  - {name: lan, type: dds, domain: 23, latency_bound: 2ms}
  - {name: viz, type: lcm, url: "$LCM_VIZ", latency_bound: 2ms}
  - {name: logbook, type: lcm, url: "$LCM_LOG", latency_bound: 2ms}
channels:
  - {name: cam-pose, subject: 0x300, class: nrt, payload: 16B, omission_degree: 3, publishers: [lan], subscribers: [viz]}
  - {name: cam.pose, subject: 0x301, class: nrt, payload: 16B, omission_degree: 3, publishers: [lan], subscribers: [viz]}
  - {name: notes, subject: 0x302, class: nrt, payload: 16B, omission_degree: 3, publishers: [viz], subscribers: [logbook]}
YAML

# verdicts: "name=verdict ..." sorted, from `cosmicctl --json channels`.
verdicts() {
  ctl g --json channels | python3 -c '
import json, sys
print(" ".join(sorted(c["name"] + "=" + c["verdict"] for c in json.load(sys.stdin)["channels"])))'
}

start_daemon g "$WORK/g.yaml" || exit 1

scenario "a channel the DDS adapter refuses at start is failed, with its reason, everywhere"
got=$(verdicts)
[ "$got" = "cam-pose=bound cam.pose=failed notes=bound" ] || fail "verdicts after start: '$got'"
ctl g --json channel cam.pose | python3 -c '
import json, sys
c = json.load(sys.stdin)["channel"]
assert c["verdict"] == "failed", c["verdict"]
assert c["admission"]["verdict"] == "failed", c["admission"]["verdict"]
want = "segment lan does not carry it: " + sys.argv[1]
assert want in c["reasons"], c["reasons"]' "$TOPIC_CLASH" || fail "cosmicctl --json channel cam.pose: no failed verdict with the adapter's reason"
ctl g channels >"$WORK/channels.txt" || fail "cosmicctl channels failed"
grep -Eq '^cam\.pose +nrt +failed ' "$WORK/channels.txt" || fail "cosmicctl channels: cam.pose not shown failed: $(cat "$WORK/channels.txt")"
grep -Eq '^cam-pose +nrt +bound ' "$WORK/channels.txt" || fail "cosmicctl channels: cam-pose not shown bound: $(cat "$WORK/channels.txt")"
grep -qF -- "- segment lan does not carry it: $TOPIC_CLASH" "$WORK/channels.txt" ||
  fail "cosmicctl channels: no reason line: $(cat "$WORK/channels.txt")"
ctl g channel cam.pose >"$WORK/channel.txt" || fail "cosmicctl channel failed"
grep -Eq '^cam\.pose +nrt +failed ' "$WORK/channel.txt" || fail "cosmicctl channel cam.pose: not failed: $(cat "$WORK/channel.txt")"
ctl g status >"$WORK/status.txt" || fail "cosmicctl status failed"
grep -qF "2 bound, 0 degraded, 1 failed" "$WORK/status.txt" || fail "cosmicctl status: $(cat "$WORK/status.txt")"
[ "$(grep -cF " error channel cam.pose: segment lan does not carry it: $TOPIC_CLASH (verdict failed)" "$WORK/g.log")" -eq 1 ] ||
  fail "log: not exactly one error line for cam.pose: $(grep -F "channel cam.pose" "$WORK/g.log")"
grep -qF " warning channel cam.pose (nrt): failed; segment lan does not carry it: $TOPIC_CLASH" "$WORK/g.log" ||
  fail "log: no start-up verdict line 'failed' for cam.pose"
grep -qF "channel cam-pose: segment" "$WORK/g.log" && fail "log: cam-pose named in a refusal: $(grep -F "channel cam-pose" "$WORK/g.log")"
passed

scenario "the segment takes new channels; a third name on the topic is refused and changes nothing"
cat >"$WORK/extra.yaml" <<YAML
- {name: extra, subject: 0x303, class: nrt, payload: 8B, omission_degree: 3, publishers: [lan], subscribers: [viz]}
YAML
ctl g bind "$WORK/extra.yaml" >"$WORK/bind.out" 2>&1 || fail "bind of an unrelated channel onto lan failed: $(cat "$WORK/bind.out")"
cat >"$WORK/clash.yaml" <<YAML
- {name: cam_pose, subject: 0x304, class: nrt, payload: 8B, omission_degree: 3, publishers: [lan], subscribers: [viz]}
YAML
ctl g bind "$WORK/clash.yaml" >"$WORK/clash.out" 2>&1
code=$?
[ "$code" -eq 1 ] || fail "bind of cam_pose exited $code, expected 1"
grep -qF "segment lan does not carry channel cam_pose: channels 'cam-pose' and 'cam_pose' both map to DDS topic cosmic/cam_pose" "$WORK/clash.out" &&
  grep -qF "; nothing changed" "$WORK/clash.out" || fail "bind of cam_pose: no reason: $(cat "$WORK/clash.out")"
got=$(verdicts)
[ "$got" = "cam-pose=bound cam.pose=failed extra=bound notes=bound" ] || fail "verdicts after the refused bind: '$got'"
passed

scenario "once the clash is gone the segment carries the channel and it flows"
ctl g unbind cam.pose >/dev/null || fail "unbind cam.pose failed"
got=$(verdicts)
[ "$got" = "cam-pose=bound extra=bound notes=bound" ] || fail "verdicts after the unbind: '$got'"
"$LCM_PEER" sub --url "$LCM_VIZ" --channel cam-pose --count 1 --timeout 30 >"$WORK/sub.out" 2>"$WORK/sub.err" &
sub=$!
PIDS+=("$sub")
wait_until 10 "LCM subscriber ready" stderr_has "$WORK/sub.err" READY || exit 1
mkfifo "$WORK/start"
"$DDS_PEER" pub --domain 23 --topic cosmic/cam_pose --subject 768 --count 1 --size 16 --start-on-stdin \
  <"$WORK/start" 2>"$WORK/pub.err" &
pub=$!
PIDS+=("$pub")
exec 7>"$WORK/start"
wait_until 20 "cosmicd's reader of cam-pose matched" field_at_least g cam-pose lan matched 1
echo go >&7
exec 7>&-
wait "$pub" || fail "DDS publisher failed: $(tail -2 "$WORK/pub.err")"
wait "$sub" || fail "the event did not reach LCM: $(cat "$WORK/sub.err")"
passed

[ "$FAILED" = 0 ] || exit 1
log "all scenarios passed"

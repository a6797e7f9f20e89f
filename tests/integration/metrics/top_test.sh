#!/usr/bin/env bash
# cosmicctl top in a real terminal (tmux): it draws the channel with a moving rate, survives a
# refresh, and `q` quits it with exit 0 and the terminal given back.
#   top_test.sh COSMICD COSMICCTL COSMIC_LCM_PEER   (through netns-run)
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
COSMICD=$1 COSMICCTL=$2 LCM_PEER=$3
WORK=$(mktemp -d /tmp/cosmic-top.XXXXXX)
HERE=$(dirname "$0")
# shellcheck source=../daemon/lib.sh
source "$HERE/../daemon/lib.sh"
# shellcheck source=common.sh
source "$HERE/common.sh"
TMUX_SERVER="cosmic-top-$$"
tmux_() { tmux -L "$TMUX_SERVER" -f /dev/null "$@"; }
trap 'tmux_ kill-server 2>/dev/null; cleanup; rm -rf "$WORK"' EXIT

pane() { tmux_ capture-pane -p -t top; }
# pane_matches REGEX: the visible screen has a line matching REGEX (extended).
pane_matches() { pane | grep -qE -- "$1"; }

test_top_under_tmux() {
  scenario "cosmicctl top: live rates in tmux, q quits"
  tmux_ new-session -d -s top -x 160 -y 40 \
    "$COSMICCTL --socket $WORK/gw.sock top --interval 0.2; echo \"top exited \$?\"; exec cat" || { fail "tmux"; return; }
  wait_until 10 "top shows the gateway" pane_matches '^cosmicd gw-metrics \(id [0-9a-f]{16}\), up' || { pane >&2; return; }
  pane_matches '^SEGMENT +TYPE +HEALTH' || fail "no segment table"
  pane_matches '^lcm-a +lcm +up ' || fail "segment lcm-a not shown up"
  pane_matches '^pose +nrt +lcm-a +P ' || fail "no publisher row for pose"
  pane_matches 'refresh 0\.2 s +q quits' || fail "no footer"
  # Traffic at 500 events/s: the subscriber row's TX/s becomes a positive rate.
  "$LCM_PEER" pub --url "$LCM_A" --channel pose --count 100000 --size 64 --raw --rate 500 >/dev/null 2>&1 &
  local publisher=$!
  PIDS+=("$publisher")
  wait_until 15 "a TX rate on pose/lcm-b" pane_matches '^ +lcm-b +S +- +[1-9][0-9.]*k? ' || pane >&2
  kill "$publisher" 2>/dev/null
  tmux_ send-keys -t top q
  wait_until 10 "top quits on q" pane_matches '^top exited 0$' || { pane >&2; return; }
  pane_matches '^SEGMENT' && fail "the alternate screen was not left"
  passed
}

write_config "$WORK/gw.yaml" ""
start_daemon gw "$WORK/gw.yaml" || exit 1
test_top_under_tmux
exit "$FAILED"

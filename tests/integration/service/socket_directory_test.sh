#!/usr/bin/env bash
# cosmicd started by hand (no systemd RuntimeDirectory=): it creates the socket's directory
# itself. The directory must be 0750 and let the read group through, or the 0660 group-owned
# socket inside is unreachable for everyone but root (issue 5, item 3: "mode 0660, group cosmic,
# in a 0750 runtime directory"). A user in no group stays turned away.
#
# Usage (as root, through scripts/netns-run): socket_directory_test.sh COSMICD COSMICCTL
set -u
COSMICD=${1:?path to cosmicd}
COSMICCTL=${2:?path to cosmicctl}
DOMAIN=72
LCM_PORT=7772
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
in_netns_or_skip

WORK=$(mktemp -d /tmp/cosmic-svc-sockdir.XXXXXX)
chmod 0755 "$WORK"
cleanup() {
  kill_daemon
  remove_accounts
  [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

make_accounts
SOCKET=$WORK/run/cosmicd/control.sock  # neither run/ nor run/cosmicd/ exists yet
write_config "$WORK/cosmicd.yaml" "$SOCKET"
start_daemon --config "$WORK/cosmicd.yaml" --state-file "$WORK/state/bindings.json" \
  --read-group "$READ_GROUP" --admin-group "$ADMIN_GROUP" || finish

note "what cosmicd created"
got=$(mode_owner "$SOCKET")
[ "$got" = "660 root $READ_GROUP" ] || fail "socket is '$got', expected '660 root $READ_GROUP'"
got=$(stat -c '%a' "$WORK/run/cosmicd")
[ "$got" = 750 ] || fail "socket directory has mode $got, expected 750"
got=$(stat -c '%G' "$WORK/run/cosmicd")
[ "$got" = "$READ_GROUP" ] ||
  fail "socket directory belongs to group '$got', not the read group '$READ_GROUP': members of the read group cannot reach the socket"

note "who gets through"
ctl reader_status 0 as "$READER" status
ctl admin_channels 0 as "$ADMIN" channels
ctl other_status 69,77 as "$OTHER" status
contains other_status err "Permission denied"
ctl root_status 0 status

stop_daemon
finish

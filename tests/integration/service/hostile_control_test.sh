#!/usr/bin/env bash
# Hostile input at the control socket and in cosmicctl (issue 9 items 6-8): invalid UTF-8 in a
# bind file or an argument is a clear error with an exit code (never SIGABRT); a request the
# daemon refuses before reading all of it shows the daemon's answer (too_large), not "Broken
# pipe"; a YAML alias bomb is refused with a located error and cosmicd keeps serving; a --socket
# path that is a regular file is refused and kept.
#
# Usage (as root, through scripts/netns-run): hostile_control_test.sh COSMICD COSMICCTL
set -u
COSMICD=${1:?path to cosmicd}
COSMICCTL=${2:?path to cosmicctl}
DOMAIN=75
LCM_PORT=7775
# shellcheck source=lib.sh
. "$(dirname "$0")/lib.sh"
service_test_setup hostile

SOCKET=$WORK/run/control.sock
write_config "$WORK/cosmicd.yaml" "$SOCKET"
ARGS=(--config "$WORK/cosmicd.yaml" --state-file "$WORK/state/bindings.json")

note "a --socket path that is a regular file: refused, never deleted"
mkdir -p "$WORK/run"
echo precious >"$WORK/run/file"
ctl_raw socket_file 1 "$COSMICD" "${ARGS[@]}" --socket "$WORK/run/file"
contains socket_file err "exists and is not a socket; refusing to replace it"
[ "$(cat "$WORK/run/file")" = precious ] || fail "the regular file at the socket path was changed or deleted"

start_daemon "${ARGS[@]}" || finish

note "invalid UTF-8 in a bind file and in an argument: clear errors, no abort"
printf 'channels:\n  - {name: "bad\xff\xfe", subject: 5, class: nrt, publishers: [viz], subscribers: [lan]}\n' >"$WORK/bad_utf8.yaml"
ctl bad_utf8_file 2 bind "$WORK/bad_utf8.yaml"
contains bad_utf8_file err "is not valid UTF-8 (byte"
ctl bad_utf8_name 64 unbind $'sp\xffeed'
contains bad_utf8_name err "channel name is not valid UTF-8"

note "a bind file above the request limit: the daemon's too_large answer, not Broken pipe"
{
  echo "channels:"
  for i in $(seq 1 3000); do
    echo "  - {name: big$i, subject: $((100000 + i)), class: nrt, publishers: [viz], subscribers: [lan]}"
  done
} >"$WORK/big.yaml"
ctl too_large 1 bind "$WORK/big.yaml"
contains too_large err "request larger than the limit"
if grep -q "Broken pipe" "$WORK/too_large.err"; then fail "too_large: cosmicctl reported Broken pipe"; fi

note "a YAML alias bomb in a bind request: refused with its location, the daemon keeps serving"
{
  echo "a: &a [x, x, x, x, x, x, x, x, x, x]"
  prev=a
  for level in b c d e f g h i; do
    printf '%s: &%s [' "$level" "$level"
    for _ in 1 2 3 4 5 6 7 8 9; do printf '*%s, ' "$prev"; done
    printf '*%s]\n' "$prev"
    prev=$level
  done
  echo "channels: *i"
} >"$WORK/bomb.yaml"
ctl bomb 2 bind "$WORK/bomb.yaml"
contains bomb err "alias"
ctl after_bomb 0 status
ctl_raw check_bomb 2 "$COSMICCTL" check "$WORK/bomb.yaml"
contains check_bomb err "bomb.yaml:"

stop_daemon
finish

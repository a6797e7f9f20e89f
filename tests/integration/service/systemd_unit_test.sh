#!/usr/bin/env bash
# The service as installed (issue 5, item 1): `cmake --install --prefix /usr` into a DESTDIR
# puts binaries, unit, sysusers file and example configuration where the unit expects them;
# `systemd-analyze verify` is clean for the installed unit (resolving its ExecStart= and
# ExecReload= binaries inside the DESTDIR); `systemd-analyze security --offline=yes` rates it
# 2.5 or lower; systemd-sysusers accepts the sysusers file and creates user and groups in a
# scratch root. Nothing is installed on this machine.
#
# Usage: systemd_unit_test.sh BUILD_DIR
set -u
BUILD=${1:?build directory}
MAX_EXPOSURE=2.5
FAILURES=0
fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}
note() { echo "-- $*"; }
for tool in systemd-analyze systemd-sysusers; do
  command -v "$tool" >/dev/null || { echo "SKIP: no $tool (package systemd)"; exit 77; }
done

WORK=$(mktemp -d /tmp/cosmic-svc-unit.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
DEST=$WORK/dest
UNIT=/usr/lib/systemd/system/cosmicd.service

note "cmake --install --prefix /usr into a DESTDIR"
if ! DESTDIR=$DEST cmake --install "$BUILD" --prefix /usr >"$WORK/install.log" 2>&1; then
  fail "cmake --install failed"
  sed 's/^/    /' "$WORK/install.log" >&2
fi
grep -q "CMake Warning" "$WORK/install.log" && { fail "cmake --install warned"; sed 's/^/    /' "$WORK/install.log" >&2; }
for f in /usr/sbin/cosmicd /usr/bin/cosmicctl; do
  [ -x "$DEST$f" ] || fail "$f is not installed as an executable"
done
for f in "$UNIT" /usr/lib/sysusers.d/cosmic.conf /etc/cosmic/cosmicd.yaml \
         /usr/share/doc/cosmic-gateway/operations.md /usr/share/doc/cosmic-gateway/README.md; do
  [ -f "$DEST$f" ] || fail "$f is not installed"
done
[ -f "$DEST$UNIT" ] || { echo "no unit to check" >&2; exit 1; }

note "the unit names what was installed"
# ExecStart=/usr/sbin/cosmicd --config /etc/cosmic/cosmicd.yaml --state-file /var/lib/cosmicd/...
exec_start=$(sed -n 's/^ExecStart=//p' "$DEST$UNIT")
exec_reload=$(sed -n 's/^ExecReload=//p' "$DEST$UNIT")
for command in "$exec_start" "$exec_reload"; do
  binary=${command%% *}
  binary=${binary#[-@:+!]}
  [ -x "$DEST$binary" ] || fail "the unit runs $binary, which the install did not put there"
done
config=$(sed -n 's/.*--config \([^ ]*\).*/\1/p' <<<"$exec_start")
[ -f "$DEST$config" ] || fail "ExecStart= reads $config, which the install did not put there"
"$DEST/usr/bin/cosmicctl" check "$DEST$config" >"$WORK/check.out" 2>&1 ||
  { fail "the installed configuration $config does not pass cosmicctl check"; sed 's/^/    /' "$WORK/check.out" >&2; }
state_file=$(sed -n 's/.*--state-file \([^ ]*\).*/\1/p' <<<"$exec_start")
state_dir=$(sed -n 's/^StateDirectory=//p' "$DEST$UNIT")
[ "$(dirname "$state_file")" = "/var/lib/$state_dir" ] ||
  fail "--state-file $state_file is not in StateDirectory=$state_dir"
reload_socket=$(sed -n 's/.*--socket \([^ ]*\).*/\1/p' <<<"$exec_reload")
runtime_dir=$(sed -n 's/^RuntimeDirectory=//p' "$DEST$UNIT")
[ "$(dirname "$reload_socket")" = "/run/$runtime_dir" ] ||
  fail "ExecReload= talks to $reload_socket, not in RuntimeDirectory=$runtime_dir"
grep -q "control_socket: $reload_socket\$" "$DEST$config" ||
  fail "the installed configuration's control_socket is not $reload_socket"
user=$(sed -n 's/^User=//p' "$DEST$UNIT")
grep -qE "^u $user " "$DEST/usr/lib/sysusers.d/cosmic.conf" || fail "User=$user is not created by the sysusers file"
for setting in Type=notify NotifyAccess=main Restart=on-failure WatchdogSec= NoNewPrivileges=yes \
               ProtectSystem=strict 'CapabilityBoundingSet=$' 'SystemCallFilter=@system-service$' \
               'RestrictAddressFamilies=AF_UNIX AF_NETLINK AF_INET AF_INET6 AF_CAN$'; do
  grep -qE "^$setting" "$DEST$UNIT" || fail "the unit lacks $setting"
done

note "systemd-analyze verify, with the unit and its binaries resolved inside the DESTDIR"
# verify --root needs the units the service depends on (sysinit.target, ...) inside the root:
# a scratch copy of the DESTDIR gets this machine's unit directory next to ours.
ROOT=$WORK/verify-root
cp -a "$DEST" "$ROOT"
if [ -d /usr/lib/systemd/system ]; then
  cp -an /usr/lib/systemd/system/. "$ROOT/usr/lib/systemd/system/"
fi
systemd-analyze verify --root="$ROOT" cosmicd.service >"$WORK/verify.out" 2>&1
code=$?
if [ "$code" -ne 0 ] || [ -s "$WORK/verify.out" ]; then
  fail "systemd-analyze verify: exit $code"
  sed 's/^/    /' "$WORK/verify.out" >&2
fi
# Control: the same verify does see a binary missing from the root (so the clean result above
# covered ExecStart= and ExecReload=).
chmod a-x "$ROOT/usr/sbin/cosmicd"
systemd-analyze verify --root="$ROOT" cosmicd.service >"$WORK/verify-control.out" 2>&1 &&
  fail "systemd-analyze verify does not notice a non-executable /usr/sbin/cosmicd inside the root"
grep -q "/usr/sbin/cosmicd" "$WORK/verify-control.out" ||
  { fail "the control verify did not name /usr/sbin/cosmicd"; sed 's/^/    /' "$WORK/verify-control.out" >&2; }

note "systemd-analyze security --offline=yes: <= $MAX_EXPOSURE"
systemd-analyze security --offline=yes "$DEST$UNIT" >"$WORK/security.out" 2>&1
exposure=$(sed -n 's/.*Overall exposure level for cosmicd.service: \([0-9.]*\).*/\1/p' "$WORK/security.out")
if [ -z "$exposure" ]; then
  fail "no 'Overall exposure level' in the output of systemd-analyze security"
  sed 's/^/    /' "$WORK/security.out" >&2
elif ! awk -v e="$exposure" -v m="$MAX_EXPOSURE" 'BEGIN { exit !(e <= m) }'; then
  fail "exposure level $exposure > $MAX_EXPOSURE"
  grep '✗' "$WORK/security.out" | sed 's/^/    /' >&2
else
  echo "   exposure level $exposure"
fi
grep -q "cosmicd.service:[0-9]*:" "$WORK/security.out" &&
  { fail "systemd-analyze security reports problems in the unit file"; grep "cosmicd.service:[0-9]*:" "$WORK/security.out" >&2; }

note "systemd-sysusers accepts the sysusers file"
SROOT=$WORK/sysusers-root
cp -a "$DEST" "$SROOT"
if ! systemd-sysusers --root="$SROOT" --dry-run cosmic.conf >"$WORK/sysusers-dry.out" 2>&1; then
  fail "systemd-sysusers --dry-run rejects cosmic.conf"
  sed 's/^/    /' "$WORK/sysusers-dry.out" >&2
fi
grep -q "cosmic.conf:[0-9]*:" "$WORK/sysusers-dry.out" &&
  { fail "systemd-sysusers warns about cosmic.conf"; sed 's/^/    /' "$WORK/sysusers-dry.out" >&2; }
[ -e "$SROOT/etc/passwd" ] && fail "--dry-run wrote $SROOT/etc/passwd"
if systemd-sysusers --root="$SROOT" cosmic.conf >"$WORK/sysusers.out" 2>&1; then
  grep -qE '^cosmic:x:[0-9]+:[0-9]+:[^:]*:/var/lib/cosmicd:/usr/sbin/nologin$' "$SROOT/etc/passwd" ||
    { fail "no system user cosmic with home /var/lib/cosmicd and no login"; sed 's/^/    /' "$SROOT/etc/passwd" >&2; }
  uid=$(awk -F: '$1 == "cosmic" { print $3 }' "$SROOT/etc/passwd")
  [ -n "$uid" ] && [ "$uid" -lt 1000 ] || fail "cosmic has uid '$uid', not a system uid"
  for g in cosmic cosmic-admin; do
    grep -qE "^$g:x:[0-9]+:" "$SROOT/etc/group" || fail "no group $g"
  done
  # ExecReload= runs `cosmicctl reload` as User=: that user must be in the admin group, or
  # `systemctl reload cosmicd` is refused with permission_denied.
  grep -qE "^cosmic-admin:x:[0-9]+:(.*,)?$user(,|\$)" "$SROOT/etc/group" ||
    fail "User=$user is not a member of cosmic-admin: ExecReload= (cosmicctl reload) would be refused"
else
  fail "systemd-sysusers --root failed"
  sed 's/^/    /' "$WORK/sysusers.out" >&2
fi

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed"

#!/usr/bin/env bash
# The service as installed (issue 5, item 1): `cmake --install --prefix /usr` into a DESTDIR
# puts binaries, unit, sysusers file and example configuration where the unit expects them;
# `systemd-analyze verify` is clean for the installed unit (resolving its ExecStart= and
# ExecReload= binaries inside the DESTDIR); `systemd-analyze security --offline=yes` rates it
# 2.5 or lower; systemd-sysusers accepts the sysusers file and creates user and groups in a
# scratch root. Nothing is installed on this machine.
# The FMU runner's template unit (issue 38) likewise: cosmic-fmu@NAME runs the installed
# cosmic-fmu on the installed configuration as the same user, who is in the control socket's
# group (its reports); its work directory is its RuntimeDirectory= and may hold an executable
# library (ExecPaths=: /run is noexec where initramfs-tools mounts it); verify is clean for an
# instance (its binary and its man page resolved inside the DESTDIR) and security rates it no
# worse than cosmicd.service.
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
FMU_UNIT=/usr/lib/systemd/system/cosmic-fmu@.service
FMU_INSTANCE=cosmic-fmu@speed_controller.service

note "cmake --install --prefix /usr into a DESTDIR"
if ! DESTDIR=$DEST cmake --install "$BUILD" --prefix /usr >"$WORK/install.log" 2>&1; then
  fail "cmake --install failed"
  sed 's/^/    /' "$WORK/install.log" >&2
fi
grep -q "CMake Warning" "$WORK/install.log" && { fail "cmake --install warned"; sed 's/^/    /' "$WORK/install.log" >&2; }
for f in /usr/sbin/cosmicd /usr/bin/cosmicctl /usr/bin/cosmic-fmu; do
  [ -x "$DEST$f" ] || fail "$f is not installed as an executable"
done
for f in "$UNIT" "$FMU_UNIT" /usr/lib/sysusers.d/cosmic.conf /etc/cosmic/cosmicd.yaml \
         /usr/share/doc/cosmic-gateway/operations.md /usr/share/doc/cosmic-gateway/README.md \
         /usr/share/doc/cosmic-gateway/fmu.md /usr/share/man/man1/cosmic-fmu.1.gz; do
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

note "the FMU template names what was installed, as cosmicd's unit does"
fmu_user="" fmu_group=""
if [ -f "$DEST$FMU_UNIT" ]; then
  fmu_group=$(sed -n 's/^Group=//p' "$DEST$FMU_UNIT")
  fmu_start=$(sed -n 's/^ExecStart=//p' "$DEST$FMU_UNIT")
  [ -x "$DEST${fmu_start%% *}" ] || fail "cosmic-fmu@.service runs ${fmu_start%% *}, which the install did not put there"
  [ "$(sed -n 's/.*--config \([^ ]*\).*/\1/p' <<<"$fmu_start")" = "$config" ] ||
    fail "cosmic-fmu@.service does not read cosmicd's configuration $config: $fmu_start"
  grep -qE -- "--name %i( |\$)" <<<"$fmu_start" || fail "cosmic-fmu@.service does not run the fmus: entry named by its instance: $fmu_start"
  fmu_user=$(sed -n 's/^User=//p' "$DEST$FMU_UNIT")
  # Not cosmicd's user (a member of cosmic-admin): an FMU is a third-party binary in-process.
  [ -n "$fmu_user" ] && [ "$fmu_user" != "$user" ] || fail "cosmic-fmu@.service runs as '$fmu_user', not as a user of its own"
  grep -qE "^u $fmu_user " "$DEST/usr/lib/sysusers.d/cosmic.conf" || fail "User=$fmu_user is not created by the sysusers file"
  fmu_runtime=$(sed -n 's/^RuntimeDirectory=//p' "$DEST$FMU_UNIT")
  [ "$fmu_runtime" = "cosmic-fmu/%i" ] || fail "cosmic-fmu@.service: RuntimeDirectory=$fmu_runtime, not one per instance"
  grep -qx "ExecPaths=/run/$fmu_runtime" "$DEST$FMU_UNIT" ||
    fail "cosmic-fmu@.service: the work directory /run/$fmu_runtime is not in ExecPaths= (the FMU's library is loaded from it)"
  for setting in Type=notify NotifyAccess=main Restart=on-failure 'RestartPreventExitStatus=2 64$' \
                 'After=cosmicd.service' 'Wants=cosmicd.service' NoNewPrivileges=yes ProtectSystem=strict \
                 'CapabilityBoundingSet=$' 'SystemCallFilter=@system-service$' MemoryDenyWriteExecute=yes \
                 'RestrictAddressFamilies=AF_UNIX AF_NETLINK AF_INET AF_INET6 AF_CAN$'; do
    grep -qE "^$setting" "$DEST$FMU_UNIT" || fail "cosmic-fmu@.service lacks $setting"
  done
fi

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
# A template verifies as an instance. Documentation= names man:cosmic-fmu(1), which verify looks
# up with man(1): MANPATH points it at the root's pages.
MANPATH=$ROOT/usr/share/man systemd-analyze verify --root="$ROOT" "$FMU_INSTANCE" >"$WORK/verify-fmu.out" 2>&1
code=$?
if [ "$code" -ne 0 ] || [ -s "$WORK/verify-fmu.out" ]; then
  fail "systemd-analyze verify $FMU_INSTANCE: exit $code"
  sed 's/^/    /' "$WORK/verify-fmu.out" >&2
fi
# Control: the same verify does see a binary missing from the root (so the clean result above
# covered ExecStart= and ExecReload=), and a manual page missing from it.
chmod a-x "$ROOT/usr/sbin/cosmicd" "$ROOT/usr/bin/cosmic-fmu"
systemd-analyze verify --root="$ROOT" cosmicd.service >"$WORK/verify-control.out" 2>&1 &&
  fail "systemd-analyze verify does not notice a non-executable /usr/sbin/cosmicd inside the root"
grep -q "/usr/sbin/cosmicd" "$WORK/verify-control.out" ||
  { fail "the control verify did not name /usr/sbin/cosmicd"; sed 's/^/    /' "$WORK/verify-control.out" >&2; }
MANPATH=$ROOT/usr/share/man systemd-analyze verify --root="$ROOT" "$FMU_INSTANCE" >"$WORK/verify-control.out" 2>&1 &&
  fail "systemd-analyze verify does not notice a non-executable /usr/bin/cosmic-fmu inside the root"
grep -q "/usr/bin/cosmic-fmu" "$WORK/verify-control.out" ||
  { fail "the control verify did not name /usr/bin/cosmic-fmu"; sed 's/^/    /' "$WORK/verify-control.out" >&2; }
chmod a+x "$ROOT/usr/bin/cosmic-fmu"
rm "$ROOT/usr/share/man/man1/cosmic-fmu.1.gz"
MANPATH=$ROOT/usr/share/man systemd-analyze verify --root="$ROOT" "$FMU_INSTANCE" >"$WORK/verify-control.out" 2>&1 &&
  fail "systemd-analyze verify does not notice cosmic-fmu(1) missing from the root"

note "systemd-analyze security --offline=yes: cosmicd.service <= $MAX_EXPOSURE, $FMU_INSTANCE no worse"
# rate NAME LIMIT WHAT ARGS...: `systemd-analyze security --offline=yes ARGS` rates the unit NAME
# at most LIMIT (WHAT says what the limit is) and finds nothing wrong in its file; RATED is its level.
rate() {
  local name=$1 limit=$2 what=$3 out=$WORK/security-$1.out
  shift 3
  systemd-analyze security --offline=yes "$@" >"$out" 2>&1
  RATED=$(sed -n "s/.*Overall exposure level for $name: \([0-9.]*\).*/\1/p" "$out")
  if [ -z "$RATED" ]; then
    fail "no 'Overall exposure level' for $name in the output of systemd-analyze security"
    sed 's/^/    /' "$out" >&2
  elif ! awk -v e="$RATED" -v m="$limit" 'BEGIN { exit !(e <= m) }'; then
    fail "$name: exposure level $RATED > $what"
    grep '✗' "$out" | sed 's/^/    /' >&2
  else
    echo "   $name: exposure level $RATED"
  fi
  grep -q "\.service:[0-9]*:" "$out" &&
    { fail "systemd-analyze security reports problems in the file of $name"; grep "\.service:[0-9]*:" "$out" >&2; }
}
rate cosmicd.service "$MAX_EXPOSURE" "$MAX_EXPOSURE" "$DEST$UNIT"
exposure=${RATED:-0}
rate "$FMU_INSTANCE" "$exposure" "cosmicd.service's $exposure" --root="$DEST" "$FMU_INSTANCE"

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
  # cosmic-fmu@ reports to the control socket (group cosmic, mode 0660; fmu_report is for cosmicd's
  # read group, cosmic): the runner must have that group, or every report is refused. Its group is
  # Group= (else its user's own); its other groups are those that list its user (initgroups).
  socket_gid=$(awk -F: '$1 == "cosmic" { print $3 }' "$SROOT/etc/group")
  fmu_gid=$(awk -F: -v u="$fmu_user" '$1 == u { print $4 }' "$SROOT/etc/passwd")
  [ -z "$fmu_group" ] || fmu_gid=$(awk -F: -v g="$fmu_group" '$1 == g { print $3 }' "$SROOT/etc/group")
  [ -n "$socket_gid" ] && { [ "$fmu_gid" = "$socket_gid" ] || grep -qE "^cosmic:x:[0-9]+:(.*,)?$fmu_user(,|\$)" "$SROOT/etc/group"; } ||
    fail "cosmic-fmu@.service (User=$fmu_user, Group=$fmu_group) is not in the group cosmic of the control socket: its reports would be refused"
  grep -qE "^cosmic-admin:x:[0-9]+:(.*,)?$fmu_user(,|\$)" "$SROOT/etc/group" &&
    fail "cosmic-fmu@.service's user $fmu_user is in cosmic-admin: an FMU could bind, unbind and reload the gateway"
else
  fail "systemd-sysusers --root failed"
  sed 's/^/    /' "$WORK/sysusers.out" >&2
fi

if [ "$FAILURES" -ne 0 ]; then
  echo "$FAILURES check(s) failed" >&2
  exit 1
fi
echo "all checks passed"

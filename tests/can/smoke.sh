#!/usr/bin/env bash
# Smoke test for scripts/can-vm: vcan0/vcan1 exist inside, CAN frames flow over vcan0, and the exit
# status of the command comes back. Works in host mode and VM mode (each can-vm call boots a VM
# when the host kernel lacks AF_CAN, ~10 s each under TCG).
set -euo pipefail

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
can_vm="$repo/scripts/can-vm"
fail() { echo "FAIL: $*" >&2; exit 1; }

# 1) candump sees two frames sent with cansend. Readiness: wait (bounded) until candump's raw
#    socket shows up in vcan0's receive list instead of sleeping a fixed time.
inner=$(cat <<'INNER'
set -eu
log=$(mktemp /tmp/smoke-candump.XXXXXX)
nrecv() { awk '$1 == "vcan0" && $NF == "raw"' /proc/net/can/rcvlist_all | wc -l; }
before=$(nrecv)
timeout 60 candump -n 2 vcan0 >"$log" &
dump=$!
i=0
while [ "$(nrecv)" -le "$before" ]; do
  i=$((i + 1))
  [ "$i" -le 300 ] || { echo "candump did not open its socket" >&2; exit 1; }
  kill -0 "$dump" 2>/dev/null || { echo "candump exited early" >&2; exit 1; }
  sleep 0.1
done
cansend vcan0 12345678#DEADBEEF
cansend vcan0 123#01
wait "$dump"
cat "$log"
INNER
)
out=$("$can_vm" -- "$inner") || fail "candump/cansend run failed (exit $?)"
printf '%s\n' "$out"
grep -Eq '^ *vcan0 +12345678 +\[4\] +DE AD BE EF *$' <<<"$out" || fail "extended frame 12345678#DEADBEEF not seen"
grep -Eq '^ *vcan0 +123 +\[1\] +01 *$' <<<"$out" || fail "standard frame 123#01 not seen"
[ "$(grep -c vcan0 <<<"$out")" -eq 2 ] || fail "expected exactly 2 frames"

# 2) exit status is propagated
rc=0
"$can_vm" -- 'exit 7' || rc=$?
[ "$rc" -eq 7 ] || fail "can-vm -- 'exit 7' returned $rc, expected 7"

# 3) vcan1 exists too
"$can_vm" -- 'ip link show vcan1' >/dev/null || fail "vcan1 missing"

echo "PASS: tests/can/smoke.sh"

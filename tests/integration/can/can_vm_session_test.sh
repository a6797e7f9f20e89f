#!/bin/bash
# scripts/can-vm sessions (issue 40): every command of a session starts as in a VM of its own.
# The first command leaves a process running, files in /tmp, /var/tmp and /dev/shm, vcan0 down and
# vcan1 gone; the second, in the same VM (the same boot id), must find none of it.
#   can_vm_session_test.sh SCRIPTS_CAN_VM   (run by ctest in the can_vm fixture: CAN_VM_SESSION set)
set -u
CAN_VM=$1
[ -n "${CAN_VM_SESSION:-}" ] || { echo "SKIP: needs CAN_VM_SESSION (ctest runs it in the can_vm fixture)"; exit 77; }
fail() { echo "FAIL: $*" >&2; exit 1; }

first=$("$CAN_VM" -- bash -c '
  set -e
  setsid bash -c "exec -a cosmic_leftover sleep 600" </dev/null >/dev/null 2>&1 &
  for d in /tmp /var/tmp /dev/shm; do echo left >"$d/cosmic_leftover"; done
  ip link set vcan0 down
  ip link del vcan1
  cat /proc/sys/kernel/random/boot_id
') || fail "the first command failed: $first"

second=$("$CAN_VM" -- bash -c '
  cat /proc/sys/kernel/random/boot_id
  for d in /tmp /var/tmp /dev/shm; do [ ! -e "$d/cosmic_leftover" ] || echo "LEFT: $d/cosmic_leftover"; done
  for p in /proc/[0-9]*; do
    tr "\0" " " <"$p/cmdline" 2>/dev/null | grep -q "^cosmic_leftover" && echo "LEFT: process ${p#/proc/}"
  done
  for i in vcan0 vcan1; do
    ip link show "$i" 2>/dev/null | grep -q "[<,]UP[,>]" || echo "LEFT: $i missing or down"
  done
  true
') || fail "the second command failed: $second"

echo "first command:  $first"
echo "second command: $second"
[ "$(head -1 <<<"$first")" = "$(head -1 <<<"$second")" ] ||
  fail "the commands ran in different VMs (boot ids differ): the session was not used"
! grep -q "^LEFT" <<<"$second" || fail "the second command found what the first left: $(grep '^LEFT' <<<"$second" | tr '\n' ' ')"
echo "PASS: the second command of the session started clean in the same VM"

#!/usr/bin/env bash
# End-to-end tests of the CAN segment through the real daemon: can-utils on vcan0 <-> cosmicd <->
# cosmic-lcm-peer (LCM) and cosmic-dds-peer (Fast DDS), all on this machine (ctest: can.e2e).
#
#   scripts/can-vm -- bash tests/integration/can/e2e_test.sh COSMICD COSMICCTL DDS_PEER LCM_PEER [CYCLONE_ROS2_PEER]
#
# Needs root, vcan0 and vcan1 up (scripts/can-vm provides them, in a VM when the host has no
# AF_CAN); vcan1 is switched to CAN FD (mtu 72) if it is not.
# One cosmicd (e2e/gateway.yaml) serves every scenario, in this order; each prints PASS or FAIL
# with its duration (and on failure what it waited for, the peers' and cosmicd's last log lines):
#   etags           cosmicctl channels (JSON and text) shows the static and dynamic etags; the
#                   identifier admission plans is the documented one
#   get_etag        hand-made GET_ETAG requests (cansend) are answered with the documented
#                   SUPPLY_ETAG frames; an unknown subject gets none; a malformed one is counted
#   can_to_ip       cansend in the COSMIC layout -> cosmicd -> an LCM and a DDS subscriber
#   ip_to_can       an LCM and a DDS event -> cosmicd -> candump: 29-bit identifier and payload
#   fragments_up    a 1 KiB and a 13-byte NRT event as classic fragments (canplayer) -> LCM, DDS
#   fragments_down  a 1 KiB LCM and a 1 KiB DDS event -> 171 fragments each (candump), checked
#                   against the sender rules and reassembled
#   can_fd          vcan1 in FD mode: LCM -> FD frames with BRS, padded to the next FD length;
#                   FD (with/without BRS) and classic frames -> LCM, cut at the payload; too long:
#                   counted
#   native          native identifiers with can-utils while cangen runs a declared background
#                   frame: cansend 123#... -> LCM and DDS; LCM -> candump 18FF1234#...; no etag
#   typed           DBC-typed channels checked with python3-canmatrix: a WheelSpeed frame -> JSON on
#                   LCM and the re-packed ClusterSpeed on vcan1; DriveCommand's compact event -> 0x200
#   ros2            a ROS 2 node (Cyclone DDS, idlc's Twist): WheelVelocity frames -> Twists on
#                   rt/wheel_twist; Twists on rt/cmd_vel -> DriveTwist frames, decoded by canmatrix
#                   (needs CYCLONE_ROS2_PEER)
#   e2e             AUTOSAR E2E profile 1 counters and CRCs, checked with python3-crcmod
#   unexplained     frames nothing explains are listed by cosmicctl segments (id, rate); one that
#                   beats the HRT channel brake's identifier turns brake violated, logged once
#   garbage         cangen (random 29-bit, 11-bit, mixed FD/remote, aimed at the bound etags,
#                   malformed GET_ETAG) and hostile fragments: cosmicd survives, every frame is
#                   accounted for (frames of unbound etags never reach it), errors are counted,
#                   traffic still flows
#   overflow        frames sent while cosmicd is stopped (SIGSTOP): kernel drops shown as overflow
#                   drops, received + dropped = sent
#   burst           2,500 frames on vcan1 while cosmicd is stopped -> every one on vcan0 (CAN -> CAN,
#                   counted by vcan0's tx_packets): no lane or socket drop
#   error_frames    controller error frames (injected with cansend): bus-off -> down + degraded,
#                   restarted -> up; error-passive/warning -> degraded, error-active -> up;
#                   controller overflow counted; traffic flows afterwards
#   link_down_up    ip link set vcan0 down / up: segment down, channels degraded, events for the
#                   bus counted as not sent; then up, bound again, traffic resumes both ways with
#                   the same cosmicd process
#   shutdown        SIGTERM: cosmicd exits 0
# Exit status 0 when all passed. Every wait has a deadline (DDS: until both sides report the
# match); no fixed sleeps. CAN_E2E_KEEP=1 keeps the work directory under /tmp.
set -euo pipefail

if [ $# -ne 4 ] && [ $# -ne 5 ]; then
  echo "usage: $0 COSMICD COSMICCTL DDS_PEER LCM_PEER [CYCLONE_ROS2_PEER]   (as root with vcan0: scripts/can-vm)" >&2
  exit 64
fi
for f in "$@"; do
  [ -x "$f" ] || { echo "e2e: not an executable: $f" >&2; exit 64; }
done
for tool in cansend candump cangen canplayer ip; do
  command -v "$tool" >/dev/null || { echo "e2e: missing $tool (can-utils, iproute2)" >&2; exit 64; }
done
if [ "$(id -u)" -ne 0 ] || ! ip link show vcan0 >/dev/null 2>&1 || ! ip link show vcan1 >/dev/null 2>&1; then
  echo "e2e: needs root, vcan0 and vcan1: run it through scripts/can-vm" >&2
  exit 64
fi
# The system interpreter: a version-manager shim (pyenv) spawns dozens of processes per start,
# which costs seconds each time under the VM's emulation.
python=/usr/bin/python3
[ -x "$python" ] || python=$(command -v python3) || { echo "e2e: python3 not found" >&2; exit 64; }
exec "$python" -B -u "$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/e2e/e2e_test.py" "$@"

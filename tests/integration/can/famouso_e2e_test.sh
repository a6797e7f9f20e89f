#!/usr/bin/env bash
# FAMOUSO interoperability through the real daemon (ctest: can.famouso): FAMOUSO-behaving nodes
# (python3 AF_CAN sockets) on vcan0 <-> cosmicd (profile: famouso) <-> LCM and DDS peers. The
# scenarios are listed in famouso/famouso_e2e.py.
#
#   scripts/can-vm -- bash tests/integration/can/famouso_e2e_test.sh COSMICD COSMICCTL DDS_PEER LCM_PEER
set -euo pipefail
if [ $# -ne 4 ]; then
  echo "usage: $0 COSMICD COSMICCTL DDS_PEER LCM_PEER   (as root with vcan0: scripts/can-vm)" >&2
  exit 64
fi
if [ "$(id -u)" -ne 0 ] || ! ip link show vcan0 >/dev/null 2>&1; then
  echo "famouso e2e: needs root and vcan0: run it through scripts/can-vm" >&2
  exit 64
fi
python=/usr/bin/python3
[ -x "$python" ] || python=$(command -v python3) || { echo "famouso e2e: python3 not found" >&2; exit 64; }
exec "$python" -B -u "$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/famouso/famouso_e2e.py" "$@"

# vm_test_lib.sh: what the shell tests that run inside scripts/can-vm share. Source it after
# `set -uo pipefail`: vm_test_begin NAME INTERFACE checks for root and the interface (exit 64
# otherwise) and makes $WORK (removed at exit unless KEEP_WORK is set); background processes go to
# PIDS and are killed at exit; fail records a failure in FAILED; wait_until polls a condition.
vm_test_begin() {  # vm_test_begin NAME INTERFACE
  if [ "$(id -u)" -ne 0 ] || ! ip link show "$2" >/dev/null 2>&1; then
    echo "$1: needs root and $2: run it through scripts/can-vm" >&2
    exit 64
  fi
  python=/usr/bin/python3
  [ -x "$python" ] || python=$(command -v python3)
  WORK=$(mktemp -d "/tmp/cosmic-$1.XXXXXX")
  PIDS=()
  FAILED=0
  trap 'vm_test_cleanup; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT
}
vm_test_cleanup() {
  for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
  for pid in "${PIDS[@]}"; do wait "$pid" 2>/dev/null || true; done
}
log() { printf '%s\n' "$*" >&2; }
fail() { log "FAIL: $*"; FAILED=1; }
wait_until() { # wait_until TIMEOUT_S WHAT CMD...
  local deadline=$((SECONDS + $1)) what=$2
  shift 2
  until "$@" >/dev/null 2>&1; do
    [ "$SECONDS" -ge "$deadline" ] && { fail "timed out waiting for: $what"; return 1; }
    sleep 0.1
  done
}

# shellcheck shell=bash
# Shared by the service tests (sourced, not run). A cosmicd with one DDS and one LCM segment
# (no CAN), started as root, its control socket and state file under a scratch directory.
# The caller sets COSMICD, COSMICCTL, WORK (scratch directory, traversable by everyone),
# DOMAIN (DDS domain id) and LCM_PORT, and runs inside scripts/netns-run.

FAILURES=0
DAEMON_PID=
# The Python interpreter itself, resolved once: the tests parse JSON with it dozens of times, and a
# version manager's shim first in PATH (pyenv's python3 is a shell script that runs `pyenv exec`)
# costs seconds per call on a loaded machine where the interpreter starts in a fraction of one.
# The JSON checks need only the standard library: run them as `"$PYTHON" -S` (no site
# initialisation, a third of the start-up time).
PYTHON=$(python3 -S -c 'import sys; print(sys.executable)' 2>/dev/null)
[ -n "$PYTHON" ] && [ -x "$PYTHON" ] || PYTHON=python3
DAEMON_RUN=0  # counts starts; run N logs to $WORK/cosmicd.N.log

fail() {
  echo "FAIL: $*" >&2
  FAILURES=$((FAILURES + 1))
}

note() { echo "-- $*"; }

# finish: prints the verdict and exits with it (0 when nothing failed).
finish() {
  if [ "$FAILURES" -ne 0 ]; then
    echo "$FAILURES check(s) failed" >&2
    exit 1
  fi
  echo "all checks passed"
  exit 0
}

# service_test_setup NAME: checks the environment, makes the scratch directory $WORK (kept with
# KEEP_WORK=1) and kills a daemon left running on exit.
service_test_setup() {
  in_netns_or_skip
  WORK=$(mktemp -d "/tmp/cosmic-svc-$1.XXXXXX")
  trap 'kill_daemon; [ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT
  trap 'exit 130' INT TERM
}

in_netns_or_skip() {
  if [ "$(id -u)" -ne 0 ]; then
    echo "SKIP: needs root (network namespace, users, groups)"
    exit 77
  fi
  if [ "${COSMIC_IN_NETNS:-}" != 1 ]; then
    echo "run me through scripts/netns-run (DDS and LCM must stay on a private loopback)" >&2
    exit 2
  fi
}

# write_config FILE SOCKET: the configuration the tests run: channels `status` (nrt) and
# `speed` (srt) from DDS to LCM.
write_config() {
  cat >"$1" <<EOF
gateway:
  name: svc-test
  residence_bound: 1ms
  control_socket: $2
segments:
  - {name: lan, type: dds, domain: $DOMAIN, latency_bound: 2ms}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:$LCM_PORT?ttl=0", latency_bound: 5ms}
channels:
  - {name: status, subject: 0x000000090000A001, class: nrt, max_rate: 10Hz, omission_degree: 5,
     payload: 32B, publishers: [lan], subscribers: [viz]}
  - {name: speed, subject: 0x000000090000A002, class: srt, period: 10ms, reaction_time: 50ms,
     omission_degree: 1, temp_validity: 100ms, payload: 8B, publishers: [lan], subscribers: [viz]}
EOF
}

# write_extra FILE NAME SUBJECT: a channel to bind at run time (nrt, LCM -> DDS).
write_extra() {
  cat >"$1" <<EOF
channels:
  - {name: $2, subject: $3, class: nrt, max_rate: 5Hz, omission_degree: 5, payload: 16B,
     publishers: [viz], subscribers: [lan]}
EOF
}

# start_daemon ARGS...: starts cosmicd as root with ARGS, its stderr in $WORK/cosmicd.N.log;
# returns once `cosmicctl status` answers on $SOCKET (fails after 30 s or if cosmicd exits). It asks
# every 20 ms: cosmicd is up in a fraction of a second, and these tests start it dozens of times.
start_daemon() {
  DAEMON_RUN=$((DAEMON_RUN + 1))
  DAEMON_LOG=$WORK/cosmicd.$DAEMON_RUN.log
  "$COSMICD" "$@" >"$DAEMON_LOG.out" 2>"$DAEMON_LOG" &
  DAEMON_PID=$!
  local deadline=$((SECONDS + 30))
  while [ $SECONDS -lt $deadline ]; do
    if ! kill -0 "$DAEMON_PID" 2>/dev/null; then
      wait "$DAEMON_PID"
      fail "cosmicd run $DAEMON_RUN exited with status $? during start"
      sed 's/^/    /' "$DAEMON_LOG" >&2
      DAEMON_PID=
      return 1
    fi
    if [ -S "$SOCKET" ] && "$COSMICCTL" --socket "$SOCKET" status >/dev/null 2>&1; then
      return 0
    fi
    sleep 0.02
  done
  fail "cosmicd run $DAEMON_RUN did not answer on $SOCKET within 30 s"
  sed 's/^/    /' "$DAEMON_LOG" >&2
  return 1
}

# stop_daemon: SIGTERM, then expects exit status 0 within 15 s. Waits for the exit itself (whichever
# ends first, cosmicd or a 15 s timer), not in polling steps.
stop_daemon() {
  [ -n "$DAEMON_PID" ] || return 0
  kill -TERM "$DAEMON_PID" 2>/dev/null
  sleep 15 &
  local timer=$! finished= code
  wait -n -p finished "$DAEMON_PID" "$timer"
  code=$?
  if [ "$finished" != "$DAEMON_PID" ]; then
    fail "cosmicd run $DAEMON_RUN ignored SIGTERM for 15 s"
    kill -KILL "$DAEMON_PID" 2>/dev/null
    wait "$DAEMON_PID" 2>/dev/null
  else
    kill "$timer" 2>/dev/null
    wait "$timer" 2>/dev/null
    [ "$code" -eq 0 ] || fail "cosmicd run $DAEMON_RUN exited with status $code after SIGTERM (expected 0)"
  fi
  DAEMON_PID=
}

# Kills a daemon left running (for the EXIT trap).
kill_daemon() {
  if [ -n "$DAEMON_PID" ]; then
    kill -KILL "$DAEMON_PID" 2>/dev/null
    wait "$DAEMON_PID" 2>/dev/null
    DAEMON_PID=
  fi
}

# ctl NAME EXPECTED_EXIT [as USER] ARGS...: runs cosmicctl (as root or as USER through setpriv
# with USER's own groups), keeps stdout/stderr in $WORK/NAME.{out,err}, checks the exit status
# (EXPECTED_EXIT may list several, "69,77").
ctl() {
  local name=$1 expected=$2
  shift 2
  local prefix=()
  if [ "${1:-}" = as ]; then
    prefix=(setpriv --reuid "$2" --regid "$(id -g "$2")" --init-groups)
    shift 2
  fi
  ctl_raw "$name" "$expected" "${prefix[@]}" "$COSMICCTL" --socket "$SOCKET" "$@"
}

# ctl_raw NAME EXPECTED_EXIT COMMAND...: as ctl, for any command line.
ctl_raw() {
  local name=$1 expected=$2
  shift 2
  "$@" >"$WORK/$name.out" 2>"$WORK/$name.err" </dev/null
  local code=$?
  if [[ ",$expected," != *",$code,"* ]]; then
    fail "$name: exit $code, expected $expected ($*)"
    sed 's/^/    /' "$WORK/$name.out" "$WORK/$name.err" >&2
    return 1
  fi
  return 0
}

contains() {  # contains NAME out|err TEXT
  if ! grep -qF -- "$3" "$WORK/$1.$2"; then
    fail "$1: $2 lacks '$3'"
    sed 's/^/    /' "$WORK/$1.$2" >&2
  fi
}

log_contains() {  # log_contains TEXT [LOG]: the daemon's stderr has a line with TEXT
  local log=${2:-$DAEMON_LOG}
  if ! grep -qF -- "$1" "$log"; then
    fail "cosmicd log $(basename "$log") lacks '$1'"
    sed 's/^/    /' "$log" >&2
  fi
}

log_matches() {  # log_matches REGEX [LOG]: the daemon's stderr has a line matching REGEX (grep -E)
  local log=${2:-$DAEMON_LOG}
  if ! grep -qE -- "$1" "$log"; then
    fail "cosmicd log $(basename "$log") has no line matching '$1'"
    sed 's/^/    /' "$log" >&2
  fi
}

log_lacks() {  # log_lacks TEXT [LOG]
  local log=${2:-$DAEMON_LOG}
  if grep -qF -- "$1" "$log"; then
    fail "cosmicd log $(basename "$log") has '$1'"
    grep -F -- "$1" "$log" | sed 's/^/    /' >&2
  fi
}

# channel_names: the bound channels, sorted, one line ("a b c"), from `cosmicctl --json channels`.
channel_names() {
  "$COSMICCTL" --socket "$SOCKET" --json channels |
    "$PYTHON" -S -c 'import json,sys; print(" ".join(sorted(c["name"] for c in json.load(sys.stdin)["channels"])))'
}

expect_channels() {  # expect_channels WHAT "sorted names"
  local got
  got=$(channel_names)
  [ "$got" = "$2" ] || fail "$1: channels are '$got', expected '$2'"
}

# json_check FILE PYTHON_EXPRESSIONS: every line must hold for `d`, the parsed JSON in FILE.
json_check() {
  local file=$1 script=$2
  if ! "$PYTHON" -S -c '
import json, sys
d = json.load(open(sys.argv[1]))
for line in sys.argv[2].strip().splitlines():
    line = line.strip()
    if line and not eval(line, {"d": d, "all": all, "any": any, "set": set, "len": len, "isinstance": isinstance}):
        sys.exit("does not hold: " + line)
' "$file" "$script"; then
    fail "$(basename "$file"): JSON check"
    sed 's/^/    /' "$file" >&2
  fi
}

# Real users and groups for the access tests, removed again by remove_accounts (EXIT trap).
# Names carry a tag unique to this run: csvNNNNN-r (read group), csvNNNNN-a (admin group),
# csvNNNNNo (a user in no group), csvNNNNNr (reader), csvNNNNNa (admin).
CREATED_USERS=()
CREATED_GROUPS=()

pick_account_tag() {
  local tries=0
  while :; do
    ACCOUNT_TAG=csv$(printf '%05d' $(((RANDOM * 32768 + RANDOM + $$) % 100000)))
    if ! getent group "$ACCOUNT_TAG-r" "$ACCOUNT_TAG-a" >/dev/null &&
       ! getent passwd "${ACCOUNT_TAG}o" "${ACCOUNT_TAG}r" "${ACCOUNT_TAG}a" >/dev/null; then
      return 0
    fi
    tries=$((tries + 1))
    [ $tries -lt 20 ] || { echo "no free account tag" >&2; exit 1; }
  done
}

add_group() {  # add_group NAME
  groupadd "$1" || { echo "groupadd $1 failed" >&2; exit 1; }
  CREATED_GROUPS+=("$1")
}

add_user() {  # add_user NAME [SUPPLEMENTARY_GROUPS]: with its own primary group, no home, no shell
  local extra=()
  [ -n "${2:-}" ] && extra=(-G "$2")
  useradd --no-create-home --user-group --shell /usr/sbin/nologin "${extra[@]}" "$1" ||
    { echo "useradd $1 failed" >&2; exit 1; }
  CREATED_USERS+=("$1")
}

remove_accounts() {
  local u g
  for u in "${CREATED_USERS[@]}"; do
    userdel "$u" 2>/dev/null || echo "warning: userdel $u failed" >&2
    getent group "$u" >/dev/null && groupdel "$u" 2>/dev/null  # its own group, if userdel left it
  done
  for g in "${CREATED_GROUPS[@]}"; do
    groupdel "$g" 2>/dev/null || echo "warning: groupdel $g failed" >&2
  done
  CREATED_USERS=()
  CREATED_GROUPS=()
}

# make_accounts: the two groups and three users of the access tests.
make_accounts() {
  pick_account_tag
  READ_GROUP=$ACCOUNT_TAG-r
  ADMIN_GROUP=$ACCOUNT_TAG-a
  OTHER=${ACCOUNT_TAG}o
  READER=${ACCOUNT_TAG}r
  ADMIN=${ACCOUNT_TAG}a
  add_group "$READ_GROUP"
  add_group "$ADMIN_GROUP"
  add_user "$OTHER"
  add_user "$READER" "$READ_GROUP"
  # Operators who change the gateway belong to both groups: the socket's file mode lets the
  # read group in, the admin group decides what they may do (docs/operations.md).
  add_user "$ADMIN" "$READ_GROUP,$ADMIN_GROUP"
}

# mode_owner PATH: "MODE USER GROUP", e.g. "660 root cosmic"
mode_owner() { stat -c '%a %U %G' "$1"; }

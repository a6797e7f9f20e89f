#!/usr/bin/env bash
# cosmic-fmu@.service's sandbox lets an FMU load and step (issue 38), tested without a service
# manager by doing what its two settings that touch loading a library do:
#   - MemoryDenyWriteExecute=yes (with SystemCallArchitectures=native): under the same seccomp
#     filter (mdwe_exec.py), the test FMUs (Plant FMI 3.0 on LCM, SpeedController FMI 2.0 on DDS)
#     are extracted, loaded, initialized and stepped. Controls: the filter refuses a writable and
#     executable mapping, and an FMU whose library asks for an executable stack (the Plant with
#     its PT_GNU_STACK made executable) loads without the filter but is refused under it, with
#     the loader's "cannot enable executable stack" in the runner's error;
#   - RuntimeDirectory= on a /run mounted noexec (as initramfs-tools mounts it on Debian and
#     Ubuntu): with $RUNTIME_DIRECTORY on a noexec tmpfs the runner extracts the FMU there and
#     cannot map its library (exit 1); the same directory bind-mounted without noexec, as the
#     unit's ExecPaths= does, runs it. Either way the work directory is gone after the exit.
# Runs in scripts/netns-run (the FMUs' channels go to the namespace's loopback) as root (mounts).
#
# Usage: fmu_sandbox_test.sh COSMIC_FMU FMU_DIR UNIT_FILE
set -u
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
FMU_RUNNER=${1:?cosmic-fmu} FMU_DIR=${2:?directory of the test FMUs} UNIT=${3:?cosmic-fmu@.service}
MDWE="/usr/bin/python3 $(dirname "$(readlink -f "$0")")/mdwe_exec.py"
STEPS=200
# shellcheck source=lib.sh
source "$(dirname "$0")/lib.sh"  # fail, note, finish
[ "$(uname -m)" = x86_64 ] || { echo "SKIP: the seccomp filter is written for x86-64"; exit 77; }
[ "$(id -u)" = 0 ] || { echo "SKIP: mounting a noexec tmpfs needs root"; exit 77; }
WORK=$(mktemp -d /tmp/cosmic-fmu-sandbox.XXXXXX)
trap '[ -n "${KEEP_WORK:-}" ] || rm -rf "$WORK"' EXIT

note "the unit has the settings this test reproduces"
for setting in MemoryDenyWriteExecute=yes SystemCallArchitectures=native 'RuntimeDirectory=cosmic-fmu/%i' \
               'ExecPaths=/run/cosmic-fmu/%i'; do
  grep -qx "$setting" "$UNIT" || fail "$(basename "$UNIT") lacks $setting"
done

cat >"$WORK/loop.yaml" <<YAML
gateway: {name: gw-sandbox}
segments:
  - {name: lan, type: dds, domain: 47}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7873?ttl=0", latency_bound: 2ms}
channels:
  - {name: speed, subject: 0x700, class: srt, period: 10ms, reaction_time: 40ms,
     type: {fields: [{name: value, type: float64}]}}
  - {name: drive, subject: 0x701, class: srt, period: 10ms, reaction_time: 40ms,
     type: {fields: [{name: value, type: float64}]}}
fmus:
  - {name: plant, fmu: $FMU_DIR/Plant-fmi3.fmu, segment: viz, step: 10ms,
     inputs: {drive: drive.value}, outputs: {speed: speed.value}}
  - {name: controller, fmu: $FMU_DIR/SpeedController-fmi2.fmu, segment: lan, step: 10ms,
     inputs: {speed: speed.value}, outputs: {drive: drive.value}}
YAML

# run_fmu LOG NAME [CONFIG]: the entry NAME, unpaced, STEPS steps, no reports; the exit code.
run_fmu() {
  local log=$1 name=$2 config=${3:-$WORK/loop.yaml}
  timeout 60 "${PREFIX[@]}" "$FMU_RUNNER" --config "$config" --name "$name" --pace free --steps "$STEPS" \
    --no-report --ready-timeout 300ms --work-dir "$WORK" >"$log" 2>&1
}
stepped() {  # stepped LOG WHAT: the run logged its STEPS steps
  grep -q "stopped: $STEPS steps of 10 ms" "$1" || { fail "$2: no '$STEPS steps' in its log"; sed 's/^/    /' "$1" >&2; }
}

note "MemoryDenyWriteExecute=yes: the filter refuses a writable and executable mapping (control)"
$MDWE /usr/bin/python3 -c 'import mmap; mmap.mmap(-1, 4096, prot=mmap.PROT_READ | mmap.PROT_WRITE | mmap.PROT_EXEC)' \
  2>"$WORK/wx.err" && fail "a writable and executable mapping was made under the filter"
grep -q "Operation not permitted" "$WORK/wx.err" || { fail "the mapping was not refused with EPERM"; cat "$WORK/wx.err" >&2; }
/usr/bin/python3 -c 'import mmap; mmap.mmap(-1, 4096, prot=mmap.PROT_READ | mmap.PROT_WRITE | mmap.PROT_EXEC)' ||
  fail "a writable and executable mapping is refused even without the filter: the control proves nothing"

note "MemoryDenyWriteExecute=yes: the test FMUs load and step under it"
read -r -a PREFIX <<<"$MDWE"
for name in plant controller; do
  run_fmu "$WORK/$name.mdwe.log" "$name"
  code=$?
  [ "$code" -eq 0 ] || { fail "$name under the filter exited $code"; sed 's/^/    /' "$WORK/$name.mdwe.log" >&2; continue; }
  stepped "$WORK/$name.mdwe.log" "$name under the filter"
done

note "an FMU whose library asks for an executable stack: loads without the filter, refused under it"
/usr/bin/python3 - "$FMU_DIR/Plant-fmi2.fmu" "$WORK/Plant-execstack.fmu" <<'PY' || fail "could not make the executable-stack FMU"
import struct, sys, zipfile
PT_GNU_STACK, PF_X = 0x6474E551, 1
with zipfile.ZipFile(sys.argv[1]) as source, zipfile.ZipFile(sys.argv[2], "w", zipfile.ZIP_DEFLATED) as target:
    marked = 0
    for entry in source.infolist():
        data = bytearray(source.read(entry))
        if entry.filename.endswith(".so"):
            (table,) = struct.unpack_from("<Q", data, 0x20)
            size, count = struct.unpack_from("<HH", data, 0x36)
            for at in range(table, table + size * count, size):
                kind, flags = struct.unpack_from("<II", data, at)
                if kind == PT_GNU_STACK:
                    struct.pack_into("<I", data, at + 4, flags | PF_X)
                    marked += 1
        target.writestr(entry, bytes(data))
sys.exit(0 if marked == 1 else 1)
PY
sed "s#$FMU_DIR/Plant-fmi3.fmu#$WORK/Plant-execstack.fmu#" "$WORK/loop.yaml" >"$WORK/execstack.yaml"
PREFIX=()
run_fmu "$WORK/execstack.log" plant "$WORK/execstack.yaml" ||
  { fail "the executable-stack FMU does not run even without the filter"; sed 's/^/    /' "$WORK/execstack.log" >&2; }
read -r -a PREFIX <<<"$MDWE"
run_fmu "$WORK/execstack.mdwe.log" plant "$WORK/execstack.yaml"
code=$?
[ "$code" -eq 1 ] || fail "the executable-stack FMU under the filter exited $code, not 1"
grep -q "cannot load the FMU's binary .*cannot enable executable stack" "$WORK/execstack.mdwe.log" ||
  { fail "the refusal does not say 'cannot enable executable stack'"; sed 's/^/    /' "$WORK/execstack.mdwe.log" >&2; }

note "RuntimeDirectory= on a noexec /run: refused; made executable as ExecPaths= does: runs"
PREFIX=()
mkdir -p "$WORK/run"
unshare --mount --propagation private -- env FMU_RUNNER="$FMU_RUNNER" WORK="$WORK" STEPS="$STEPS" bash -c '
  mount -t tmpfs -o nodev,noexec,nosuid,mode=0755 tmpfs "$WORK/run" || exit 90
  mkdir "$WORK/run/cosmic-fmu-plant"
  # RUNTIME_DIRECTORY (no --work-dir): what systemd sets for RuntimeDirectory=.
  run() {
    RUNTIME_DIRECTORY=$WORK/run/cosmic-fmu-plant timeout 60 "$FMU_RUNNER" --config "$WORK/loop.yaml" --name plant \
      --pace free --steps "$STEPS" --no-report --ready-timeout 300ms >"$1" 2>&1
    echo "exit $?" >>"$1"
    ls -A "$WORK/run/cosmic-fmu-plant" >"$1.left"
  }
  run "$WORK/noexec.log"
  mount --bind "$WORK/run/cosmic-fmu-plant" "$WORK/run/cosmic-fmu-plant" &&
    mount -o remount,bind,exec,nosuid,nodev "$WORK/run/cosmic-fmu-plant" || exit 91
  run "$WORK/exec.log"' || fail "could not mount the scratch tmpfs (exit $?)"
grep -qx "exit 1" "$WORK/noexec.log" || { fail "the runner did not exit 1 with its work directory on noexec"; sed 's/^/    /' "$WORK/noexec.log" >&2; }
grep -q "cannot load the FMU's binary $WORK/run/cosmic-fmu-plant/cosmic-fmu-plant-.*failed to map segment" "$WORK/noexec.log" ||
  { fail "the noexec refusal does not name the library in \$RUNTIME_DIRECTORY"; sed 's/^/    /' "$WORK/noexec.log" >&2; }
grep -qx "exit 0" "$WORK/exec.log" || { fail "the runner did not run with its work directory made executable"; sed 's/^/    /' "$WORK/exec.log" >&2; }
stepped "$WORK/exec.log" "the runner in an executable \$RUNTIME_DIRECTORY"
for log in noexec exec; do
  [ -s "$WORK/$log.log.left" ] && fail "the $log run left its work directory behind: $(cat "$WORK/$log.log.left")"
done

finish

#!/usr/bin/env bash
# The part of installed_build_test.sh that runs in a private mount namespace: ROOT/usr laid over
# /usr, SOURCE and BUILD hidden. MODE installed: everything must build and run against the
# packages; MODE runtime (no libcosmic-client-dev in ROOT): nothing may. Exit: 0 as expected,
# 77 the mounts are not possible here, otherwise the number of failed checks.
#
# Usage: installed_build_inner.sh MODE ROOT WORK VERSION TRIPLET SOURCE BUILD
set -u
MODE=$1 ROOT=$2 WORK=$3 VERSION=$4 TRIPLET=$5 SOURCE=$6 BUILD=$7
FAILURES=0
fail() {
  echo "FAIL ($MODE): $*" >&2
  FAILURES=$((FAILURES + 1))
}
show() { sed 's/^/    /' "$@" >&2; }

mount -t overlay cosmic-installed -o "lowerdir=$ROOT/usr:/usr" /usr 2>"$WORK/mount.err" || { cat "$WORK/mount.err" >&2; exit 77; }
# The build tree first: it may lie inside the source tree, which hides it once covered.
for hidden in "$BUILD" "$SOURCE"; do
  mount -t tmpfs -o ro,size=64k cosmic-hidden "$hidden" || exit 77
  [ -z "$(ls -A "$hidden")" ] || { echo "$hidden is still visible" >&2; exit 77; }
done
mkdir -p "$HOME"
OUT=$WORK/$MODE
mkdir -p "$OUT"
CONFIG_DIR=/usr/lib/$TRIPLET/cmake/cosmic_client

[ "$(command -v cosmicctl)" = /usr/bin/cosmicctl ] || fail "cosmicctl is not /usr/bin/cosmicctl: $(command -v cosmicctl)"
[ "$(cosmicctl --version)" = "cosmicctl $VERSION" ] || fail "cosmicctl --version: $(cosmicctl --version 2>&1)"
[ "$(/usr/sbin/cosmicd --version)" = "cosmicd $VERSION" ] || fail "cosmicd --version: $(/usr/sbin/cosmicd --version 2>&1)"

# The skeleton, from the installed cosmicctl.
SC=$OUT/speed_controller
cosmicctl gen "$WORK/model/robot.yaml" --component speed_controller --output "$SC" 2>"$OUT/gen.err" ||
  { fail "cosmicctl gen exited $?"; show "$OUT/gen.err"; }
grep -qF "HINTS \"$CONFIG_DIR\"" "$SC/CMakeLists.txt" ||
  fail "the skeleton does not look for the installed package in $CONFIG_DIR: $(grep find_package "$SC/CMakeLists.txt")"
grep -lF -e "$SOURCE" -e "$BUILD" "$SC"/* && fail "the skeleton names the source or build tree"

# With CMake: find_package(cosmic_client) from /usr.
cmake -S "$SC" -B "$SC/build" -DCMAKE_BUILD_TYPE=Release >"$OUT/configure.log" 2>&1
configured=$?
if [ "$MODE" = runtime ]; then
  [ "$configured" -ne 0 ] || fail "the skeleton configured without libcosmic-client-dev ($(grep cosmic_client_DIR "$SC/build/CMakeCache.txt"))"
  grep -q "cosmic_client" "$OUT/configure.log" || { fail "configure failed, but not for want of cosmic_client"; show "$OUT/configure.log"; }
else
  [ "$configured" -eq 0 ] || { fail "configuring the skeleton failed"; show "$OUT/configure.log"; }
  grep -qx "cosmic_client_DIR:PATH=$CONFIG_DIR" "$SC/build/CMakeCache.txt" ||
    fail "find_package found $(grep cosmic_client_DIR "$SC/build/CMakeCache.txt"), not $CONFIG_DIR"
  cmake --build "$SC/build" >"$OUT/build.log" 2>&1 || { fail "building the skeleton failed"; show "$OUT/build.log"; }
  binary=$SC/build/speed_controller
  ldd "$binary" 2>&1 | grep -qE "libcosmic-client.so.0 => (/usr)?/lib/$TRIPLET/libcosmic-client.so.0" ||
    { fail "the skeleton does not load /usr/lib/$TRIPLET/libcosmic-client.so.0"; ldd "$binary" >&2; }
  readelf -d "$binary" | grep -E "RPATH|RUNPATH" && fail "the skeleton carries a run path"
  # Loads and starts (every library resolved): a wrong option gives the usage, exit 64; nothing
  # is opened, so no traffic.
  "$binary" --no-such-option >/dev/null 2>"$OUT/run.err"
  [ $? -eq 64 ] || { fail "the CMake-built skeleton did not start"; show "$OUT/run.err"; }
fi

# With pkg-config, as a Makefile would.
if [ "$MODE" = runtime ]; then
  pkg-config --exists cosmic-client && fail "pkg-config finds cosmic-client without libcosmic-client-dev: $(pkg-config --variable=pcfiledir cosmic-client)"
  echo '#include "cosmic/client.h"' | gcc -x c -fsyntax-only - 2>/dev/null && fail "cosmic/client.h is found without libcosmic-client-dev"
else
  [ "$(pkg-config --modversion cosmic-client)" = "$VERSION" ] || fail "pkg-config --modversion cosmic-client: $(pkg-config --modversion cosmic-client 2>&1)"
  [ "$(pkg-config --variable=pcfiledir cosmic-client)" = "/usr/lib/$TRIPLET/pkgconfig" ] ||
    fail "cosmic-client.pc is not in /usr/lib/$TRIPLET/pkgconfig: $(pkg-config --variable=pcfiledir cosmic-client)"
  # shellcheck disable=SC2046 # word splitting of pkg-config's flags is what we want
  g++ -std=c++20 -Wall -Wextra -Werror $(pkg-config --cflags cosmic-client) "$SC"/*.cpp -o "$OUT/speed_controller.pc" \
    $(pkg-config --libs cosmic-client) 2>"$OUT/pc.err" || { fail "building the skeleton with pkg-config failed"; show "$OUT/pc.err"; }
  "$OUT/speed_controller.pc" --no-such-option >/dev/null 2>&1
  [ $? -eq 64 ] || fail "the pkg-config-built skeleton did not start"

  # C: the header is C, and the library answers (a segment string it cannot parse: no traffic).
  cat >"$OUT/probe.c" <<'C'
#include <stdio.h>
#include "cosmic/client.h"
int main(void) {
  char error[256] = "";
  cosmic_client* client = cosmic_open("nowhere:0", error, sizeof error);
  if (client != NULL || error[0] == '\0') return 1;
  printf("%s\n", error);
  return 0;
}
C
  # shellcheck disable=SC2046
  gcc -std=c11 -Wall -Wextra -Werror $(pkg-config --cflags cosmic-client) "$OUT/probe.c" -o "$OUT/probe" \
    $(pkg-config --libs cosmic-client) 2>"$OUT/probe.err" || { fail "a C program on cosmic/client.h did not build"; show "$OUT/probe.err"; }
  "$OUT/probe" >"$OUT/probe.out" 2>&1 || { fail "cosmic_open() of a bad segment did not fail with a reason"; show "$OUT/probe.out"; }

  # Python: the installed package, from dist-packages, and its errors carry the library's.
  python3 - >"$OUT/python.out" 2>&1 <<'PY' || { fail "the installed Python package does not work"; show "$OUT/python.out"; }
import cosmic
assert cosmic.__file__.startswith("/usr/lib/python3/dist-packages/cosmic/"), cosmic.__file__
try:
    cosmic.Client("nowhere:0")
except cosmic.InvalidError as error:
    print("refused:", error)
else:
    raise SystemExit("a bad segment was accepted")
PY

  for f in /usr/share/man/man8/cosmicd.8.gz /usr/share/man/man1/cosmicctl.1.gz; do
    gzip -t "$f" 2>/dev/null || fail "no manual page $f"
  done
  bash --norc -c 'source /usr/share/bash-completion/completions/cosmicctl && complete -p cosmicctl' >/dev/null 2>&1 ||
    fail "no bash completion for cosmicctl in /usr/share/bash-completion/completions"
fi
exit "$FAILURES"

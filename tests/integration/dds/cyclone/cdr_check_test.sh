#!/usr/bin/env bash
# cosmic::CdrRepresentation against Eclipse Cyclone DDS's own serializer (an implementation we did
# not write), both ways, on the types of cdr_check.idl (nested structs, sequences of structs, of
# int64, of enums and of booleans, strings, arrays of strings, a two-dimensional array, an int64
# after an int8 and a uint8; @final and @appendable; three samples each, empty and full sequences):
#   cdr_check_test.sh COSMIC_CYCLONE_CDR_PEER COSMIC_CDR_PEER
# 1. Cyclone writes XCDR1 and XCDR2 (final and appendable; little- and big-endian) and we read
#    every sample as the values it holds; we write each little-endian one back byte for byte.
# 2. We write the same samples and Cyclone's receive path reads them as the same values.
# Cyclone runs in process (a participant whose writer and reader meet by local delivery), inside a
# fresh network namespace (run through scripts/netns-run) so that its participant stays private.
set -uo pipefail
[ "${COSMIC_IN_NETNS:-}" = 1 ] || { echo "run me through scripts/netns-run" >&2; exit 2; }
CYCLONE_PEER=$1 OUR_PEER=$2
WORK=$(mktemp -d /tmp/cosmic-cdr.XXXXXX)
trap 'rm -rf "$WORK"' EXIT
export CYCLONEDDS_URI='<CycloneDDS><Domain id="any"><General><Interfaces><NetworkInterface name="lo" multicast="true"/></Interfaces></General></Domain></CycloneDDS>'

fail=0
if ! "$CYCLONE_PEER" write >"$WORK/cyclone.txt"; then
  echo "FAIL: the Cyclone peer did not write its samples" >&2
  exit 1
fi
echo "== Cyclone's samples ($(wc -l <"$WORK/cyclone.txt")) read by CdrRepresentation"
"$OUR_PEER" decode <"$WORK/cyclone.txt" || fail=1
"$OUR_PEER" encode >"$WORK/ours.txt" || { echo "FAIL: we did not write our samples" >&2; exit 1; }
echo "== our samples ($(wc -l <"$WORK/ours.txt")) read by Cyclone"
"$CYCLONE_PEER" read <"$WORK/ours.txt" || fail=1
[ "$fail" = 0 ] && echo "PASS" || echo "FAIL"
exit "$fail"

#!/usr/bin/env bash
# `cosmicctl security permissions` end to end with a test PKI made by the openssl command line
# (tests/support/make_test_pki.sh): with --sign-with it writes both documents signed where the
# configuration names them, `openssl smime -verify` accepts them against the permissions CA and
# `cosmicctl check` then loads the configuration; without it, it writes the XML next to them and
# prints openssl commands that, run as printed, sign them into place. Bad arguments (a missing,
# open or foreign CA key, a CA the configuration does not trust, a configuration without a secure
# segment, a directory that does not exist) fail with the reason and their exit status and leave
# every existing document as it was.
# Usage: security_cli_test.sh PATH_TO_cosmicctl PROJECT_SOURCE_DIR
set -u

. "$(dirname "${BASH_SOURCE[0]}")/cli_lib.sh"

"$SRC/tests/support/make_test_pki.sh" "$WORK/pki" || { echo "FAIL: make_test_pki.sh" >&2; exit 1; }
PKI=$WORK/pki

# gateway FILE OUT_DIR: gateway-a's configuration, its documents in OUT_DIR (relative to FILE).
gateway() {
  cat >"$1" <<YAML
gateway: {name: gw-a}
segments:
  - name: lan
    type: dds
    domain: 5
    security: {identity_ca: pki/identity_ca.pem, certificate: pki/gateway-a_cert.pem,
               private_key: pki/gateway-a_key.pem, permissions_ca: pki/permissions_ca.pem,
               governance: $2/governance.p7s, permissions: $2/permissions.p7s}
  - {name: viz, type: lcm, url: "udpm://239.255.76.67:7667?ttl=0"}
channels:
  - {name: obstacle, subject: 0x10, class: nrt, publishers: [lan], subscribers: [viz]}
  - {name: drive, subject: 0x11, class: nrt, publishers: [viz], subscribers: [lan]}
components:
  - {name: detector, segment: lan, publishes: [obstacle], subject: "CN=detector,O=cosmic"}
  - {name: driver, segment: lan, subscribes: [drive]}
YAML
}
mkdir -p "$WORK/signed" "$WORK/plain"
gateway "$WORK/signed.yaml" signed
gateway "$WORK/plain.yaml" plain

# verify NAME FILE: the document verifies against the permissions CA and holds `drive`'s topic.
verify() {
  if ! openssl smime -verify -text -in "$2" -CAfile "$PKI/permissions_ca.pem" -out "$WORK/$1.verified" 2>/dev/null; then
    fail "$1: openssl smime -verify refuses $2"
  fi
}

# 1. Signed with the permissions CA: both documents in place, verified, 0644; the file loads.
run signed 0 security permissions "$WORK/signed.yaml" --sign-with "$PKI/permissions_ca.pem" "$PKI/permissions_ca_key.pem"
verify signed_governance "$WORK/signed/governance.p7s"
verify signed_permissions "$WORK/signed/permissions.p7s"
contains signed_governance verified "<enable_join_access_control>true</enable_join_access_control>"
contains signed_permissions verified "<subject_name>CN=gateway-a,O=cosmic</subject_name>"
contains signed_permissions verified "<subject_name>CN=detector,O=cosmic</subject_name>"
contains signed_permissions verified "<default>DENY</default>"
python3 - "$WORK/signed_permissions.verified" <<'PY' || fail "signed: cosmicd's grant publishes cosmic/drive and subscribes cosmic/obstacle"
import re, sys
text = open(sys.argv[1]).read()
grant = re.search(r'<grant name="gw-a">(.*?)</grant>', text, re.S).group(1)
publish = re.search(r"<publish>(.*?)</publish>", grant, re.S).group(1)
subscribe = re.search(r"<subscribe>(.*?)</subscribe>", grant, re.S).group(1)
assert re.findall(r"<topic>(.*?)</topic>", publish) == ["cosmic/drive"], publish
assert re.findall(r"<topic>(.*?)</topic>", subscribe) == ["cosmic/obstacle"], subscribe
PY
for f in governance permissions; do
  mode=$(stat -c %a "$WORK/signed/$f.p7s")
  [ "$mode" = 644 ] || fail "signed: $f.p7s has mode $mode, not 644"
done
[ -z "$(find "$WORK/signed" -name '.*')" ] || fail "signed: temporary files left: $(ls -A "$WORK/signed")"
contains signed out "grant gw-a: CN=gateway-a,O=cosmic"
contains signed err "note: component driver on the secure segment lan has no subject"
run signed_check 0 check "$WORK/signed.yaml"

# 2. Without the CA: the XML next to the configured paths, and the commands that sign them.
run plain 0 security permissions "$WORK/plain.yaml"
[ -f "$WORK/plain/governance.xml" ] && [ -f "$WORK/plain/permissions.xml" ] || fail "plain: no XML written"
[ ! -e "$WORK/plain/governance.p7s" ] || fail "plain: wrote a signed document without a CA"
contains plain out "openssl smime -sign -text -in $WORK/plain/permissions.xml -out $WORK/plain/permissions.p7s"
run plain_check_unsigned 2 check "$WORK/plain.yaml"
if ! PERMISSIONS_CA_KEY=$PKI/permissions_ca_key.pem bash -e "$WORK/plain.out" >"$WORK/sign.log" 2>&1; then
  fail "plain: the printed commands failed: $(cat "$WORK/sign.log")"
fi
run plain_check 0 check "$WORK/plain.yaml"
verify plain_permissions "$WORK/plain/permissions.p7s"
cmp -s "$WORK/plain_permissions.verified" "$WORK/signed_permissions.verified" ||
  fail "plain: the openssl-signed permissions differ from the ones --sign-with signed"

# 3. Refusals: each with its reason and status, no document changed.
checksums() { (cd "$WORK" && md5sum signed/* plain/*); }
checksums >"$WORK/before"
sign() { run "$1" "$2" security permissions "$WORK/signed.yaml" --sign-with "$3" "$4"; }
sign missing_key 64 "$PKI/permissions_ca.pem" "$PKI/nowhere_key.pem"
contains missing_key err "nowhere_key.pem: No such file or directory"
sign wrong_key 64 "$PKI/permissions_ca.pem" "$PKI/rogue_ca_key.pem"
contains wrong_key err "the CA key is not the key of the CA certificate"
cp "$PKI/permissions_ca_key.pem" "$WORK/open_ca_key.pem" && chmod 644 "$WORK/open_ca_key.pem"
sign open_key 64 "$PKI/permissions_ca.pem" "$WORK/open_ca_key.pem"
contains open_key err "group or others may read or write it (mode 0644; chmod 600 it)"
sign foreign_ca 64 "$PKI/rogue_ca.pem" "$PKI/rogue_ca_key.pem"
contains foreign_ca err "is not the permissions CA $PKI/permissions_ca.pem the configuration names"
run one_argument 64 security permissions "$WORK/signed.yaml" --sign-with "$PKI/permissions_ca.pem"
printf 'segments:\n  - {name: lan, type: dds, domain: 5}\nchannels: []\n' >"$WORK/open.yaml"
run no_security 2 security permissions "$WORK/open.yaml"
contains no_security err "no DDS segment has security: there are no documents to write"
# The governance's directory exists, the permissions' does not: neither is written.
sed 's|permissions: signed/permissions.p7s|permissions: missing/permissions.p7s|' "$WORK/signed.yaml" >"$WORK/half.yaml"
run unwritable 1 security permissions "$WORK/half.yaml" --sign-with "$PKI/permissions_ca.pem" "$PKI/permissions_ca_key.pem"
contains unwritable err "cannot write $WORK/missing/permissions.p7s: No such file or directory; no document was changed"
checksums >"$WORK/after"
cmp -s "$WORK/before" "$WORK/after" || fail "a refused run changed a document: $(diff "$WORK/before" "$WORK/after")"
[ -z "$(find "$WORK/signed" -name '.*')" ] || fail "unwritable: temporary files left: $(ls -A "$WORK/signed")"

finish "cosmicctl security permissions"

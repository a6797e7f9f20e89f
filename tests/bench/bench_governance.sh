#!/usr/bin/env bash
# bench_governance.sh DIR: the governance documents of scripts/bench's DDS Security rows, written
# into DIR, a PKI made by tests/support/make_test_pki.sh, whose governance (everything ENCRYPT,
# governance.p7s) is the "encryption" row. The other two are that document with other protection
# kinds (the same domains and topic rule), signed with the PKI's permissions CA as make_test_pki.sh
# signs its own:
#   governance_auth.p7s  authentication only: unauthenticated participants refused, join access
#                        control on, every protection kind NONE (RTPS messages, discovery,
#                        liveliness, metadata and data travel in the clear, unsigned)
#   governance_sign.p7s  signing: rtps_protection_kind SIGN (every RTPS message carries a GMAC),
#                        discovery and liveliness SIGN, metadata and data NONE. Fast DDS 2.9's
#                        data_protection_kind SIGN matches but delivers no sample (fixed upstream
#                        by eProsima/Fast-DDS PR #6498), so that setting cannot be measured here.
set -euo pipefail
dir=$1
cd "$dir"
umask 077

# variant NAME SED_SCRIPT: governance_NAME.xml from governance.xml, checked to hold no ENCRYPT any
# more (make_test_pki.sh's document changed shape otherwise), then signed.
variant() {
  sed -E "$2" governance.xml >"governance_$1.xml"
  if grep -q ENCRYPT "governance_$1.xml"; then
    echo "bench_governance: governance.xml has a protection kind this script does not rewrite" >&2
    exit 1
  fi
  openssl smime -sign -text -in "governance_$1.xml" -out "governance_$1.p7s" -signer permissions_ca.pem \
    -inkey permissions_ca_key.pem 2>"governance_$1.err" || { cat "governance_$1.err" >&2; exit 1; }
  rm -f "governance_$1.err"
  chmod 644 "governance_$1.xml" "governance_$1.p7s"
}
variant auth 's|>ENCRYPT<|>NONE<|; s|(<enable_(discovery\|liveliness)_protection>)true<|\1false<|'
variant sign 's|(<(discovery\|liveliness\|rtps)_protection_kind>)ENCRYPT<|\1SIGN<|; s|(<(metadata\|data)_protection_kind>)ENCRYPT<|\1NONE<|'

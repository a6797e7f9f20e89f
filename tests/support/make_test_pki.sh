#!/usr/bin/env bash
# make_test_pki.sh DIR: a DDS Security test PKI made with the openssl command line (never checked in):
# an identity CA and a permissions CA (ECDSA P-256), identities gateway-a, gateway-b and gateway-c
# ("/O=cosmic/CN=gateway-X", keys 0600), governance (everything ENCRYPT, as Fast DDS 2.9 and Cyclone
# DDS both handle it) and permissions granting gateway-a and gateway-b every topic of domains 0-230,
# gateway-c every topic to subscribe but only cosmic/telemetry and cosmic/federation to publish (it
# may join a federation; whether its gateways list it is theirs to say), and monitor every topic
# to subscribe and none to publish, signed S/MIME with -text as the DDS Security specification and Fast DDS want them.
# Under PKI-DH a participant's GUID prefix follows from its certificate's subject (bit 0 set, then
# the first 47 bits of SHA-256 over the subject's DER encoding): gateway-a b3.18, gateway-b ce.c4,
# gateway-c e0.f5, monitor a0.fa. It matters to Cyclone DDS peers, which complete a handshake with
# Fast DDS only when they start it, that is when their prefix is the lower (docs/security.md). Material for the
# refusals too: expired.pem (a gateway-b certificate valid 2020-2021), open_key.pem (0644),
# governance_unsigned.xml, permissions_rogue.p7s (signed by another CA), rogue_ca.pem.
set -euo pipefail
dir=$1
mkdir -p "$dir"
cd "$dir"
umask 077
quiet() { "$@" >/dev/null 2>&1 || { echo "make_test_pki: failed: $*" >&2; "$@"; exit 1; }; }

ca() {  # ca NAME SUBJECT KEYUSAGE
  quiet openssl ecparam -name prime256v1 -genkey -noout -out "$1_key.pem"
  quiet openssl req -x509 -new -key "$1_key.pem" -sha256 -days 30 -subj "$2" -out "$1.pem" \
    -addext "basicConstraints=critical,CA:TRUE" -addext "keyUsage=critical,$3"
}
ca identity_ca "/O=cosmic/CN=cosmic test identity CA" keyCertSign,cRLSign
ca permissions_ca "/O=cosmic/CN=cosmic test permissions CA" keyCertSign,cRLSign,digitalSignature
ca rogue_ca "/O=cosmic/CN=cosmic test permissions CA" keyCertSign,cRLSign,digitalSignature
printf 'basicConstraints=critical,CA:FALSE\nkeyUsage=critical,digitalSignature,keyAgreement\n' >leaf.cnf
for name in gateway-a gateway-b gateway-c monitor; do
  quiet openssl ecparam -name prime256v1 -genkey -noout -out "${name}_key.pem"
  quiet openssl req -new -key "${name}_key.pem" -subj "/O=cosmic/CN=$name" -out "$name.csr"
  quiet openssl x509 -req -in "$name.csr" -CA identity_ca.pem -CAkey identity_ca_key.pem -CAcreateserial -sha256 \
    -days 30 -extfile leaf.cnf -out "${name}_cert.pem"
done

# An expired certificate: `openssl ca` takes explicit dates.
mkdir -p cadb && : >cadb/index.txt && echo 1000 >cadb/serial
cat >ca.cnf <<'CNF'
[ ca ]
default_ca = test_ca
[ test_ca ]
dir = ./cadb
database = $dir/index.txt
new_certs_dir = $dir
serial = $dir/serial
default_md = sha256
policy = any
unique_subject = no
[ any ]
organizationName = supplied
commonName = supplied
[ leaf ]
basicConstraints = critical,CA:FALSE
keyUsage = critical,digitalSignature,keyAgreement
CNF
quiet openssl req -new -key gateway-b_key.pem -subj "/O=cosmic/CN=gateway-b" -out expired.csr
quiet openssl ca -batch -config ca.cnf -extensions leaf -cert identity_ca.pem -keyfile identity_ca_key.pem \
  -startdate 20200101000000Z -enddate 20210101000000Z -in expired.csr -out expired.pem -notext
cp gateway-b_key.pem open_key.pem && chmod 644 open_key.pem

cat >governance.xml <<'XML'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
XML
grant() {  # grant NAME
  cat <<XML
    <grant name="$1">
      <subject_name>CN=$1,O=cosmic</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        <publish><topics><topic>*</topic></topics></publish>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
XML
}
{
  echo '<?xml version="1.0" encoding="UTF-8"?>'
  echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
  echo '     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
  echo '  <permissions>'
  grant gateway-a
  grant gateway-b
  cat <<XML
    <grant name="gateway-c">
      <subject_name>CN=gateway-c,O=cosmic</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        <publish><topics><topic>cosmic/telemetry</topic><topic>cosmic/federation</topic></topics></publish>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
    <grant name="monitor">
      <subject_name>CN=monitor,O=cosmic</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
        <subscribe><topics><topic>*</topic></topics></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
XML
  echo '  </permissions>'
  echo '</dds>'
} >permissions.xml
for doc in governance permissions; do
  quiet openssl smime -sign -text -in "$doc.xml" -out "$doc.p7s" -signer permissions_ca.pem -inkey permissions_ca_key.pem
done
cp governance.xml governance_unsigned.xml
quiet openssl smime -sign -text -in permissions.xml -out permissions_rogue.p7s -signer rogue_ca.pem -inkey rogue_ca_key.pem
chmod 644 ./*.pem ./*.p7s ./*.xml && chmod 600 ./*_key.pem && chmod 644 open_key.pem

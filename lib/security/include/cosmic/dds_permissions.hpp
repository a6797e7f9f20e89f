// The DDS Security governance and permissions documents of a configuration (issue 36, item 1;
// `cosmicctl security permissions`, docs/security.md): per secure DDS segment, a governance that
// admits only authenticated participants, controls every topic's readers and writers and protects
// what they say as `DdsProtection` asks; and permissions that grant each participant exactly the
// topics the channel table gives it. cosmicd's grant on a segment publishes the topics of the
// channels that segment subscribes (cosmicd writes there) and subscribes the topics of the channels
// it publishes (cosmicd reads there), under their DDS names (cosmic/dds_names.hpp: cosmic/NAME, or
// a native binding's topic, rt/... for ROS 2), plus cosmic/federation on the federation's segment.
// A component that lives on a secure segment and declares `subject` gets a grant of what it
// publishes and subscribes there. The XML follows the OMG schemas (omg_shared_ca_governance.xsd,
// omg_shared_ca_permissions.xsd) in the element order Fast DDS 2.9's parsers require.
//
// Pure: no I/O, no clock (the validity comes with the identities). Any thread.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cosmic/model.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// What the governance asks of the messages (`--protection`):
//   encrypt: discovery, liveliness, RTPS messages and every topic's metadata and data encrypted
//            (AES-GCM), which Fast DDS 2.9 and Cyclone DDS both handle;
//   sign:    discovery, liveliness and whole RTPS messages signed (GMAC), topics' metadata and data
//            left to that: Fast DDS 2.9 delivers no sample of a topic with data_protection_kind
//            SIGN (a padding bug, fixed upstream by Fast DDS PR #6498);
//   none:    nothing signed or encrypted; authentication and access control still apply.
enum class DdsProtection { encrypt, sign, none };
const char* to_string(DdsProtection value);

// A grant's validity, in the documents' form: UTC, "2024-01-31T12:00:00".
struct GrantValidity {
  std::string not_before;
  std::string not_after;
  friend bool operator==(const GrantValidity&, const GrantValidity&) = default;
};

// cosmicd's identity on one secure DDS segment: the subject of the segment's certificate in RFC
// 2253 form ("CN=gateway-a,O=cosmic"), and the validity of the grants written for that segment
// (its own, and its components').
struct DdsSegmentIdentity {
  std::string segment;
  std::string subject;
  GrantValidity validity;
};

// What a participant may do in one domain: the topics it may publish and subscribe, in the order of
// the channel table, each once.
struct DdsAllowRule {
  std::string segment;  // the segment whose domain this is
  std::uint32_t domain = 0;
  std::vector<std::string> publish;
  std::vector<std::string> subscribe;
  friend bool operator==(const DdsAllowRule&, const DdsAllowRule&) = default;
};

// One participant's grant (one per subject and document; everything else is denied).
struct DdsGrant {
  std::string name;     // the gateway's name, or the component's
  std::string subject;  // RFC 2253
  GrantValidity validity;
  std::vector<DdsAllowRule> rules;
  friend bool operator==(const DdsGrant&, const DdsGrant&) = default;
};

struct DdsGovernanceDocument {
  std::string path;                    // the segments' `security.governance`, where it goes signed
  std::vector<std::uint32_t> domains;  // one domain_rule each
  std::string xml;
};

struct DdsPermissionsDocument {
  std::string path;  // the segments' `security.permissions`, where it goes signed
  std::vector<DdsGrant> grants;
  std::string xml;
};

struct DdsAccessDocuments {
  // One document per distinct path, in the order of the segments naming them.
  std::vector<DdsGovernanceDocument> governance;
  std::vector<DdsPermissionsDocument> permissions;
  // What the operator should know but does not stop the documents: a component on a secure segment
  // without `subject` (no grant), a component sharing cosmicd's subject (one grant for both).
  std::vector<std::string> notes;
};

// The documents of every secure DDS segment of `config`, with cosmicd's identity on each from
// `identities`. Fails when no DDS segment has `security`, or a secure segment has no identity.
Result<DdsAccessDocuments> dds_access_documents(const Config& config, std::span<const DdsSegmentIdentity> identities,
                                                DdsProtection protection);

// The documents' XML (UTF-8), names and subjects escaped.
std::string governance_xml(std::span<const std::uint32_t> domains, DdsProtection protection);
std::string permissions_xml(std::span<const DdsGrant> grants);

// The strongest protection a governance document (its XML, signed or not) asks for anywhere: any
// *_protection_kind of ENCRYPT or ENCRYPT_WITH_ORIGIN_AUTHENTICATION is `encrypt`, else any SIGN... is
// `sign`, else `none`. What `cosmicctl calibrate` times a secure segment's hop with: the worst its
// samples can meet. Fails when the text names no protection kind at all (not a governance).
Result<DdsProtection> governance_protection(std::string_view governance);

}  // namespace cosmic

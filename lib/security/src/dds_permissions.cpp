// The governance and permissions documents of a configuration (cosmic/dds_permissions.hpp).
#include "cosmic/dds_permissions.hpp"

#include <algorithm>

#include "cosmic/dds_names.hpp"

namespace cosmic {
namespace {

constexpr const char* kXmlDeclaration = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
constexpr const char* kSchemaBase = "http://www.omg.org/spec/DDS-SECURITY/20170901/";

// Text and attribute values: the five characters XML reserves.
std::string escaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out.push_back(c);
    }
  }
  return out;
}

std::string document_head(const char* schema) {
  return std::string(kXmlDeclaration) +
         "<dds xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\"\n"
         "     xsi:noNamespaceSchemaLocation=\"" +
         kSchemaBase + schema + "\">\n";
}

// The governance's protection kinds for `protection`: RTPS-wide (discovery, liveliness, messages)
// and per topic (metadata, data).
struct ProtectionKinds {
  const char* participant;
  const char* topic;
  bool topic_discovery_and_liveliness;
};

ProtectionKinds kinds_of(DdsProtection protection) {
  switch (protection) {
    case DdsProtection::encrypt:
      return {"ENCRYPT", "ENCRYPT", true};
    case DdsProtection::sign:
      // Not SIGN per topic: Fast DDS 2.9 then delivers no sample (DdsProtection says why).
      return {"SIGN", "NONE", true};
    case DdsProtection::none:
      break;
  }
  return {"NONE", "NONE", false};
}

bool contains(const std::vector<std::string>& list, const std::string& value) {
  return std::find(list.begin(), list.end(), value) != list.end();
}

void add_once(std::vector<std::string>& list, const std::string& value) {
  if (!contains(list, value)) list.push_back(value);
}

// cosmicd's topics on the DDS segment `segment`: it writes where the segment subscribes a channel,
// reads where it publishes one, and does both on the federation's topic.
DdsAllowRule gateway_rule(const Config& config, const SegmentSpec& segment) {
  DdsAllowRule rule{segment.name, segment.dds.domain, {}, {}};
  for (const ChannelSpec& channel : config.channels) {
    const std::string topic = dds_topic_of(channel, segment.name).topic;
    if (contains(channel.subscribers, segment.name)) add_once(rule.publish, topic);
    if (contains(channel.publishers, segment.name)) add_once(rule.subscribe, topic);
  }
  if (config.gateway.federation.segment == segment.name) {
    add_once(rule.publish, kFederationTopicName);
    add_once(rule.subscribe, kFederationTopicName);
  }
  return rule;
}

// A component's topics on its segment: what it publishes and subscribes there.
DdsAllowRule component_rule(const Config& config, const ComponentSpec& component, const SegmentSpec& segment) {
  DdsAllowRule rule{segment.name, segment.dds.domain, {}, {}};
  for (const auto* names : {&component.publishes, &component.subscribes}) {
    for (const std::string& name : *names) {
      const ChannelSpec* channel = config.find_channel(name);
      if (channel == nullptr) continue;  // the loader refuses such a component
      add_once(names == &component.publishes ? rule.publish : rule.subscribe,
               dds_topic_of(*channel, segment.name).topic);
    }
  }
  return rule;
}

// Adds `rule` to the grant of `subject` in `document`, made with `name` and `validity` if the
// document has none yet; a grant that already exists keeps its name, narrows its validity to both,
// and takes the rule's topics into its rule for the same segment. Returns the grant's name.
std::string grant(DdsPermissionsDocument& document, const std::string& name, const std::string& subject,
                  const GrantValidity& validity, DdsAllowRule rule) {
  auto it = std::find_if(document.grants.begin(), document.grants.end(),
                         [&](const DdsGrant& g) { return g.subject == subject; });
  if (it == document.grants.end()) {
    document.grants.push_back(DdsGrant{name, subject, validity, {std::move(rule)}});
    return name;
  }
  // The fixed-width form orders as the times do.
  it->validity.not_before = std::max(it->validity.not_before, validity.not_before);
  it->validity.not_after = std::min(it->validity.not_after, validity.not_after);
  auto same = std::find_if(it->rules.begin(), it->rules.end(),
                           [&](const DdsAllowRule& r) { return r.segment == rule.segment; });
  if (same == it->rules.end()) {
    it->rules.push_back(std::move(rule));
  } else {
    for (const std::string& topic : rule.publish) add_once(same->publish, topic);
    for (const std::string& topic : rule.subscribe) add_once(same->subscribe, topic);
  }
  return it->name;
}

template <typename Document>
Document& document_at(std::vector<Document>& documents, const std::string& path) {
  auto it = std::find_if(documents.begin(), documents.end(), [&](const Document& d) { return d.path == path; });
  if (it != documents.end()) return *it;
  documents.push_back(Document{path, {}, {}});
  return documents.back();
}

void append_topics(std::string& out, const char* element, const std::vector<std::string>& topics) {
  if (topics.empty()) return;
  out += std::string("        <") + element + ">\n          <topics>\n";
  for (const std::string& topic : topics) out += "            <topic>" + escaped(topic) + "</topic>\n";
  out += std::string("          </topics>\n        </") + element + ">\n";
}

}  // namespace

const char* to_string(DdsProtection value) {
  switch (value) {
    case DdsProtection::encrypt:
      return "encrypt";
    case DdsProtection::sign:
      return "sign";
    case DdsProtection::none:
      break;
  }
  return "none";
}

std::string governance_xml(std::span<const std::uint32_t> domains, DdsProtection protection) {
  const ProtectionKinds kinds = kinds_of(protection);
  const std::string p = kinds.participant;
  const std::string t = kinds.topic;
  const std::string topic_protection = kinds.topic_discovery_and_liveliness ? "true" : "false";
  std::string out = document_head("omg_shared_ca_governance.xsd") + "  <domain_access_rules>\n";
  for (const std::uint32_t domain : domains) {
    out +=
        "    <domain_rule>\n"
        "      <domains><id>" +
        std::to_string(domain) +
        "</id></domains>\n"
        "      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>\n"
        "      <enable_join_access_control>true</enable_join_access_control>\n"
        "      <discovery_protection_kind>" +
        p + "</discovery_protection_kind>\n      <liveliness_protection_kind>" + p +
        "</liveliness_protection_kind>\n      <rtps_protection_kind>" + p +
        "</rtps_protection_kind>\n"
        "      <topic_access_rules>\n"
        "        <topic_rule>\n"
        "          <topic_expression>*</topic_expression>\n"
        "          <enable_discovery_protection>" +
        topic_protection + "</enable_discovery_protection>\n          <enable_liveliness_protection>" +
        topic_protection +
        "</enable_liveliness_protection>\n"
        "          <enable_read_access_control>true</enable_read_access_control>\n"
        "          <enable_write_access_control>true</enable_write_access_control>\n"
        "          <metadata_protection_kind>" +
        t + "</metadata_protection_kind>\n          <data_protection_kind>" + t +
        "</data_protection_kind>\n"
        "        </topic_rule>\n"
        "      </topic_access_rules>\n"
        "    </domain_rule>\n";
  }
  return out + "  </domain_access_rules>\n</dds>\n";
}

std::string permissions_xml(std::span<const DdsGrant> grants) {
  std::string out = document_head("omg_shared_ca_permissions.xsd") + "  <permissions>\n";
  for (const DdsGrant& g : grants) {
    out += "    <grant name=\"" + escaped(g.name) + "\">\n      <subject_name>" + escaped(g.subject) +
           "</subject_name>\n      <validity><not_before>" + g.validity.not_before + "</not_before><not_after>" +
           g.validity.not_after + "</not_after></validity>\n";
    for (const DdsAllowRule& rule : g.rules) {
      out += "      <allow_rule>\n        <domains><id>" + std::to_string(rule.domain) + "</id></domains>\n";
      append_topics(out, "publish", rule.publish);
      append_topics(out, "subscribe", rule.subscribe);
      out += "      </allow_rule>\n";
    }
    out += "      <default>DENY</default>\n    </grant>\n";
  }
  return out + "  </permissions>\n</dds>\n";
}

Result<DdsAccessDocuments> dds_access_documents(const Config& config, std::span<const DdsSegmentIdentity> identities,
                                                DdsProtection protection) {
  DdsAccessDocuments out;
  auto identity_of = [&](const std::string& segment) -> const DdsSegmentIdentity* {
    for (const DdsSegmentIdentity& identity : identities) {
      if (identity.segment == segment) return &identity;
    }
    return nullptr;
  };
  bool any = false;
  for (const SegmentSpec& segment : config.segments) {
    if (segment.type != SegmentType::dds || !segment.dds.security) continue;
    any = true;
    const DdsSegmentIdentity* identity = identity_of(segment.name);
    if (identity == nullptr) return Error{"no identity given for the secure DDS segment " + segment.name};
    DdsGovernanceDocument& governance = document_at(out.governance, segment.dds.security->governance);
    if (std::find(governance.domains.begin(), governance.domains.end(), segment.dds.domain) == governance.domains.end())
      governance.domains.push_back(segment.dds.domain);
    DdsPermissionsDocument& permissions = document_at(out.permissions, segment.dds.security->permissions);
    // Another certificate of this gateway already has the plain name in this document.
    const bool named = std::any_of(permissions.grants.begin(), permissions.grants.end(), [&](const DdsGrant& g) {
      return g.name == config.gateway.name && g.subject != identity->subject;
    });
    grant(permissions, named ? config.gateway.name + " on " + segment.name : config.gateway.name, identity->subject,
          identity->validity, gateway_rule(config, segment));
  }
  if (!any) return Error{"no DDS segment has security: there are no documents to write"};
  for (const ComponentSpec& component : config.components) {
    const SegmentSpec* segment = config.find_segment(component.segment);
    if (segment == nullptr || segment->type != SegmentType::dds || !segment->dds.security) continue;
    if (component.subject.empty()) {
      out.notes.push_back("component " + component.name + " on the secure segment " + segment->name +
                          " has no subject: no grant written for it (declare its certificate's subject, e.g. "
                          "subject: CN=" +
                          component.name + ",O=cosmic)");
      continue;
    }
    DdsPermissionsDocument& permissions = document_at(out.permissions, segment->dds.security->permissions);
    const std::string name = grant(permissions, component.name, component.subject, identity_of(segment->name)->validity,
                                   component_rule(config, component, *segment));
    if (name != component.name) {
      out.notes.push_back("component " + component.name + " has the subject " + component.subject + " of grant " +
                          name + ": one grant holds the topics of both");
    }
  }
  for (DdsGovernanceDocument& document : out.governance) document.xml = governance_xml(document.domains, protection);
  for (DdsPermissionsDocument& document : out.permissions) document.xml = permissions_xml(document.grants);
  return out;
}

Result<DdsProtection> governance_protection(std::string_view governance) {
  constexpr std::string_view kSuffix = "_protection_kind>";
  bool named = false;
  DdsProtection strongest = DdsProtection::none;
  for (std::size_t at = governance.find(kSuffix); at != std::string_view::npos;
       at = governance.find(kSuffix, at + kSuffix.size())) {
    // An opening tag (`<rtps_protection_kind>`), not a closing one: its value follows it.
    const std::size_t open = governance.rfind('<', at);
    if (open == std::string_view::npos || governance.substr(open, 2) == "</") continue;
    named = true;
    std::size_t value = at + kSuffix.size();
    while (value < governance.size() && std::string_view(" \t\r\n").find(governance[value]) != std::string_view::npos)
      ++value;
    const std::string_view kind = governance.substr(value);
    if (kind.starts_with("ENCRYPT")) strongest = DdsProtection::encrypt;
    if (kind.starts_with("SIGN") && strongest == DdsProtection::none) strongest = DdsProtection::sign;
  }
  if (!named) return Error{"names no protection kind: not a DDS Security governance document"};
  return strongest;
}

}  // namespace cosmic

// The DDS Security documents of a configuration (cosmic/dds_permissions.hpp): the exact governance
// and permissions XML for a small configuration (two secure segments sharing a governance, the
// federation on one of them, a native ROS 2 topic, components with and without a subject, names
// that need escaping), which topics cosmicd publishes and which it subscribes, that a segment
// without security gets no grant, the protection kinds, and grants merged by subject.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cosmic/dds_permissions.hpp"

namespace cosmic {
namespace {

SegmentSpec permissions_test_segment(const std::string& name, SegmentType type, std::uint32_t domain,
                                     const std::string& governance = "", const std::string& permissions = "") {
  SegmentSpec s;
  s.name = name;
  s.type = type;
  s.dds.domain = domain;
  if (!governance.empty()) {
    DdsSecuritySpec security;
    security.governance = governance;
    security.permissions = permissions;
    s.dds.security = security;
  }
  return s;
}

ChannelSpec permissions_test_channel(const std::string& name, std::vector<std::string> publishers,
                                     std::vector<std::string> subscribers) {
  ChannelSpec c;
  c.name = name;
  c.publishers = std::move(publishers);
  c.subscribers = std::move(subscribers);
  return c;
}

// lan (domain 3) and backbone (domain 9) are secure and share a governance; plain (domain 4) is not;
// body is a CAN bus. The federation runs on backbone.
Config permissions_test_config() {
  Config config;
  config.gateway.name = "gw-a";
  config.gateway.federation.segment = "backbone";
  config.segments = {permissions_test_segment("lan", SegmentType::dds, 3, "/pki/governance.p7s", "/pki/lan.p7s"),
                     permissions_test_segment("backbone", SegmentType::dds, 9, "/pki/governance.p7s", "/pki/bb.p7s"),
                     permissions_test_segment("plain", SegmentType::dds, 4),
                     permissions_test_segment("body", SegmentType::can, 0)};
  config.channels = {permissions_test_channel("obstacle", {"lan"}, {"body", "backbone"}),
                     permissions_test_channel("drive", {"body"}, {"lan"}),
                     permissions_test_channel("cmd.vel", {"lan"}, {"plain"}),
                     permissions_test_channel("telemetry", {"plain"}, {"body"})};
  NativeBinding ros;
  ros.segment = "lan";
  ros.dds = NativeDdsTopic{"rt/cmd_vel", "geometry_msgs::msg::dds_::Twist_", DdsRepresentation::xcdr1};
  config.channels[2].native = {ros};
  config.components = {
      ComponentSpec{"detector", "lan", {"obstacle"}, {}, "CN=detector,O=R&D <\"lab\">"},
      ComponentSpec{"driver", "lan", {}, {"drive"}, ""},
      ComponentSpec{"joystick", "plain", {"telemetry"}, {}, "CN=joystick,O=cosmic"},
  };
  return config;
}

const GrantValidity kYear2025{"2025-01-01T00:00:00", "2026-01-01T00:00:00"};

std::vector<DdsSegmentIdentity> permissions_test_identities() {
  return {{"lan", "CN=gateway-a,O=cosmic", kYear2025}, {"backbone", "CN=gateway-a,O=cosmic", kYear2025}};
}

DdsAccessDocuments documents_of(const Config& config, DdsProtection protection = DdsProtection::encrypt) {
  const auto identities = permissions_test_identities();
  auto documents = dds_access_documents(config, identities, protection);
  EXPECT_TRUE(documents) << (documents ? "" : documents.error().text);
  return documents ? std::move(documents).value() : DdsAccessDocuments{};
}

const DdsPermissionsDocument* permissions_at(const DdsAccessDocuments& documents, const std::string& path) {
  for (const auto& d : documents.permissions) {
    if (d.path == path) return &d;
  }
  return nullptr;
}

constexpr const char* kEncryptedDomainRule =
    R"(      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
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
)";

TEST(DdsPermissions, TheGovernanceOfTwoSegmentsIsOneDocumentWithARulePerDomain) {
  const auto documents = documents_of(permissions_test_config());
  ASSERT_EQ(documents.governance.size(), 1u);
  EXPECT_EQ(documents.governance[0].path, "/pki/governance.p7s");
  EXPECT_EQ(documents.governance[0].xml, std::string(R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id>3</id></domains>
)") + kEncryptedDomainRule +
                                             R"(    <domain_rule>
      <domains><id>9</id></domains>
)" + kEncryptedDomainRule +
                                             R"(  </domain_access_rules>
</dds>
)");
}

TEST(DdsPermissions, ThePermissionsOfASegmentGrantCosmicdAndItsComponentsExactlyTheirTopics) {
  const auto documents = documents_of(permissions_test_config());
  ASSERT_EQ(documents.permissions.size(), 2u);
  const auto* lan = permissions_at(documents, "/pki/lan.p7s");
  ASSERT_NE(lan, nullptr);
  // cosmicd writes drive (lan subscribes it) and reads obstacle and the ROS 2 topic of cmd.vel (lan
  // publishes them); the detector publishes obstacle; driver has no subject, joystick is not on a
  // secure segment; telemetry never touches a secure segment.
  EXPECT_EQ(lan->xml, R"(<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="gw-a">
      <subject_name>CN=gateway-a,O=cosmic</subject_name>
      <validity><not_before>2025-01-01T00:00:00</not_before><not_after>2026-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id>3</id></domains>
        <publish>
          <topics>
            <topic>cosmic/drive</topic>
          </topics>
        </publish>
        <subscribe>
          <topics>
            <topic>cosmic/obstacle</topic>
            <topic>rt/cmd_vel</topic>
          </topics>
        </subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
    <grant name="detector">
      <subject_name>CN=detector,O=R&amp;D &lt;&quot;lab&quot;&gt;</subject_name>
      <validity><not_before>2025-01-01T00:00:00</not_before><not_after>2026-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id>3</id></domains>
        <publish>
          <topics>
            <topic>cosmic/obstacle</topic>
          </topics>
        </publish>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
)");
}

TEST(DdsPermissions, TheFederationsSegmentAlsoGrantsTheFederationTopicBothWays) {
  const auto documents = documents_of(permissions_test_config());
  const auto* backbone = permissions_at(documents, "/pki/bb.p7s");
  ASSERT_NE(backbone, nullptr);
  ASSERT_EQ(backbone->grants.size(), 1u);
  const DdsGrant& grant = backbone->grants[0];
  EXPECT_EQ(grant.name, "gw-a");
  ASSERT_EQ(grant.rules.size(), 1u);
  EXPECT_EQ(grant.rules[0].domain, 9u);
  // backbone subscribes obstacle: cosmicd writes it there.
  EXPECT_EQ(grant.rules[0].publish, (std::vector<std::string>{"cosmic/obstacle", "cosmic/federation"}));
  EXPECT_EQ(grant.rules[0].subscribe, (std::vector<std::string>{"cosmic/federation"}));
  EXPECT_NE(backbone->xml.find("<subscribe>\n          <topics>\n            <topic>cosmic/federation</topic>\n"),
            std::string::npos)
      << backbone->xml;
}

TEST(DdsPermissions, ASegmentWithoutSecurityGetsNoGrant) {
  const auto documents = documents_of(permissions_test_config());
  for (const auto& d : documents.permissions) {
    for (const auto& grant : d.grants) {
      EXPECT_NE(grant.name, "joystick");
      for (const auto& rule : grant.rules) {
        EXPECT_NE(rule.domain, 4u) << grant.name;
        EXPECT_NE(rule.segment, "plain") << grant.name;
      }
    }
    EXPECT_EQ(d.xml.find("telemetry"), std::string::npos) << d.xml;
  }
  for (const auto& d : documents.governance) EXPECT_EQ(d.xml.find("<id>4</id>"), std::string::npos) << d.xml;
}

TEST(DdsPermissions, AComponentOnASecureSegmentWithoutSubjectIsNotedNotGranted) {
  const auto documents = documents_of(permissions_test_config());
  ASSERT_EQ(documents.notes.size(), 1u);
  EXPECT_EQ(documents.notes[0],
            "component driver on the secure segment lan has no subject: no grant written for it (declare its "
            "certificate's subject, e.g. subject: CN=driver,O=cosmic)");
}

TEST(DdsPermissions, SignSignsRtpsMessagesAndLeavesTopicDataToThem) {
  const auto documents = documents_of(permissions_test_config(), DdsProtection::sign);
  const std::string& xml = documents.governance.at(0).xml;
  EXPECT_NE(xml.find("<discovery_protection_kind>SIGN</discovery_protection_kind>\n"
                     "      <liveliness_protection_kind>SIGN</liveliness_protection_kind>\n"
                     "      <rtps_protection_kind>SIGN</rtps_protection_kind>"),
            std::string::npos)
      << xml;
  // Never SIGN per topic: Fast DDS 2.9 would deliver no sample.
  EXPECT_NE(xml.find("<metadata_protection_kind>NONE</metadata_protection_kind>\n"
                     "          <data_protection_kind>NONE</data_protection_kind>"),
            std::string::npos)
      << xml;
  EXPECT_EQ(xml.find("ENCRYPT"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<enable_read_access_control>true</enable_read_access_control>"), std::string::npos);
}

TEST(DdsPermissions, NoneProtectsNothingButStillAuthenticatesAndControlsAccess) {
  const auto documents = documents_of(permissions_test_config(), DdsProtection::none);
  const std::string& xml = documents.governance.at(0).xml;
  EXPECT_EQ(xml.find("SIGN"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("ENCRYPT"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<enable_discovery_protection>false</enable_discovery_protection>"), std::string::npos) << xml;
  EXPECT_NE(xml.find("<allow_unauthenticated_participants>false</allow_unauthenticated_participants>"),
            std::string::npos);
  EXPECT_NE(xml.find("<enable_join_access_control>true</enable_join_access_control>"), std::string::npos);
  EXPECT_NE(xml.find("<enable_write_access_control>true</enable_write_access_control>"), std::string::npos);
}

// Segments naming one permissions file: one grant per subject, a rule per segment, valid only when
// every certificate it stands for is; a component with cosmicd's subject joins cosmicd's grant.
TEST(DdsPermissions, SegmentsSharingAPermissionsFileShareTheGrantOfTheirSubject) {
  Config config = permissions_test_config();
  config.segments[1].dds.security->permissions = "/pki/lan.p7s";
  config.components[0].subject = "CN=gateway-a,O=cosmic";
  std::vector<DdsSegmentIdentity> identities = permissions_test_identities();
  identities[1].validity = {"2025-06-01T00:00:00", "2027-01-01T00:00:00"};
  const auto documents = dds_access_documents(config, identities, DdsProtection::encrypt);
  ASSERT_TRUE(documents);
  ASSERT_EQ(documents.value().permissions.size(), 1u);
  const auto& grants = documents.value().permissions[0].grants;
  ASSERT_EQ(grants.size(), 1u);
  EXPECT_EQ(grants[0].validity, (GrantValidity{"2025-06-01T00:00:00", "2026-01-01T00:00:00"}));
  ASSERT_EQ(grants[0].rules.size(), 2u);
  EXPECT_EQ(grants[0].rules[0].segment, "lan");
  EXPECT_EQ(grants[0].rules[0].publish, (std::vector<std::string>{"cosmic/drive", "cosmic/obstacle"}));
  EXPECT_EQ(grants[0].rules[1].segment, "backbone");
  const auto& notes = documents.value().notes;
  EXPECT_NE(std::find(notes.begin(), notes.end(),
                      "component detector has the subject CN=gateway-a,O=cosmic of grant gw-a: one grant holds the "
                      "topics of both"),
            notes.end());
}

TEST(DdsPermissions, AConfigurationWithoutSecureSegmentsOrWithoutAnIdentityIsRefused) {
  Config plain = permissions_test_config();
  for (auto& s : plain.segments) s.dds.security.reset();
  const auto identities = permissions_test_identities();
  const auto none = dds_access_documents(plain, identities, DdsProtection::encrypt);
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().text, "no DDS segment has security: there are no documents to write");
  const std::vector<DdsSegmentIdentity> only_lan{identities[0]};
  const auto missing = dds_access_documents(permissions_test_config(), only_lan, DdsProtection::encrypt);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().text, "no identity given for the secure DDS segment backbone");
}

}  // namespace
}  // namespace cosmic

namespace cosmic {
namespace {

// What `cosmicctl calibrate` times a secure segment with: the strongest kind the governance names.
TEST(DdsPermissions, AGovernancesProtectionIsTheStrongestKindItNames) {
  const std::vector<std::uint32_t> domains{0, 5};
  for (const DdsProtection kind : {DdsProtection::encrypt, DdsProtection::sign, DdsProtection::none}) {
    const auto read = governance_protection(governance_xml(domains, kind));
    ASSERT_TRUE(read) << read.error().text;
    EXPECT_EQ(read.value(), kind) << to_string(kind);
  }
  // Anywhere: a topic's ENCRYPT under a participant's SIGN, origin authentication, spaces, and a
  // closing tag that looks like an opening one never count.
  EXPECT_EQ(governance_protection("<rtps_protection_kind>SIGN</rtps_protection_kind>"
                                  "<data_protection_kind> ENCRYPT_WITH_ORIGIN_AUTHENTICATION</data_protection_kind>")
                .value(),
            DdsProtection::encrypt);
  EXPECT_EQ(governance_protection("<rtps_protection_kind>\n  SIGN_WITH_ORIGIN_AUTHENTICATION\n</rtps_protection_kind>")
                .value(),
            DdsProtection::sign);
  EXPECT_EQ(governance_protection("<x>ENCRYPT</x><rtps_protection_kind>NONE</rtps_protection_kind>").value(),
            DdsProtection::none);
  const auto not_governance = governance_protection("<permissions><grant/></permissions>");
  ASSERT_FALSE(not_governance);
  EXPECT_EQ(not_governance.error().text, "names no protection kind: not a DDS Security governance document");
}

}  // namespace
}  // namespace cosmic

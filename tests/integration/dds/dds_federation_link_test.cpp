// The federation's DDS transport (cosmic/dds_federation_link.hpp), two gateways' links in one
// process on one domain: the newest announcement arrives under its key, a link never hears itself,
// a withdrawal and a writer that goes are reported with the writer that announced. Run under TSan
// by scripts/test (the listener threads queue, the test thread takes).
#include "cosmic/dds_federation_link.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "test_support.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;
using Kind = FederationMessage::Kind;

SegmentSpec federation_segment() {
  SegmentSpec s;
  s.name = "backbone";
  s.type = SegmentType::dds;
  s.dds.domain = 57;
  return s;
}

FederationSpec lease_of(Nanos lease) {
  FederationSpec f;
  f.segment = "backbone";
  f.lease = lease;
  return f;
}

// Takes from `link` until `wanted` is among what it delivered (all kept in `heard`).
bool hears(FederationLink& link, std::vector<FederationMessage>& heard,
           const std::function<bool(const FederationMessage&)>& wanted) {
  return test::eventually(
      [&] {
        for (auto& m : link.take()) heard.push_back(std::move(m));
        return std::any_of(heard.begin(), heard.end(), wanted);
      },
      20s);
}

TEST(DdsFederationLink, AnnouncesWithdrawsAndReportsAWriterThatGoes) {
  test::StderrLogger log;
  auto a = make_dds_federation_link(federation_segment(), GatewayIdentity{0xA, "a"}, lease_of(1s), log);
  auto b = make_dds_federation_link(federation_segment(), GatewayIdentity{0xB, "b"}, lease_of(1s), log);
  ASSERT_EQ(a->start(), "");
  ASSERT_EQ(b->start(), "");
  ASSERT_TRUE(a->publish(0xA, "first"));
  ASSERT_TRUE(a->publish(0xA, "second"));
  ASSERT_TRUE(b->publish(0xB, "b's own"));
  std::vector<FederationMessage> heard;
  // Durable, KEEP_LAST 1: the newest of a's announcements, whenever b matched.
  ASSERT_TRUE(hears(*b, heard,
                    [](const auto& m) { return m.kind == Kind::announcement && m.key == 0xA && m.body == "second"; }));
  EXPECT_TRUE(std::none_of(heard.begin(), heard.end(), [](const auto& m) { return m.key == 0xB; }))
      << "a link never hears itself";
  const std::string writer =
      std::find_if(heard.begin(), heard.end(), [](const auto& m) { return m.key == 0xA; })->source;
  EXPECT_FALSE(writer.empty());

  a->withdraw();
  ASSERT_TRUE(hears(*b, heard, [&](const auto& m) { return m.kind == Kind::withdrawn && m.source == writer; }));
  a.reset();  // the participant goes: its writer is unmatched
  ASSERT_TRUE(hears(*b, heard, [&](const auto& m) { return m.kind == Kind::lost && m.source == writer; }));
  EXPECT_EQ(b->counters().published, 1u);
  EXPECT_EQ(b->counters().dropped, 0u);
}

}  // namespace
}  // namespace cosmic

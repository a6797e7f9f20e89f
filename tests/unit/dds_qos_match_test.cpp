// The DDS request-vs-offered matching rules the gateway applies to discovered endpoints itself
// (issue 22, item 11; cosmic/dds_qos_match.hpp): every rule, with our endpoint as the writer and
// as the reader, and the wording of the reasons from our side.
#include <gtest/gtest.h>

#include <chrono>

#include "cosmic/dds_qos_match.hpp"

namespace cosmic {
namespace {

using namespace std::chrono_literals;

// What a default DDS endpoint announces: the pair matches.
DdsEndpointQos endpoint() {
  DdsEndpointQos e;
  e.topic = "cosmic/wheel";
  e.type_name = "cosmic::Envelope";
  return e;
}

std::vector<DdsMatchPolicy> policies(const std::vector<DdsMatchConflict>& conflicts) {
  std::vector<DdsMatchPolicy> out;
  for (const auto& c : conflicts) out.push_back(c.policy);
  return out;
}

// Our writer against a remote reader, and our reader against a remote writer, with the same
// two endpoints in the writer and reader roles: both must find exactly `expected`.
void expect_conflict(const DdsEndpointQos& writer, const DdsEndpointQos& reader, DdsMatchPolicy expected) {
  const auto as_writer = dds_match_conflicts(writer, reader, DdsLocalRole::writer);
  const auto as_reader = dds_match_conflicts(reader, writer, DdsLocalRole::reader);
  EXPECT_EQ(policies(as_writer), std::vector{expected}) << (as_writer.empty() ? "" : as_writer[0].reason);
  EXPECT_EQ(policies(as_reader), std::vector{expected}) << (as_reader.empty() ? "" : as_reader[0].reason);
}

void expect_match(const DdsEndpointQos& writer, const DdsEndpointQos& reader) {
  EXPECT_TRUE(dds_match_conflicts(writer, reader, DdsLocalRole::writer).empty());
  EXPECT_TRUE(dds_match_conflicts(reader, writer, DdsLocalRole::reader).empty());
}

TEST(DdsQosMatch, DefaultEndpointsMatch) { expect_match(endpoint(), endpoint()); }

TEST(DdsQosMatch, DataRepresentationOfferedMustBeAccepted) {
  auto writer = endpoint(), reader = endpoint();
  reader.representations = {DdsDataRepresentationId::xcdr2};  // e.g. Cyclone reader of an appendable type
  expect_conflict(writer, reader, DdsMatchPolicy::data_representation);
  writer.representations = {DdsDataRepresentationId::xcdr2, DdsDataRepresentationId::xcdr1};  // offers its first
  expect_match(writer, reader);
  reader.representations = {};  // empty: XCDR1 only
  expect_conflict(writer, reader, DdsMatchPolicy::data_representation);
  reader.representations = {DdsDataRepresentationId::xcdr1, DdsDataRepresentationId::xcdr2};
  expect_match(writer, reader);
  writer.representations = {DdsDataRepresentationId::xml};
  expect_conflict(writer, reader, DdsMatchPolicy::data_representation);
}

TEST(DdsQosMatch, DataRepresentationReasonsAreWordedFromOurSide) {
  auto ours = endpoint(), theirs = endpoint();
  ours.extensibility = DdsTypeExtensibility::final_kind;
  theirs.representations = {DdsDataRepresentationId::xcdr2};
  const auto as_writer = dds_match_conflicts(ours, theirs, DdsLocalRole::writer);
  ASSERT_EQ(as_writer.size(), 1u);
  EXPECT_EQ(as_writer[0].reason.rfind("requests data representation XCDR2 only, this writer offers XCDR1 (", 0), 0u)
      << as_writer[0].reason;
  EXPECT_NE(as_writer[0].reason.find("appendable or mutable, this one is final"), std::string::npos)
      << as_writer[0].reason;
  const auto as_reader = dds_match_conflicts(ours, theirs, DdsLocalRole::reader);
  ASSERT_EQ(as_reader.size(), 1u);
  EXPECT_EQ(as_reader[0].reason.rfind("offers data representation XCDR2, this reader requests XCDR1 only (", 0), 0u)
      << as_reader[0].reason;
  // Our type's extensibility unknown (native topic): no guess about the far side's type.
  ours.extensibility = DdsTypeExtensibility::unknown;
  const auto unknown = dds_match_conflicts(ours, theirs, DdsLocalRole::writer);
  ASSERT_EQ(unknown.size(), 1u);
  EXPECT_EQ(unknown[0].reason.find("appendable"), std::string::npos) << unknown[0].reason;
}

TEST(DdsQosMatch, LatencyBudgetOfferedMustNotExceedRequested) {
  auto writer = endpoint(), reader = endpoint();
  writer.latency_budget = 50ms;
  reader.latency_budget = 5ms;
  expect_conflict(writer, reader, DdsMatchPolicy::latency_budget);
  const auto as_reader = dds_match_conflicts(reader, writer, DdsLocalRole::reader);
  ASSERT_EQ(as_reader.size(), 1u);
  EXPECT_EQ(as_reader[0].reason.rfind("offers latency budget 50", 0), 0u) << as_reader[0].reason;
  EXPECT_NE(as_reader[0].reason.find("this reader requests 5"), std::string::npos) << as_reader[0].reason;
  reader.latency_budget = 50ms;
  expect_match(writer, reader);
  writer.latency_budget = 0ms;  // cosmicd's writers: 0 satisfies every reader
  reader.latency_budget = 0ms;
  expect_match(writer, reader);
}

TEST(DdsQosMatch, ReliabilityOfferedMustBeAtLeastRequested) {
  auto writer = endpoint(), reader = endpoint();
  reader.reliability = DdsReliabilityKind::reliable;
  expect_conflict(writer, reader, DdsMatchPolicy::reliability);
  writer.reliability = DdsReliabilityKind::reliable;
  expect_match(writer, reader);
  reader.reliability = DdsReliabilityKind::best_effort;
  expect_match(writer, reader);
}

TEST(DdsQosMatch, DurabilityOfferedMustBeAtLeastRequested) {
  auto writer = endpoint(), reader = endpoint();
  reader.durability = DdsDurabilityKind::transient_local;
  expect_conflict(writer, reader, DdsMatchPolicy::durability);
  writer.durability = DdsDurabilityKind::transient_local;
  expect_match(writer, reader);
  reader.durability = DdsDurabilityKind::persistent;
  expect_conflict(writer, reader, DdsMatchPolicy::durability);
}

TEST(DdsQosMatch, DeadlineOfferedPeriodMustNotExceedRequested) {
  auto writer = endpoint(), reader = endpoint();
  reader.deadline = 10ms;  // writer: infinite
  expect_conflict(writer, reader, DdsMatchPolicy::deadline);
  writer.deadline = 20ms;
  expect_conflict(writer, reader, DdsMatchPolicy::deadline);
  writer.deadline = 10ms;
  expect_match(writer, reader);
  reader.deadline.reset();
  expect_match(writer, reader);
}

TEST(DdsQosMatch, LivelinessKindAndLease) {
  auto writer = endpoint(), reader = endpoint();
  reader.liveliness = DdsLivelinessKind::manual_by_topic;
  expect_conflict(writer, reader, DdsMatchPolicy::liveliness);
  writer.liveliness = DdsLivelinessKind::manual_by_topic;
  expect_match(writer, reader);
  reader.liveliness_lease = 1s;  // writer: infinite lease
  expect_conflict(writer, reader, DdsMatchPolicy::liveliness);
  writer.liveliness_lease = 500ms;
  expect_match(writer, reader);
}

TEST(DdsQosMatch, OwnershipKindsMustBeEqual) {
  auto writer = endpoint(), reader = endpoint();
  writer.ownership = DdsOwnershipKind::exclusive;
  expect_conflict(writer, reader, DdsMatchPolicy::ownership);
  std::swap(writer, reader);
  expect_conflict(writer, reader, DdsMatchPolicy::ownership);
}

TEST(DdsQosMatch, DestinationOrderOfferedMustBeAtLeastRequested) {
  auto writer = endpoint(), reader = endpoint();
  reader.destination_order = DdsDestinationOrderKind::by_source_timestamp;
  expect_conflict(writer, reader, DdsMatchPolicy::destination_order);
  writer.destination_order = DdsDestinationOrderKind::by_source_timestamp;
  expect_match(writer, reader);
  reader.destination_order = DdsDestinationOrderKind::by_reception_timestamp;
  expect_match(writer, reader);
}

TEST(DdsQosMatch, PresentationScopeCoherentAndOrderedAccess) {
  auto writer = endpoint(), reader = endpoint();
  reader.presentation = DdsPresentationScope::topic;
  expect_conflict(writer, reader, DdsMatchPolicy::presentation);
  writer.presentation = DdsPresentationScope::group;
  expect_match(writer, reader);
  reader.coherent_access = true;
  expect_conflict(writer, reader, DdsMatchPolicy::presentation);
  writer.coherent_access = true;
  expect_match(writer, reader);
  reader.ordered_access = true;
  expect_conflict(writer, reader, DdsMatchPolicy::presentation);
  writer.ordered_access = true;
  expect_match(writer, reader);
}

TEST(DdsQosMatch, PartitionsMustMeetWildcardsIncluded) {
  auto writer = endpoint(), reader = endpoint();
  reader.partitions = {"left"};
  expect_conflict(writer, reader, DdsMatchPolicy::partition);
  writer.partitions = {"right", "left"};
  expect_match(writer, reader);
  writer.partitions = {"le*"};
  expect_match(writer, reader);
  writer.partitions = {"ri*"};
  expect_conflict(writer, reader, DdsMatchPolicy::partition);
  writer.partitions = {""};  // the default partition, spelled out
  reader.partitions = {};
  expect_match(writer, reader);
}

TEST(DdsQosMatch, TypeNameTopicKindAndExtensibility) {
  auto writer = endpoint(), reader = endpoint();
  reader.type_name = "other::Envelope";
  expect_conflict(writer, reader, DdsMatchPolicy::type_name);
  reader = endpoint();
  reader.keyed = true;
  expect_conflict(writer, reader, DdsMatchPolicy::topic_kind);
  reader = endpoint();
  writer.extensibility = DdsTypeExtensibility::final_kind;
  reader.extensibility = DdsTypeExtensibility::appendable;
  expect_conflict(writer, reader, DdsMatchPolicy::type_extensibility);
  const auto as_writer = dds_match_conflicts(writer, reader, DdsLocalRole::writer);
  ASSERT_EQ(as_writer.size(), 1u);
  EXPECT_EQ(as_writer[0].reason.rfind("its type's extensibility is appendable, this writer's is final", 0), 0u)
      << as_writer[0].reason;
  reader.extensibility = DdsTypeExtensibility::unknown;  // a peer that announces no type object
  expect_match(writer, reader);
}

TEST(DdsQosMatch, EveryBrokenRuleIsListedInPolicyOrder) {
  auto writer = endpoint(), reader = endpoint();
  reader.representations = {DdsDataRepresentationId::xcdr2};
  reader.latency_budget = 1ms;
  writer.latency_budget = 2ms;
  reader.reliability = DdsReliabilityKind::reliable;
  reader.destination_order = DdsDestinationOrderKind::by_source_timestamp;
  EXPECT_EQ(policies(dds_match_conflicts(writer, reader, DdsLocalRole::writer)),
            (std::vector{DdsMatchPolicy::data_representation, DdsMatchPolicy::reliability,
                         DdsMatchPolicy::latency_budget, DdsMatchPolicy::destination_order}));
  EXPECT_STREQ(to_string(DdsMatchPolicy::latency_budget), "latency_budget");
  EXPECT_STREQ(to_string(DdsMatchPolicy::data_representation), "data_representation");
  EXPECT_STREQ(to_string(DdsMatchPolicy::partition), "partition");
}

}  // namespace
}  // namespace cosmic

// Whether a DDS writer and reader may match: the request-vs-offered (RxO) rules of DDS 1.4
// section 2.2.3 and the data-representation and type rules of DDS-XTypes 1.3 sections 7.6.3.1
// and 7.6.3.4, as a pure function of two endpoints' QoS (no DDS library, no I/O).
//
// Why the gateway checks these itself: Fast DDS 2.9 applies only part of them (reliability,
// durability, deadline, liveliness, ownership, partition, and a lenient data-representation
// table) and reports only those as incompatible QoS. A peer that applies the others (Cyclone DDS
// refuses a writer's latency budget above the reader's, an XCDR1 writer for an XCDR2-only reader,
// ...) refuses the match on its side while Fast DDS shows it matched: nothing flows and nothing
// says why. The DDS adapter feeds this function from discovery; docs/dds-mapping.md has the list.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace cosmic {

enum class DdsReliabilityKind { best_effort, reliable };
enum class DdsDurabilityKind { volatile_kind, transient_local, transient, persistent };
enum class DdsLivelinessKind { automatic, manual_by_participant, manual_by_topic };
enum class DdsOwnershipKind { shared, exclusive };
enum class DdsDestinationOrderKind { by_reception_timestamp, by_source_timestamp };
enum class DdsPresentationScope { instance, topic, group };
// DDS-XTypes 1.3 section 7.6.3.1.1: the representation identifiers of the QoS policy.
enum class DdsDataRepresentationId { xcdr1, xml, xcdr2 };
enum class DdsTypeExtensibility { unknown, final_kind, appendable, mutable_kind };

// One endpoint as the matching rules see it. Durations: nullopt is infinite.
struct DdsEndpointQos {
  std::string topic;
  std::string type_name;
  bool keyed = false;
  DdsReliabilityKind reliability = DdsReliabilityKind::best_effort;
  DdsDurabilityKind durability = DdsDurabilityKind::volatile_kind;
  std::optional<std::chrono::nanoseconds> deadline;  // nullopt: none (infinite)
  std::chrono::nanoseconds latency_budget{0};
  DdsLivelinessKind liveliness = DdsLivelinessKind::automatic;
  std::optional<std::chrono::nanoseconds> liveliness_lease;  // nullopt: infinite
  DdsOwnershipKind ownership = DdsOwnershipKind::shared;
  DdsDestinationOrderKind destination_order = DdsDestinationOrderKind::by_reception_timestamp;
  DdsPresentationScope presentation = DdsPresentationScope::instance;
  bool coherent_access = false;
  bool ordered_access = false;
  std::vector<std::string> partitions;  // empty: the default partition ""
  // A writer offers its first entry; a reader accepts any entry. Empty: XCDR1 (XTypes 1.3
  // section 7.6.3.1.1, the value an endpoint that does not send the policy has).
  std::vector<DdsDataRepresentationId> representations;
  // The local writer's configured representations that its DDS library does not announce (Fast
  // DDS before 2.13 sends none: eProsima/Fast-DDS#3935), so peers take it for XCDR1; empty else.
  std::vector<DdsDataRepresentationId> unannounced;
  // From the announced type object, when there is one (unknown otherwise: most peers announce
  // only a TypeInformation hash, which does not say it).
  DdsTypeExtensibility extensibility = DdsTypeExtensibility::unknown;
};

// The policies the rules concern (named in reports as to_string() says).
enum class DdsMatchPolicy {
  topic_kind,
  type_name,
  type_extensibility,
  data_representation,
  reliability,
  durability,
  deadline,
  latency_budget,
  liveliness,
  ownership,
  destination_order,
  presentation,
  partition,
};
inline constexpr std::size_t kDdsMatchPolicyCount = 13;
const char* to_string(DdsMatchPolicy policy);
const char* to_string(DdsDataRepresentationId id);

// Which of the two endpoints is ours: the reasons are worded from our side ("requests ...,
// this writer offers ...").
enum class DdsLocalRole { writer, reader };

struct DdsMatchConflict {
  DdsMatchPolicy policy;
  std::string reason;  // the remote endpoint's value against ours, e.g. "offers latency budget 50 ms, ..."
};

// Every rule the pair breaks, in DdsMatchPolicy order (empty: they match). Endpoints of
// different topics never match and are not compared: the caller pairs by topic name.
std::vector<DdsMatchConflict> dds_match_conflicts(const DdsEndpointQos& local, const DdsEndpointQos& remote,
                                                  DdsLocalRole local_role);

}  // namespace cosmic

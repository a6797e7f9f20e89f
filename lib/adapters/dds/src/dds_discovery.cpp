#include "dds_discovery.hpp"

#include <algorithm>
#include <sstream>
#include <utility>

#include <fastrtps/config.h>

#include <fastrtps/types/TypeObject.h>

namespace cosmic::dds_detail {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

std::optional<std::chrono::nanoseconds> duration_of(const eprosima::fastrtps::Duration_t& d) {
  if (d.seconds >= eprosima::fastrtps::Time_t::INFINITE_SECONDS) return std::nullopt;
  return std::chrono::seconds(d.seconds) + std::chrono::nanoseconds(d.nanosec);
}

DdsDataRepresentationId representation_of(dds::DataRepresentationId_t id) {
  switch (id) {
    case dds::XCDR2_DATA_REPRESENTATION:
      return DdsDataRepresentationId::xcdr2;
    case dds::XML_DATA_REPRESENTATION:
      return DdsDataRepresentationId::xml;
    default:
      return DdsDataRepresentationId::xcdr1;
  }
}

// The policies every endpoint has, whatever holds them (a local DataWriterQos or DataReaderQos,
// or the WriterQos/ReaderQos of a discovered endpoint): the same Fast DDS policy types.
struct Policies {
  const dds::ReliabilityQosPolicy& reliability;
  const dds::DurabilityQosPolicy& durability;
  const dds::DeadlineQosPolicy& deadline;
  const dds::LatencyBudgetQosPolicy& latency_budget;
  const dds::LivelinessQosPolicy& liveliness;
  const dds::OwnershipQosPolicy& ownership;
  const dds::DestinationOrderQosPolicy& destination_order;
  const dds::DataRepresentationQosPolicy& representation;
};

void fill(DdsEndpointQos& out, const Policies& p) {
  out.reliability = p.reliability.kind == dds::RELIABLE_RELIABILITY_QOS ? DdsReliabilityKind::reliable
                                                                        : DdsReliabilityKind::best_effort;
  out.durability = static_cast<DdsDurabilityKind>(std::clamp(static_cast<int>(p.durability.kind), 0, 3));
  out.deadline = duration_of(p.deadline.period);
  out.latency_budget = duration_of(p.latency_budget.duration).value_or(std::chrono::nanoseconds::max());
  out.liveliness = static_cast<DdsLivelinessKind>(std::clamp(static_cast<int>(p.liveliness.kind), 0, 2));
  out.liveliness_lease = duration_of(p.liveliness.lease_duration);
  out.ownership =
      p.ownership.kind == dds::EXCLUSIVE_OWNERSHIP_QOS ? DdsOwnershipKind::exclusive : DdsOwnershipKind::shared;
  out.destination_order = p.destination_order.kind == dds::BY_SOURCE_TIMESTAMP_DESTINATIONORDER_QOS
                              ? DdsDestinationOrderKind::by_source_timestamp
                              : DdsDestinationOrderKind::by_reception_timestamp;
  out.representations.clear();
  for (auto id : p.representation.m_value) out.representations.push_back(representation_of(id));
}

void fill_group(DdsEndpointQos& out, const dds::PresentationQosPolicy& presentation,
                const dds::PartitionQosPolicy& partition) {
  out.presentation = static_cast<DdsPresentationScope>(std::clamp(static_cast<int>(presentation.access_scope), 0, 2));
  out.coherent_access = presentation.coherent_access;
  out.ordered_access = presentation.ordered_access;
  out.partitions.clear();
  for (auto it = partition.begin(); it != partition.end(); ++it) out.partitions.emplace_back(it->name());
}

// Only a Fast DDS peer announces a type object (its own pre-XTypes-1.3 form); most peers, Cyclone
// DDS included, announce a TypeInformation hash, which does not say the extensibility.
template <typename ProxyData>
DdsTypeExtensibility extensibility_of(const ProxyData& data) {
  if (!data.has_type()) return DdsTypeExtensibility::unknown;
  const auto& object = data.type().get();
  auto flags_of = [](const auto& struct_type) {
    const auto& flags = struct_type.struct_flags();
    return flags.IS_MUTABLE()      ? DdsTypeExtensibility::mutable_kind
           : flags.IS_APPENDABLE() ? DdsTypeExtensibility::appendable
           : flags.IS_FINAL()      ? DdsTypeExtensibility::final_kind
                                   : DdsTypeExtensibility::unknown;
  };
  if (object._d() == eprosima::fastrtps::types::EK_MINIMAL &&
      object.minimal()._d() == eprosima::fastrtps::types::TK_STRUCTURE) {
    return flags_of(object.minimal().struct_type());
  }
  if (object._d() == eprosima::fastrtps::types::EK_COMPLETE &&
      object.complete()._d() == eprosima::fastrtps::types::TK_STRUCTURE) {
    return flags_of(object.complete().struct_type());
  }
  return DdsTypeExtensibility::unknown;
}

template <typename ProxyData>
RemoteEndpoint remote_endpoint(const ProxyData& data) {
  RemoteEndpoint out;
  std::ostringstream guid;
  guid << data.guid();
  out.guid = guid.str();
  out.qos.topic = data.topicName().to_string();
  out.qos.type_name = data.typeName().to_string();
  out.qos.keyed = data.topicKind() == rtps::WITH_KEY;
  const auto& q = data.m_qos;
  fill(out.qos, Policies{q.m_reliability, q.m_durability, q.m_deadline, q.m_latencyBudget, q.m_liveliness,
                         q.m_ownership, q.m_destinationOrder, q.representation});
  fill_group(out.qos, q.m_presentation, q.m_partition);
  out.qos.extensibility = extensibility_of(data);
  return out;
}

DdsEndpointQos local_base(const DdsTopicRef& topic) {
  DdsEndpointQos out;
  out.topic = topic.topic;
  out.type_name = topic.type;
  out.keyed = false;  // the envelope and every native topic are keyless (keyed: true is refused at load)
  // The envelope is @final (Envelope.idl); a native topic's type is opaque to cosmicd.
  out.extensibility = topic.native ? DdsTypeExtensibility::unknown : DdsTypeExtensibility::final_kind;
  return out;
}

bool counted_by_fastdds(DdsMatchPolicy policy) {
  // Fast DDS 2.9 refuses these itself and reports them (on_*_incompatible_qos), which the
  // channel's `incompatible` count and its own mismatch line already show.
  switch (policy) {
    case DdsMatchPolicy::reliability:
    case DdsMatchPolicy::durability:
    case DdsMatchPolicy::deadline:
    case DdsMatchPolicy::liveliness:
    case DdsMatchPolicy::ownership:
    case DdsMatchPolicy::partition:
      return true;
    default:
      return false;
  }
}

// What the conflict means for the data, by who applies the rule.
const char* consequence(DdsMatchPolicy policy) {
  switch (policy) {
    case DdsMatchPolicy::topic_kind:
    case DdsMatchPolicy::type_name:
      return "neither side matches";
    default:
      return "Fast DDS 2.9 does not check this and counts it matched; the peer's DDS refuses it, nothing flows";
  }
}

}  // namespace

void DiscoveryBook::on_subscriber_discovery(dds::DomainParticipant*, rtps::ReaderDiscoveryInfo&& info) {
  try {
    const bool removed = info.status == rtps::ReaderDiscoveryInfo::REMOVED_READER;
    store(readers_, info.info.guid(), removed, removed ? RemoteEndpoint{} : remote_endpoint(info.info));
  } catch (...) {
    // A Fast DDS thread must not see an exception; the endpoint is simply not checked.
  }
}

void DiscoveryBook::on_publisher_discovery(dds::DomainParticipant*, rtps::WriterDiscoveryInfo&& info) {
  try {
    const bool removed = info.status == rtps::WriterDiscoveryInfo::REMOVED_WRITER;
    store(writers_, info.info.guid(), removed, removed ? RemoteEndpoint{} : remote_endpoint(info.info));
  } catch (...) {
  }
}

void DiscoveryBook::store(Table& table, const rtps::GUID_t& guid, bool removed, RemoteEndpoint endpoint) {
  std::lock_guard lock(mutex_);
  if (removed) {
    table.erase(guid);
  } else {
    table[guid] = std::move(endpoint);
  }
}

void DiscoveryBook::add_own_participant(const rtps::GuidPrefix_t& prefix) {
  std::lock_guard lock(mutex_);
  own_.insert(prefix);
}

void DiscoveryBook::clear() {
  std::lock_guard lock(mutex_);
  own_.clear();
  readers_.clear();
  writers_.clear();
}

std::vector<RemoteEndpoint> DiscoveryBook::remote_of(const std::string& topic, bool readers) const {
  std::vector<RemoteEndpoint> out;
  std::lock_guard lock(mutex_);
  for (const auto& [guid, endpoint] : readers ? readers_ : writers_) {
    if (endpoint.qos.topic == topic && own_.count(guid.guidPrefix) == 0) out.push_back(endpoint);
  }
  return out;
}

DdsEndpointQos local_writer_qos(const DdsTopicRef& topic, const dds::DataWriterQos& qos) {
  DdsEndpointQos out = local_base(topic);
  fill(out, Policies{qos.reliability(), qos.durability(), qos.deadline(), qos.latency_budget(), qos.liveliness(),
                     qos.ownership(), qos.destination_order(), qos.representation()});
  // The adapter's Publisher has the default QoS (docs/dds-mapping.md, Entities).
  fill_group(out, dds::PUBLISHER_QOS_DEFAULT.presentation(), dds::PUBLISHER_QOS_DEFAULT.partition());
#if FASTRTPS_VERSION_MAJOR == 2 && FASTRTPS_VERSION_MINOR < 13
  // What goes on the wire is what the far side matches against: Fast DDS before 2.13 leaves a
  // writer's data representation out of its announcement (eProsima/Fast-DDS#3935), which peers
  // read as XCDR1.
  out.unannounced = std::exchange(out.representations, {});
  if (out.unannounced.size() == 1 && out.unannounced.front() == DdsDataRepresentationId::xcdr1) out.unannounced.clear();
#endif
  return out;
}

DdsEndpointQos local_reader_qos(const DdsTopicRef& topic, const dds::DataReaderQos& qos) {
  DdsEndpointQos out = local_base(topic);
  fill(out, Policies{qos.reliability(), qos.durability(), qos.deadline(), qos.latency_budget(), qos.liveliness(),
                     qos.ownership(), qos.destination_order(), qos.type_consistency().representation});
  fill_group(out, dds::SUBSCRIBER_QOS_DEFAULT.presentation(), dds::SUBSCRIBER_QOS_DEFAULT.partition());
  return out;
}

std::vector<PeerQosConflict> peer_conflicts(const DdsEndpointQos& local, DdsLocalRole local_role,
                                            const std::vector<RemoteEndpoint>& remotes, bool reaction_time_budget) {
  std::vector<PeerQosConflict> out;
  const char* peer = local_role == DdsLocalRole::writer ? "reader" : "writer";
  for (const RemoteEndpoint& remote : remotes) {
    for (DdsMatchConflict& c : dds_match_conflicts(local, remote.qos, local_role)) {
      if (counted_by_fastdds(c.policy)) continue;
      std::string reason = std::move(c.reason);
      if (c.policy == DdsMatchPolicy::latency_budget && reaction_time_budget) {
        reason += "; this reader's budget is the channel's reaction_time";
      }
      out.push_back({peer, remote.guid, local.topic, to_string(c.policy), reason + "; " + consequence(c.policy)});
    }
  }
  return out;
}

}  // namespace cosmic::dds_detail

#include "dds_qos.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netinet/in.h>

#include <algorithm>
#include <charconv>
#include <memory>
#include <set>
#include <vector>

#include <fastdds/rtps/attributes/ServerAttributes.h>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include "cosmic/dds_adapter.hpp"
#include "cosmic/dds_security_qos.hpp"

namespace cosmic::dds_detail {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;

namespace {

eprosima::fastrtps::Duration_t to_duration(Nanos value) {
  const std::int64_t ns = std::max<std::int64_t>(0, value.count());
  const std::int64_t seconds = ns / 1'000'000'000;
  if (seconds >= 0x7fffffff) {
    return eprosima::fastrtps::c_TimeInfinite;
  }
  return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(seconds),
                                        static_cast<std::uint32_t>(ns % 1'000'000'000));
}

dds::ReliabilityQosPolicyKind reliability_of(const SegmentSpec& segment) {
  return segment.reliability == Reliability::reliable ? dds::RELIABLE_RELIABILITY_QOS
                                                      : dds::BEST_EFFORT_RELIABILITY_QOS;
}

// Local IPv4 addresses by interface name, and the set of all of them.
struct LocalAddresses {
  std::vector<std::pair<std::string, std::string>> by_name;
  std::set<std::string> all;
};

LocalAddresses local_ipv4_addresses() {
  LocalAddresses out;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) {
    return out;
  }
  for (const ifaddrs* it = list; it != nullptr; it = it->ifa_next) {
    if (it->ifa_addr == nullptr || it->ifa_addr->sa_family != AF_INET) {
      continue;
    }
    char text[INET_ADDRSTRLEN] = {};
    const auto* in = reinterpret_cast<const sockaddr_in*>(it->ifa_addr);
    if (inet_ntop(AF_INET, &in->sin_addr, text, sizeof text) == nullptr) {
      continue;
    }
    out.by_name.emplace_back(it->ifa_name, text);
    out.all.insert(text);
  }
  freeifaddrs(list);
  return out;
}

bool is_ipv4(const std::string& text) {
  in_addr addr{};
  return inet_pton(AF_INET, text.c_str(), &addr) == 1;
}

}  // namespace

std::int32_t history_depth(std::uint32_t omission_degree) {
  const std::uint64_t depth = static_cast<std::uint64_t>(omission_degree) + 1;
  return static_cast<std::int32_t>(std::min<std::uint64_t>(std::max<std::uint64_t>(depth, 1), kMaxHistoryDepth));
}

EndpointShape shape_of(const SegmentSpec& segment, const ChannelSpec& channel) {
  EndpointShape shape;
  shape.topic = dds_topic_of(channel, segment.name);
  shape.depth = history_depth(channel.omission_degree);
  shape.validity = channel.temp_validity;
  shape.reaction_time = channel.reaction_time;
  return shape;
}

dds::DataWriterQos writer_qos(const SegmentSpec& segment, const ChannelSpec& channel) {
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  // A writer offers exactly one representation; a native topic's bytes carry the one declared
  // (send() refuses others). The envelope keeps the default (XCDR), which every reader accepts.
  if (const auto native = channel.native_dds(segment.name)) {
    qos.representation().m_value = {native->representation == DdsRepresentation::xcdr2 ? dds::XCDR2_DATA_REPRESENTATION
                                                                                       : dds::XCDR_DATA_REPRESENTATION};
  }
  // Offered QoS is chosen so that any requested QoS a default reader can have is satisfied:
  // RELIABLE serves reliable and best-effort readers, TRANSIENT_LOCAL serves volatile and
  // transient-local readers, and neither deadline nor latency_budget is offered (a reader's
  // default deadline is infinite, its default latency budget 0; an offered budget above the
  // reader's refuses the match).
  qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  qos.reliability().max_blocking_time = to_duration(Nanos(kMaxBlockingNs));
  qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = history_depth(channel.omission_degree);
  qos.latency_budget().duration = eprosima::fastrtps::Duration_t(0, 0);
  qos.deadline().period = eprosima::fastrtps::c_TimeInfinite;
  // Lifespan does not take part in matching: a sample older than the channel's validity is
  // neither delivered nor repaired nor handed to a late-joining transient-local reader.
  if (channel.temp_validity && channel.temp_validity->count() > 0) {
    qos.lifespan().duration = to_duration(*channel.temp_validity);
  }
  // Heartbeats announce what a reliable writer has, so a reader can ask for what it lost; the
  // last event of a burst is only repaired at the next one. Fast DDS's default period (3 s) is
  // far beyond a real-time channel: half the reaction time, within [5 ms, 100 ms].
  Nanos heartbeat(kMaxHeartbeatNs);
  if (channel.reaction_time) {
    heartbeat = std::clamp(*channel.reaction_time / 2, Nanos(kMinHeartbeatNs), Nanos(kMaxHeartbeatNs));
  }
  qos.reliable_writer_qos().times.heartbeatPeriod = to_duration(heartbeat);
  // NACK suppression: a NACK for a sample sent less than this ago is taken as one that crossed it in
  // flight and ignored. Fast DDS's default (0) fires the suppression timer for every sample sent,
  // which wakes the participant's event thread once per event (issue 39: about a third of the
  // relay's wake-ups at 20 kHz); while the timer is armed, the samples sent after it share it.
  // 1 ms is far below the heartbeat period (>= 5 ms), which bounds a repair's delay anyway.
  qos.reliable_writer_qos().times.nackSupressionDuration = to_duration(Nanos(kNackSuppressionNs));
  // Synchronous publication: write() hands the sample to the transport on the calling thread,
  // which keeps the added latency minimal for small events.
  qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
  qos.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

constexpr std::int32_t kReaderBufferDepth = 256;

dds::DataReaderQos reader_qos(const SegmentSpec& segment, const ChannelSpec& channel) {
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  // Requested QoS is the least a default writer offers: the segment's reliability (a
  // best-effort segment also accepts best-effort writers; on a reliable segment they are a
  // reported mismatch, the DDS rule has no way to both accept them and demand repair), VOLATILE
  // durability, no deadline, and a latency budget no writer's default (0) exceeds.
  qos.reliability().kind = reliability_of(segment);
  qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
  // A native topic's reader takes the bytes as they come, in either extended CDR version.
  if (channel.native_dds(segment.name)) {
    qos.type_consistency().representation.m_value = {dds::XCDR_DATA_REPRESENTATION, dds::XCDR2_DATA_REPRESENTATION};
  }
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  // The reader's history only buffers between Fast DDS's receive thread and our listener's
  // take(): deeper than the channel's own depth so a burst does not fill it. A full reliable
  // reader rejects samples and stalls a KEEP_ALL writer until it gives up (seen under overload).
  qos.history().depth = std::max<std::int32_t>(history_depth(channel.omission_degree), kReaderBufferDepth);
  // A requested budget accepts every writer offering at most that much: the channel's reaction
  // time is the most it can allow, and it only widens what matches.
  if (channel.reaction_time) {
    qos.latency_budget().duration = to_duration(*channel.reaction_time);
  }
  qos.deadline().period = eprosima::fastrtps::c_TimeInfinite;
  // No lifespan here (it is a writer policy): validity is the router's business, from the
  // envelope's age.
  qos.endpoint().history_memory_policy = rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  return qos;
}

namespace {
// Puts the segment's interface allow-list (IPv4 addresses or interface names) on `udp`.
Status allow_interfaces(const std::vector<std::string>& interfaces,
                        eprosima::fastdds::rtps::UDPv4TransportDescriptor& udp) {
  if (interfaces.empty()) return Status::success();
  const LocalAddresses local = local_ipv4_addresses();
  for (const std::string& entry : interfaces) {
    if (is_ipv4(entry)) {
      if (local.all.count(entry) == 0) {
        return Status::failure("DDS interface " + entry + " is not an address of this host");
      }
      udp.interfaceWhiteList.push_back(entry);
      continue;
    }
    bool found = false;
    for (const auto& [name, address] : local.by_name) {
      if (name == entry) {
        udp.interfaceWhiteList.push_back(address);
        found = true;
      }
    }
    if (!found) {
      return Status::failure("DDS interface " + entry + " is neither an IPv4 address nor an interface with one");
    }
  }
  return Status::success();
}
// DDS Security through Fast DDS's builtin plugins (docs/security.md): authentication (PKI-DH),
// access control (Access-Permissions) and cryptography (AES-GCM-GMAC), the files as file:// URIs.
void add_security(const DdsSecuritySpec& security, dds::DomainParticipantQos& qos) {
  auto& properties = qos.properties().properties();
  auto file = [](const std::string& path) { return "file://" + path; };
  properties.emplace_back("dds.sec.auth.plugin", "builtin.PKI-DH");
  properties.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_ca", file(security.identity_ca));
  properties.emplace_back("dds.sec.auth.builtin.PKI-DH.identity_certificate", file(security.certificate));
  properties.emplace_back("dds.sec.auth.builtin.PKI-DH.private_key", file(security.private_key));
  properties.emplace_back("dds.sec.access.plugin", "builtin.Access-Permissions");
  properties.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions_ca", file(security.permissions_ca));
  properties.emplace_back("dds.sec.access.builtin.Access-Permissions.governance", file(security.governance));
  properties.emplace_back("dds.sec.access.builtin.Access-Permissions.permissions", file(security.permissions));
  properties.emplace_back("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

}  // namespace

Status participant_qos(const SegmentSpec& segment, const std::string& participant_name, bool shared_memory,
                       dds::DomainParticipantQos& qos) {
  qos = dds::PARTICIPANT_QOS_DEFAULT;
  qos.name(participant_name);
  // Fast DDS >= 2.10 stops matching this participant's own readers and writers; 2.9 ignores
  // the property and the adapter filters by GUID prefix on reception.
  qos.properties().properties().emplace_back("fastdds.ignore_local_endpoints", "true");
  if (segment.dds.security) add_security(*segment.dds.security, qos);

  if (!segment.dds.interfaces.empty() || !shared_memory) {
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    if (Status st = allow_interfaces(segment.dds.interfaces, *udp); !st.ok) return st;
    qos.transport().use_builtin_transports = false;
    qos.transport().user_transports.push_back(udp);
    // Shared memory only reaches participants on this host, so an allow-list leaves it on.
    if (shared_memory) {
      qos.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
    }
  }

  if (!segment.dds.discovery_server.empty()) {
    const std::string& text = segment.dds.discovery_server;
    const auto colon = text.rfind(':');
    if (colon == std::string::npos) {
      return Status::failure("DDS discovery_server '" + text + "' is not IP:PORT");
    }
    const std::string ip = text.substr(0, colon);
    const std::string port_text = text.substr(colon + 1);
    unsigned port = 0;
    const auto [end, ec] = std::from_chars(port_text.data(), port_text.data() + port_text.size(), port);
    if (!is_ipv4(ip) || ec != std::errc() || end != port_text.data() + port_text.size() || port == 0 || port > 65535) {
      return Status::failure("DDS discovery_server '" + text + "' is not IPv4:PORT");
    }
    rtps::Locator_t locator;
    locator.kind = LOCATOR_KIND_UDPv4;
    eprosima::fastrtps::rtps::IPLocator::setIPv4(locator, ip);
    locator.port = port;
    eprosima::fastdds::rtps::RemoteServerAttributes server;
    server.metatrafficUnicastLocatorList.push_back(locator);
    // The server's default GUID prefix for id 0 (`fastdds discovery -i 0`).
    eprosima::fastdds::rtps::get_server_client_default_guidPrefix(0, server.guidPrefix);
    auto& discovery = qos.wire_protocol().builtin.discovery_config;
    discovery.discoveryProtocol = rtps::DiscoveryProtocol_t::CLIENT;
    discovery.m_DiscoveryServers.push_back(server);
  }
  return Status::success();
}

}  // namespace cosmic::dds_detail

namespace cosmic {

void add_dds_security(const DdsSecuritySpec& security, eprosima::fastdds::dds::DomainParticipantQos& qos) {
  dds_detail::add_security(security, qos);
}

}  // namespace cosmic

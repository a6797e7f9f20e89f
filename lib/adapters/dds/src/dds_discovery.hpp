// The remote readers and writers the DDS adapter's participants discovered, with the QoS and type
// they announced, and the mismatches against the adapter's own endpoints that Fast DDS 2.9 does
// not see or does not report (internal to the DDS adapter; the rules are cosmic/dds_qos_match.hpp).
//
// Threads: Fast DDS calls the discovery callbacks on its own threads (every participant of the
// segment discovers every remote endpoint, so the same endpoint may arrive up to three times: an
// entry is keyed by GUID, and the latest announcement wins). They convert what was announced to
// plain structs first and hold `mutex_` only to store them. The control thread reads a copy
// (remote_of) when a report asks for it. Nothing here touches the forwarding path.
#pragma once

#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>
#include <fastdds/rtps/builtin/data/ReaderProxyData.h>
#include <fastdds/rtps/builtin/data/WriterProxyData.h>

#include "cosmic/dds_names.hpp"
#include "cosmic/dds_qos_match.hpp"
#include "cosmic/segment_adapter.hpp"
#include "dds_authentication.hpp"

namespace cosmic::dds_detail {

struct RemoteEndpoint {
  std::string guid;  // "01.0f.ab...|0.0.1.4", as Fast DDS prints it
  DdsEndpointQos qos;
};

class DiscoveryBook final : public eprosima::fastdds::dds::DomainParticipantListener {
 public:
  void on_subscriber_discovery(eprosima::fastdds::dds::DomainParticipant*,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override;
  void on_publisher_discovery(eprosima::fastdds::dds::DomainParticipant*,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override;
  // On a secure segment: remote participants and their authentication go to `authentications`.
  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant*,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    if (authentications_) authentications_->discovered(info);
  }
  void onParticipantAuthentication(eprosima::fastdds::dds::DomainParticipant*,
                                   eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
    if (authentications_) authentications_->authenticated(info);
  }
  // Before the first participant is created (the callbacks read it unguarded).
  void watch_authentications(ParticipantAuthentications* authentications) { authentications_ = authentications; }

  // The adapter's own participants: their endpoints are never remote peers of each other.
  void add_own_participant(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix);
  // After the participants are deleted (stop): nothing discovered by them remains.
  void clear();

  // The remote readers (`readers` true) or writers on `topic` (a copy; control thread).
  std::vector<RemoteEndpoint> remote_of(const std::string& topic, bool readers) const;

 private:
  using Table = std::map<eprosima::fastrtps::rtps::GUID_t, RemoteEndpoint>;
  void store(Table& table, const eprosima::fastrtps::rtps::GUID_t& guid, bool removed, RemoteEndpoint endpoint);

  ParticipantAuthentications* authentications_ = nullptr;
  mutable std::mutex mutex_;
  std::set<eprosima::fastrtps::rtps::GuidPrefix_t> own_;
  Table readers_;
  Table writers_;
};

// Our own endpoint of a channel as the matching rules see it (the QoS dds_qos.cpp gives it).
DdsEndpointQos local_writer_qos(const DdsTopicRef& topic, const eprosima::fastdds::dds::DataWriterQos& qos);
DdsEndpointQos local_reader_qos(const DdsTopicRef& topic, const eprosima::fastdds::dds::DataReaderQos& qos);

// The conflicts between our endpoint `local` (a writer when `local_role` says so) and the remote
// endpoints of its topic that cosmicd reports itself: those Fast DDS 2.9 does not already refuse
// and count as incompatible QoS (SegmentAdapter::incompatible_peers). `reaction_time_budget`: the
// local reader's latency budget is the channel's reaction time (named in the reason).
std::vector<PeerQosConflict> peer_conflicts(const DdsEndpointQos& local, DdsLocalRole local_role,
                                            const std::vector<RemoteEndpoint>& remotes, bool reaction_time_budget);

}  // namespace cosmic::dds_detail

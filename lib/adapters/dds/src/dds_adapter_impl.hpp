// The DDS adapter's internals, shared by its units (internal to the DDS adapter):
//   dds_adapter.cpp    lifecycle: start, configure (create, swap, delete), send, stop
//   dds_endpoints.cpp  participants, topics, readers and writers, and Fast DDS's callbacks
// The mapping is documented in cosmic/dds_adapter.hpp; threads and locks in dds_adapter.cpp.
#pragma once

#include <array>
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <shared_mutex>
#include <string>
#include <unordered_map>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>

#include "cosmic/adapter_counters.hpp"
#include "cosmic/dds_adapter.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/health_cell.hpp"
#include "cosmic/log_prefix.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/result.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/snapshot_table.hpp"
#include "cosmic/thread_policy.hpp"
#include "dds_discovery.hpp"
#include "dds_qos.hpp"
#include "dds_sample_format.hpp"

namespace cosmic::dds_detail {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using eprosima::fastrtps::types::ReturnCode_t;

class DdsAdapter;

struct TopicRef {
  dds::Topic* topic = nullptr;
  int users = 0;
};

// The DDS entities serving one class of channels on the segment (control thread only).
struct ClassParticipant {
  dds::DomainParticipant* participant = nullptr;
  dds::Publisher* publisher = nullptr;
  dds::Subscriber* subscriber = nullptr;
  rtps::GuidPrefix_t prefix;
  std::map<std::string, TopicRef> topics;
};

struct WriterEntry : dds::DataWriterListener {
  WriterEntry(DdsAdapter& owner, ChannelId id, const ChannelSpec& spec, EndpointShape shape)
      : owner(owner),
        id(id),
        spec(spec),
        shape(std::move(shape)),
        format(make_sample_format(this->shape.topic, spec)) {}
  void on_offered_incompatible_qos(dds::DataWriter*, const dds::OfferedIncompatibleQosStatus& status) override;

  DdsAdapter& owner;
  std::atomic<std::uint64_t> incompatible{0};  // remote readers refused for their QoS
  ChannelId id;
  ChannelSpec spec;
  EndpointShape shape;
  ClassParticipant* home = nullptr;  // the participant of the channel's class
  dds::Topic* topic = nullptr;
  dds::DataWriter* writer = nullptr;
  // Guards format's sample, which every send of this channel fills. Held across write(), which
  // takes Fast DDS's own lock of this same writer anyway: only sends of this one channel can wait
  // for it (the router sends a channel to a segment from one sender at a time: its class's lane,
  // or a receive thread of that class in the lane's place), never another channel, class or
  // segment. Priority-inheriting, as every lock a forwarding thread takes.
  PiMutex sample_mutex;
  std::unique_ptr<DdsSampleFormat> format COSMIC_GUARDED_BY(sample_mutex);
  std::atomic<bool> refusal_logged{false};  // one log line for events the format cannot carry
};

// The writers of the segment by channel: what send() reads.
using WriterTable = std::unordered_map<ChannelId, std::shared_ptr<WriterEntry>>;

struct ReaderEntry : dds::DataReaderListener {
  ReaderEntry(DdsAdapter& owner, ChannelId id, const ChannelSpec& spec, EndpointShape shape)
      : owner(owner),
        id(id),
        spec(spec),
        shape(std::move(shape)),
        format(make_sample_format(this->shape.topic, spec)) {}
  void on_data_available(dds::DataReader* reader) override;
  void on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus& status) override;
  void on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) override;

  DdsAdapter& owner;
  std::atomic<std::uint64_t> incompatible{0};  // remote writers refused for their QoS
  ChannelId id;
  ChannelSpec spec;
  EndpointShape shape;
  ClassParticipant* home = nullptr;  // the participant of the channel's class
  // GUID prefix of `home`: a sample whose writer has it is this gateway's own publication (a
  // channel's reader and writer on one segment share the class, hence the participant).
  rtps::GuidPrefix_t own_prefix;
  dds::Topic* topic = nullptr;
  dds::DataReader* reader = nullptr;
  // Serialises callbacks; guards `active` and format's sample. Priority-inheriting: the control
  // thread takes it to retire the reader while the class's receive thread may wait for it.
  PiMutex mutex;
  bool active COSMIC_GUARDED_BY(mutex) = false;  // false: never calls the sink
  std::unique_ptr<DdsSampleFormat> format COSMIC_GUARDED_BY(mutex);
};

class DdsAdapter final : public DdsSegmentAdapter {
 public:
  DdsAdapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log)
      : segment_(segment),
        self_(self),
        log_(log),
        prefix_(segment_log_prefix(SegmentType::dds, segment.name)),
        authentications_(prefix_, log, true) {
    if (segment_.dds.security) discovery_.watch_authentications(&authentications_);
  }
  ~DdsAdapter() override { stop(); }

  Status start(EventSink& sink) override;
  Status configure(std::span<const ChannelBinding> bindings) override;
  SendStatus send(const OutboundEvent& event) override;
  HealthReport health() const override { return health_.get(); }
  AdapterStatistics statistics() const override {
    AdapterStatistics out = counters_.snapshot();
    if (segment_.dds.security) authentications_.report(out);
    return out;
  }
  void stop() override;
  std::size_t matched_endpoints(ChannelId channel, HopRole role) const override;
  std::optional<std::size_t> matched_peers(ChannelId channel) const override {
    // A channel is either written or read on one segment: the other count is 0.
    return matched_endpoints(channel, HopRole::subscriber) + matched_endpoints(channel, HopRole::publisher);
  }
  std::optional<std::uint64_t> incompatible_peers(ChannelId channel) const override;
  std::vector<PeerQosConflict> peer_qos_conflicts(ChannelId channel) const override;

  // Reader callbacks (Fast DDS threads, reader mutex held).
  void deliver(ReaderEntry& entry, const dds::SampleInfo& info) COSMIC_REQUIRES(entry.mutex);
  void count_receive_error(ReaderEntry& entry) {
    counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
    if (sink_ != nullptr) {
      sink_->on_problem(entry.id, InboundProblem::decode_error);
    }
  }
  void count_lost(std::uint64_t n) { counters_.overflow_drops.fetch_add(n, std::memory_order_relaxed); }
  void warn(const std::string& text) { log_.log(LogLevel::warning, prefix() + text); }
  void warn_refused(const WriterEntry& writer, FillRefusal refusal, std::uint16_t first_bytes, std::size_t size);

 private:
  const std::string& prefix() const { return prefix_; }
  void set_health(SegmentHealth state, std::string detail) { health_.set(state, std::move(detail)); }
  ClassParticipant& home_of(ChannelClass cls) { return classes_.at(static_cast<std::size_t>(cls)); }
  bool started() const { return classes_[static_cast<std::size_t>(ChannelClass::nrt)].participant != nullptr; }
  Status open_participant(ChannelClass cls, const ThreadPolicy& threads, const std::string& thread_name);
  Status ensure_class_participant(ChannelClass cls);
  void close_participant(ClassParticipant& home);
  Result<dds::Topic*> acquire_topic(ClassParticipant& home, const DdsTopicRef& ref);
  void release_topic(ClassParticipant& home, dds::Topic* topic);
  Result<std::unique_ptr<WriterEntry>> create_writer(const ChannelBinding& binding);
  Result<std::unique_ptr<ReaderEntry>> create_reader(const ChannelBinding& binding);
  // " (a secure segment: do the permissions grant SUBJECT to ACTION it?)", or nothing without security.
  std::string permission_hint(const char* action) const;
  // The class participant of `binding`, then `create`; every failure (an exception of Fast DDS
  // included) comes back as an error.
  template <typename Entry>
  Result<std::unique_ptr<Entry>> create_endpoint(
      const ChannelBinding& binding, Result<std::unique_ptr<Entry>> (DdsAdapter::*create)(const ChannelBinding&));
  void destroy_writer(WriterEntry& entry);
  void deactivate(ReaderEntry& entry);
  void destroy_reader(std::unique_ptr<ReaderEntry> entry);
  void teardown();
  dds::DomainParticipant* create_participant_as(const ThreadPolicy& threads, const dds::DomainParticipantQos& qos);

  const SegmentSpec segment_;
  const GatewayIdentity self_;
  Logger& log_;
  const std::string prefix_;  // "DDS segment NAME: " (cosmic/log_prefix.hpp)
  // A secure segment's remote participants refused authentication (the listener's, via discovery_).
  ParticipantAuthentications authentications_;

  // Serialises start/configure/stop (control thread); never taken on a send or receive path.
  Mutex control_mutex_;
  EventSink* sink_ = nullptr;
  // Whether the NRT participant's threads may send an NRT event on themselves
  // (InboundEvent::receiver_class): they run as the receive threads do, not as the NRT lanes, and
  // may do a lane's work only where that puts it above no higher class. Set by start() before
  // the participant's threads exist.
  bool nrt_receivers_send_ = false;
  std::array<ClassParticipant, 3> classes_;  // indexed by ChannelClass; entries point into it
  bool log_attached_ = false;

  // send() (lane threads, receive threads of the class, components' threads) reads the table without holding a lock
  // across the write; configure()/stop() replace it (cosmic/snapshot_table.hpp) and delete the DataWriters of a
  // replaced table only after its last send has ended.
  SnapshotTable<WriterTable> writers_;
  // Readers: only the control thread changes this table; matched_endpoints() reads it shared.
  mutable SharedMutex readers_mutex_;
  std::unordered_map<ChannelId, std::unique_ptr<ReaderEntry>> readers_ COSMIC_GUARDED_BY(readers_mutex_);
  std::vector<std::unique_ptr<ReaderEntry>> retired_readers_;

  AdapterCounters counters_;
  HealthCell health_;
  // Every participant's listener: the remote endpoints discovered, for peer_qos_conflicts().
  DiscoveryBook discovery_;
};

// Fast DDS's reception stamp (realtime clock) on the steady clock, never later than now.
Nanos arrival_on_steady_clock(const eprosima::fastrtps::rtps::Time_t& reception);

}  // namespace cosmic::dds_detail

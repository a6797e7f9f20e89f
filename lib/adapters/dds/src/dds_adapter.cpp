// The DDS segment adapter on Fast DDS 2.9. The mapping is documented in cosmic/dds_adapter.hpp.
//
// Participants: one per class of channel in use on the segment. The NRT participant is created
// by start() and also carries discovery of the segment's health; the HRT and SRT ones when the
// first channel of their class is configured. Readers and writers of a channel live in its
// class's participant, so a lower class never shares Fast DDS's per-participant send lock,
// shared-memory segment, event thread or receive threads with a higher one (a flood of NRT writes
// would otherwise hold the send lock an HRT write needs, on a thread that runs below every
// real-time thread: a priority inversion the router's own locks cannot fix). Each participant's
// Fast DDS threads run as its class's lane does (see create_participant_as).
//
// Threads and locks:
// - control_mutex_ serialises start/configure/stop (control thread).
// - writers_mutex_ (shared_mutex) guards the channel -> writer table: send() (router thread)
//   takes it shared, configure()/stop() exclusive only to swap entries in or out. DDS entities
//   are created before and deleted after that exclusive section, so the router never waits for
//   Fast DDS discovery work.
// - Each writer has its own sample in its topic's format (dds_sample_format: envelope or opaque),
//   reused for every send (its buffer keeps its capacity: no allocation per event in steady
//   state), guarded by the writer's mutex.
// - Each reader has its own sample and mutex; Fast DDS calls on_data_available on its
//   receive threads. A reader is retired by clearing its `active` flag under its mutex (after
//   which it never calls the sink) before Fast DDS deletes it; its listener object is kept until
//   stop() so a late callback never touches freed memory.
#include "cosmic/dds_adapter.hpp"

#include "cosmic/adapter_counters.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <exception>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <shared_mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <utility>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <cosmic_dds_idl/EnvelopePubSubTypes.h>

#include "cosmic/dds_encapsulation.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/thread_policy.hpp"
#include "dds_log_router.hpp"
#include "dds_opaque_type.hpp"
#include "dds_qos.hpp"
#include "dds_sample_format.hpp"

namespace cosmic {

namespace {

namespace dds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using dds_detail::EndpointShape;
using eprosima::fastrtps::types::ReturnCode_t;

const char* policy_name(dds::QosPolicyId_t id) {
  switch (id) {
    case dds::RELIABILITY_QOS_POLICY_ID: return "reliability";
    case dds::DURABILITY_QOS_POLICY_ID: return "durability";
    case dds::DEADLINE_QOS_POLICY_ID: return "deadline";
    case dds::LATENCYBUDGET_QOS_POLICY_ID: return "latency_budget";
    case dds::LIVELINESS_QOS_POLICY_ID: return "liveliness";
    case dds::OWNERSHIP_QOS_POLICY_ID: return "ownership";
    case dds::PARTITION_QOS_POLICY_ID: return "partition";
    case dds::DATAREPRESENTATION_QOS_POLICY_ID: return "data_representation";
    default: return "other";
  }
}

// ---- the adapter -------------------------------------------------------------------------------

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
  WriterEntry(DdsAdapter& owner, ChannelId id, const ChannelSpec& spec, EndpointShape shape, std::uint64_t self)
      : owner(owner), id(id), spec(spec), shape(std::move(shape)),
        format(dds_detail::make_sample_format(this->shape.topic, spec, self)) {}
  void on_offered_incompatible_qos(dds::DataWriter*,
                                   const dds::OfferedIncompatibleQosStatus& status) override;

  DdsAdapter& owner;
  std::atomic<std::uint64_t> incompatible{0};  // remote readers refused for their QoS
  ChannelId id;
  ChannelSpec spec;
  EndpointShape shape;
  ClassParticipant* home = nullptr;  // the participant of the channel's class
  dds::Topic* topic = nullptr;
  dds::DataWriter* writer = nullptr;
  std::mutex sample_mutex;  // guards format's sample
  std::unique_ptr<dds_detail::DdsSampleFormat> format;
  std::atomic<bool> refusal_logged{false};  // one log line for events the format cannot carry
};

struct ReaderEntry : dds::DataReaderListener {
  ReaderEntry(DdsAdapter& owner, ChannelId id, const ChannelSpec& spec, EndpointShape shape, std::uint64_t self)
      : owner(owner), id(id), spec(spec), shape(std::move(shape)),
        format(dds_detail::make_sample_format(this->shape.topic, spec, self)) {}
  void on_data_available(dds::DataReader* reader) override;
  void on_requested_incompatible_qos(dds::DataReader*,
                                     const dds::RequestedIncompatibleQosStatus& status) override;
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
  std::mutex mutex;     // serialises callbacks; guards `active` and format's sample
  bool active = false;  // false: never calls the sink
  std::unique_ptr<dds_detail::DdsSampleFormat> format;
};

class DdsAdapter final : public DdsSegmentAdapter {
 public:
  DdsAdapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log)
      : segment_(segment), self_(self), log_(log) {
    health_.state = SegmentHealth::down;
    health_.detail = "not started";
  }
  ~DdsAdapter() override { stop(); }

  Status start(EventSink& sink) override;
  Status configure(std::span<const ChannelBinding> bindings) override;
  SendStatus send(const OutboundEvent& event) override;
  HealthReport health() const override {
    std::lock_guard lock(health_mutex_);
    return health_;
  }
  AdapterStatistics statistics() const override { return counters_.snapshot(); }
  void stop() override;
  std::size_t matched_endpoints(ChannelId channel, HopRole role) const override;
  std::optional<std::size_t> matched_peers(ChannelId channel) const override {
    // A channel is either written or read on one segment: the other count is 0.
    return matched_endpoints(channel, HopRole::subscriber) + matched_endpoints(channel, HopRole::publisher);
  }
  std::optional<std::uint64_t> incompatible_peers(ChannelId channel) const override;

  // Reader callbacks (Fast DDS threads, reader mutex held).
  void deliver(ReaderEntry& entry, const dds::SampleInfo& info);
  void count_receive_error(ReaderEntry& entry) {
    counters_.receive_errors.fetch_add(1, std::memory_order_relaxed);
    if (sink_ != nullptr) {
      sink_->on_problem(entry.id, InboundProblem::decode_error);
    }
  }
  void count_lost(std::uint64_t n) { counters_.overflow_drops.fetch_add(n, std::memory_order_relaxed); }
  void warn(const std::string& text) { log_.log(LogLevel::warning, prefix() + text); }
  void warn_refused(const WriterEntry& writer, dds_detail::FillRefusal refusal, std::uint16_t first_bytes,
                    std::size_t size);

 private:
  std::string prefix() const { return "dds segment " + segment_.name + ": "; }
  void set_health(SegmentHealth state, std::string detail) {
    std::lock_guard lock(health_mutex_);
    health_.state = state;
    health_.detail = std::move(detail);
  }
  ClassParticipant& home_of(ChannelClass cls) { return classes_.at(static_cast<std::size_t>(cls)); }
  bool started() const { return classes_[static_cast<std::size_t>(ChannelClass::nrt)].participant != nullptr; }
  Status open_participant(ChannelClass cls, const ThreadPolicy& threads, const std::string& thread_name);
  Status ensure_class_participant(ChannelClass cls);
  void close_participant(ClassParticipant& home);
  dds::Topic* acquire_topic(ClassParticipant& home, const DdsTopicRef& ref, std::string& error);
  void release_topic(ClassParticipant& home, dds::Topic* topic);
  std::unique_ptr<WriterEntry> create_writer(const ChannelBinding& binding, std::string& error);
  std::unique_ptr<ReaderEntry> create_reader(const ChannelBinding& binding, std::string& error);
  void destroy_writer(std::unique_ptr<WriterEntry> entry);
  void deactivate(ReaderEntry& entry);
  void destroy_reader(std::unique_ptr<ReaderEntry> entry);
  void teardown();
  dds::DomainParticipant* create_participant_as(const ThreadPolicy& threads, const dds::DomainParticipantQos& qos);

  const SegmentSpec segment_;
  const GatewayIdentity self_;
  Logger& log_;

  std::mutex control_mutex_;
  EventSink* sink_ = nullptr;
  std::array<ClassParticipant, 3> classes_;  // indexed by ChannelClass; entries point into it
  bool log_attached_ = false;

  mutable std::shared_mutex writers_mutex_;
  std::unordered_map<ChannelId, std::unique_ptr<WriterEntry>> writers_;
  // Readers: only the control thread changes this table; matched_endpoints() reads it shared.
  mutable std::shared_mutex readers_mutex_;
  std::unordered_map<ChannelId, std::unique_ptr<ReaderEntry>> readers_;
  std::vector<std::unique_ptr<ReaderEntry>> retired_readers_;

  mutable std::mutex health_mutex_;
  AdapterCounters counters_;
  HealthReport health_;

};

void WriterEntry::on_offered_incompatible_qos(dds::DataWriter*,
                                              const dds::OfferedIncompatibleQosStatus& status) {
  incompatible.fetch_add(static_cast<std::uint64_t>(status.total_count_change),
                         std::memory_order_relaxed);
  owner.warn("a reader of " + shape.topic.topic + " requests incompatible QoS (" +
             policy_name(status.last_policy_id) + "); not matched");
}

void ReaderEntry::on_requested_incompatible_qos(
    dds::DataReader*, const dds::RequestedIncompatibleQosStatus& status) {
  incompatible.fetch_add(static_cast<std::uint64_t>(status.total_count_change),
                         std::memory_order_relaxed);
  owner.warn("a writer of " + shape.topic.topic + " offers incompatible QoS (" +
             policy_name(status.last_policy_id) + "); not matched");
}

void ReaderEntry::on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) {
  if (status.total_count_change > 0) {
    owner.count_lost(static_cast<std::uint64_t>(status.total_count_change));
  }
}

void ReaderEntry::on_data_available(dds::DataReader* dr) {
  std::lock_guard lock(mutex);
  if (!active) {
    return;
  }
  dds::SampleInfo info;
  for (;;) {
    ReturnCode_t rc = ReturnCode_t::RETCODE_ERROR;
    try {
      rc = dr->take_next_sample(format->sample(), &info);
    } catch (...) {
      owner.count_receive_error(*this);
      return;
    }
    if (rc == ReturnCode_t::RETCODE_NO_DATA) {
      return;
    }
    if (rc != ReturnCode_t::RETCODE_OK) {
      owner.count_receive_error(*this);
      return;
    }
    if (info.valid_data) {
      owner.deliver(*this, info);
    }
  }
}

// Fast DDS stamps a sample with the realtime clock when its receive thread got it; the router
// measures residence on the steady clock. Moved over by the current offset between the two and
// never later than now, so residence counts from arrival rather than from this callback.
Nanos arrival_on_steady_clock(const eprosima::fastrtps::rtps::Time_t& reception) {
  const Nanos steady_now = std::chrono::duration_cast<Nanos>(
      std::chrono::steady_clock::now().time_since_epoch());
  const Nanos realtime_now = std::chrono::duration_cast<Nanos>(
      std::chrono::system_clock::now().time_since_epoch());
  const Nanos arrived(reception.to_ns());
  const Nanos waited = realtime_now - arrived;
  return waited > Nanos(0) ? steady_now - waited : steady_now;
}

void DdsAdapter::deliver(ReaderEntry& entry, const dds::SampleInfo& info) {
  counters_.received.fetch_add(1, std::memory_order_relaxed);
  if (info.sample_identity.writer_guid().guidPrefix == entry.own_prefix) {
    sink_->on_problem(entry.id, InboundProblem::own_echo);
    return;
  }
  InboundEvent event;
  event.channel = entry.id;
  switch (entry.format->decode(info, segment_.max_message_size, event)) {
    case dds_detail::DecodeResult::own_echo:
      sink_->on_problem(entry.id, InboundProblem::own_echo);
      return;
    case dds_detail::DecodeResult::too_large:
      count_receive_error(entry);
      return;
    case dds_detail::DecodeResult::event:
      break;
  }
  event.received_at = arrival_on_steady_clock(info.reception_timestamp);
  sink_->on_event(event);
}

void DdsAdapter::warn_refused(const WriterEntry& writer, dds_detail::FillRefusal refusal, std::uint16_t first_bytes,
                              std::size_t size) {
  char id[8];
  std::snprintf(id, sizeof id, "0x%04X", static_cast<unsigned>(first_bytes));
  const char* wanted = to_string(writer.shape.topic.representation);
  const std::string why = refusal == dds_detail::FillRefusal::wrong_representation
                              ? std::string("its encapsulation ") + id + " is not " + wanted + ", which the writer announces"
                              : size < kDdsEncapsulationBytes ? "it is shorter than an encapsulation header"
                                                              : std::string("it starts with ") + id + ", no CDR encapsulation";
  warn("channel " + writer.spec.name + ": an event of " + std::to_string(size) + " bytes is not a serialized " +
       writer.shape.topic.type + " sample for " + writer.shape.topic.topic + " (" + why +
       "); such events are not sent and count as send errors (logged once)");
}

// Fast DDS 2.9 has no thread settings, but Linux threads inherit the scheduling policy, priority,
// CPU affinity and name of the thread that creates them, and a participant starts its receive
// and event threads when it is created. So it is created on a short-lived thread that runs as
// `threads` says (named by the caller), and Fast DDS's threads of that participant run that way
// too: the NRT participant's as gateway.realtime's receive threads (rx:<segment>), an HRT or SRT
// participant's as that class's lanes (rx-hrt:<segment>, rx-srt:<segment>).
dds::DomainParticipant* DdsAdapter::create_participant_as(const ThreadPolicy& threads,
                                                          const dds::DomainParticipantQos& qos) {
  const auto domain = static_cast<dds::DomainId_t>(segment_.dds.domain);
  dds::DomainParticipant* created = nullptr;
  std::vector<std::string> problems;
  std::thread creator([&] {
    problems = apply_thread_policy(threads);
    created = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos);
  });
  creator.join();
  for (const auto& problem : problems) {
    log_.log(LogLevel::warning, prefix() + "Fast DDS threads " + threads.name + ": " + problem);
  }
  return created;
}

// Creates the participant of `cls` with its publisher and subscriber; on failure nothing of it
// remains. Control thread, control_mutex_ held.
Status DdsAdapter::open_participant(ChannelClass cls, const ThreadPolicy& threads,
                                    const std::string& thread_name) {
  static const char* const kClassName[3] = {"hrt", "srt", "nrt"};
  ClassParticipant& home = home_of(cls);
  const std::string gateway = self_.name.empty() ? std::string("cosmicd") : self_.name;
  std::string name = gateway + "/" + segment_.name;
  if (cls != ChannelClass::nrt) name += std::string("/") + kClassName[static_cast<std::size_t>(cls)];
  dds::DomainParticipantQos qos;
  if (Status st = dds_detail::participant_qos(segment_, name, qos); !st.ok) {
    return st;
  }
  ThreadPolicy policy = threads;
  policy.name = thread_name;
  home.participant = create_participant_as(policy, qos);
  if (home.participant == nullptr) {
    return Status::failure("cannot create a DDS participant (" + std::string(kClassName[static_cast<std::size_t>(cls)]) +
                           ") in domain " + std::to_string(segment_.dds.domain));
  }
  dds::TypeSupport type(new cosmic::EnvelopePubSubType());
  if (type.register_type(home.participant) != ReturnCode_t::RETCODE_OK) {
    close_participant(home);
    return Status::failure(std::string("cannot register type ") + kEnvelopeTypeName);
  }
  home.publisher = home.participant->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  home.subscriber = home.participant->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (home.publisher == nullptr || home.subscriber == nullptr) {
    close_participant(home);
    return Status::failure("cannot create the DDS publisher/subscriber");
  }
  home.prefix = home.participant->guid().guidPrefix;
  return Status::success();
}

// The HRT or SRT participant is created with the first channel of its class and kept until
// stop(): creating one costs discovery time, and a class that had channels is likely to again.
Status DdsAdapter::ensure_class_participant(ChannelClass cls) {
  if (home_of(cls).participant != nullptr) {
    return Status::success();
  }
  const std::string thread_name = (cls == ChannelClass::hrt ? "rx-hrt:" : "rx-srt:") + segment_.name;
  Status st = open_participant(cls, sink_->class_thread_policy(cls), thread_name);
  if (st.ok) {
    log_.log(LogLevel::info, prefix() + "participant for " + (cls == ChannelClass::hrt ? "HRT" : "SRT") +
                                 " channels up in domain " + std::to_string(segment_.dds.domain));
  }
  return st;
}

// Deletes what is left of a participant whose endpoints are gone (control thread).
void DdsAdapter::close_participant(ClassParticipant& home) {
  if (home.participant == nullptr) {
    return;
  }
  if (home.publisher != nullptr) home.participant->delete_publisher(home.publisher);
  if (home.subscriber != nullptr) home.participant->delete_subscriber(home.subscriber);
  for (auto& [name, ref] : home.topics) home.participant->delete_topic(ref.topic);
  if (dds::DomainParticipantFactory::get_instance()->delete_participant(home.participant) !=
      ReturnCode_t::RETCODE_OK) {
    warn("cannot delete the DDS participant");
  }
  home = ClassParticipant{};
}

Status DdsAdapter::start(EventSink& sink) {
  std::lock_guard control(control_mutex_);
  if (started()) {
    return Status::failure("DDS segment " + segment_.name + " already started");
  }
  auto fail = [&](std::string why) {
    set_health(SegmentHealth::down, why);
    log_.log(LogLevel::error, prefix() + why);
    teardown();
    return Status::failure(std::move(why));
  };
  if (segment_.type != SegmentType::dds) {
    return fail("segment is not of type dds");
  }
  if (segment_.dds.domain > dds_detail::kMaxDomainId) {
    return fail("DDS domain " + std::to_string(segment_.dds.domain) + " is out of range 0.." +
                std::to_string(dds_detail::kMaxDomainId));
  }
  if (!log_attached_) {
    dds_detail::attach_fastdds_log(log_);
    log_attached_ = true;
  }
  try {
    if (Status st = open_participant(ChannelClass::nrt, sink.receive_thread_policy(), "rx:" + segment_.name);
        !st.ok) {
      return fail(st.error);
    }
  } catch (const std::exception& e) {
    return fail(std::string("Fast DDS: ") + e.what());
  } catch (...) {
    return fail("Fast DDS failed to start");
  }
  sink_ = &sink;
  set_health(SegmentHealth::up, "domain " + std::to_string(segment_.dds.domain));
  log_.log(LogLevel::info, prefix() + "participant up in domain " +
                               std::to_string(segment_.dds.domain));
  return Status::success();
}

// The participant's topic `ref` (created with its first user), registering a native topic's type
// as an opaque type the first time the participant meets it. Control thread.
dds::Topic* DdsAdapter::acquire_topic(ClassParticipant& home, const DdsTopicRef& ref, std::string& error) {
  auto it = home.topics.find(ref.topic);
  if (it != home.topics.end()) {
    if (it->second.topic->get_type_name() != ref.type) {
      error = "topic " + ref.topic + " already has type " + it->second.topic->get_type_name() + ", not " + ref.type;
      return nullptr;
    }
    ++it->second.users;
    return it->second.topic;
  }
  if (ref.native && !home.participant->find_type(ref.type)) {
    dds::TypeSupport type(new dds_detail::OpaqueType(ref.type));
    if (type.register_type(home.participant) != ReturnCode_t::RETCODE_OK) {
      error = "cannot register type " + ref.type;
      return nullptr;
    }
  }
  dds::Topic* topic = home.participant->create_topic(ref.topic, ref.type, dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) {
    error = "cannot create topic " + ref.topic + " of type " + ref.type;
    return nullptr;
  }
  home.topics[ref.topic] = TopicRef{topic, 1};
  return topic;
}

void DdsAdapter::release_topic(ClassParticipant& home, dds::Topic* topic) {
  for (auto it = home.topics.begin(); it != home.topics.end(); ++it) {
    if (it->second.topic == topic) {
      if (--it->second.users == 0) {
        home.participant->delete_topic(topic);
        home.topics.erase(it);
      }
      return;
    }
  }
}

std::unique_ptr<WriterEntry> DdsAdapter::create_writer(const ChannelBinding& binding,
                                                       std::string& error) {
  auto entry = std::make_unique<WriterEntry>(*this, binding.id, binding.spec, dds_detail::shape_of(segment_, binding.spec),
                                             self_.id);
  entry->home = &home_of(binding.spec.cls);
  entry->topic = acquire_topic(*entry->home, entry->shape.topic, error);
  if (entry->topic == nullptr) return nullptr;
  entry->writer = entry->home->publisher->create_datawriter(entry->topic,
                                                dds_detail::writer_qos(segment_, binding.spec),
                                                entry.get(), dds::StatusMask::offered_incompatible_qos());
  if (entry->writer == nullptr) {
    release_topic(*entry->home, entry->topic);
    error = "cannot create a DataWriter on " + entry->shape.topic.topic;
    return nullptr;
  }
  entry->format->reserve(std::min<std::uint64_t>(binding.spec.payload, segment_.max_message_size));
  return entry;
}

std::unique_ptr<ReaderEntry> DdsAdapter::create_reader(const ChannelBinding& binding,
                                                       std::string& error) {
  auto entry = std::make_unique<ReaderEntry>(*this, binding.id, binding.spec, dds_detail::shape_of(segment_, binding.spec),
                                             self_.id);
  entry->home = &home_of(binding.spec.cls);
  entry->own_prefix = entry->home->prefix;
  entry->topic = acquire_topic(*entry->home, entry->shape.topic, error);
  if (entry->topic == nullptr) return nullptr;
  entry->active = true;  // before the reader exists: no callback can race with this
  entry->format->reserve(std::min<std::uint64_t>(binding.spec.payload, segment_.max_message_size));
  const dds::StatusMask mask = dds::StatusMask::data_available() <<
                               dds::StatusMask::requested_incompatible_qos() <<
                               dds::StatusMask::sample_lost();
  entry->reader = entry->home->subscriber->create_datareader(
      entry->topic, dds_detail::reader_qos(segment_, binding.spec), entry.get(), mask);
  if (entry->reader == nullptr) {
    release_topic(*entry->home, entry->topic);
    error = "cannot create a DataReader on " + entry->shape.topic.topic;
    return nullptr;
  }
  return entry;
}

void DdsAdapter::destroy_writer(std::unique_ptr<WriterEntry> entry) {
  if (entry->writer != nullptr &&
      entry->home->publisher->delete_datawriter(entry->writer) != ReturnCode_t::RETCODE_OK) {
    warn("cannot delete the DataWriter of " + entry->shape.topic.topic);
  }
  release_topic(*entry->home, entry->topic);
}

void DdsAdapter::deactivate(ReaderEntry& entry) {
  std::lock_guard lock(entry.mutex);  // waits for a callback in progress
  entry.active = false;
}

void DdsAdapter::destroy_reader(std::unique_ptr<ReaderEntry> entry) {
  deactivate(*entry);
  if (entry->reader != nullptr &&
      entry->home->subscriber->delete_datareader(entry->reader) != ReturnCode_t::RETCODE_OK) {
    warn("cannot delete the DataReader of " + entry->shape.topic.topic);
  }
  entry->reader = nullptr;
  release_topic(*entry->home, entry->topic);
  entry->format->release();  // release the buffer; the listener object itself stays
  retired_readers_.push_back(std::move(entry));
}

Status DdsAdapter::configure(std::span<const ChannelBinding> bindings) {
  std::lock_guard control(control_mutex_);
  if (!started()) {
    return Status::failure("DDS segment " + segment_.name + " is not started");
  }
  // Validate and index the wanted endpoints.
  std::map<ChannelId, const ChannelBinding*> want_writers;
  std::map<ChannelId, const ChannelBinding*> want_readers;
  for (const ChannelBinding& b : bindings) {
    if (b.id == kNoChannel) {
      return Status::failure("binding of channel '" + b.spec.name + "' has no channel id");
    }
    if (b.spec.name.empty()) {
      return Status::failure("binding " + std::to_string(b.id) + " has an empty channel name");
    }
    auto& table = b.role == HopRole::subscriber ? want_writers : want_readers;
    if (!table.emplace(b.id, &b).second) {
      return Status::failure("channel '" + b.spec.name + "' is bound twice in the same role");
    }
  }

  std::vector<const ChannelSpec*> specs;
  for (const ChannelBinding& b : bindings) specs.push_back(&b.spec);
  if (const auto collision = dds_topic_collision(specs, segment_.name)) {
    log_.log(LogLevel::error, prefix() + *collision);
    return Status::failure(*collision);
  }

  // 1. Create what is new or changed, before touching anything that runs: a failure leaves the
  //    running configuration as it was.
  std::vector<std::unique_ptr<WriterEntry>> new_writers;
  std::vector<std::unique_ptr<ReaderEntry>> new_readers;
  std::vector<ReaderEntry*> replaced_readers;  // deactivated while their successor is created
  std::string error;
  auto rollback = [&]() {
    for (auto& w : new_writers) destroy_writer(std::move(w));
    for (auto& r : new_readers) destroy_reader(std::move(r));
    for (ReaderEntry* r : replaced_readers) {
      std::lock_guard lock(r->mutex);
      r->active = true;
    }
    log_.log(LogLevel::error, prefix() + error);
    return Status::failure(error);
  };
  try {
    for (const auto& [id, b] : want_writers) {
      auto it = writers_.find(id);  // only this (control) thread changes writers_
      if (it != writers_.end() && it->second->shape == dds_detail::shape_of(segment_, b->spec) &&
          it->second->home == &home_of(b->spec.cls)) {
        continue;
      }
      if (Status st = ensure_class_participant(b->spec.cls); !st.ok) {
        error = st.error;
        return rollback();
      }
      auto entry = create_writer(*b, error);
      if (!entry) return rollback();
      new_writers.push_back(std::move(entry));
    }
    for (const auto& [id, b] : want_readers) {
      auto it = readers_.find(id);
      if (it != readers_.end()) {
        if (it->second->shape == dds_detail::shape_of(segment_, b->spec) && it->second->home == &home_of(b->spec.cls)) {
          continue;
        }
        // Changed QoS: stop the old reader first so that an event is never delivered twice.
        deactivate(*it->second);
        replaced_readers.push_back(it->second.get());
      }
      if (Status st = ensure_class_participant(b->spec.cls); !st.ok) {
        error = st.error;
        return rollback();
      }
      auto entry = create_reader(*b, error);
      if (!entry) return rollback();
      new_readers.push_back(std::move(entry));
    }
  } catch (const std::exception& e) {
    error = std::string("Fast DDS: ") + e.what();
    return rollback();
  }

  // 2. Swap: the router sees the new writer table at once.
  std::vector<std::unique_ptr<WriterEntry>> old_writers;
  {
    std::unique_lock lock(writers_mutex_);
    for (auto it = writers_.begin(); it != writers_.end();) {
      if (want_writers.count(it->first) == 0) {
        old_writers.push_back(std::move(it->second));
        it = writers_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto& w : new_writers) {
      auto& slot = writers_[w->id];
      if (slot) old_writers.push_back(std::move(slot));
      slot = std::move(w);
    }
  }
  std::vector<std::unique_ptr<ReaderEntry>> old_readers;
  {
    std::unique_lock lock(readers_mutex_);
    for (auto it = readers_.begin(); it != readers_.end();) {
      if (want_readers.count(it->first) == 0) {
        old_readers.push_back(std::move(it->second));
        it = readers_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto& r : new_readers) {
      auto& slot = readers_[r->id];
      if (slot) old_readers.push_back(std::move(slot));
      slot = std::move(r);
    }
  }

  // 3. Delete what is gone (no send() can still use these writers).
  for (auto& w : old_writers) destroy_writer(std::move(w));
  for (auto& r : old_readers) destroy_reader(std::move(r));
  return Status::success();
}

SendStatus DdsAdapter::send(const OutboundEvent& event) {
  try {
    std::shared_lock lock(writers_mutex_);
    auto it = writers_.find(event.channel);
    if (it == writers_.end() || event.payload.size() > segment_.max_message_size) {
      counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
      return SendStatus::failed;
    }
    WriterEntry& w = *it->second;
    std::lock_guard sample_lock(w.sample_mutex);
    std::uint16_t first_bytes = 0;
    if (const auto refusal = w.format->fill(event, first_bytes); refusal != dds_detail::FillRefusal::none) {
      counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
      if (!w.refusal_logged.exchange(true, std::memory_order_relaxed)) warn_refused(w, refusal, first_bytes, event.payload.size());
      return SendStatus::failed;
    }
    const ReturnCode_t rc = w.writer->write(w.format->sample(), dds::HANDLE_NIL);
    if (rc == ReturnCode_t::RETCODE_OK) {
      counters_.sent.fetch_add(1, std::memory_order_relaxed);
      return SendStatus::sent;
    }
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    if (rc == ReturnCode_t::RETCODE_TIMEOUT || rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES) {
      return SendStatus::queue_full;
    }
    return SendStatus::failed;
  } catch (...) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return SendStatus::failed;
  }
}

std::size_t DdsAdapter::matched_endpoints(ChannelId channel, HopRole role) const {
  try {
    if (role == HopRole::subscriber) {
      std::shared_lock lock(writers_mutex_);
      auto it = writers_.find(channel);
      dds::PublicationMatchedStatus status;
      if (it == writers_.end() ||
          it->second->writer->get_publication_matched_status(status) != ReturnCode_t::RETCODE_OK) {
        return 0;
      }
      return static_cast<std::size_t>(std::max(0, status.current_count));
    }
    std::shared_lock lock(readers_mutex_);
    auto it = readers_.find(channel);
    dds::SubscriptionMatchedStatus status;
    if (it == readers_.end() ||
        it->second->reader->get_subscription_matched_status(status) != ReturnCode_t::RETCODE_OK) {
      return 0;
    }
    return static_cast<std::size_t>(std::max(0, status.current_count));
  } catch (...) {
    return 0;
  }
}

std::optional<std::uint64_t> DdsAdapter::incompatible_peers(ChannelId channel) const {
  std::uint64_t total = 0;
  {
    std::shared_lock lock(writers_mutex_);
    if (auto it = writers_.find(channel); it != writers_.end()) {
      total += it->second->incompatible.load(std::memory_order_relaxed);
    }
  }
  std::shared_lock lock(readers_mutex_);
  if (auto it = readers_.find(channel); it != readers_.end()) {
    total += it->second->incompatible.load(std::memory_order_relaxed);
  }
  return total;
}

void DdsAdapter::teardown() {
  // Readers first: after deactivation no callback reaches the sink any more.
  {
    std::shared_lock lock(readers_mutex_);
    for (auto& [id, r] : readers_) deactivate(*r);
  }
  std::unordered_map<ChannelId, std::unique_ptr<WriterEntry>> writers;
  {
    std::unique_lock lock(writers_mutex_);
    writers.swap(writers_);
  }
  std::unordered_map<ChannelId, std::unique_ptr<ReaderEntry>> readers;
  {
    std::unique_lock lock(readers_mutex_);
    readers.swap(readers_);
  }
  try {
    for (auto& [id, w] : writers) destroy_writer(std::move(w));
    for (auto& [id, r] : readers) destroy_reader(std::move(r));
    for (ClassParticipant& home : classes_) close_participant(home);
  } catch (...) {
    warn("Fast DDS threw while stopping");
  }
  classes_ = {};
  retired_readers_.clear();
  sink_ = nullptr;
  if (log_attached_) {
    dds_detail::detach_fastdds_log(log_);
    log_attached_ = false;
  }
}

void DdsAdapter::stop() {
  std::lock_guard control(control_mutex_);
  if (!started()) {
    return;
  }
  teardown();
  set_health(SegmentHealth::down, "stopped");
  log_.log(LogLevel::info, prefix() + "stopped");
}

}  // namespace

std::unique_ptr<DdsSegmentAdapter> make_dds_segment_adapter(const SegmentSpec& segment,
                                                            const GatewayIdentity& self,
                                                            Logger& log) {
  return std::make_unique<DdsAdapter>(segment, self, log);
}

std::unique_ptr<SegmentAdapter> make_dds_adapter(const SegmentSpec& segment,
                                                 const GatewayIdentity& self, Logger& log) {
  return make_dds_segment_adapter(segment, self, log);
}

}  // namespace cosmic

// Participants, topics, readers and writers of the DDS adapter, and Fast DDS's callbacks on them
// (see dds_adapter.cpp for threads and locks).
#include <chrono>
#include <cstdio>
#include <thread>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <cosmic_dds_idl/EnvelopePubSubTypes.h>

#include "cosmic/arrival_clock.hpp"
#include "cosmic/dds_encapsulation.hpp"
#include "dds_adapter_impl.hpp"
#include "dds_opaque_type.hpp"

namespace cosmic::dds_detail {
namespace {

const char* policy_name(dds::QosPolicyId_t id) {
  switch (id) {
    case dds::RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case dds::DURABILITY_QOS_POLICY_ID:
      return "durability";
    case dds::DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case dds::LATENCYBUDGET_QOS_POLICY_ID:
      return "latency_budget";
    case dds::LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case dds::OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    case dds::PARTITION_QOS_POLICY_ID:
      return "partition";
    case dds::DATAREPRESENTATION_QOS_POLICY_ID:
      return "data_representation";
    default:
      return "other";
  }
}

}  // namespace

void WriterEntry::on_offered_incompatible_qos(dds::DataWriter*, const dds::OfferedIncompatibleQosStatus& status) {
  incompatible.fetch_add(static_cast<std::uint64_t>(status.total_count_change), std::memory_order_relaxed);
  owner.warn("a reader of " + shape.topic.topic + " requests incompatible QoS (" + policy_name(status.last_policy_id) +
             "); not matched");
}

void ReaderEntry::on_requested_incompatible_qos(dds::DataReader*, const dds::RequestedIncompatibleQosStatus& status) {
  incompatible.fetch_add(static_cast<std::uint64_t>(status.total_count_change), std::memory_order_relaxed);
  owner.warn("a writer of " + shape.topic.topic + " offers incompatible QoS (" + policy_name(status.last_policy_id) +
             "); not matched");
}

void ReaderEntry::on_sample_lost(dds::DataReader*, const dds::SampleLostStatus& status) {
  if (status.total_count_change > 0) {
    owner.count_lost(static_cast<std::uint64_t>(status.total_count_change));
  }
}

void ReaderEntry::on_data_available(dds::DataReader* dr) {
  PiLock lock(mutex);
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
// measures residence on the steady clock. Moved over by the current offset between the two,
// clamped like every adapter's kernel timestamps (arrival_clock.hpp): never later than now, and a
// stepped clock never invents more than a second of residence (which could mark an HRT channel
// violated), so residence counts from arrival rather than from this callback.
Nanos arrival_on_steady_clock(const eprosima::fastrtps::rtps::Time_t& reception) {
  return steady_arrival_now(reception.to_ns());
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
    case DecodeResult::too_large:
      count_receive_error(entry);
      return;
    case DecodeResult::event:
      break;
  }
  event.received_at = arrival_on_steady_clock(info.reception_timestamp);
  // This thread is a receive thread of the channel's class participant, which carries that class
  // alone: the router may send the event on from here (cosmic/event.hpp); NRT only where the
  // receive threads' scheduling allows it (cosmic/thread_policy.hpp: may_do_lane_work).
  if (entry.spec.cls != ChannelClass::nrt || nrt_receivers_send_) event.receiver_class = entry.spec.cls;
  sink_->on_event(event);
}

// Control thread, for reports: the tables are read under their shared locks only to copy what
// the rules need; the rules run after, on copies (no Fast DDS call, no lock across them).
std::vector<PeerQosConflict> DdsAdapter::peer_qos_conflicts(ChannelId channel) const {
  try {
    std::optional<std::pair<DdsTopicRef, ChannelSpec>> writer, reader;
    {
      const auto writers = writers_.read();
      if (auto it = writers->find(channel); it != writers->end())
        writer.emplace(it->second->shape.topic, it->second->spec);
    }
    {
      SharedLock lock(readers_mutex_);
      if (auto it = readers_.find(channel); it != readers_.end())
        reader.emplace(it->second->shape.topic, it->second->spec);
    }
    std::vector<PeerQosConflict> out;
    if (writer) {
      const auto& [topic, spec] = *writer;
      out = peer_conflicts(local_writer_qos(topic, writer_qos(segment_, spec)), DdsLocalRole::writer,
                           discovery_.remote_of(topic.topic, true), false);
    }
    if (reader) {
      const auto& [topic, spec] = *reader;
      auto found = peer_conflicts(local_reader_qos(topic, reader_qos(segment_, spec)), DdsLocalRole::reader,
                                  discovery_.remote_of(topic.topic, false), spec.reaction_time.has_value());
      out.insert(out.end(), found.begin(), found.end());
    }
    return out;
  } catch (...) {
    return {};
  }
}

void DdsAdapter::warn_refused(const WriterEntry& writer, FillRefusal refusal, std::uint16_t first_bytes,
                              std::size_t size) {
  char id[8];
  std::snprintf(id, sizeof id, "0x%04X", static_cast<unsigned>(first_bytes));
  const char* wanted = to_string(writer.shape.topic.representation);
  const std::string why =
      refusal == FillRefusal::wrong_representation
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
    // The listener from the start: a remote endpoint discovered before it was set would never
    // be checked. Mask none: only discovery reaches it, never an endpoint's status.
    created = dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos, &discovery_,
                                                                                dds::StatusMask::none());
  });
  creator.join();
  for (const auto& problem : problems) {
    log_.log(LogLevel::warning, prefix() + "Fast DDS threads " + threads.name + ": " + problem);
  }
  return created;
}

// Creates the participant of `cls` with its publisher and subscriber; on failure nothing of it
// remains. Control thread, control_mutex_ held.
Status DdsAdapter::open_participant(ChannelClass cls, const ThreadPolicy& threads, const std::string& thread_name) {
  static const char* const kClassName[3] = {"hrt", "srt", "nrt"};
  ClassParticipant& home = home_of(cls);
  const std::string gateway = self_.name.empty() ? std::string("cosmicd") : self_.name;
  std::string name = gateway + "/" + segment_.name;
  if (cls != ChannelClass::nrt) name += std::string("/") + kClassName[static_cast<std::size_t>(cls)];
  dds::DomainParticipantQos qos;
  if (Status st = participant_qos(segment_, name, segment_.dds.shared_memory[static_cast<std::size_t>(cls)], qos);
      !st.ok) {
    return st;
  }
  ThreadPolicy policy = threads;
  policy.name = thread_name;
  // start() opens the NRT participant first: what an earlier run discovered is gone with it.
  if (cls == ChannelClass::nrt) discovery_.clear();
  home.participant = create_participant_as(policy, qos);
  if (home.participant == nullptr) {
    return Status::failure("cannot create a DDS participant (" +
                           std::string(kClassName[static_cast<std::size_t>(cls)]) + ") in domain " +
                           std::to_string(segment_.dds.domain));
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
  discovery_.add_own_participant(home.prefix);
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
  if (dds::DomainParticipantFactory::get_instance()->delete_participant(home.participant) != ReturnCode_t::RETCODE_OK) {
    warn("cannot delete the DDS participant");
  }
  home = ClassParticipant{};
}

// The participant's topic `ref` (created with its first user), registering a native topic's type
// as an opaque type the first time the participant meets it. Control thread.
Result<dds::Topic*> DdsAdapter::acquire_topic(ClassParticipant& home, const DdsTopicRef& ref) {
  auto it = home.topics.find(ref.topic);
  if (it != home.topics.end()) {
    if (it->second.topic->get_type_name() != ref.type) {
      return Error{"topic " + ref.topic + " already has type " + it->second.topic->get_type_name() + ", not " +
                   ref.type};
    }
    ++it->second.users;
    return it->second.topic;
  }
  if (ref.native && !home.participant->find_type(ref.type)) {
    dds::TypeSupport type(new OpaqueType(ref.type));
    if (type.register_type(home.participant) != ReturnCode_t::RETCODE_OK)
      return Error{"cannot register type " + ref.type};
  }
  dds::Topic* topic = home.participant->create_topic(ref.topic, ref.type, dds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) return Error{"cannot create topic " + ref.topic + " of type " + ref.type};
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

Result<std::unique_ptr<WriterEntry>> DdsAdapter::create_writer(const ChannelBinding& binding) {
  auto entry = std::make_unique<WriterEntry>(*this, binding.id, binding.spec, shape_of(segment_, binding.spec));
  entry->home = &home_of(binding.spec.cls);
  Result<dds::Topic*> topic = acquire_topic(*entry->home, entry->shape.topic);
  if (!topic) return std::move(topic).error();
  entry->topic = topic.value();
  entry->writer = entry->home->publisher->create_datawriter(entry->topic, writer_qos(segment_, binding.spec),
                                                            entry.get(), dds::StatusMask::offered_incompatible_qos());
  if (entry->writer == nullptr) {
    release_topic(*entry->home, entry->topic);
    return Error{"cannot create a DataWriter on " + entry->shape.topic.topic + permission_hint("publish")};
  }
  {
    PiLock sample(entry->sample_mutex);  // nothing sends on it yet; the analysis asks for it all the same
    entry->format->reserve(std::min<std::uint64_t>(binding.spec.payload_on(segment_.name), segment_.max_message_size));
  }
  return entry;
}

// On a secure segment the usual reason a DataWriter or DataReader is refused: the signed permissions
// do not grant this identity the topic (Fast DDS logs it, but does not say so to its caller).
std::string DdsAdapter::permission_hint(const char* action) const {
  if (!segment_.dds.security) return {};
  return std::string(" (a secure segment: do the permissions grant ") + segment_.dds.security->subject + " to " +
         action + " it?)";
}

Result<std::unique_ptr<ReaderEntry>> DdsAdapter::create_reader(const ChannelBinding& binding) {
  auto entry = std::make_unique<ReaderEntry>(*this, binding.id, binding.spec, shape_of(segment_, binding.spec));
  entry->home = &home_of(binding.spec.cls);
  entry->own_prefix = entry->home->prefix;
  Result<dds::Topic*> topic = acquire_topic(*entry->home, entry->shape.topic);
  if (!topic) return std::move(topic).error();
  entry->topic = topic.value();
  {
    PiLock lock(entry->mutex);  // the reader does not exist yet: no callback can race with this
    entry->active = true;
    entry->format->reserve(std::min<std::uint64_t>(binding.spec.payload_on(segment_.name), segment_.max_message_size));
  }
  const dds::StatusMask mask = dds::StatusMask::data_available()
                               << dds::StatusMask::requested_incompatible_qos() << dds::StatusMask::sample_lost();
  entry->reader =
      entry->home->subscriber->create_datareader(entry->topic, reader_qos(segment_, binding.spec), entry.get(), mask);
  if (entry->reader == nullptr) {
    release_topic(*entry->home, entry->topic);
    return Error{"cannot create a DataReader on " + entry->shape.topic.topic + permission_hint("subscribe")};
  }
  return entry;
}

void DdsAdapter::destroy_writer(WriterEntry& entry) {
  if (entry.writer != nullptr && entry.home->publisher->delete_datawriter(entry.writer) != ReturnCode_t::RETCODE_OK) {
    warn("cannot delete the DataWriter of " + entry.shape.topic.topic);
  }
  entry.writer = nullptr;
  release_topic(*entry.home, entry.topic);
}

void DdsAdapter::deactivate(ReaderEntry& entry) {
  PiLock lock(entry.mutex);  // waits for a callback in progress
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
  {
    PiLock lock(entry->mutex);  // inactive already: no callback holds it for long
    entry->format->release();   // release the buffer; the listener object itself stays
  }
  retired_readers_.push_back(std::move(entry));
}

}  // namespace cosmic::dds_detail

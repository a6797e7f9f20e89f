#include "cosmic/dds_federation_link.hpp"

#include <pthread.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <sstream>
#include <thread>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "cosmic/certificate_subject.hpp"
#include "cosmic/dds_names.hpp"
#include "cosmic/held_announcements.hpp"
#include "cosmic_dds_idl/FederationPubSubTypes.h"
#include "dds_authentication.hpp"
#include "dds_qos.hpp"

namespace cosmic {
namespace {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;

constexpr const char* kTopic = kFederationTopicName;
// Messages queued between two take() calls, and announcements held for their senders'
// authentication (secure segments); beyond either a flood is dropped and counted.
constexpr std::size_t kMaxQueued = 4096;
// An announcement whose sender has not authenticated in this time is reported as refused (and
// stays held: a handshake Fast DDS completes later still releases it).
constexpr Nanos kHoldReportAfter = std::chrono::seconds(10);

eprosima::fastrtps::Duration_t duration_of(Nanos value) {
  return eprosima::fastrtps::Duration_t(static_cast<std::int32_t>(value.count() / 1'000'000'000),
                                        static_cast<std::uint32_t>(value.count() % 1'000'000'000));
}

// A writer's handle as text: its GUID's 16 bytes in hexadecimal.
std::string handle_text(const dds::InstanceHandle_t& handle) {
  std::string out;
  char byte[3];
  for (std::size_t i = 0; i < 16; ++i) {
    std::snprintf(byte, sizeof byte, "%02x", static_cast<unsigned>(handle.value[i]));
    out += byte;
  }
  return out;
}

bool from_prefix(const dds::InstanceHandle_t& handle, const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  for (std::size_t i = 0; i < eprosima::fastrtps::rtps::GuidPrefix_t::size; ++i) {
    if (prefix.value[i] != handle.value[i]) return false;
  }
  return true;
}

eprosima::fastrtps::rtps::GuidPrefix_t prefix_of(const dds::InstanceHandle_t& handle) {
  eprosima::fastrtps::rtps::GuidPrefix_t prefix;
  for (std::size_t i = 0; i < prefix.size; ++i) prefix.value[i] = handle.value[i];
  return prefix;
}

eprosima::fastrtps::rtps::GuidPrefix_t guid_prefix(const ParticipantKey& key) {
  eprosima::fastrtps::rtps::GuidPrefix_t prefix;
  std::copy(key.begin(), key.end(), std::begin(prefix.value));
  return prefix;
}

Nanos steady_now() { return std::chrono::duration_cast<Nanos>(std::chrono::steady_clock::now().time_since_epoch()); }

std::string prefix_text(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  std::ostringstream out;
  out << prefix;
  return out.str();
}

// The subject a participant claims, when its GUID prefix proves it holds it (the prefix follows
// from the certificate's subject under PKI-DH); empty otherwise.
std::string proven(const std::string& claim, const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  if (claim.empty()) return {};
  const auto subject = parse_certificate_subject(claim);
  return subject && holds_subject(subject.value(), prefix.value) ? subject.value().text : std::string();
}

class DdsFederationLink final : public FederationLink, private dds::DataReaderListener {
 public:
  DdsFederationLink(SegmentSpec segment, GatewayIdentity self, FederationSpec federation, Logger& log)
      : segment_(std::move(segment)),
        self_(std::move(self)),
        federation_(std::move(federation)),
        lease_(federation_.lease),
        log_(log),
        authentications_("federation: ", log, false),
        participant_listener_(authentications_) {}

  ~DdsFederationLink() override { close(); }

  std::string start() override {
    dds::DomainParticipantQos qos;
    if (Status st =
            dds_detail::participant_qos(segment_, (self_.name.empty() ? "cosmicd" : self_.name) + "/federation",
                                        segment_.dds.shared_memory[static_cast<std::size_t>(ChannelClass::nrt)], qos);
        !st.ok) {
      return st.error;
    }
    // The participant's lease is what the others judge this gateway by: each reader drops a remote
    // participant after the lease *that participant* announced, so gateways may differ in lease.
    qos.wire_protocol().builtin.discovery_config.leaseDuration = duration_of(lease_);
    qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = duration_of(lease_ / 3);
    participant_ = create_participant(qos, segment_.dds.security ? &participant_listener_ : nullptr);
    if (participant_ == nullptr)
      return "cannot create the federation's DDS participant in domain " + std::to_string(segment_.dds.domain);
    own_prefix_ = participant_->guid().guidPrefix;
    dds::TypeSupport type(new cosmic_federation::AnnouncementPubSubType());
    if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK)
      return fail("cannot register the federation type");
    topic_ = participant_->create_topic(kTopic, type.get_type_name(), dds::TOPIC_QOS_DEFAULT);
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (!topic_ || !publisher_ || !subscriber_)
      return fail("cannot create the federation topic, publisher or subscriber");
    writer_ = publisher_->create_datawriter(topic_, writer_qos());
    const dds::StatusMask mask = dds::StatusMask::data_available() << dds::StatusMask::subscription_matched();
    reader_ = subscriber_->create_datareader(topic_, reader_qos(), this, mask);
    if (!writer_ || !reader_) return fail("cannot create the federation writer or reader");
    return {};
  }

  bool publish(std::uint64_t gateway, const std::string& body) override {
    if (!writer_) return false;
    cosmic_federation::Announcement sample;
    sample.gateway(gateway);
    sample.body(body);
    const bool ok = writer_->write(&sample);
    std::lock_guard lock(mutex_);
    ++(ok ? counters_.published : counters_.publish_errors);
    if (ok) announced_ = gateway;
    return ok;
  }

  void withdraw() override {
    if (!writer_ || announced_ == 0) return;
    cosmic_federation::Announcement sample;
    sample.gateway(announced_);
    if (writer_->dispose(&sample, dds::HANDLE_NIL) != ReturnCode_t::RETCODE_OK) {
      log_.log(LogLevel::warning,
               "federation: cannot withdraw this gateway's announcement; peers release it after the lease");
    }
    // Asynchronous publishing: give the dispose a moment to leave before the writer goes.
    writer_->wait_for_acknowledgments(duration_of(Nanos(500'000'000)));
    announced_ = 0;
  }

  std::vector<FederationMessage> take() override {
    std::lock_guard lock(mutex_);
    if (held_.size() != 0) {
      const auto state_of = [this](const ParticipantKey& key) { return sender_state(guid_prefix(key)); };
      const auto judge = [this](const ParticipantKey& key, FederationMessage& m) { authenticate(guid_prefix(key), m); };
      for (FederationMessage& m : held_.release(steady_now(), state_of, judge)) queue_.push_back(std::move(m));
    }
    std::vector<FederationMessage> out;
    out.swap(queue_);
    return out;
  }

  FederationLinkCounters counters() const override {
    std::lock_guard lock(mutex_);
    return counters_;
  }

 private:
  // Both ends: reliable, durable for late joiners, the newest announcement per gateway. Liveliness
  // stays DDS's default (automatic, infinite): a reader's requested lease would have to be at least
  // every writer's, and Fast DDS times writers by the reader's; the participant lease does it instead.
  template <typename EndpointQos>
  void common_qos(EndpointQos& qos) const {
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.durability().kind = dds::TRANSIENT_LOCAL_DURABILITY_QOS;
    qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 1;
    qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  }

  dds::DataWriterQos writer_qos() const {
    dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
    common_qos(qos);
    qos.publish_mode().kind = dds::ASYNCHRONOUS_PUBLISH_MODE;
    return qos;
  }

  dds::DataReaderQos reader_qos() const {
    dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
    common_qos(qos);
    const auto peers = static_cast<std::int32_t>(FederationView::kDefaultMaxPeers);
    qos.resource_limits().max_instances = peers;
    qos.resource_limits().max_samples_per_instance = 1;
    qos.resource_limits().max_samples = peers;
    return qos;
  }

  // Fast DDS threads inherit their creator's name: they show as fed:<segment> in ps and top.
  dds::DomainParticipant* create_participant(const dds::DomainParticipantQos& qos,
                                             dds::DomainParticipantListener* listener) {
    dds::DomainParticipant* created = nullptr;
    const std::string name = ("fed:" + segment_.name).substr(0, 15);
    std::thread creator([&] {
      pthread_setname_np(pthread_self(), name.c_str());
      created = dds::DomainParticipantFactory::get_instance()->create_participant(
          static_cast<dds::DomainId_t>(segment_.dds.domain), qos, listener, dds::StatusMask::none());
    });
    creator.join();
    return created;
  }

  std::string fail(std::string why) {
    close();
    return why;
  }

  void close() {
    if (!participant_) return;
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
    participant_ = nullptr;
    writer_ = nullptr;
    reader_ = nullptr;
    topic_ = nullptr;
    publisher_ = nullptr;
    subscriber_ = nullptr;
  }

  // Listener thread, mutex_ held.
  void queue(FederationMessage message) {
    ++counters_.received;
    if (message.kind == FederationMessage::Kind::announcement) {
      for (FederationMessage& queued : queue_) {
        if (queued.kind == message.kind && queued.key == message.key && queued.source == message.source) {
          queued.body = std::move(message.body);
          return;
        }
      }
    }
    if (queue_.size() >= kMaxQueued) {
      ++counters_.dropped;
      return;
    }
    queue_.push_back(std::move(message));
  }

  void on_data_available(dds::DataReader* reader) override {
    cosmic_federation::Announcement sample;
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (from_prefix(info.publication_handle, own_prefix_)) continue;
      FederationMessage m;
      m.source = handle_text(info.publication_handle);
      const bool secure = segment_.dds.security.has_value();
      if (info.valid_data) {
        m.key = sample.gateway();
        m.body = std::move(sample.body());
        if (secure) {
          hold(std::move(m), prefix_of(info.publication_handle));
          continue;
        }
      } else {
        m.kind = info.instance_state == dds::NOT_ALIVE_DISPOSED_INSTANCE_STATE ? FederationMessage::Kind::withdrawn
                                                                               : FederationMessage::Kind::lost;
      }
      std::lock_guard lock(mutex_);
      if (secure) held_.forget(m.source);
      queue(std::move(m));
    }
  }

  SenderAuthentication sender_state(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) const {
    using State = dds_detail::ParticipantAuthentications::State;
    switch (authentications_.state(prefix)) {
      case State::authorized:
        return SenderAuthentication::authorized;
      case State::refused:
        return SenderAuthentication::refused;
      case State::pending:
        break;
    }
    return SenderAuthentication::pending;
  }

  // On a secure segment every announcement waits in held_ until take() finds its participant's
  // authentication decided (held_announcements.hpp says why); then authenticate() judges it.
  void hold(FederationMessage m, const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
    ParticipantKey key;
    std::copy(std::begin(prefix.value), std::end(prefix.value), key.begin());
    std::lock_guard lock(mutex_);
    ++counters_.received;
    if (!held_.hold(std::move(m), key, "participant " + prefix_text(prefix), steady_now())) ++counters_.dropped;
  }

  // The sender's subject, or why its announcement does not count; its participant authenticated
  // (the handshake proved it holds the certificate behind its GUID). With gateway.federation.peers
  // its GUID prefix must be one a listed subject gives.
  void authenticate(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix, FederationMessage& m) const {
    const std::string participant = "participant " + prefix_text(prefix);
    const std::string claim = authentications_.claimed_subject(prefix);
    if (federation_.peers.empty()) {
      m.subject = proven(claim, prefix);
      return;
    }
    for (const FederationPeerSpec& peer : federation_.peers) {
      for (const auto& key : peer.key_prefixes) {
        if (std::equal(key.begin(), key.end(), prefix.value)) {
          m.subject = peer.subject;
          return;
        }
      }
    }
    const std::string holds = proven(claim, prefix);
    m.refusal = participant +
                (!holds.empty()   ? " authenticated as " + holds
                 : !claim.empty() ? " authenticated and claims subject " + claim
                                  : " authenticated without naming its subject") +
                ", which gateway.federation.peers does not list";
  }

  // A writer unmatched: its participant's lease expired (killed, cut off) or it was deleted without
  // withdrawing first. Matched again: back (its durable announcement follows).
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override {
    if (status.current_count_change == 0 || from_prefix(status.last_publication_handle, own_prefix_)) return;
    const auto kind = status.current_count_change < 0 ? FederationMessage::Kind::lost : FederationMessage::Kind::alive;
    const std::string source = handle_text(status.last_publication_handle);
    std::lock_guard lock(mutex_);
    // A writer gone takes what it left held with it: released after its `lost`, it would revive a
    // gateway whose writer no longer exists.
    if (kind == FederationMessage::Kind::lost) held_.forget(source);
    queue(FederationMessage{kind, source, 0, {}});
  }

  SegmentSpec segment_;
  GatewayIdentity self_;
  FederationSpec federation_;
  Nanos lease_;
  Logger& log_;
  dds_detail::ParticipantAuthentications authentications_;  // secure segments only
  dds_detail::AuthenticationListener participant_listener_;
  dds::DomainParticipant* participant_ = nullptr;
  dds::Topic* topic_ = nullptr;
  dds::Publisher* publisher_ = nullptr;
  dds::Subscriber* subscriber_ = nullptr;
  dds::DataWriter* writer_ = nullptr;
  dds::DataReader* reader_ = nullptr;
  eprosima::fastrtps::rtps::GuidPrefix_t own_prefix_;
  std::uint64_t announced_ = 0;  // the key of our instance, once written

  mutable std::mutex mutex_;
  std::vector<FederationMessage> queue_;
  HeldAnnouncements held_{kMaxQueued, kHoldReportAfter};  // secure segments only
  FederationLinkCounters counters_;
};

}  // namespace

std::unique_ptr<FederationLink> make_dds_federation_link(const SegmentSpec& segment, const GatewayIdentity& self,
                                                         const FederationSpec& federation, Logger& log) {
  return std::make_unique<DdsFederationLink>(segment, self, federation, log);
}

}  // namespace cosmic

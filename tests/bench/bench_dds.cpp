#include "bench_dds.hpp"

#include <chrono>
#include <condition_variable>
#include <cstring>
#include <functional>
#include <iostream>
#include <mutex>
#include <string>
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
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/common/SerializedPayload.h>

#include <cosmic_dds_idl/EnvelopePubSubTypes.h>

#include "bench_peer.hpp"
#include "cosmic/dds_security_qos.hpp"

namespace cosmic_bench {
namespace {

namespace fdds = eprosima::fastdds::dds;
namespace rtps = eprosima::fastrtps::rtps;
using eprosima::fastrtps::types::ReturnCode_t;

// The encapsulation header of every native sample the peer writes: CDR little-endian (XCDR1),
// options 0. Its body is the event's payload (stamp, index, pattern), which a CDR type such as
// struct Sample_ { uint64 stamp_ns; uint32 index; uint32 zero; octet rest[N]; } serializes to.
constexpr std::uint8_t kCdrLe[4] = {0x00, 0x01, 0x00, 0x00};
constexpr std::size_t kHeader = sizeof kCdrLe;

// A sample that starts with the CDR_LE (XCDR1) encapsulation header: 00 01, options 00 0x where the
// low two bits count the padding after the body (a typed hop's struct, 63 bytes, announces 1).
bool cdr_le_sample(const std::vector<std::uint8_t>& bytes) {
  return bytes.size() >= kHeader && std::memcmp(bytes.data(), kCdrLe, 3) == 0 && (bytes[3] & 0xFC) == 0;
}

// A native topic's sample: the serialized bytes, encapsulation header included.
struct RawSample {
  std::vector<std::uint8_t> bytes;
};

// A type known only by name, whose samples are their serialized bytes (as cosmicd's opaque type,
// written apart from it so the bench does not borrow the gateway's own code).
class RawType final : public fdds::TopicDataType {
 public:
  RawType(const std::string& name, std::uint32_t initial_bytes) {
    setName(name.c_str());
    m_typeSize = initial_bytes;  // history memory PREALLOCATED_WITH_REALLOC: bigger samples grow it
    m_isGetKeyDefined = false;
    auto_fill_type_object(false);
    auto_fill_type_information(false);
  }
  bool serialize(void* data, rtps::SerializedPayload_t* payload) override {
    const auto& bytes = static_cast<const RawSample*>(data)->bytes;
    if (bytes.size() > payload->max_size) return false;
    std::memcpy(payload->data, bytes.data(), bytes.size());
    payload->length = static_cast<std::uint32_t>(bytes.size());
    payload->encapsulation = CDR_LE;
    return true;
  }
  bool deserialize(rtps::SerializedPayload_t* payload, void* data) override {
    if (payload->length > payload->max_size) return false;
    static_cast<RawSample*>(data)->bytes.assign(payload->data, payload->data + payload->length);
    return true;
  }
  std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
    const auto* sample = static_cast<const RawSample*>(data);
    return [sample]() { return static_cast<std::uint32_t>(sample->bytes.size()); };
  }
  void* createData() override { return new RawSample(); }
  void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
  bool getKey(void*, rtps::InstanceHandle_t*, bool) override { return false; }
};

class Participant {
 public:
  fdds::DomainParticipant* participant = nullptr;
  fdds::Topic* topic = nullptr;
  ~Participant() {
    if (participant != nullptr) {
      participant->delete_contained_entities();
      fdds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    }
  }
  // o.native_type empty: the topic carries cosmic::Envelope; otherwise RawType of that name. With
  // o.identity, a secure participant with the same plugins and properties as cosmicd's.
  bool open(const DdsOptions& o) {
    fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
    qos.name("cosmic-bench-peer");
    if (!o.identity.empty()) cosmic::add_dds_security(security_spec(o), qos);
    participant = fdds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<fdds::DomainId_t>(o.domain), qos);
    if (participant == nullptr) return false;
    fdds::TypeSupport type(
        o.native_type.empty()
            ? static_cast<fdds::TopicDataType*>(new cosmic::EnvelopePubSubType())
            : new RawType(o.native_type, static_cast<std::uint32_t>(std::max<std::uint64_t>(o.size + kHeader, 512))));
    type.register_type(participant);
    topic = participant->create_topic(o.topic, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
    return topic != nullptr;
  }

 private:
  static cosmic::DdsSecuritySpec security_spec(const DdsOptions& o) {
    cosmic::DdsSecuritySpec spec;
    spec.identity_ca = o.pki + "/identity_ca.pem";
    spec.certificate = o.pki + "/" + o.identity + "_cert.pem";
    spec.private_key = o.pki + "/" + o.identity + "_key.pem";
    spec.permissions_ca = o.pki + "/permissions_ca.pem";
    spec.governance = o.governance.empty() ? o.pki + "/governance.p7s" : o.governance;
    spec.permissions = o.pki + "/permissions.p7s";
    return spec;
  }
};

class Matched {
 public:
  void set(int n) {
    {
      std::lock_guard lock(mutex_);
      count_ = n;
    }
    cv_.notify_all();
  }
  bool wait(int n, double timeout_s) {
    std::unique_lock lock(mutex_);
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(static_cast<int>(timeout_s * 1000));
    while (count_ < n && !g_stop) {
      if (cv_.wait_until(lock, std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(100))) ==
              std::cv_status::timeout &&
          std::chrono::steady_clock::now() >= deadline)
        return false;
    }
    return count_ >= n;
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  int count_ = 0;
};

class WriterListener : public fdds::DataWriterListener {
 public:
  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& status) override {
    matched.set(status.current_count);
  }
  Matched matched;
};

class ReaderListener : public fdds::DataReaderListener {
 public:
  ReaderListener(Recorder& r, bool native) : recorder(r), native_(native) {}
  void on_data_available(fdds::DataReader* reader) override {
    fdds::SampleInfo info;
    void* sample = native_ ? static_cast<void*>(&raw_) : static_cast<void*>(&env_);
    while (reader->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const std::int64_t now = mono_ns();
      if (!native_) {
        recorder.record(env_.payload().data(), env_.payload().size(), now);
      } else if (!cdr_le_sample(raw_.bytes)) {
        recorder.record(raw_.bytes.data(), 0, now);  // not what the publisher wrote: malformed
      } else {
        recorder.record(raw_.bytes.data() + kHeader, raw_.bytes.size() - kHeader, now);
      }
    }
  }
  void on_subscription_matched(fdds::DataReader*, const fdds::SubscriptionMatchedStatus& status) override {
    if (status.current_count_change > 0 && status.current_count >= 1) err_line("MATCHED");
  }
  Recorder& recorder;

 private:
  bool native_;
  cosmic::Envelope env_;
  RawSample raw_;
};

// A writer's or reader's history: KEEP_LAST of depth keep_last, or (keep_last 0) KEEP_ALL of at most
// max_samples, `allocated` of them allocated up front.
template <typename Qos>
void set_history(Qos& qos, int keep_last, std::int32_t max_samples, std::int32_t allocated) {
  if (keep_last > 0) {
    qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = keep_last;
  } else {
    qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
    qos.resource_limits().max_samples = max_samples;
    qos.resource_limits().allocated_samples = allocated;
    qos.resource_limits().max_samples_per_instance = max_samples;
  }
}

}  // namespace

int dds_pub(const DdsOptions& o) {
  Participant p;
  const bool native = !o.native_type.empty();
  if (!p.open(o)) {
    err_line("cannot create the DDS participant/topic");
    return 3;
  }
  fdds::Publisher* publisher = p.participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  // The native samples are XCDR1 (their header says so); the envelope keeps the default, also XCDR1.
  if (native) qos.representation().m_value = {fdds::XCDR_DATA_REPRESENTATION};
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(1, 0);
  if (!o.default_heartbeat)
    qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 50'000'000);
  qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  set_history(qos, o.keep_last, 5000, 500);
  qos.publish_mode().kind = fdds::SYNCHRONOUS_PUBLISH_MODE;
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  WriterListener listener;
  fdds::DataWriter* writer =
      publisher->create_datawriter(p.topic, qos, &listener, fdds::StatusMask::publication_matched());
  if (writer == nullptr) {
    err_line("cannot create the DataWriter");
    return 3;
  }
  if (!listener.matched.wait(1, o.match_timeout)) {
    err_line("no reader matched");
    return 2;
  }
  err_line("MATCHED");
  if (o.wait_go) {
    err_line("WAITING");
    std::string go;
    std::getline(std::cin, go);
  }
  cosmic::Envelope env;
  RawSample raw;
  raw.bytes.reserve(kHeader + std::max<std::uint64_t>(o.size, kMinSize));
  void* const sample = native ? static_cast<void*>(&raw) : static_cast<void*>(&env);
  std::uint64_t retries = 0;
  const int rc = publish_all(
      o.count, o.size, o.rate, o.warmup,
      [&](const std::vector<std::uint8_t>& payload) {
        const auto index = static_cast<std::uint32_t>(get_le(payload.data() + 8, 4));
        if (native) {
          // Header, then the payload with the stamp the publisher just wrote (one copy, as any
          // serialization of a native type would make).
          raw.bytes.resize(kHeader + payload.size());
          std::memcpy(raw.bytes.data(), kCdrLe, kHeader);
          std::memcpy(raw.bytes.data() + kHeader, payload.data(), payload.size());
        } else {
          env.subject(0);
          env.origin(0);
          env.hop_count(0);
          env.age_ns(0);
          env.sequence(index);
          env.created_ns(static_cast<std::int64_t>(get_le(payload.data(), 8)));
          env.payload() = payload;
        }
        ReturnCode_t r = writer->write(sample, fdds::HANDLE_NIL);
        // A reliable KEEP_ALL writer blocks (max_blocking_time 1 s) while its history is full of
        // unacknowledged samples; retry until --stall seconds pass without success.
        const std::int64_t give_up = mono_ns() + static_cast<std::int64_t>(o.stall * 1e9);
        while (!g_stop && (r == ReturnCode_t::RETCODE_TIMEOUT || r == ReturnCode_t::RETCODE_OUT_OF_RESOURCES)) {
          if (mono_ns() >= give_up) {
            g_stalled = true;
            char text[160];
            std::snprintf(text, sizeof text, "STALLED: no write accepted for %.1f s at event index %u%s", o.stall,
                          index & ~kWarmupBit, (index & kWarmupBit) != 0 ? " (warm-up)" : "");
            err_line(text);
            return false;
          }
          ++retries;
          r = writer->write(sample, fdds::HANDLE_NIL);
        }
        return r == ReturnCode_t::RETCODE_OK;
      },
      o.max_rate);
  if (!g_stalled) writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(5, 0));
  if (retries > 0) err_line("write retries: " + std::to_string(retries));
  return rc;
}

int dds_sub(const DdsOptions& o) {
  Participant p;
  if (!p.open(o)) {
    err_line("cannot create the DDS participant/topic");
    return 3;
  }
  Recorder recorder(o.count);
  recorder.dump_path = o.dump;
  ReaderListener listener(recorder, !o.native_type.empty());
  fdds::Subscriber* subscriber = p.participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
  qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  set_history(qos, o.keep_last, 100000, 1000);
  qos.endpoint().history_memory_policy = eprosima::fastrtps::rtps::PREALLOCATED_WITH_REALLOC_MEMORY_MODE;
  fdds::DataReader* reader = subscriber->create_datareader(
      p.topic, qos, &listener, fdds::StatusMask::data_available() << fdds::StatusMask::subscription_matched());
  if (reader == nullptr) {
    err_line("cannot create the DataReader");
    return 3;
  }
  recorder.wait(o.timeout, o.idle);
  // Stop the callbacks before reporting: the listener must not outlive the reader.
  reader->set_listener(nullptr);
  return recorder.report();
}

}  // namespace cosmic_bench

// DDS Security's cost on a hop, measured through Fast DDS (cosmic/dds_security_timing.hpp).
#include "cosmic/dds_security_timing.hpp"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstring>
#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/xmlparser/XMLProfileManager.h>

#include "cosmic/dds_security_qos.hpp"
#include "cosmic/ephemeral_pki.hpp"
#include "cosmic/smime_sign.hpp"
#include "dds_opaque_type.hpp"

namespace cosmic {
namespace {

namespace dds = eprosima::fastdds::dds;
using Clock = std::chrono::steady_clock;

constexpr const char* kTopic = "cosmic/calibrate";
constexpr std::size_t kWarmUp = 200;
// Sequence number (u32) and send time (i64 ns) after the 4-byte encapsulation header.
constexpr std::size_t kStampBytes = 4 + 4 + 8;

// A private directory with the PKI and the signed documents, removed with this object.
class CalibrationFiles {
 public:
  static Result<std::unique_ptr<CalibrationFiles>> make(std::uint32_t domain, DdsProtection protection);
  ~CalibrationFiles() {
    std::error_code ignored;
    std::filesystem::remove_all(directory_, ignored);
  }
  CalibrationFiles(const CalibrationFiles&) = delete;
  CalibrationFiles& operator=(const CalibrationFiles&) = delete;

  // The spec of identity `index` (0 writes, 1 reads) with the governance of `protection`.
  DdsSecuritySpec spec(std::size_t index, DdsProtection protection) const;

 private:
  explicit CalibrationFiles(std::filesystem::path directory) : directory_(std::move(directory)) {}
  Result<void> write(const std::string& name, const std::string& text) const;
  std::string path(const std::string& name) const { return (directory_ / name).string(); }

  std::filesystem::path directory_;
};

Result<void> CalibrationFiles::write(const std::string& name, const std::string& text) const {
  const int fd = ::open(path(name).c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0) return Error::from_errno("cannot create " + path(name), errno);
  const bool written = ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  const int err = errno;
  ::close(fd);
  if (!written) return Error::from_errno("cannot write " + path(name), err);
  return {};
}

Result<std::unique_ptr<CalibrationFiles>> CalibrationFiles::make(std::uint32_t domain, DdsProtection protection) {
  const std::vector<std::string> names{"calibrate-writer", "calibrate-reader"};
  auto pki = make_ephemeral_pki(names, std::chrono::hours(1));
  if (!pki) return std::move(pki).error();
  std::string pattern = (std::filesystem::temp_directory_path() / "cosmic-calibrate-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr) return Error::from_errno("cannot make a directory in /tmp", errno);
  std::unique_ptr<CalibrationFiles> files(new CalibrationFiles(pattern));
  const EphemeralPki& p = pki.value();
  std::vector<DdsGrant> grants;
  for (std::size_t i = 0; i < p.identities.size(); ++i) {
    DdsAllowRule rule{"calibrate", domain, {}, {}};
    (i == 0 ? rule.publish : rule.subscribe).push_back(kTopic);
    grants.push_back({p.identities[i].name, p.identities[i].subject, {p.not_before, p.not_after}, {rule}});
  }
  const std::vector<std::uint32_t> domains{domain};
  std::vector<std::pair<std::string, std::string>> texts{{"ca.pem", p.ca_certificate_pem}};
  std::vector<DdsProtection> kinds{DdsProtection::none};
  if (protection != DdsProtection::none) kinds.push_back(protection);
  for (const DdsProtection kind : kinds) {
    auto governance = smime_sign_text(governance_xml(domains, kind), p.ca_certificate_pem, p.ca_private_key_pem);
    if (!governance) return std::move(governance).error();
    texts.emplace_back(std::string("governance-") + to_string(kind) + ".p7s", std::move(governance).value());
  }
  auto permissions = smime_sign_text(permissions_xml(grants), p.ca_certificate_pem, p.ca_private_key_pem);
  if (!permissions) return std::move(permissions).error();
  texts.emplace_back("permissions.p7s", std::move(permissions).value());
  for (std::size_t i = 0; i < p.identities.size(); ++i) {
    texts.emplace_back(std::to_string(i) + ".pem", p.identities[i].certificate_pem);
    texts.emplace_back(std::to_string(i) + ".key", p.identities[i].private_key_pem);
  }
  for (const auto& [name, text] : texts) {
    if (auto written = files->write(name, text); !written) return std::move(written).error();
  }
  return files;
}

DdsSecuritySpec CalibrationFiles::spec(std::size_t index, DdsProtection protection) const {
  DdsSecuritySpec spec;
  spec.identity_ca = path("ca.pem");
  spec.permissions_ca = path("ca.pem");
  spec.certificate = path(std::to_string(index) + ".pem");
  spec.private_key = path(std::to_string(index) + ".key");
  spec.governance = path(std::string("governance-") + to_string(protection) + ".p7s");
  spec.permissions = path("permissions.p7s");
  return spec;
}

// The reader's end: each sample's latency from the send time it carries. Fast DDS's receive thread
// calls on_data_available; the measuring thread waits for a count.
class LatencyCollector final : public dds::DataReaderListener {
 public:
  void on_data_available(dds::DataReader* reader) override {
    dds_detail::OpaqueSample sample;
    dds::SampleInfo info;
    while (reader->take_next_sample(&sample, &info) == eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || sample.bytes.size() < kStampBytes) continue;
      std::int64_t sent = 0;
      std::memcpy(&sent, sample.bytes.data() + 8, sizeof sent);
      const Nanos latency = Clock::now().time_since_epoch() - Nanos(sent);
      const std::lock_guard lock(mutex_);
      latencies_.push_back(latency);
      arrived_.notify_all();
    }
  }

  // Waits until `count` samples arrived in all, or `deadline`; the latencies of those after `skip`.
  std::vector<Nanos> wait_for(std::size_t count, std::size_t skip, Clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    arrived_.wait_until(lock, deadline, [&] { return latencies_.size() >= count; });
    return {latencies_.begin() + static_cast<std::ptrdiff_t>(std::min(skip, latencies_.size())), latencies_.end()};
  }

 private:
  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<Nanos> latencies_;
};

struct ParticipantDeleter {
  void operator()(dds::DomainParticipant* participant) const noexcept {
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
  }
};
using Participant = std::unique_ptr<dds::DomainParticipant, ParticipantDeleter>;

Result<Participant> make_participant(std::uint32_t domain, const DdsSecuritySpec& security, const char* name) {
  dds::DomainParticipantQos qos;
  qos.name(name);
  qos.transport().use_builtin_transports = false;
  qos.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
  add_dds_security(security, qos);
  Participant participant(dds::DomainParticipantFactory::get_instance()->create_participant(domain, qos));
  if (!participant) return Error{std::string("Fast DDS refused the participant ") + name + " (its log says why)"};
  dds::TypeSupport type(new dds_detail::OpaqueType("cosmic::Calibration"));
  if (type.register_type(participant.get()) != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK)
    return Error{"cannot register the calibration type"};
  return participant;
}

// One run: a writer and a reader with the governance of `protection`, `samples` timed after a
// warm-up, and this process's CPU time over them.
struct RunFigures {
  std::vector<Nanos> latencies;
  double cpu_us_per_sample = 0;
  std::size_t lost = 0;
};

double process_cpu_us() {
  rusage usage{};
  ::getrusage(RUSAGE_SELF, &usage);
  const auto us = [](const timeval& t) { return static_cast<double>(t.tv_sec) * 1e6 + static_cast<double>(t.tv_usec); };
  return us(usage.ru_utime) + us(usage.ru_stime);
}

bool wait_matched(dds::DataWriter* writer, dds::DataReader* reader, Clock::time_point deadline) {
  while (Clock::now() < deadline) {
    dds::PublicationMatchedStatus written;
    dds::SubscriptionMatchedStatus read;
    writer->get_publication_matched_status(written);
    reader->get_subscription_matched_status(read);
    if (written.current_count > 0 && read.current_count > 0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return false;
}

void send_paced(dds::DataWriter* writer, std::size_t first, std::size_t count, std::size_t payload_bytes,
                double rate_hz) {
  dds_detail::OpaqueSample sample;
  sample.bytes.assign(std::max(payload_bytes + 4, kStampBytes), 0x5a);
  sample.bytes[0] = 0x00;
  sample.bytes[1] = 0x01;  // CDR little endian
  sample.bytes[2] = sample.bytes[3] = 0x00;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
  const Clock::time_point start = Clock::now();
  for (std::size_t i = 0; i < count; ++i) {
    std::this_thread::sleep_until(start + period * static_cast<std::int64_t>(i));
    const auto sequence = static_cast<std::uint32_t>(first + i);
    const std::int64_t now = Clock::now().time_since_epoch().count();
    std::memcpy(sample.bytes.data() + 4, &sequence, sizeof sequence);
    std::memcpy(sample.bytes.data() + 8, &now, sizeof now);
    writer->write(&sample);
  }
}

Result<RunFigures> run_once(const CalibrationFiles& files, const DdsSecurityTimingRequest& request,
                            DdsProtection protection) {
  // Before the participants: destroyed after them, so no callback of the reader outlives it.
  LatencyCollector collector;
  auto writing = make_participant(request.domain, files.spec(0, protection), "cosmic-calibrate-writer");
  if (!writing) return std::move(writing).error();
  auto reading = make_participant(request.domain, files.spec(1, protection), "cosmic-calibrate-reader");
  if (!reading) return std::move(reading).error();
  dds::DomainParticipant* w = writing.value().get();
  dds::DomainParticipant* r = reading.value().get();
  dds::Topic* write_topic = w->create_topic(kTopic, "cosmic::Calibration", dds::TOPIC_QOS_DEFAULT);
  dds::Topic* read_topic = r->create_topic(kTopic, "cosmic::Calibration", dds::TOPIC_QOS_DEFAULT);
  dds::Publisher* publisher = w->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
  dds::Subscriber* subscriber = r->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
  if (!write_topic || !read_topic || !publisher || !subscriber) return Error{"cannot make the calibration topic"};
  dds::DataWriterQos writer_qos = dds::DATAWRITER_QOS_DEFAULT;
  writer_qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  writer_qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  writer_qos.history().depth = 64;
  writer_qos.data_sharing().off();  // through the RTPS messages the plugins transform
  dds::DataReaderQos reader_qos = dds::DATAREADER_QOS_DEFAULT;
  reader_qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
  reader_qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  reader_qos.history().depth = 64;
  reader_qos.data_sharing().off();
  dds::DataWriter* writer = publisher->create_datawriter(write_topic, writer_qos);
  dds::DataReader* reader = subscriber->create_datareader(read_topic, reader_qos, &collector);
  if (!writer || !reader) return Error{"cannot make the calibration writer and reader (access control refused them)"};
  if (!wait_matched(writer, reader, Clock::now() + request.match_timeout))
    return Error{std::string("the calibration pair did not authenticate and match within ") +
                 std::to_string(std::chrono::duration_cast<std::chrono::seconds>(request.match_timeout).count()) +
                 " s (governance " + to_string(protection) + ")"};
  // Warm-up: the key exchange's last steps and the first allocations stay out of the figures.
  send_paced(writer, 0, kWarmUp, request.payload_bytes, request.rate_hz);
  collector.wait_for(kWarmUp, 0, Clock::now() + request.match_timeout);
  const double cpu_before = process_cpu_us();
  send_paced(writer, kWarmUp, request.samples, request.payload_bytes, request.rate_hz);
  RunFigures figures;
  figures.latencies = collector.wait_for(kWarmUp + request.samples, kWarmUp, Clock::now() + std::chrono::seconds(2));
  figures.cpu_us_per_sample = (process_cpu_us() - cpu_before) / static_cast<double>(request.samples);
  figures.lost = request.samples - std::min(request.samples, figures.latencies.size());
  return figures;
}

Nanos at_least_zero(Nanos value) { return std::max(value, Nanos(0)); }

}  // namespace

IntraProcessDeliveryOff::IntraProcessDeliveryOff()
    : saved_(eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings()) {
  auto settings = saved_;
  settings.intraprocess_delivery = eprosima::fastrtps::INTRAPROCESS_OFF;
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(settings);
}

IntraProcessDeliveryOff::~IntraProcessDeliveryOff() {
  eprosima::fastrtps::xmlparser::XMLProfileManager::library_settings(saved_);
}

Result<DdsSecurityTiming> time_dds_security(const DdsSecurityTimingRequest& request) {
  if (request.samples == 0 || request.rate_hz <= 0) return Error{"the calibration needs samples and a rate"};
  auto files = CalibrationFiles::make(request.domain, request.protection);
  if (!files) return std::move(files).error();
  const IntraProcessDeliveryOff over_the_transport;
  auto plain = run_once(*files.value(), request, DdsProtection::none);
  if (!plain) return std::move(plain).error();
  auto protected_run = run_once(*files.value(), request, request.protection);
  if (!protected_run) return std::move(protected_run).error();
  const std::size_t bytes = request.payload_bytes;
  DdsSecurityTiming out;
  out.protection = request.protection;
  out.plain = timing_summary(bytes, plain.value().latencies);
  out.protected_ = timing_summary(bytes, protected_run.value().latencies);
  out.added.message_bytes = bytes;
  out.added.runs = out.protected_.runs;
  out.added.p50 = at_least_zero(out.protected_.p50 - out.plain.p50);
  out.added.p99 = at_least_zero(out.protected_.p99 - out.plain.p99);
  out.added.p999 = at_least_zero(out.protected_.p999 - out.plain.p999);
  out.added.max = at_least_zero(out.protected_.max - out.plain.max);
  // Differences of quantiles need not grow with the quantile as the quantiles do: each figure is
  // at least the one before, so the worst reads as the worst.
  out.added.p99 = std::max(out.added.p99, out.added.p50);
  out.added.p999 = std::max(out.added.p999, out.added.p99);
  out.added.max = std::max(out.added.max, out.added.p999);
  out.plain_cpu_us = plain.value().cpu_us_per_sample;
  out.protected_cpu_us = protected_run.value().cpu_us_per_sample;
  out.lost = plain.value().lost + protected_run.value().lost;
  return out;
}

}  // namespace cosmic

// cosmic-dds-peer: a native Fast DDS program speaking the gateway's envelope (cosmic::Envelope),
// used by the integration tests, the end-to-end tests and the benchmark.
//
//   cosmic-dds-peer pub --domain D --topic NAME --count N --size B [--rate HZ]
//                       [--reliable|--best-effort] [--subject S] [--origin O]
//                       [--wait-subscribers K] [--match-timeout S] [--hop-count H] [--age-ns A]
//                       [--start-on-stdin] [--first-sequence F]
//   cosmic-dds-peer sub --domain D --topic NAME --count N [--timeout S]
//                       [--reliable|--best-effort] [--transient-local] [--quiet]
//
// --topic is the DDS topic name verbatim; --channel NAME is a shorthand for the gateway's
// scheme, --topic cosmic/NAME.
//
// pub waits until K (default 1) subscribers matched (discovery, never a fixed sleep; exit 2 after
// --match-timeout seconds), then writes N envelopes, envelope sequence F..F+N-1 (F = 1 unless
// --first-sequence; the RTPS sample sequence numbers are always 1..N), payload byte i of event q =
// (q + i) mod 256, created_ns = CLOCK_MONOTONIC now (comparable between processes of one host),
// paced at --rate events/s (0: as fast as possible). Reliable (the default) uses KEEP_ALL, so
// nothing is dropped by the writer, and waits for all acknowledgements before exiting.
// Matching is not symmetric: when our writer has matched a reader, that reader may not yet have
// matched our writer, and a VOLATILE reader drops (and never recovers) what arrives before. With
// --start-on-stdin, pub waits after its own match for one line on stdin (or EOF) before
// publishing, so the caller can first check the far side (e.g. the adapter's matched readers).
//
// sub prints one JSON line per received envelope on stdout:
//   {"subject":S,"origin":O,"sequence":Q,"hop_count":H,"created_ns":C,"age_ns":A,
//    "received_ns":R,"size":B,"payload":"hex"}
// (received_ns: CLOCK_MONOTONIC at reception) and exits 0 once N arrived (N = 0: runs until the
// timeout and exits 0), 1 on timeout (default 30 s). The default reader is best-effort, which
// matches every writer; --reliable requests RELIABLE, --transient-local TRANSIENT_LOCAL
// durability (default VOLATILE).
//
// Diagnostics go to stderr as JSON lines, so tests can wait on them:
//   {"event":"matched","count":K}                  matched remote endpoints changed
//   {"event":"incompatible_qos","policy":"reliability"}
//   {"event":"publication"|"subscription","topic":T,"participant":P,"reliability":"reliable"|"best_effort",
//    "durability":..,"deadline_ns":..,"lifespan_ns":..,"latency_budget_ns":..}
//      a remote writer (sub mode) or reader (pub mode) of the topic was discovered, with the QoS
//      it announced (durations null when infinite), its participant's GUID prefix P (hex) and
//      "transports": the kinds of the unicast locators it is reached at ("udpv4", "shm", ...)
//   {"event":"done",...}
// Fast DDS's own log goes to stderr too.
#include <signal.h>
#include <time.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <set>
#include <mutex>
#include <string>
#include <thread>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <cosmic_dds_idl/EnvelopePubSubTypes.h>

#include "cosmic/dds_adapter.hpp"

namespace {

namespace fdds = eprosima::fastdds::dds;
using eprosima::fastrtps::types::ReturnCode_t;
using json = nlohmann::json;

std::int64_t monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// Set by SIGTERM/SIGINT: every wait ends early and the entities are deleted cleanly (a killed
// process would leave its shared-memory segments behind in /dev/shm).
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

std::mutex g_err_mutex;
void diag(const json& line) {
  std::lock_guard lock(g_err_mutex);
  std::cerr << line.dump() << std::endl;
}

class StderrLineConsumer : public fdds::LogConsumer {
 public:
  void Consume(const fdds::Log::Entry& entry) override {
    std::string line = "fastdds ";
    line += entry.kind == fdds::Log::Error ? "error" : entry.kind == fdds::Log::Warning ? "warning" : "info";
    if (entry.context.category != nullptr) {
      line += " [";
      line += entry.context.category;
      line += "]";
    }
    line += ": ";
    line += entry.message;
    std::lock_guard lock(g_err_mutex);
    std::cerr << line << std::endl;
  }
};

json duration_json(const eprosima::fastrtps::Duration_t& d) {
  if (d == eprosima::fastrtps::c_TimeInfinite) {
    return nullptr;
  }
  return static_cast<std::int64_t>(d.seconds) * 1'000'000'000 + d.nanosec;
}

const char* policy_name(fdds::QosPolicyId_t id) {
  switch (id) {
    case fdds::RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case fdds::DURABILITY_QOS_POLICY_ID:
      return "durability";
    case fdds::DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case fdds::LATENCYBUDGET_QOS_POLICY_ID:
      return "latency_budget";
    case fdds::LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case fdds::OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    default:
      return "other";
  }
}

// The GUID prefix of an endpoint's participant, as hex: which participant a remote endpoint lives in.
std::string prefix_hex(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  for (const auto octet : prefix.value) {
    out.push_back(digits[octet >> 4]);
    out.push_back(digits[octet & 0xf]);
  }
  return out;
}

// The kinds of the locators an endpoint announced, each once: what transports reach it.
json locator_kinds(const eprosima::fastrtps::rtps::RemoteLocatorList& locators) {
  std::set<std::string> kinds;
  for (const auto& locator : locators.unicast) {
    switch (locator.kind) {
      case LOCATOR_KIND_UDPv4:
        kinds.insert("udpv4");
        break;
      case LOCATOR_KIND_UDPv6:
        kinds.insert("udpv6");
        break;
      case LOCATOR_KIND_SHM:
        kinds.insert("shm");
        break;
      default:
        kinds.insert("kind " + std::to_string(locator.kind));
        break;
    }
  }
  return json(std::vector<std::string>(kinds.begin(), kinds.end()));
}

template <typename Qos>
json qos_json(const char* kind, const std::string& topic, const Qos& qos,
              const eprosima::fastrtps::rtps::GuidPrefix_t& participant,
              const eprosima::fastrtps::rtps::RemoteLocatorList& locators) {
  return json{{"event", kind},
              {"transports", locator_kinds(locators)},
              {"topic", topic},
              {"participant", prefix_hex(participant)},
              {"reliability", qos.m_reliability.kind == fdds::RELIABLE_RELIABILITY_QOS ? "reliable" : "best_effort"},
              {"durability", qos.m_durability.kind == fdds::VOLATILE_DURABILITY_QOS ? "volatile" : "non_volatile"},
              {"deadline_ns", duration_json(qos.m_deadline.period)},
              {"lifespan_ns", duration_json(qos.m_lifespan.duration)},
              {"latency_budget_ns", duration_json(qos.m_latencyBudget.duration)}};
}

// Participant listener: reports remote endpoints of our topic with their QoS, matches and
// incompatible QoS of our own endpoint.
class Listener : public fdds::DomainParticipantListener {
 public:
  explicit Listener(std::string topic) : topic_(std::move(topic)) {}

  void on_publisher_discovery(fdds::DomainParticipant* participant,
                              eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    if (info.info.guid().guidPrefix == participant->guid().guidPrefix) return;  // our own
    if (info.status == eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERED_WRITER &&
        info.info.topicName().to_string() == topic_) {
      diag(qos_json("publication", topic_, info.info.m_qos, info.info.guid().guidPrefix, info.info.remote_locators()));
    }
  }
  void on_subscriber_discovery(fdds::DomainParticipant* participant,
                               eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    if (info.info.guid().guidPrefix == participant->guid().guidPrefix) return;  // our own
    if (info.status == eprosima::fastrtps::rtps::ReaderDiscoveryInfo::DISCOVERED_READER &&
        info.info.topicName().to_string() == topic_) {
      diag(qos_json("subscription", topic_, info.info.m_qos, info.info.guid().guidPrefix, info.info.remote_locators()));
    }
  }
  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& status) override {
    matched(status.current_count);
  }
  void on_subscription_matched(fdds::DataReader*, const fdds::SubscriptionMatchedStatus& status) override {
    matched(status.current_count);
  }
  void on_offered_incompatible_qos(fdds::DataWriter*, const fdds::OfferedIncompatibleQosStatus& status) override {
    diag({{"event", "incompatible_qos"}, {"policy", policy_name(status.last_policy_id)}});
  }
  void on_requested_incompatible_qos(fdds::DataReader*, const fdds::RequestedIncompatibleQosStatus& status) override {
    diag({{"event", "incompatible_qos"}, {"policy", policy_name(status.last_policy_id)}});
  }

  bool wait_matched(int count, std::chrono::steady_clock::time_point deadline) {
    std::unique_lock lock(mutex_);
    while (!g_stop) {
      const auto slice = std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(100));
      if (cv_.wait_until(lock, slice, [&] { return matched_ >= count; })) return true;
      if (std::chrono::steady_clock::now() >= deadline) return false;
    }
    return false;
  }

 private:
  void matched(int count) {
    {
      std::lock_guard lock(mutex_);
      matched_ = count;
    }
    cv_.notify_all();
    diag({{"event", "matched"}, {"count", count}});
  }

  std::string topic_;
  std::mutex mutex_;
  std::condition_variable cv_;
  int matched_ = 0;
};

struct Options {
  unsigned domain = 0;
  std::string topic;
  std::string channel;
  std::uint64_t count = 0;
  std::uint64_t size = 8;
  double rate = 0;
  bool reliable = false;
  bool best_effort = false;
  std::uint64_t subject = 0;
  std::uint64_t origin = 0;
  unsigned hop_count = 0;
  std::int64_t age_ns = 0;
  int wait_subscribers = 1;
  double match_timeout = 10;
  double timeout = 30;
  bool quiet = false;
  bool start_on_stdin = false;
  bool transient_local = false;
  std::uint32_t first_sequence = 1;
};

struct Entities {
  fdds::DomainParticipant* participant = nullptr;
  fdds::Topic* topic = nullptr;
  fdds::Publisher* publisher = nullptr;
  fdds::Subscriber* subscriber = nullptr;
  ~Entities() {
    if (participant != nullptr) {
      participant->delete_contained_entities();
      fdds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    }
  }
};

bool open(const Options& o, Listener& listener, Entities& e) {
  fdds::DomainParticipantQos qos = fdds::PARTICIPANT_QOS_DEFAULT;
  qos.name("cosmic-dds-peer");
  // Only the endpoint-level callbacks and discovery go to the participant listener.
  const fdds::StatusMask mask = fdds::StatusMask::publication_matched()
                                << fdds::StatusMask::subscription_matched()
                                << fdds::StatusMask::offered_incompatible_qos()
                                << fdds::StatusMask::requested_incompatible_qos();
  e.participant = fdds::DomainParticipantFactory::get_instance()->create_participant(
      static_cast<fdds::DomainId_t>(o.domain), qos, &listener, mask);
  if (e.participant == nullptr) {
    diag({{"event", "error"}, {"what", "cannot create participant"}});
    return false;
  }
  fdds::TypeSupport type(new cosmic::EnvelopePubSubType());
  type.register_type(e.participant);
  e.topic = e.participant->create_topic(o.topic, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (e.topic == nullptr) {
    diag({{"event", "error"}, {"what", "cannot create topic"}});
    return false;
  }
  return true;
}

int run_pub(const Options& o) {
  Listener listener(o.topic);
  Entities e;
  if (!open(o, listener, e)) return 3;
  e.publisher = e.participant->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  fdds::DataWriterQos qos = fdds::DATAWRITER_QOS_DEFAULT;
  const bool reliable = !o.best_effort;
  if (reliable) {
    qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
    qos.reliability().max_blocking_time = eprosima::fastrtps::Duration_t(10, 0);
    qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 50'000'000);
    qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
    qos.resource_limits().max_samples = 1000;
    qos.resource_limits().allocated_samples = 100;
    qos.resource_limits().max_samples_per_instance = 1000;
  } else {
    qos.reliability().kind = fdds::BEST_EFFORT_RELIABILITY_QOS;
    qos.history().kind = fdds::KEEP_LAST_HISTORY_QOS;
    qos.history().depth = 1;
  }
  qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
  fdds::DataWriter* writer = e.publisher->create_datawriter(e.topic, qos);
  if (writer == nullptr) {
    diag({{"event", "error"}, {"what", "cannot create writer"}});
    return 3;
  }
  const auto match_deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(o.match_timeout));
  if (!listener.wait_matched(o.wait_subscribers, match_deadline)) {
    diag({{"event", "error"}, {"what", "no subscriber matched"}});
    return 2;
  }
  if (o.start_on_stdin) {
    // Our writer matched the readers, but a reader only accepts data from writers it matched
    // itself (and a VOLATILE reader skips what was sent before): the caller knows when.
    diag({{"event", "waiting_for_start"}});
    std::string go;
    std::getline(std::cin, go);  // interrupted by SIGTERM (no SA_RESTART)
  }

  cosmic::Envelope env;
  env.subject(o.subject);
  env.origin(o.origin);
  env.hop_count(static_cast<std::uint8_t>(o.hop_count));
  env.age_ns(o.age_ns);
  env.payload().resize(o.size);
  const auto start = std::chrono::steady_clock::now();
  std::uint64_t sent = 0;
  std::uint64_t failed = 0;
  std::uint64_t retries = 0;
  int last_error = 0;
  for (std::uint64_t q = 1; q <= o.count && !g_stop; ++q) {
    if (o.rate > 0) {
      std::this_thread::sleep_until(start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                                std::chrono::duration<double>(static_cast<double>(q - 1) / o.rate)));
    }
    for (std::uint64_t i = 0; i < o.size; ++i) {
      env.payload()[i] = static_cast<std::uint8_t>((q + i) & 0xff);
    }
    env.sequence(static_cast<std::uint32_t>(o.first_sequence + q - 1));
    env.created_ns(monotonic_ns());
    // A reliable KEEP_ALL writer blocks while its history is full, but may still answer
    // OUT_OF_RESOURCES/TIMEOUT (acknowledged samples not yet released): retry for up to 10 s.
    ReturnCode_t rc = writer->write(&env, fdds::HANDLE_NIL);
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (reliable && !g_stop &&
           (rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES || rc == ReturnCode_t::RETCODE_TIMEOUT) &&
           std::chrono::steady_clock::now() < give_up) {
      ++retries;
      std::this_thread::sleep_for(std::chrono::microseconds(100));  // back-off
      rc = writer->write(&env, fdds::HANDLE_NIL);
    }
    if (rc == ReturnCode_t::RETCODE_OK) {
      ++sent;
    } else {
      ++failed;
      last_error = static_cast<int>(rc());
    }
  }
  bool acked = true;
  if (reliable && !g_stop) {
    acked = writer->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(10, 0)) == ReturnCode_t::RETCODE_OK;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  diag({{"event", "done"},
        {"sent", sent},
        {"failed", failed},
        {"retries", retries},
        {"last_error", last_error},
        {"acknowledged", acked},
        {"seconds", seconds}});
  return failed == 0 ? 0 : 4;
}

int run_sub(const Options& o) {
  Listener listener(o.topic);
  Entities e;
  if (!open(o, listener, e)) return 3;
  e.subscriber = e.participant->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  fdds::DataReaderQos qos = fdds::DATAREADER_QOS_DEFAULT;
  qos.reliability().kind = o.reliable ? fdds::RELIABLE_RELIABILITY_QOS : fdds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = o.transient_local ? fdds::TRANSIENT_LOCAL_DURABILITY_QOS : fdds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
  qos.resource_limits().max_samples = 100000;
  qos.resource_limits().allocated_samples = 100;
  qos.resource_limits().max_samples_per_instance = 100000;
  fdds::DataReader* reader = e.subscriber->create_datareader(e.topic, qos);
  if (reader == nullptr) {
    diag({{"event", "error"}, {"what", "cannot create reader"}});
    return 3;
  }
  const auto deadline =
      std::chrono::steady_clock::now() +
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(o.timeout));
  cosmic::Envelope env;
  fdds::SampleInfo info;
  std::uint64_t received = 0;
  std::string line;
  static const char* kHex = "0123456789abcdef";
  while ((o.count == 0 || received < o.count) && !g_stop) {
    const auto now = std::chrono::steady_clock::now();
    if (now >= deadline) break;
    const auto left = std::min<std::chrono::steady_clock::duration>(deadline - now, std::chrono::milliseconds(200));
    const auto left_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(left).count();
    reader->wait_for_unread_message(eprosima::fastrtps::Duration_t(
        static_cast<std::int32_t>(left_ns / 1'000'000'000), static_cast<std::uint32_t>(left_ns % 1'000'000'000)));
    while (reader->take_next_sample(&env, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data) continue;
      const std::int64_t at = monotonic_ns();
      ++received;
      if (o.quiet) continue;
      std::string hex;
      hex.reserve(env.payload().size() * 2);
      for (std::uint8_t b : env.payload()) {
        hex.push_back(kHex[b >> 4]);
        hex.push_back(kHex[b & 0xf]);
      }
      json out{{"subject", env.subject()},
               {"origin", env.origin()},
               {"sequence", env.sequence()},
               {"hop_count", env.hop_count()},
               {"created_ns", env.created_ns()},
               {"age_ns", env.age_ns()},
               {"received_ns", at},
               {"size", env.payload().size()},
               {"payload", hex}};
      line = out.dump();
      line.push_back('\n');
      std::fwrite(line.data(), 1, line.size(), stdout);
      std::fflush(stdout);
    }
  }
  diag({{"event", "done"}, {"received", received}});
  if (o.count == 0) return 0;
  return received >= o.count ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = 0;  // no SA_RESTART: a blocking read of stdin returns
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);

  // Fast DDS's log to stderr, whole lines under the same lock as the diagnostics: stdout
  // carries only the JSON lines, stderr never mixes two lines.
  fdds::Log::ClearConsumers();
  fdds::Log::RegisterConsumer(std::make_unique<StderrLineConsumer>());
  fdds::Log::SetVerbosity(fdds::Log::Warning);

  CLI::App app{"Native Fast DDS peer speaking cosmic::Envelope"};
  app.require_subcommand(1);
  Options o;
  auto common = [&](CLI::App* sub) {
    sub->add_option("--domain", o.domain, "DDS domain id")->required();
    auto* topic = sub->add_option("--topic", o.topic, "DDS topic name, verbatim");
    auto* channel = sub->add_option("--channel", o.channel, "channel name: topic cosmic/NAME");
    topic->excludes(channel);
    sub->add_option("--count", o.count, "number of events")->required();
    auto* rel = sub->add_flag("--reliable", o.reliable, "RELIABLE");
    auto* be = sub->add_flag("--best-effort", o.best_effort, "BEST_EFFORT");
    rel->excludes(be);
  };
  CLI::App* pub = app.add_subcommand("pub", "publish N envelopes");
  common(pub);
  pub->add_option("--size", o.size, "payload bytes")->required();
  pub->add_option("--rate", o.rate, "events per second (0: as fast as possible)");
  pub->add_option("--subject", o.subject, "envelope subject");
  pub->add_option("--origin", o.origin, "envelope origin (0: native source)");
  pub->add_option("--hop-count", o.hop_count, "envelope hop count")->check(CLI::Range(0, 255));
  pub->add_option("--age-ns", o.age_ns, "envelope age");
  pub->add_option("--wait-subscribers", o.wait_subscribers, "matched subscribers to wait for before publishing");
  pub->add_option("--match-timeout", o.match_timeout, "seconds to wait for them (exit 2)");
  pub->add_flag("--start-on-stdin", o.start_on_stdin,
                "after matching, wait for a line on stdin (or EOF) before publishing");
  pub->add_option("--first-sequence", o.first_sequence, "envelope sequence of the first event");
  CLI::App* sub = app.add_subcommand("sub", "receive N envelopes, one JSON line each");
  common(sub);
  sub->add_option("--timeout", o.timeout, "seconds before giving up (exit 1)");
  sub->add_flag("--quiet", o.quiet, "count only, print nothing per envelope");
  sub->add_flag("--transient-local", o.transient_local, "request TRANSIENT_LOCAL durability");
  CLI11_PARSE(app, argc, argv);

  if (!o.channel.empty()) {
    o.topic = cosmic::dds_topic_name(o.channel);
  }
  if (o.topic.empty()) {
    std::cerr << "one of --topic or --channel is required\n";
    return 64;
  }
  int rc = 3;
  try {
    rc = pub->parsed() ? run_pub(o) : run_sub(o);
  } catch (const std::exception& ex) {
    diag({{"event", "error"}, {"what", ex.what()}});
    rc = 3;
  }
  fdds::Log::Flush();
  return rc;
}

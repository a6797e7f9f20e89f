#include "dds_log_router.hpp"

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

#include <fastdds/dds/log/Log.hpp>

namespace cosmic::dds_detail {
namespace {

namespace dds = eprosima::fastdds::dds;

// Fast DDS logs through a process-wide singleton that prints to stdout by default. The first
// adapter replaces that with one consumer forwarding to the Loggers of the running adapters
// (each distinct Logger once): the library never prints.
// Lock order: Fast DDS's log thread holds its own configuration mutex while it calls Consume(),
// which takes mutex_; so mutex_ is never held while calling into dds::Log (Clear/Register/
// SetVerbosity take that configuration mutex: holding mutex_ there could deadlock against a
// message being consumed, as ThreadSanitizer's lock-order check showed).
class LogRouter {
 public:
  static LogRouter& instance() {
    static LogRouter* router = new LogRouter();  // leaked: Fast DDS's log thread may outlive us
    return *router;
  }
  void attach(Logger& log) {
    {
      std::lock_guard lock(mutex_);
      ++loggers_[&log];
    }
    std::call_once(installed_, [] {
      dds::Log::ClearConsumers();
      dds::Log::RegisterConsumer(std::make_unique<Consumer>());
      dds::Log::SetVerbosity(dds::Log::Warning);
    });
  }
  void detach(Logger& log) {
    std::lock_guard lock(mutex_);
    auto it = loggers_.find(&log);
    if (it != loggers_.end() && --it->second == 0) {
      loggers_.erase(it);
    }
  }

 private:
  class Consumer : public dds::LogConsumer {
   public:
    void Consume(const dds::Log::Entry& entry) override { LogRouter::instance().forward(entry); }
  };
  void forward(const dds::Log::Entry& entry) {
    LogLevel level = entry.kind == dds::Log::Error     ? LogLevel::error
                     : entry.kind == dds::Log::Warning ? LogLevel::warning
                                                       : LogLevel::debug;
    std::string note;
    if (is_peer_key_only_dispose(entry)) {
      // Not a fault of ours or the peer's: explained once, then kept at debug.
      level = LogLevel::debug;
      if (!key_only_explained_.exchange(true)) {
        level = LogLevel::info;
        note = kKeyOnlyNote;
      }
    }
    std::string text = "fastdds";
    if (entry.context.category != nullptr) {
      text += " [";
      text += entry.context.category;
      text += "]";
    }
    text += ": ";
    text += entry.message;
    text += note;
    std::lock_guard lock(mutex_);
    for (auto& [log, count] : loggers_) {
      log->log(level, text);
    }
  }
  // A DDS peer that leaves (or deletes an endpoint) announces it with a key-only DATA whose key
  // is serialized in the payload, as DDSI-RTPS allows and Cyclone DDS does (28 bytes: a GUID
  // parameter list). Fast DDS 2.9 reads only a key of at most 16 bytes there: it warns, ignores
  // the announcement and forgets the peer when its lease ends instead (docs/operations.md).
  static bool is_peer_key_only_dispose(const dds::Log::Entry& entry) {
    const std::string_view category = entry.context.category ? entry.context.category : "";
    const std::string_view message = entry.message;
    return (category == "RTPS_MSG_IN" &&
            message.find("Ignoring Serialized Payload for too large key-only data") != std::string_view::npos) ||
           (category == "RTPS_PDP" &&
            message.find("Problem getting the key of the change, removing") != std::string_view::npos) ||
           (category == "RTPS_EDP" && message.find("Received change with no Key") != std::string_view::npos);
  }
  static constexpr const char* kKeyOnlyNote =
      " (a DDS peer, e.g. Cyclone DDS, announced that a participant or endpoint left with its key serialized in "
      "the message; Fast DDS 2.9 cannot read that form and forgets the peer when its lease ends instead: "
      "harmless, see docs/operations.md \"Fast DDS messages about key-only data\"; logged at debug from now on)";
  std::atomic<bool> key_only_explained_{false};
  std::once_flag installed_;  // the consumer is installed once per process
  std::mutex mutex_;          // guards loggers_; never held while calling into dds::Log
  std::map<Logger*, int> loggers_;
};

}  // namespace

void attach_fastdds_log(Logger& log) { LogRouter::instance().attach(log); }
void detach_fastdds_log(Logger& log) { LogRouter::instance().detach(log); }

}  // namespace cosmic::dds_detail

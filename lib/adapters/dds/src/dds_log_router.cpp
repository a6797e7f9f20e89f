#include "dds_log_router.hpp"

#include <map>
#include <memory>
#include <mutex>
#include <string>

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
    void Consume(const dds::Log::Entry& entry) override {
      LogRouter::instance().forward(entry);
    }
  };
  void forward(const dds::Log::Entry& entry) {
    const LogLevel level = entry.kind == dds::Log::Error     ? LogLevel::error
                           : entry.kind == dds::Log::Warning ? LogLevel::warning
                                                             : LogLevel::debug;
    std::string text = "fastdds";
    if (entry.context.category != nullptr) {
      text += " [";
      text += entry.context.category;
      text += "]";
    }
    text += ": ";
    text += entry.message;
    std::lock_guard lock(mutex_);
    for (auto& [log, count] : loggers_) {
      log->log(level, text);
    }
  }
  std::once_flag installed_;  // the consumer is installed once per process
  std::mutex mutex_;          // guards loggers_; never held while calling into dds::Log
  std::map<Logger*, int> loggers_;
};

}  // namespace

void attach_fastdds_log(Logger& log) { LogRouter::instance().attach(log); }
void detach_fastdds_log(Logger& log) { LogRouter::instance().detach(log); }

}  // namespace cosmic::dds_detail

// The SecOC freshness store of a CAN segment (secoc_freshness.hpp).
#include "secoc_freshness.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cosmic/thread_policy.hpp"

namespace cosmic::can_detail {
namespace {

using Json = nlohmann::json;

constexpr int kFileVersion = 1;
constexpr int kPersistIntervalMs = 1000;  // receivers' values; a sender's lease as soon as it is due
constexpr std::size_t kMaxFileBytes = 1 << 20;

std::string stream_key(const std::string& channel, std::uint32_t data_id) {
  return channel + "/" + std::to_string(data_id);
}

std::string errno_string(int err) { return std::strerror(err); }

// Writes `text` to `path` atomically: a temporary file beside it, fsync, rename, fsync of the
// directory. Empty on success, else why not.
std::string write_atomically(const std::string& path, const std::string& text) {
  const std::string temporary = path + ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return "cannot create " + temporary + ": " + errno_string(errno);
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int err = errno;
      ::close(fd);
      return "cannot write " + temporary + ": " + errno_string(err);
    }
    done += static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0) return "cannot sync " + temporary + ": " + errno_string(errno);
  if (::rename(temporary.c_str(), path.c_str()) != 0) return "cannot rename to " + path + ": " + errno_string(errno);
  const std::string directory = std::filesystem::path(path).parent_path().string();
  const int dir = ::open(directory.empty() ? "." : directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
  return {};
}

// The map of one of the file's sections; why not in `error`.
std::map<std::string, std::uint64_t> read_section(const Json& document, const char* name, std::string& error) {
  std::map<std::string, std::uint64_t> values;
  if (!document.contains(name)) return values;
  const Json& section = document[name];
  if (!section.is_object()) {
    error = std::string("\"") + name + "\" is not an object";
    return values;
  }
  for (const auto& [stream, value] : section.items()) {
    if (!value.is_number_unsigned()) {
      error = std::string("\"") + name + "\"." + stream + " is not an unsigned number";
      return {};
    }
    values[stream] = value.get<std::uint64_t>();
  }
  return values;
}

}  // namespace

SecocFreshness::SecocFreshness(std::string file, std::string log_prefix, std::string thread_name, Logger& log)
    : file_(std::move(file)), prefix_(std::move(log_prefix)), thread_name_(std::move(thread_name)), log_(log) {}

SecocFreshness::~SecocFreshness() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

Result<void> SecocFreshness::load() {
  if (loaded_) return load_error_.empty() ? Result<void>() : Result<void>(Error{load_error_});
  loaded_ = true;
  if (file_.empty()) return {};
  std::ifstream in(file_, std::ios::binary);
  if (!in) {
    if (errno == ENOENT) return {};  // a first start: every counter from 0
    load_error_ = "cannot read the SecOC freshness file " + file_ + ": " + errno_string(errno);
    return Error{load_error_};
  }
  std::ostringstream text;
  text << in.rdbuf();
  const std::string content = text.str();
  std::string error;
  const Json document = content.size() > kMaxFileBytes ? Json() : Json::parse(content, nullptr, false);
  if (!document.is_object() || document.value("version", 0) != kFileVersion) {
    error = "not a version " + std::to_string(kFileVersion) + " SecOC freshness file";
  } else {
    file_senders_ = read_section(document, "senders", error);
    if (error.empty()) file_receivers_ = read_section(document, "receivers", error);
  }
  if (!error.empty()) {
    // Starting from 0 would repeat freshness values (a sender) or accept old frames (a receiver).
    load_error_ = "SecOC freshness file " + file_ + ": " + error +
                  " (SecOC is refused on this segment until it is repaired or removed)";
    return Error{load_error_};
  }
  return {};
}

Result<std::shared_ptr<SecocTx>> SecocFreshness::sender(const std::string& channel, const SecocSpec& spec,
                                                        std::uint32_t data_id) {
  LockGuard lock(mutex_);
  if (Result<void> loaded = load(); !loaded) return loaded.error();
  const std::string key = stream_key(channel, data_id);
  std::uint64_t last_used = 0;
  std::uint64_t lease = file_.empty() ? UINT64_MAX : 0;
  if (const auto kept = streams_.senders.find(key); kept != streams_.senders.end()) {
    if (kept->second->spec() == spec) return kept->second;
    last_used = kept->second->last_used();
    lease = kept->second->lease();
  } else if (const auto stored = file_senders_.find(key); stored != file_senders_.end()) {
    last_used = stored->second;  // every value up to the lease may have been used before the restart
    lease = file_.empty() ? UINT64_MAX : stored->second;
  }
  Result<std::shared_ptr<SecocTx>> made = SecocTx::make(spec, data_id, last_used, lease);
  if (made) streams_.senders[key] = made.value();
  return made;
}

Result<std::shared_ptr<SecocRx>> SecocFreshness::receiver(const std::string& channel, const SecocSpec& spec,
                                                          bool layout) {
  LockGuard lock(mutex_);
  if (Result<void> loaded = load(); !loaded) return loaded.error();
  std::map<std::uint32_t, std::uint64_t> restored;
  if (const auto kept = streams_.receivers.find(channel); kept != streams_.receivers.end()) {
    if (kept->second->spec() == spec && kept->second->layout() == layout) return kept->second;
    restored = kept->second->snapshot();
  } else {
    const std::string prefix = channel + "/";
    for (const auto& [stream, last] : file_receivers_) {
      if (stream.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string id = stream.substr(prefix.size());
      if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos || id.size() > 10) continue;
      const unsigned long long value = std::stoull(id);
      if (value <= UINT32_MAX) restored[static_cast<std::uint32_t>(value)] = last;
    }
  }
  auto made = std::make_shared<SecocRx>(spec, layout, std::move(restored));
  streams_.receivers[channel] = made;
  return made;
}

SecocFreshness::Streams SecocFreshness::streams() const {
  LockGuard lock(mutex_);
  return streams_;
}

bool SecocFreshness::persist(bool force) {
  if (file_.empty()) return true;
  const Streams streams = this->streams();
  Json senders = Json::object();
  Json receivers = Json::object();
  std::map<std::shared_ptr<SecocTx>, std::uint64_t> renewed;
  {
    LockGuard lock(mutex_);
    // Never over a file that was not read, or could not be: it may hold counters still needed.
    if (!loaded_ || !load_error_.empty()) return false;
    // Streams of channels no longer bound keep their values: a channel bound again continues.
    for (const auto& [key, value] : file_senders_) senders[key] = value;
    for (const auto& [key, value] : file_receivers_) receivers[key] = value;
  }
  for (const auto& [key, tx] : streams.senders) {
    std::uint64_t lease = tx->lease();
    if (tx->lease_due()) {
      const std::uint64_t step = secoc_lease_step(tx->spec().freshness_bits);
      const std::uint64_t used = tx->last_used();
      lease = used > UINT64_MAX - step ? UINT64_MAX : used + step;
      renewed[tx] = lease;
    }
    senders[key] = lease;
  }
  for (const auto& [channel, rx] : streams.receivers) {
    for (const auto& [data_id, last] : rx->snapshot()) receivers[stream_key(channel, data_id)] = last;
  }
  const Json document{{"version", kFileVersion}, {"senders", senders}, {"receivers", receivers}};
  const std::string text = document.dump(1) + "\n";
  std::lock_guard<std::mutex> write_lock(write_mutex_);
  if (text == written_ && !force) return true;
  if (const std::string error = write_atomically(file_, text); !error.empty()) {
    if (!write_error_logged_) {
      write_error_logged_ = true;
      log_.log(LogLevel::error,
               prefix_ + "SecOC freshness not persisted (" + error + "): senders stop at their last persisted value");
    }
    return false;
  }
  write_error_logged_ = false;
  written_ = text;
  for (const auto& [tx, lease] : renewed) tx->persisted(lease);
  {
    LockGuard lock(mutex_);
    for (const auto& [key, value] : senders.items()) file_senders_[key] = value.get<std::uint64_t>();
    for (const auto& [key, value] : receivers.items()) file_receivers_[key] = value.get<std::uint64_t>();
  }
  return true;
}

void SecocFreshness::persist_now() {
  bool any = false;
  {
    LockGuard lock(mutex_);
    any = !streams_.senders.empty() || !streams_.receivers.empty();
  }
  if (!any || file_.empty()) return;
  persist(false);
  if (thread_.joinable()) return;
  if (wake_fd_ < 0) wake_fd_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (wake_fd_ < 0) {
    log_.log(LogLevel::error, prefix_ + "SecOC freshness store: eventfd: " + errno_string(errno));
    return;
  }
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void SecocFreshness::poke() noexcept {
  if (poked_.exchange(true, std::memory_order_acq_rel) || wake_fd_ < 0) return;
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
}

void SecocFreshness::run() {
  (void)apply_thread_policy(ThreadPolicy{thread_name_, 0, 0, {}});
  pollfd wait{wake_fd_, POLLIN, 0};
  while (!stopping_.load(std::memory_order_acquire)) {
    if (::poll(&wait, 1, kPersistIntervalMs) > 0) {
      std::uint64_t count = 0;
      (void)!::read(wake_fd_, &count, sizeof count);
    }
    poked_.store(false, std::memory_order_release);
    if (stopping_.load(std::memory_order_acquire)) break;
    persist(false);
  }
}

void SecocFreshness::stop() {
  if (thread_.joinable()) {
    stopping_ = true;
    const std::uint64_t one = 1;
    (void)!::write(wake_fd_, &one, sizeof one);
    thread_.join();
  }
  persist(false);
}

}  // namespace cosmic::can_detail

// The SecOC freshness store of a CAN segment (secoc_freshness.hpp).
#include "secoc_freshness.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "cosmic/thread_policy.hpp"

namespace cosmic::can_detail {
namespace {

using Json = nlohmann::json;

constexpr int kFileVersion = 1;
constexpr int kPersistIntervalMs = 1000;  // receivers' values; a sender's lease as soon as it is due
constexpr std::chrono::seconds kRetryAfterFailure{1};
constexpr std::uintmax_t kMaxFileBytes = 1 << 20;

std::string stream_key(const std::string& channel, std::uint32_t id) { return channel + "/" + std::to_string(id); }

std::string errno_string(int err) { return std::strerror(err); }

// Writes `text` to `path` atomically: a temporary file beside it (never through a symbolic link),
// fsync, rename, fsync of the directory, which is made (0700) when missing. Empty on success, else
// why not.
std::string write_atomically(const std::string& path, const std::string& text) {
  const std::filesystem::path directory = std::filesystem::path(path).parent_path();
  std::error_code made;
  if (!directory.empty() && std::filesystem::create_directories(directory, made))
    std::filesystem::permissions(directory, std::filesystem::perms::owner_all, made);
  const std::string temporary = path + ".tmp";
  const int fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_NOFOLLOW | O_CLOEXEC, 0600);
  if (fd < 0) return "cannot create " + temporary + ": " + errno_string(errno);
  std::size_t done = 0;
  int err = 0;
  while (done < text.size() && err == 0) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      err = n < 0 ? errno : EIO;
    } else {
      done += static_cast<std::size_t>(n);
    }
  }
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) return "cannot write " + temporary + ": " + errno_string(err);
  if (::rename(temporary.c_str(), path.c_str()) != 0) return "cannot rename to " + path + ": " + errno_string(errno);
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

bool same_secoc_mac(const SecocSpec& a, const SecocSpec& b) {
  return a.key == b.key && a.mac_bits == b.mac_bits && a.freshness_bits == b.freshness_bits && a.data_id == b.data_id;
}

SecocFreshness::SecocFreshness(std::string file, std::string log_prefix, std::string thread_name, Logger& log)
    : file_(std::move(file)),
      prefix_(std::move(log_prefix)),
      thread_name_(std::move(thread_name)),
      log_(log),
      wake_fd_(file_.empty() ? -1 : ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {}

SecocFreshness::~SecocFreshness() {
  stop_thread();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

Result<void> SecocFreshness::load() {
  if (loaded_) return load_error_.empty() ? Result<void>() : Result<void>(Error{load_error_});
  std::string error;
  if (!file_.empty()) {
    std::error_code status;
    const bool exists = std::filesystem::exists(file_, status);
    if (exists && std::filesystem::file_size(file_, status) > kMaxFileBytes) {
      error = "larger than " + std::to_string(kMaxFileBytes) + " bytes";
    } else if (exists) {
      std::ifstream in(file_, std::ios::binary);
      std::ostringstream text;
      if (in) text << in.rdbuf();
      if (!in) {
        error = "cannot be read: " + errno_string(errno);
      } else if (Result<void> parsed = parse(text.str()); !parsed) {
        error = parsed.error().text;
      }
    } else if (status) {
      error = status.message();
    }
  }
  // Starting from 0 would repeat freshness values (a sender) or accept old frames (a receiver).
  if (!error.empty())
    load_error_ = "SecOC freshness file " + file_ + ": " + error +
                  " (SecOC is refused on this segment until it is repaired or removed)";
  loaded_ = true;
  return load_error_.empty() ? Result<void>() : Result<void>(Error{load_error_});
}

Result<void> SecocFreshness::parse(const std::string& content) {
  const Json document = Json::parse(content, nullptr, false);
  const bool versioned = document.is_object() && document.contains("version") &&
                         document["version"].is_number_unsigned() && document["version"].get<std::uint64_t>() == 1;
  if (!versioned) return Error{"not a version " + std::to_string(kFileVersion) + " SecOC freshness file"};
  std::string error;
  auto senders = read_section(document, "senders", error);
  auto receivers = error.empty() ? read_section(document, "receivers", error) : decltype(senders){};
  if (!error.empty()) return Error{error};
  file_senders_ = std::move(senders);
  file_receivers_ = std::move(receivers);
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
    if (same_secoc_mac(kept->second->spec(), spec)) return kept->second;
    // Retired first: the old state sends nothing more, the new one continues from its last value.
    last_used = kept->second->retire();
    lease = file_.empty() ? UINT64_MAX : last_used;
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
    if (same_secoc_mac(kept->second->spec(), spec) && kept->second->layout() == layout) return kept->second;
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

bool SecocFreshness::persist(bool retiring) {
  if (file_.empty()) return true;
  std::lock_guard<std::mutex> write_lock(write_mutex_);
  if (!retiring && !write_error_.empty() && std::chrono::steady_clock::now() < retry_after_) return false;
  Streams streams;
  std::map<std::string, std::uint64_t> senders;
  std::map<std::string, std::uint64_t> receivers;
  {
    LockGuard lock(mutex_);
    // Never over a file that was not read, or could not be: it may hold counters still needed.
    if (!loaded_ || !load_error_.empty()) return false;
    streams = streams_;
    // Streams of channels no longer bound keep their values: a channel bound again continues.
    senders = file_senders_;
    receivers = file_receivers_;
  }
  std::vector<std::pair<std::shared_ptr<SecocTx>, std::uint64_t>> granted;
  for (const auto& [key, tx] : streams.senders) {
    std::uint64_t lease = tx->lease();
    if (retiring) {
      lease = tx->retire();
    } else if (tx->lease_due()) {
      const std::uint64_t step =
          tx->sent() ? secoc_lease_step(tx->spec().freshness_bits) : secoc_start_step(tx->spec().freshness_bits);
      const std::uint64_t used = tx->last_used();
      lease = std::max(lease, used > UINT64_MAX - step ? UINT64_MAX : used + step);
      granted.emplace_back(tx, lease);
    }
    senders[key] = lease;
  }
  for (const auto& [channel, rx] : streams.receivers) {
    for (const auto& [source, last] : rx->snapshot()) receivers[stream_key(channel, source)] = last;
  }
  Json document{{"version", kFileVersion}, {"senders", Json::object()}, {"receivers", Json::object()}};
  for (const auto& [key, value] : senders) document["senders"][key] = value;
  for (const auto& [key, value] : receivers) document["receivers"][key] = value;
  const std::string text = document.dump(1) + "\n";
  if (text != written_) {
    if (std::string error = write_atomically(file_, text); !error.empty()) {
      if (write_error_.empty())
        log_.log(LogLevel::error, prefix_ + "SecOC freshness not persisted (" + error +
                                      "): senders stop at their last persisted value; retried every second");
      write_error_ = std::move(error);
      retry_after_ = std::chrono::steady_clock::now() + kRetryAfterFailure;
      return false;
    }
    if (!write_error_.empty()) log_.log(LogLevel::notice, prefix_ + "SecOC freshness persisted again");
    write_error_.clear();
    written_ = text;
  }
  for (const auto& [tx, lease] : granted) tx->persisted(lease);
  LockGuard lock(mutex_);
  file_senders_ = std::move(senders);
  file_receivers_ = std::move(receivers);
  return true;
}

std::string SecocFreshness::last_error() const {
  std::lock_guard<std::mutex> write_lock(write_mutex_);
  return write_error_;
}

bool SecocFreshness::persist_now() {
  {
    LockGuard lock(mutex_);
    if (streams_.senders.empty() && streams_.receivers.empty()) return true;
  }
  if (file_.empty()) return true;
  const bool written = persist(false);
  if (!thread_.joinable() && wake_fd_ >= 0) {
    stopping_ = false;
    thread_ = std::thread([this] { run(); });
  }
  return written;
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

void SecocFreshness::stop_thread() {
  if (!thread_.joinable()) return;
  stopping_ = true;
  const std::uint64_t one = 1;
  (void)!::write(wake_fd_, &one, sizeof one);
  thread_.join();
}

void SecocFreshness::attach() {
  LockGuard lock(mutex_);
  ++users_;
}

void SecocFreshness::detach() {
  {
    LockGuard lock(mutex_);
    if (users_ > 0) --users_;
    if (users_ > 0) return;
  }
  stop_thread();
  persist(true);
}

}  // namespace cosmic::can_detail

#include "lcm_transmit.hpp"

#include "cosmic/result.hpp"

#include <sys/random.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <exception>
#include <utility>

namespace cosmic::lcm_detail {

static_assert(kLcmMessageParts + 1 == SendBatch::kMaxParts, "a format's message and its trailer fit one batch entry");

namespace {

constexpr auto kReopenPause = std::chrono::seconds(1);

Endpoint endpoint_of(std::uint64_t key) {
  return Endpoint{static_cast<std::uint32_t>(key >> 16), static_cast<std::uint16_t>(key & 0xffff)};
}

// The failures a renumbered or vanished interface leaves a connected socket with.
bool source_gone(int error) {
  return error == EADDRNOTAVAIL || error == EINVAL || error == ENETUNREACH || error == ENODEV;
}

const char* class_name(std::size_t index) {
  static constexpr const char* kNames[] = {"hrt", "srt", "nrt"};
  return index < 3 ? kNames[index] : "?";
}

// A signer with a sender number of its own, drawn from the kernel's random source: a restarted
// gateway's sequence numbers from 1 are a new sender's, never taken for replays.
Result<LcmAuthSigner> make_signer(const LcmAuthSpec& auth) {
  std::uint64_t sender = 0;
  while (sender == 0) {
    const ssize_t n = ::getrandom(&sender, sizeof sender, 0);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return Error::from_errno("getrandom", errno);
    if (n != static_cast<ssize_t>(sizeof sender)) return Error{"getrandom: a short read"};
  }
  return LcmAuthSigner::make(auth.key.bytes(), sender);
}

std::int64_t wall_clock_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

LcmTransmitter::LcmTransmitter(const std::string& segment_name, const LcmAuthSpec* auth, Logger& log,
                               AdapterCounters& counters, HealthCell& health, const std::atomic<bool>& receive_failing)
    : prefix_(segment_log_prefix(SegmentType::lcm, segment_name)),
      auth_(auth),
      log_(log),
      counters_(counters),
      health_(health),
      receive_failing_(receive_failing) {}

Result<void> LcmTransmitter::open(const LcmUrl& url) {
  url_ = url;
  own_drops_.store(0, std::memory_order_release);
  counting_looped_back_.store(true, std::memory_order_release);
  for (std::size_t i = 0; i < senders_.size(); ++i) {
    OpenedSocket tx = open_send_socket(url);
    if (tx.fd < 0) {
      close();
      return Error{"transmit socket on udpm://" + url.group + ":" + std::to_string(url.port) + ": " + tx.error};
    }
    std::optional<LcmAuthSigner> signer;
    if (auth_ != nullptr) {  // made before the sender's mutex is taken: close() takes it
      Result<LcmAuthSigner> made = make_signer(*auth_);
      if (!made) {
        ::close(tx.fd);
        close();
        return Error{"cannot sign what it sends: " + made.error().text};
      }
      signer.emplace(std::move(made).value());
    }
    LockGuard lock(senders_[i].mutex);
    senders_[i].signer = std::move(signer);
    senders_[i].fd = tx.fd;
    senders_[i].failing.store(false, std::memory_order_relaxed);
    own_keys_[i].store(tx.local.key(), std::memory_order_relaxed);
  }
  return {};
}

Result<void> LcmTransmitter::follow_with_filter(int receive_fd, LcmOwnDatagrams mode) {
  {
    LockGuard lock(filter_mutex_);
    receive_fd_ = receive_fd;
    filter_mode_ = mode;
  }
  return attach_filter();
}

Result<void> LcmTransmitter::attach_filter() {
  LockGuard lock(filter_mutex_);
  if (receive_fd_ < 0) return {};
  std::array<Endpoint, 3> own{};
  std::size_t count = 0;
  for (const auto& key : own_keys_)
    if (const std::uint64_t k = key.load(std::memory_order_relaxed); k != 0) own[count++] = endpoint_of(k);
  if (count == 0) return {};
  Result<void> attached = drop_own_datagrams(receive_fd_, std::span(own.data(), count), filter_mode_);
  // A filter that could not follow leaves the new source's datagrams to be read and skipped.
  filter_drops_.store(attached.ok() && filter_mode_ == LcmOwnDatagrams::drop, std::memory_order_release);
  return attached;
}

void LcmTransmitter::count_looped_back(bool counting) {
  counting_looped_back_.store(counting, std::memory_order_release);
  if (!counting) return;
  // A lane that read the flag before it was set may still be inside its send: wait for it (each
  // send holds its sender's mutex), so nothing it sends after the join goes uncounted.
  for (auto& sender : senders_) LockGuard wait_for_send(sender.mutex);
}

void LcmTransmitter::close() {
  {
    LockGuard lock(filter_mutex_);
    receive_fd_ = -1;
    filter_drops_.store(false, std::memory_order_release);
  }
  for (std::size_t i = 0; i < senders_.size(); ++i) {
    LockGuard lock(senders_[i].mutex);  // waits for a send in flight
    if (senders_[i].fd >= 0) ::close(std::exchange(senders_[i].fd, -1));
    senders_[i].signer.reset();
    own_keys_[i].store(0, std::memory_order_relaxed);
  }
  url_.reset();
}

bool LcmTransmitter::is_own(Endpoint from) const {
  const std::uint64_t key = from.key();
  for (const auto& own : own_keys_)
    if (own.load(std::memory_order_relaxed) == key) return true;
  return false;
}

SendStatus LcmTransmitter::unbound() {
  counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
  return SendStatus::failed;
}

SendStatus LcmTransmitter::send(const Channel& channel, const OutboundEvent& event) {
  ClassSender& sender = senders_.at(static_cast<std::size_t>(channel.cls));
  SendLog later;
  SendStatus status = SendStatus::failed;
  {
    LockGuard transmit(sender.mutex);
    status = send_one(sender, channel, event, later);
  }
  write(later);
  return status;
}

void LcmTransmitter::send_batch(std::span<const OutboundEvent> events, std::span<const Channel* const> channels,
                                std::span<SendStatus> results) {
  const std::size_t n = std::min({events.size(), channels.size(), results.size()});
  SendLog later;
  std::size_t i = 0;
  while (i < n) {
    const Channel* first = channels[i];
    if (first == nullptr) {
      results[i++] = unbound();
      continue;
    }
    ClassSender& sender = senders_.at(static_cast<std::size_t>(first->cls));
    LockGuard transmit(sender.mutex);
    std::array<std::size_t, SendBatch::kCapacity> staged{};  // indices into events
    std::size_t count = 0;
    for (; i < n; ++i) {
      if (channels[i] == nullptr) {
        results[i] = unbound();
        continue;
      }
      if (channels[i]->cls != first->cls || !stage(sender, *channels[i], events[i])) break;
      staged[count++] = i;
    }
    if (count == 0) {  // the message at i needs fragments, or there is no socket (memq, stopped)
      results[i] = send_one(sender, *first, events[i], later);
      ++i;
      continue;
    }
    note_sending(count);  // one datagram each (stage())
    const SendFailure why = sender.batch.send(sender.fd);
    for (std::size_t k = 0; k < count; ++k)
      results[staged[k]] = sender.batch.failed(k) ? failed(sender, *channels[staged[k]], why, later) : sent(sender);
  }
  write(later);
}

void LcmTransmitter::write(SendLog& later) noexcept {
  try {
    for (auto& [level, text] : later) log_.log(level, text);
  } catch (...) {
    // A logger that cannot take the line: the failure is counted all the same.
  }
}

void LcmTransmitter::note_sending(std::size_t datagrams) {
  if (counting_looped_back_.load(std::memory_order_acquire) && filter_drops_.load(std::memory_order_acquire))
    own_drops_.fetch_add(datagrams, std::memory_order_release);
}

SendStatus LcmTransmitter::send_one(ClassSender& sender, const Channel& channel, const OutboundEvent& event,
                                    SendLog& later) {
  if (sender.fd < 0) return failed(sender, channel, SendFailure{0, "no transmit socket"}, later);
  WireParts parts{};
  const char* refusal = nullptr;
  const std::size_t count = wire_parts(sender, 0, channel, event, parts, refusal);
  if (count == 0) return failed(sender, channel, SendFailure{0, refusal}, later);
  std::size_t payload_size = 0;
  for (std::size_t k = 0; k < count; ++k) payload_size += parts[k].size();
  if (const auto plan = plan_lcm_message(channel.name.size(), payload_size))
    note_sending(std::max<std::size_t>(1, plan->fragment_count));
  const SendFailure why = send_lcm_message(sender.fd, sender.sequence++, channel.name, std::span(parts.data(), count));
  return why.failed() ? failed(sender, channel, why, later) : sent(sender);
}

bool LcmTransmitter::stage(ClassSender& sender, const Channel& channel, const OutboundEvent& event) {
  const std::size_t slot = sender.batch.size();
  if (slot >= SendBatch::kCapacity || sender.fd < 0) return false;
  WireParts parts{};
  const char* refusal = nullptr;
  // A message refused here goes to send_one(), which says why.
  const std::size_t count = wire_parts(sender, slot, channel, event, parts, refusal);
  if (count == 0 || !sender.batch.add(sender.sequence, channel.name, std::span(parts.data(), count))) return false;
  ++sender.sequence;
  return true;
}

std::size_t LcmTransmitter::wire_parts(ClassSender& sender, std::size_t slot, const Channel& channel,
                                       const OutboundEvent& event, WireParts& wire, const char*& refusal) {
  LcmMessageParts parts{};
  const std::size_t count = channel.format->encode(event, sender.envelope_headers[slot], parts);
  if (count == 0) {
    refusal = "payload too large";
    return 0;
  }
  std::copy_n(parts.begin(), count, wire.begin());
  if (!sender.signer) return count;
  if (!sender.signer->sign(channel.name, std::span(parts.data(), count), wall_clock_ns(), sender.trailers[slot])) {
    refusal = "cannot compute its authentication tag";
    return 0;
  }
  wire[count] = sender.trailers[slot];
  return count + 1;
}

SendStatus LcmTransmitter::sent(ClassSender& sender) {
  counters_.sent.fetch_add(1, std::memory_order_relaxed);
  if (sender.failing.exchange(false, std::memory_order_relaxed) && !receive_failing_.load(std::memory_order_relaxed))
    health_.set(SegmentHealth::up, "");
  return SendStatus::sent;
}

// Counts the failure; logs the first of a run (per class, so NRT trouble never hides HRT's), after
// the mutex is let go; reopens a socket whose source went away. Never throws: the log line is the
// one allocation.
SendStatus LcmTransmitter::failed(ClassSender& sender, const Channel& channel, SendFailure why, SendLog& later) {
  counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
  const auto index = static_cast<std::size_t>(&sender - senders_.data());
  const bool first = !sender.failing.exchange(true, std::memory_order_relaxed);
  try {
    if (first) {
      later.emplace_back(LogLevel::warning,
                         prefix_ + "send on channel " + channel.name + " (" + class_name(index) + "): " + why.what +
                             (why.error != 0 ? std::string(": ") + errno_text(why.error) : std::string()));
    }
    if (source_gone(why.error)) reopen(sender, index, later);
  } catch (const std::exception&) {
    // Out of memory for a log line: the failure is counted all the same.
  }
  return SendStatus::failed;
}

void LcmTransmitter::reopen(ClassSender& sender, std::size_t index, SendLog& later) {
  const auto now = std::chrono::steady_clock::now();
  if (!url_ || now - sender.last_reopen < kReopenPause) return;
  sender.last_reopen = now;
  OpenedSocket tx = open_send_socket(*url_);
  if (tx.fd < 0) {
    health_.set(SegmentHealth::degraded,
                std::string("the ") + class_name(index) + " transmit socket cannot reopen: " + tx.error);
    later.emplace_back(LogLevel::error, prefix_ + class_name(index) + " transmit socket cannot reopen: " + tx.error);
    return;
  }
  if (sender.fd >= 0) ::close(sender.fd);
  sender.fd = tx.fd;
  own_keys_[index].store(tx.local.key(), std::memory_order_relaxed);
  later.emplace_back(LogLevel::notice, prefix_ + class_name(index) + " transmit socket reopened");
  if (const Result<void> attached = attach_filter(); !attached)
    later.emplace_back(LogLevel::warning, prefix_ + "own datagrams read back in full (" + attached.error().text + ")");
}

}  // namespace cosmic::lcm_detail

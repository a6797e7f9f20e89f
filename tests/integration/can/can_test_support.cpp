#include "can_test_support.hpp"

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "cosmic/can_timing.hpp"
#include "cosmic/can_wire.hpp"

extern char** environ;

namespace cosmic::test {

int shell(const std::string& command) {
  const int status = std::system(command.c_str());
  if (status == -1 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

std::string shell_output(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (!pipe) return out;
  std::array<char, 4096> buffer{};
  std::size_t n = 0;
  while ((n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0) out.append(buffer.data(), n);
  ::pclose(pipe);
  return out;
}

bool wait_until(const std::function<bool()>& condition, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  for (;;) {
    if (condition()) return true;
    if (Clock::now() >= deadline) return false;
    std::this_thread::sleep_for(milliseconds(5));
  }
}

std::string hex(const std::vector<std::uint8_t>& bytes) {
  static constexpr char digits[] = "0123456789ABCDEF";
  std::string s;
  for (const auto b : bytes) {
    s += digits[b >> 4];
    s += digits[b & 0x0F];
  }
  return s;
}

std::string hex_id(std::uint32_t id) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08X", id);
  return buf;
}

namespace {
int nibble(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}
}  // namespace

std::optional<CanLine> parse_candump_line(const std::string& line) {
  // (1700000000.123456) vcan0 1FA04003#23003FFF00000001   |  ... 020140C8##1AABB...  |  123#R
  std::istringstream in(line);
  std::string stamp;
  std::string frame;
  CanLine out;
  if (!(in >> stamp >> out.interface >> frame)) return std::nullopt;
  const auto hash = frame.find('#');
  if (hash == std::string::npos) return std::nullopt;
  const std::string id = frame.substr(0, hash);
  out.extended = id.size() == 8;
  out.id = static_cast<std::uint32_t>(std::stoul(id, nullptr, 16));
  std::size_t pos = hash + 1;
  if (pos < frame.size() && frame[pos] == '#') {
    out.fd = true;
    if (pos + 1 >= frame.size()) return std::nullopt;
    out.fd_flags = static_cast<std::uint8_t>(nibble(frame[pos + 1]));
    pos += 2;
  } else if (pos < frame.size() && frame[pos] == 'R') {
    out.rtr = true;
    return out;
  }
  for (; pos + 1 < frame.size(); pos += 2) {
    const int hi = nibble(frame[pos]);
    const int lo = nibble(frame[pos + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    out.data.push_back(static_cast<std::uint8_t>((hi << 4) | lo));
  }
  return out;
}

int raw_receivers(const std::string& interface) {
  // Unfiltered receivers are listed in rcvlist_all, filtered ones in the other lists.
  int count = 0;
  for (const char* list : {"all", "fil", "inv", "sff", "eff", "err"}) {
    std::ifstream in(std::string("/proc/net/can/rcvlist_") + list);
    std::string line;
    while (std::getline(in, line)) {
      std::istringstream words(line);
      std::string first;
      std::string word;
      std::string last;
      words >> first;
      while (words >> word) last = word;
      if (first == interface && last == "raw") ++count;
    }
  }
  return count;
}

Candump::Candump(const std::string& interface, const std::string& spec, int count) {
  char name[] = "/tmp/cosmic-candump.XXXXXX";
  const int fd = ::mkstemp(name);
  if (fd < 0) throw std::runtime_error("mkstemp failed");
  ::close(fd);
  file_ = name;
  const int before = raw_receivers(interface);
  // vcan delivers a burst at once, unpaced by any bus: with the default receive buffer (about 200
  // frames) a candump slowed by a loaded host loses part of a 334-frame burst in its own socket
  // (seen once under scripts/test). 4 MiB holds every burst these tests send.
  const std::string command =
      "exec candump -r 4194304 -L -n " + std::to_string(count) + " " + spec + " >" + file_ + " 2>&1";
  const char* argv[] = {"sh", "-c", command.c_str(), nullptr};
  if (::posix_spawnp(&pid_, "sh", nullptr, nullptr, const_cast<char* const*>(argv), environ) != 0) {
    throw std::runtime_error("cannot start candump");
  }
  const bool ready = wait_until(
      [&] {
        int status = 0;
        if (::waitpid(pid_, &status, WNOHANG) == pid_) {
          pid_ = -1;
          return true;  // exited early: reported below
        }
        return raw_receivers(interface) > before;
      },
      milliseconds(10000));
  if (!ready || pid_ < 0) throw std::runtime_error("candump did not start: " + shell_output("cat " + file_));
}

Candump::~Candump() {
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
  }
  ::unlink(file_.c_str());
}

std::vector<CanLine> Candump::lines() const {
  std::vector<CanLine> out;
  std::ifstream in(file_);
  std::string line;
  while (std::getline(in, line)) {
    if (auto parsed = parse_candump_line(line)) out.push_back(std::move(*parsed));
  }
  return out;
}

std::vector<CanLine> Candump::wait(milliseconds timeout) {
  if (pid_ > 0) {
    wait_until(
        [&] {
          int status = 0;
          if (::waitpid(pid_, &status, WNOHANG) != pid_) return false;
          pid_ = -1;
          return true;
        },
        timeout);
  }
  if (pid_ > 0) {
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  return lines();
}

void RecordingSink::on_event(const InboundEvent& event) {
  std::unique_lock lock(mutex_);
  events_.push_back(ReceivedEvent{event.channel, event.header.subject, {event.payload.begin(), event.payload.end()}});
  changed_.notify_all();
  changed_.wait(lock, [&] { return !blocked_; });
}

void RecordingSink::on_problem(ChannelId, InboundProblem problem) {
  std::lock_guard lock(mutex_);
  ++problems_[problem];
  changed_.notify_all();
}

std::vector<ReceivedEvent> RecordingSink::events() const {
  std::lock_guard lock(mutex_);
  return events_;
}

std::size_t RecordingSink::event_count() const {
  std::lock_guard lock(mutex_);
  return events_.size();
}

std::size_t RecordingSink::problem_count() const {
  std::lock_guard lock(mutex_);
  std::size_t total = 0;
  for (const auto& [kind, n] : problems_) total += n;
  return total;
}

std::size_t RecordingSink::problem_count(InboundProblem problem) const {
  std::lock_guard lock(mutex_);
  const auto it = problems_.find(problem);
  return it == problems_.end() ? 0 : it->second;
}

bool RecordingSink::wait_events(std::size_t count, milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return events_.size() >= count; });
}

bool RecordingSink::wait_problems(std::size_t count, milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] {
    std::size_t total = 0;
    for (const auto& [kind, n] : problems_) total += n;
    return total >= count;
  });
}

void RecordingSink::block(bool blocked) {
  std::lock_guard lock(mutex_);
  blocked_ = blocked;
  changed_.notify_all();
}

void RecordingLogger::log(LogLevel, std::string_view message) {
  std::lock_guard lock(mutex_);
  messages_.emplace_back(message);
}

std::vector<std::string> RecordingLogger::messages() const {
  std::lock_guard lock(mutex_);
  return messages_;
}

SegmentSpec can_segment(const std::string& interface, bool fd) {
  SegmentSpec spec;
  spec.name = "bus-" + interface;
  spec.type = SegmentType::can;
  spec.can.interface = interface;
  spec.can.bitrate = BitRate{500'000};
  spec.can.fd = fd;
  spec.can.data_bitrate = fd ? BitRate{2'000'000} : BitRate{500'000};
  return spec;
}

ChannelBinding can_binding(ChannelId id, const std::string& name, std::uint64_t subject, std::uint64_t payload,
                           HopRole role, std::uint8_t priority, std::uint16_t etag, const SegmentSpec& segment) {
  ChannelBinding b;
  b.id = id;
  b.spec.name = name;
  b.spec.subject = subject;
  b.spec.payload = payload;
  b.spec.cls = priority <= kHrtBand.last   ? ChannelClass::hrt
               : priority <= kSrtBand.last ? ChannelClass::srt
                                           : ChannelClass::nrt;
  b.role = role;
  CanHopPlan plan;
  plan.priority = priority;
  plan.etag = etag;
  plan.can_id = encode_can_id(CanIdentifier{priority, kGatewayNode, etag});
  const std::uint32_t capacity = max_frame_payload(segment.can);
  const bool fits = payload <= capacity;
  plan.frames_per_event = fits ? 1 : fragments_needed(payload, capacity);
  const auto data = static_cast<std::uint32_t>(fits ? payload : capacity);
  plan.frame_bytes = segment.can.fd ? fd_padded_length(data) : data;
  b.can = plan;
  return b;
}

}  // namespace cosmic::test

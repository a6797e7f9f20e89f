// A component on a CAN bus, from docs/can-wire-format.md alone: GET_ETAG binding at announce,
// one frame per event (no header) when the channel's payload fits 8 bytes, otherwise fragments.
// Classic CAN only. One receive thread per client owns the reads.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstring>
#include <map>
#include <thread>

#include "cosmic/thread_policy.hpp"
#include "cosmic/can_fragment.hpp"
#include "cosmic/can_wire.hpp"
#include "cosmic/client.h"
#include "cosmic/mutex.hpp"
#include "cosmic/steady_clock.hpp"
#include "cosmic/thread_annotations.hpp"
#include "transport.hpp"

namespace cosmic::client_detail {
namespace {

constexpr std::uint32_t kClassicCapacity = 8;
constexpr std::uint8_t kBindingPriority = 0xFD;  // the binding protocol's NRT level

struct CanChannel {
  ChannelSpec spec;
  int roles = 0;
  std::uint16_t etag = 0;  // 0 until SUPPLY_ETAG arrived
  std::uint8_t fragment_sequence = 0;
};

class CanTransport final : public Transport {
 public:
  CanTransport(std::string interface, std::uint8_t node) : interface_(std::move(interface)), node_(node) {}
  ~CanTransport() override {
    running_ = false;
    if (reader_.joinable()) reader_.join();
    if (fd_ >= 0) ::close(fd_);
  }

  int start(Delivery& delivery, std::string& error) override {
    delivery_ = &delivery;
    const unsigned index = if_nametoindex(interface_.c_str());
    fd_ = index ? ::socket(PF_CAN, SOCK_RAW, CAN_RAW) : -1;
    sockaddr_can address{};
    address.can_family = AF_CAN;
    address.can_ifindex = static_cast<int>(index);
    timeval tick{0, 100'000};  // the reader checks for stop() this often
    if (fd_ < 0 || ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tick, sizeof tick) != 0 ||
        ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
      error = "CAN interface '" + interface_ + "': " + (index ? std::strerror(errno) : "no such interface");
      return COSMIC_E_TRANSPORT;
    }
    running_ = true;
    reader_ = std::thread([this] { read_loop(); });
    return COSMIC_OK;
  }

  int announce(std::size_t index, const ChannelSpec& spec, int roles, int timeout_ms, std::string& error) override {
    UniqueLock lock(mutex_);
    channels_[index] = CanChannel{spec, roles, spec.etag.value_or(0), 0};
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::milliseconds(timeout_ms);
    // Ask again every 500 ms (the gateway answers only once the channel is bound).
    while (channels_[index].etag == 0 && std::chrono::steady_clock::now() < deadline) {
      lock.unlock();
      request_etag(spec.subject);
      lock.lock();
      const auto until = std::min(deadline, std::chrono::steady_clock::now() + std::chrono::milliseconds(500));
      while (channels_[index].etag == 0 && lock.wait_until(bound_, until) != std::cv_status::timeout) {
      }
    }
    if (channels_[index].etag != 0) return COSMIC_OK;
    error = "no gateway on " + interface_ + " answered GET_ETAG for channel '" + spec.name + "'";
    channels_.erase(index);
    return COSMIC_E_UNBOUND;
  }

  int send(std::size_t index, const EventHeader&, std::span<const std::uint8_t> payload, std::string& error) override {
    UniqueLock lock(mutex_);
    CanChannel& c = channels_.at(index);
    const std::uint32_t id = encode_can_id({band_of(c.spec.cls).first, node_, c.etag}) | CAN_EFF_FLAG;
    if (!needs_fragmentation(c.spec.payload, kClassicCapacity)) return write_frame(id, payload, error);
    Fragmenter fragments(payload, kClassicCapacity, c.fragment_sequence);
    c.fragment_sequence = static_cast<std::uint8_t>((c.fragment_sequence + 1) % kFragmentSequenceModulo);
    lock.unlock();
    std::uint8_t frame[kClassicCapacity];
    while (!fragments.done()) {
      const std::size_t n = fragments.next(frame);
      if (const int rc = write_frame(id, {frame, n}, error); rc != COSMIC_OK) return rc;
    }
    return COSMIC_OK;
  }

  // No discovery to ask, and nothing left to wait for: announce() succeeded only once a gateway's
  // SUPPLY_ETAG answered, and a gateway answers only for a channel it binds on this bus.
  std::optional<std::size_t> matched(std::size_t, int) const override { return std::nullopt; }

 private:
  int write_frame(std::uint32_t id, std::span<const std::uint8_t> data, std::string& error) {
    can_frame frame{};
    frame.can_id = id;
    frame.len = static_cast<std::uint8_t>(data.size());
    std::memcpy(frame.data, data.data(), data.size());
    if (::write(fd_, &frame, sizeof frame) == static_cast<ssize_t>(sizeof frame)) return COSMIC_OK;
    if (errno == ENOBUFS || errno == EAGAIN) return COSMIC_E_AGAIN;
    error = "CAN write on " + interface_ + ": " + std::strerror(errno);
    return COSMIC_E_TRANSPORT;
  }

  void request_etag(std::uint64_t subject) {
    std::uint8_t data[8];
    for (int i = 0; i < 8; ++i) data[i] = static_cast<std::uint8_t>(subject >> (56 - 8 * i));
    std::string ignored;
    write_frame(encode_can_id({kBindingPriority, node_, kEtagGetEtag}) | CAN_EFF_FLAG, data, ignored);
  }

  void read_loop() {
    apply_thread_policy(ThreadPolicy{"cosmic-can-rx", 0, 0, {}});  // a name only: the component sets its own policy
    can_frame frame{};
    while (running_) {
      if (::read(fd_, &frame, sizeof frame) != static_cast<ssize_t>(sizeof frame)) continue;
      if (!(frame.can_id & CAN_EFF_FLAG) || (frame.can_id & (CAN_RTR_FLAG | CAN_ERR_FLAG))) continue;
      const CanIdentifier id = decode_can_id(frame.can_id & CAN_EFF_MASK);
      if (id.etag == kEtagSupplyEtag) {
        on_supply(frame);
      } else {
        on_event(id, {frame.data, frame.len});
      }
    }
  }

  // SUPPLY_ETAG: two frames [requester, 0|1, etag hi, etag lo, 4 subject bytes]; the etag is
  // taken once both halves of the subject match a channel still waiting.
  void on_supply(const can_frame& f) {
    if (f.len != 8 || f.data[0] != node_ || f.data[1] > 1) return;
    std::uint32_t half = 0;
    for (int i = 4; i < 8; ++i) half = half << 8 | f.data[i];
    const auto etag = static_cast<std::uint16_t>((f.data[2] & 0x3F) << 8 | f.data[3]);
    LockGuard lock(mutex_);
    if (f.data[1] == 0) {
      supply_high_[etag] = half;
      return;
    }
    const auto high = supply_high_.find(etag);
    if (high == supply_high_.end()) return;
    const std::uint64_t subject = static_cast<std::uint64_t>(high->second) << 32 | half;
    for (auto& [index, c] : channels_) {
      if (c.etag == 0 && c.spec.subject == subject) c.etag = etag;
    }
    bound_.notify_all();
  }

  void on_event(const CanIdentifier& id, std::span<const std::uint8_t> data) {
    UniqueLock lock(mutex_);
    for (auto& [index, c] : channels_) {
      if (c.etag != id.etag || !(c.roles & COSMIC_SUBSCRIBE)) continue;
      EventHeader header;
      header.subject = c.spec.subject;
      if (!needs_fragmentation(c.spec.payload, kClassicCapacity)) {
        if (data.size() > c.spec.payload) return;
        lock.unlock();
        delivery_->deliver(index, header, data);
        return;
      }
      const auto result = reassembler_.accept(static_cast<std::uint32_t>(id.tx_node) << 14 | id.etag, data,
                                              c.spec.payload, steady_now());
      if (result.outcome != FragmentOutcome::complete) return;
      const std::size_t channel = index;
      lock.unlock();
      delivery_->deliver(channel, header, result.event);
      return;
    }
  }

  std::string interface_;
  std::uint8_t node_;
  int fd_ = -1;
  Delivery* delivery_ = nullptr;
  std::atomic<bool> running_{false};
  std::thread reader_;
  Mutex mutex_;
  std::condition_variable bound_;
  std::map<std::size_t, CanChannel> channels_ COSMIC_GUARDED_BY(mutex_);
  std::map<std::uint16_t, std::uint32_t> supply_high_ COSMIC_GUARDED_BY(mutex_);  // etag -> first half of a SUPPLY_ETAG
  Reassembler reassembler_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace

std::unique_ptr<Transport> make_can_transport(const std::string& interface, std::uint8_t node) {
  return std::make_unique<CanTransport>(interface, node);
}

}  // namespace cosmic::client_detail

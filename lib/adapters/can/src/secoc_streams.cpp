// SecOC state of a CAN segment's channels (secoc_streams.hpp).
#include "secoc_streams.hpp"

#include <algorithm>
#include <cstring>

namespace cosmic::can_detail {
namespace {

constexpr std::uint32_t kLayoutSenderBits = 0x1FFFFF;  // TxNode (7 bits) and etag (14 bits)
constexpr std::uint64_t kMaxLeaseStep = std::uint64_t{1} << 16;

SecocParameters parameters_of(const SecocSpec& spec, std::uint32_t data_id) {
  SecocParameters p;
  p.data_id = data_id;
  p.mac_bits = spec.mac_bits;
  p.freshness_bits = spec.freshness_bits;
  return p;
}

}  // namespace

std::uint32_t secoc_data_id(const SecocSpec& spec, canid_t can_id, bool layout) {
  if (spec.data_id) return *spec.data_id;
  return secoc_source(can_id, layout);
}

std::uint32_t secoc_source(canid_t can_id, bool layout) {
  if (layout) return can_id & kLayoutSenderBits;
  return can_id & ((can_id & CAN_EFF_FLAG) ? CAN_EFF_MASK : CAN_SFF_MASK);
}

std::uint64_t secoc_start_step(std::uint32_t freshness_bits) {
  return std::max<std::uint64_t>(1, secoc_lease_step(freshness_bits) / 16);
}

std::uint64_t secoc_lease_step(std::uint32_t freshness_bits) {
  if (freshness_bits == 0) return 1;
  if (freshness_bits >= 18) return kMaxLeaseStep;
  return std::uint64_t{1} << (freshness_bits - 1);
}

std::size_t secoc_pdu_size(const SecocSpec& spec, std::size_t data_size, std::size_t payload, bool fd) {
  return (fd ? std::max(data_size, payload) : data_size) + spec.overhead_bytes();
}

// ------------------------------------------------------------------------------ sender

Result<std::shared_ptr<SecocTx>> SecocTx::make(const SecocSpec& spec, std::uint32_t data_id, std::uint64_t last_used,
                                               std::uint64_t persisted) {
  Result<SecocSender> sender = SecocSender::make(spec.key.bytes(), parameters_of(spec, data_id), last_used);
  if (!sender) return sender.error();
  return std::shared_ptr<SecocTx>(new SecocTx(spec, data_id, std::move(sender).value(), persisted));
}

SecocTx::SecocTx(const SecocSpec& spec, std::uint32_t data_id, SecocSender sender, std::uint64_t persisted)
    : spec_(spec),
      data_id_(data_id),
      step_(secoc_lease_step(spec.freshness_bits)),
      sender_(std::move(sender)),
      last_used_(sender_.freshness()),
      lease_(persisted) {}

void SecocTx::persisted(std::uint64_t value) noexcept {
  std::uint64_t current = lease_.load(std::memory_order_acquire);
  while (value > current && !lease_.compare_exchange_weak(current, value, std::memory_order_acq_rel)) {
  }
}

std::uint64_t SecocTx::retire() noexcept {
  PiLock lock(mutex_);
  lease_.store(sender_.freshness(), std::memory_order_release);
  return sender_.freshness();
}

bool SecocTx::lease_due() const noexcept {
  const std::uint64_t lease = lease_.load(std::memory_order_acquire);
  const std::uint64_t used = last_used_.load(std::memory_order_acquire);
  return lease < used + step_ / 2 + 1 && lease != UINT64_MAX;
}

std::size_t SecocTx::protect(std::span<const std::uint8_t> data, std::size_t payload, bool fd,
                             std::span<std::uint8_t> out) noexcept {
  const std::size_t data_size = fd ? std::max(data.size(), payload) : data.size();
  if (data_size + spec_.overhead_bytes() > out.size()) return 0;
  std::memcpy(out.data(), data.data(), data.size());
  std::fill(out.begin() + static_cast<std::ptrdiff_t>(data.size()),
            out.begin() + static_cast<std::ptrdiff_t>(data_size), std::uint8_t{0});
  PiLock lock(mutex_);
  // Never a value beyond what a restart would start past.
  if (sender_.freshness() >= lease_.load(std::memory_order_acquire)) return 0;
  const std::size_t size = sender_.protect(std::span<const std::uint8_t>(out.data(), data_size), out);
  if (size != 0) {
    last_used_.store(sender_.freshness(), std::memory_order_release);
    sent_.store(true, std::memory_order_release);
  }
  return size;
}

// ------------------------------------------------------------------------------ receiver

SecocRx::SecocRx(const SecocSpec& spec, bool layout, std::map<std::uint32_t, std::uint64_t> restored)
    : spec_(spec), layout_(layout), restored_(std::move(restored)) {}

SecocReceiver* SecocRx::receiver_of(std::uint32_t source, std::uint32_t data_id) {
  if (const auto it = receivers_.find(source); it != receivers_.end()) return &it->second;
  if (receivers_.size() >= kMaxSources) {
    // Make room from a sender never heard authentic (a forger's identifier), never from one that was.
    const auto unheard =
        std::find_if(receivers_.begin(), receivers_.end(),
                     [&](const auto& entry) COSMIC_REQUIRES(mutex_) { return restored_.count(entry.first) == 0; });
    if (unheard == receivers_.end()) return nullptr;
    receivers_.erase(unheard);
  }
  const auto known = restored_.find(source);
  Result<SecocReceiver> made = SecocReceiver::make(spec_.key.bytes(), parameters_of(spec_, data_id),
                                                   known == restored_.end() ? 0 : known->second);
  if (!made) return nullptr;
  return &receivers_.emplace(source, std::move(made).value()).first->second;
}

SecocCheck SecocRx::verify(canid_t can_id, std::span<const std::uint8_t> data, std::size_t payload, bool fd) noexcept {
  const std::size_t overhead = spec_.overhead_bytes();
  // CAN FD: the PDU is the padded data and the overhead; what follows is the DLC's padding.
  if (fd) {
    const std::size_t pdu = payload + overhead;
    if (data.size() < pdu) return {};
    data = data.first(pdu);
  }
  if (data.size() < overhead) return {};
  try {
    const std::uint32_t source = secoc_source(can_id, layout_);
    PiLock lock(mutex_);
    SecocReceiver* receiver = receiver_of(source, secoc_data_id(spec_, can_id, layout_));
    if (receiver == nullptr) return {};
    const SecocReading reading = receiver->verify(data);
    if (reading.status != SecocStatus::authentic) return SecocCheck{reading.status, {}};
    restored_[source] = reading.freshness;  // heard: kept, and what the store persists
    return SecocCheck{SecocStatus::authentic, data.first(reading.authentic_size)};
  } catch (...) {  // a receiver's first frame allocates; out of memory reads as not authentic
    return {};
  }
}

std::map<std::uint32_t, std::uint64_t> SecocRx::snapshot() const {
  PiLock lock(mutex_);
  return restored_;
}

}  // namespace cosmic::can_detail

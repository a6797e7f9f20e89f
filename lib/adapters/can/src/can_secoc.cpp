// SecOC on the CAN adapter's hops (issue 36, item 4; secoc_streams.hpp): binding a hop's state,
// protecting what the lanes send, verifying what the receive thread reads.
#include "can_adapter_impl.hpp"

namespace cosmic::can_detail {

Result<CanAdapter::SecocStreams> CanAdapter::bind_secoc(const ChannelBinding& b, canid_t identifier) {
  const SecocSpec* spec = b.spec.secoc_on(segment_.name);
  if (spec == nullptr) return SecocStreams{};
  const std::size_t payload = static_cast<std::size_t>(b.spec.payload_on(segment_.name));
  const std::size_t pdu = secoc_pdu_size(*spec, payload, payload, segment_.can.fd);
  if (pdu > capacity_) {
    return Error{"SecOC: payload " + std::to_string(payload) + " B + " + std::to_string(spec->overhead_bytes()) +
                 " B of freshness and MAC do not fit one frame of " + std::to_string(capacity_) + " B"};
  }
  const bool layout = !b.can->native;
  SecocStreams streams;
  if (b.role == HopRole::subscriber) {
    auto tx = secoc_freshness_->sender(b.spec.name, *spec, secoc_data_id(*spec, identifier, layout));
    if (!tx) return Error{"SecOC: " + tx.error().text};
    // Its lease persisted before its first frame (file I/O on the control thread, no lock held).
    if (!secoc_freshness_->persist_now())
      return Error{"SecOC: the freshness counter cannot be persisted: " + secoc_freshness_->last_error()};
    streams.tx = tx.value();
  } else {
    auto rx = secoc_freshness_->receiver(b.spec.name, *spec, layout);
    if (!rx) return Error{"SecOC: " + rx.error().text};
    secoc_freshness_->persist_now();  // starts the thread that keeps the receivers' values
    streams.rx = rx.value();
  }
  secoc_bound_.store(true, std::memory_order_relaxed);
  return streams;
}

std::span<const std::uint8_t> CanAdapter::secure(const CanTxBinding& binding, std::span<const std::uint8_t> payload,
                                                 std::span<std::uint8_t> out) {
  if (!binding.secoc) return payload;
  const std::size_t size = binding.secoc->protect(payload, binding.payload, segment_.can.fd, out);
  if (binding.secoc->lease_due()) secoc_freshness_->poke();
  if (size == 0) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return {};
  }
  return out.first(size);
}

std::optional<std::span<const std::uint8_t>> CanAdapter::authenticate(const CanRxBinding& binding, canid_t can_id,
                                                                      std::span<const std::uint8_t> data,
                                                                      bool fd_frame) {
  if (!binding.secoc) return data;
  const SecocCheck check = binding.secoc->verify(can_id, data, binding.payload, fd_frame);
  if (check.status == SecocStatus::authentic) return check.data;
  if (check.status == SecocStatus::replayed) {
    secoc_replayed_.fetch_add(1, std::memory_order_relaxed);
    problem(binding.id, InboundProblem::replayed);
  } else {
    secoc_unauthenticated_.fetch_add(1, std::memory_order_relaxed);
    problem(binding.id, InboundProblem::unauthenticated);
  }
  return std::nullopt;
}

}  // namespace cosmic::can_detail

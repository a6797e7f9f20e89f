// Lock-free counters behind AdapterStatistics, shared by the adapters. Any thread may update or
// read them.
#pragma once

#include <atomic>
#include <cstdint>

#include "cosmic/segment_adapter.hpp"

namespace cosmic {

struct AdapterCounters {
  std::atomic<std::uint64_t> received{0};
  std::atomic<std::uint64_t> sent{0};
  std::atomic<std::uint64_t> receive_errors{0};
  std::atomic<std::uint64_t> send_errors{0};
  std::atomic<std::uint64_t> overflow_drops{0};

  AdapterStatistics snapshot() const {
    AdapterStatistics out;
    out.received = received.load(std::memory_order_relaxed);
    out.sent = sent.load(std::memory_order_relaxed);
    out.receive_errors = receive_errors.load(std::memory_order_relaxed);
    out.send_errors = send_errors.load(std::memory_order_relaxed);
    out.overflow_drops = overflow_drops.load(std::memory_order_relaxed);
    return out;
  }
};

}  // namespace cosmic

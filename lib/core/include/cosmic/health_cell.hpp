// A segment's health as its adapter last set it, shared by the adapters (part of the adapter kit
// beside AdapterCounters). Any thread may set or read it; a reader always sees a state and detail
// that were set together. Starts down, "not started".
#pragma once

#include <mutex>
#include <string>
#include <utility>

#include "cosmic/segment_adapter.hpp"

namespace cosmic {

class HealthCell {
 public:
  HealthReport get() const {
    std::lock_guard lock(mutex_);
    return report_;
  }
  void set(SegmentHealth state, std::string detail) {
    std::lock_guard lock(mutex_);
    report_.state = state;
    report_.detail = std::move(detail);
  }

 private:
  mutable std::mutex mutex_;
  HealthReport report_{SegmentHealth::down, "not started"};
};

}  // namespace cosmic

// A segment's health as its adapter last set it, shared by the adapters (part of the adapter kit
// beside AdapterCounters). Any thread may set or read it; a reader always sees a state and detail
// that were set together. Starts down, "not started".
#pragma once

#include <string>
#include <utility>

#include "cosmic/mutex.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

class HealthCell {
 public:
  HealthReport get() const {
    LockGuard lock(mutex_);
    return report_;
  }
  void set(SegmentHealth state, std::string detail) {
    LockGuard lock(mutex_);
    report_.state = state;
    report_.detail = std::move(detail);
  }

 private:
  mutable Mutex mutex_;
  HealthReport report_ COSMIC_GUARDED_BY(mutex_){SegmentHealth::down, "not started"};
};

}  // namespace cosmic

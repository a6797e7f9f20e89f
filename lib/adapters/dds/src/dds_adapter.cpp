// The DDS segment adapter on Fast DDS 2.9. The mapping is documented in cosmic/dds_adapter.hpp.
//
// Participants: one per class of channel in use on the segment. The NRT participant is created
// by start() and also carries discovery of the segment's health; the HRT and SRT ones when the
// first channel of their class is configured. Readers and writers of a channel live in its
// class's participant, so a lower class never shares Fast DDS's per-participant send lock,
// shared-memory segment, event thread or receive threads with a higher one (a flood of NRT writes
// would otherwise hold the send lock an HRT write needs, on a thread that runs below every
// real-time thread: a priority inversion the router's own locks cannot fix). Each participant's
// Fast DDS threads run as its class's lane does (see create_participant_as).
//
// Threads and locks:
// - control_mutex_ serialises start/configure/stop (control thread).
// - writers_ is the channel -> writer table as a snapshot (cosmic/snapshot_table.hpp): send()
//   (lane threads, or a receive thread of the class in its lane's place) takes the current table under a
//   priority-inheriting mutex (a pointer copy) and writes with no table lock held; configure()/stop() build the next
//   table outside any lock, swap it in, and delete the DataWriters it no longer holds after the last send on the old
//   table has ended. DDS entities are created before and deleted after the swap, so the router
//   never waits for Fast DDS discovery work.
// - Each writer has its own sample in its topic's format (dds_sample_format: envelope or opaque),
//   reused for every send (its buffer keeps its capacity: no allocation per event in steady
//   state), guarded by the writer's priority-inheriting mutex. What send() logs, it logs after
//   letting go of it.
// - Each reader has its own sample and mutex; Fast DDS calls on_data_available on its
//   receive threads. A reader is retired by clearing its `active` flag under its mutex (after
//   which it never calls the sink) before Fast DDS deletes it; its listener object is kept until
//   stop() so a late callback never touches freed memory.
#include "cosmic/dds_adapter.hpp"

#include <exception>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/binding_plan.hpp"
#include "dds_adapter_impl.hpp"
#include "dds_log_router.hpp"

namespace cosmic {
namespace dds_detail {

Status DdsAdapter::start(EventSink& sink) {
  LockGuard control(control_mutex_);
  if (started()) {
    return Status::failure(prefix() + "already started");
  }
  auto fail = [&](std::string why) {
    set_health(SegmentHealth::down, why);
    log_.log(LogLevel::error, prefix() + why);
    teardown();
    return Status::failure(std::move(why));
  };
  if (segment_.type != SegmentType::dds) {
    return fail("segment is not of type dds");
  }
  if (segment_.dds.domain > kMaxDomainId) {
    return fail("DDS domain " + std::to_string(segment_.dds.domain) + " is out of range 0.." +
                std::to_string(kMaxDomainId));
  }
  if (!log_attached_) {
    attach_fastdds_log(log_);
    log_attached_ = true;
  }
  // The NRT participant's threads run as the receive threads: a SCHED_FIFO receive thread
  // (gateway.realtime.priorities.receive) would write NRT events above the SRT lanes.
  nrt_receivers_send_ = may_do_lane_work(sink.receive_thread_policy(), sink.class_thread_policy(ChannelClass::nrt));
  try {
    if (Status st = open_participant(ChannelClass::nrt, sink.receive_thread_policy(), "rx:" + segment_.name); !st.ok) {
      return fail(st.error);
    }
  } catch (const std::exception& e) {
    return fail(std::string("Fast DDS: ") + e.what());
  } catch (...) {
    return fail("Fast DDS failed to start");
  }
  sink_ = &sink;
  set_health(SegmentHealth::up, "domain " + std::to_string(segment_.dds.domain));
  log_.log(LogLevel::info, prefix() + "participant up in domain " + std::to_string(segment_.dds.domain));
  return Status::success();
}

Status DdsAdapter::configure(std::span<const ChannelBinding> bindings) {
  LockGuard control(control_mutex_);
  if (!started()) return not_started(segment_.name);
  // Every other problem concerns one channel, which is refused in both roles (not carried at
  // all); the rest of the segment is configured (SegmentAdapter::configure).
  BindingPlan plan(bindings);
  auto refuse = [&](const ChannelBinding& b, const std::string& why) { plan.refuse(b, why); };
  // Index the wanted endpoints.
  std::map<ChannelId, const ChannelBinding*> want_writers;
  std::map<ChannelId, const ChannelBinding*> want_readers;
  std::vector<const ChannelSpec*> specs;
  for (const ChannelBinding* b : plan.accepted()) {
    (b->role == HopRole::subscriber ? want_writers : want_readers).emplace(b->id, b);
    specs.push_back(&b->spec);
  }
  for (const auto& [channel, why] : dds_topic_collisions(specs, segment_.name)) {
    for (const ChannelBinding& b : bindings) {
      if (&b.spec == channel) refuse(b, why);
    }
  }

  // Only this (control) thread replaces the writer table.
  const WriterTable& current_writers = writers_.current_for_publisher();
  // 1. Create what is new or changed, before touching anything that runs. A channel whose
  //    endpoint cannot be created is refused; the others go on.
  std::vector<std::unique_ptr<WriterEntry>> new_writers;
  std::vector<std::unique_ptr<ReaderEntry>> new_readers;
  for (const auto& [id, b] : want_writers) {
    if (plan.refused(id)) continue;
    auto it = current_writers.find(id);
    if (it != current_writers.end() && it->second->shape == shape_of(segment_, b->spec) &&
        it->second->home == &home_of(b->spec.cls)) {
      continue;
    }
    if (auto entry = create_endpoint(*b, &DdsAdapter::create_writer)) {
      new_writers.push_back(std::move(entry).value());
    } else {
      refuse(*b, entry.error().text);
    }
  }
  for (const auto& [id, b] : want_readers) {
    if (plan.refused(id)) continue;
    ReaderEntry* existing = nullptr;  // stays valid: only this (control) thread changes readers_
    {
      SharedLock lock(readers_mutex_);
      if (auto it = readers_.find(id); it != readers_.end()) existing = it->second.get();
    }
    if (existing != nullptr) {
      if (existing->shape == shape_of(segment_, b->spec) && existing->home == &home_of(b->spec.cls)) {
        continue;
      }
      // Changed QoS: stop the old reader first so that an event is never delivered twice. If
      // its successor cannot be created, the channel is refused and the old reader goes too.
      deactivate(*existing);
    }
    if (auto entry = create_endpoint(*b, &DdsAdapter::create_reader)) {
      new_readers.push_back(std::move(entry).value());
    } else {
      refuse(*b, entry.error().text);
    }
  }
  // A channel refused in one role is carried in neither.
  std::erase_if(want_writers, [&](const auto& w) { return plan.refused(w.first); });
  std::erase_if(want_readers, [&](const auto& r) { return plan.refused(r.first); });
  std::erase_if(new_writers, [&](std::unique_ptr<WriterEntry>& w) {
    if (!plan.refused(w->id)) return false;
    destroy_writer(*w);
    return true;
  });
  std::erase_if(new_readers, [&](std::unique_ptr<ReaderEntry>& r) {
    if (!plan.refused(r->id)) return false;
    destroy_reader(std::move(r));
    return true;
  });
  Status status = plan.status();
  if (!status.ok) log_.log(LogLevel::error, prefix() + status.error);

  // 2. Swap: the router sees the new writer table at once; the old one comes back once no send
  //    uses it any more.
  WriterTable next_writers;
  for (const auto& [id, w] : current_writers) {
    if (want_writers.count(id) != 0) next_writers.emplace(id, w);
  }
  for (auto& w : new_writers) next_writers[w->id] = std::move(w);
  WriterTable old_writers = SnapshotTable<WriterTable>::retire(writers_.publish(std::move(next_writers)));
  std::vector<std::unique_ptr<ReaderEntry>> old_readers;
  {
    LockGuard lock(readers_mutex_);
    for (auto it = readers_.begin(); it != readers_.end();) {
      if (want_readers.count(it->first) == 0) {
        old_readers.push_back(std::move(it->second));
        it = readers_.erase(it);
      } else {
        ++it;
      }
    }
    for (auto& r : new_readers) {
      auto& slot = readers_[r->id];
      if (slot) old_readers.push_back(std::move(slot));
      slot = std::move(r);
    }
  }

  // 3. Delete what is gone (no send() can still use these writers).
  const WriterTable& kept = writers_.current_for_publisher();
  for (auto& [id, w] : old_writers) {
    if (auto it = kept.find(id); it == kept.end() || it->second != w) destroy_writer(*w);
  }
  for (auto& r : old_readers) destroy_reader(std::move(r));
  return status;
}

template <typename Entry>
Result<std::unique_ptr<Entry>> DdsAdapter::create_endpoint(
    const ChannelBinding& binding, Result<std::unique_ptr<Entry>> (DdsAdapter::*create)(const ChannelBinding&)) {
  try {
    if (Status st = ensure_class_participant(binding.spec.cls); !st.ok) return Error{st.error};
    return (this->*create)(binding);
  } catch (const std::exception& e) {
    return Error{std::string("Fast DDS: ") + e.what()};
  }
}

SendStatus DdsAdapter::send(const OutboundEvent& event) {
  try {
    const auto writers = writers_.read();
    auto it = writers->find(event.channel);
    if (it == writers->end() || event.payload.size() > segment_.max_message_size) {
      counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
      return SendStatus::failed;
    }
    WriterEntry& w = *it->second;
    std::uint16_t first_bytes = 0;
    FillRefusal refusal = FillRefusal::none;
    ReturnCode_t rc = ReturnCode_t::RETCODE_OK;
    {
      PiLock sample(w.sample_mutex);
      refusal = w.format->fill(event, first_bytes);
      if (refusal == FillRefusal::none) rc = w.writer->write(w.format->sample(), dds::HANDLE_NIL);
    }
    if (refusal != FillRefusal::none) {
      counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
      if (!w.refusal_logged.exchange(true, std::memory_order_relaxed))
        warn_refused(w, refusal, first_bytes, event.payload.size());
      return SendStatus::failed;
    }
    if (rc == ReturnCode_t::RETCODE_OK) {
      counters_.sent.fetch_add(1, std::memory_order_relaxed);
      return SendStatus::sent;
    }
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    if (rc == ReturnCode_t::RETCODE_TIMEOUT || rc == ReturnCode_t::RETCODE_OUT_OF_RESOURCES) {
      return SendStatus::queue_full;
    }
    return SendStatus::failed;
  } catch (...) {
    counters_.send_errors.fetch_add(1, std::memory_order_relaxed);
    return SendStatus::failed;
  }
}

std::size_t DdsAdapter::matched_endpoints(ChannelId channel, HopRole role) const {
  try {
    if (role == HopRole::subscriber) {
      const auto writers = writers_.read();
      auto it = writers->find(channel);
      dds::PublicationMatchedStatus status;
      if (it == writers->end() ||
          it->second->writer->get_publication_matched_status(status) != ReturnCode_t::RETCODE_OK) {
        return 0;
      }
      return static_cast<std::size_t>(std::max(0, status.current_count));
    }
    SharedLock lock(readers_mutex_);
    auto it = readers_.find(channel);
    dds::SubscriptionMatchedStatus status;
    if (it == readers_.end() ||
        it->second->reader->get_subscription_matched_status(status) != ReturnCode_t::RETCODE_OK) {
      return 0;
    }
    return static_cast<std::size_t>(std::max(0, status.current_count));
  } catch (...) {
    return 0;
  }
}

std::optional<std::uint64_t> DdsAdapter::incompatible_peers(ChannelId channel) const {
  std::uint64_t total = 0;
  {
    const auto writers = writers_.read();
    if (auto it = writers->find(channel); it != writers->end()) {
      total += it->second->incompatible.load(std::memory_order_relaxed);
    }
  }
  SharedLock lock(readers_mutex_);
  if (auto it = readers_.find(channel); it != readers_.end()) {
    total += it->second->incompatible.load(std::memory_order_relaxed);
  }
  return total;
}

void DdsAdapter::teardown() {
  // Readers first: after deactivation no callback reaches the sink any more.
  {
    SharedLock lock(readers_mutex_);
    for (auto& [id, r] : readers_) deactivate(*r);
  }
  WriterTable writers = SnapshotTable<WriterTable>::retire(writers_.publish({}));
  std::unordered_map<ChannelId, std::unique_ptr<ReaderEntry>> readers;
  {
    LockGuard lock(readers_mutex_);
    readers.swap(readers_);
  }
  try {
    for (auto& [id, w] : writers) destroy_writer(*w);
    for (auto& [id, r] : readers) destroy_reader(std::move(r));
    for (ClassParticipant& home : classes_) close_participant(home);
  } catch (...) {
    warn("Fast DDS threw while stopping");
  }
  classes_ = {};
  retired_readers_.clear();
  sink_ = nullptr;
  if (log_attached_) {
    detach_fastdds_log(log_);
    log_attached_ = false;
  }
}

void DdsAdapter::stop() {
  LockGuard control(control_mutex_);
  if (!started()) {
    return;
  }
  teardown();
  set_health(SegmentHealth::down, "stopped");
  log_.log(LogLevel::info, prefix() + "stopped");
}

}  // namespace dds_detail

std::unique_ptr<DdsSegmentAdapter> make_dds_segment_adapter(const SegmentSpec& segment, const GatewayIdentity& self,
                                                            Logger& log) {
  return std::make_unique<dds_detail::DdsAdapter>(segment, self, log);
}

std::unique_ptr<SegmentAdapter> make_dds_adapter(const SegmentSpec& segment, const GatewayIdentity& self, Logger& log) {
  return make_dds_segment_adapter(segment, self, log);
}

}  // namespace cosmic

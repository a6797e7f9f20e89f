// One egress lane: the events of one class waiting for one subscriber segment, and the thread
// that hands them to that segment's adapter. Each (segment, class) has its own lane and thread,
// so a slow or blocking transport delays only its own lanes, and a lower class never holds up a
// higher one: the higher class's thread runs at a higher priority (gateway.realtime), and it
// never waits for a lower class's queue. An ingress thread of the lane's class may send in the
// thread's place while the lane is idle and light (below); a slow send hands the lane back.
//
// Threads: push() and push_or_send() from ingress (adapter) threads; the lane thread pops and
// sends; activate(), deactivate() and size() from the control thread; run_once() instead of the
// lane thread when the router runs without threads (tests).
//
// One sender at a time: the lane's thread, or an ingress thread that found the lane idle and sent
// its event itself (push_or_send). Whoever sends holds `sending_` (set under the mutex, never a
// lock across the send), so events leave in the order they were taken and the adapter, the
// scratch buffers and the counters see one thread of this lane at a time.
//
// An ingress thread that sends for itself also receives for itself: at a rate where sending takes
// a large part of the time, the two are better done by two threads on two CPUs (at saturation
// one thread doing both delivered 22k-56k events/s, two 55k-59k: scripts/bench relay-rates). So
// the lane measures how much of the time it spends sending, whoever sends, and each ingress
// thread how much it spends in its own sends (send_duty.hpp); while either is loaded, every event
// goes to the lane's thread. An ingress thread that sends waits for the transport's send()
// (bounded by its contract, cosmic/segment_adapter.hpp); the next events for it wait in the
// network or the transport meanwhile, where residence does not count them (it counts from the
// adapter's arrival time): one send as long as the residence bound hands the lane back to its
// thread.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <thread>
#include <vector>

#include "channel_state.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/thread_annotations.hpp"
#include "cosmic/thread_policy.hpp"
#include "payload_pool.hpp"
#include "send_duty.hpp"
#include "wake_signal.hpp"

namespace cosmic {

struct LaneItem {
  std::shared_ptr<ChannelState> channel;
  PayloadBuffer* payload = nullptr;
  EventHeader header;     // as it leaves (origin, sequence, hop count set), age as it arrived
  Nanos received{0};      // kernel arrival, steady clock
  std::uint32_t hop = 0;  // index of this lane's segment in the channel's route.subscribers
  std::uint64_t generation = 0;
};

// What every lane of one router shares.
struct LaneContext {
  SteadyClock clock;
  std::atomic<std::int64_t> residence_bound_ns;  // gateway.residence_bound; a reload may change it
  PayloadPool& pool;
  std::atomic<std::uint64_t>& progress;  // events handled (sent or dropped): the watchdog's measure
  std::function<void(const std::vector<std::string>&)> report_thread_problems;
};

class EgressLane {
 public:
  EgressLane(LaneContext& context, std::size_t segment, std::size_t byte_budget);
  ~EgressLane();
  EgressLane(const EgressLane&) = delete;
  EgressLane& operator=(const EgressLane&) = delete;

  // False when the lane is full (by count or bytes) or not active: the caller counts queue_full.
  bool push(LaneItem&& item) noexcept COSMIC_EXCLUDES(mutex_);
  // push(), except that when nothing is queued or being sent and the lane has a thread, the
  // caller sends the event itself, now, and the lane's thread is not woken (one wake-up and one
  // context switch fewer per event: the DDS relay at 1-20 kHz, issue 39). Only for a caller that
  // serves this lane's class alone (InboundEvent::receiver_class): it then waits for one send of
  // its own class, bounded by the adapter's send() contract. What others queued meanwhile is
  // handed to the lane's thread when the send returns.
  bool push_or_send(LaneItem&& item) noexcept COSMIC_EXCLUDES(mutex_);
  // Starts sending to `adapter`; with `threaded`, on a new thread run under `policy`. The lane
  // holds up to `depth` events (at least 1) from now on.
  void activate(SegmentAdapter* adapter, const ThreadPolicy& policy, bool threaded, std::size_t depth)
      COSMIC_EXCLUDES(mutex_);
  // Stops sending: joins the thread (after its send in progress) and drops what is queued.
  void deactivate() COSMIC_EXCLUDES(mutex_);
  // Without a thread: handles up to `budget` queued events now; returns how many.
  std::size_t run_once(std::size_t budget) COSMIC_EXCLUDES(mutex_);
  std::size_t size() const COSMIC_EXCLUDES(mutex_);

 private:
  // At most this many queued events go to the adapter at once (SegmentAdapter::send_batch).
  static constexpr std::size_t kSendBatch = 16;
  bool offer(LaneItem&& item, bool may_send_here) noexcept COSMIC_EXCLUDES(mutex_);
  // Counts a send from `started` to `ended` into the lane's send duty (by the sender holding `sending_`).
  void note_send(Nanos started, Nanos ended) noexcept;
  // A send this long loads its sender at once: the residence bound (gateway.residence_bound).
  Nanos slow_send() const noexcept;
  // The end of an ingress thread's own send: the lane's thread takes over what queued meanwhile.
  void end_direct_send() noexcept COSMIC_EXCLUDES(mutex_);
  // Until no ingress thread is sending (deactivate(), after forbidding new ones).
  void wait_for_direct_send() noexcept COSMIC_EXCLUDES(mutex_);
  // Moves up to `out.size()` queued events out in one lock; returns how many. The lane's thread
  // holds `sending_` while this returns more than none; none while an ingress thread sends.
  std::size_t pop_batch(std::span<LaneItem> out) noexcept COSMIC_EXCLUDES(mutex_);
  void forward(LaneItem& item) noexcept;
  // forward() for several events, handed to the adapter in one send_batch().
  void forward_batch(std::span<LaneItem> items) noexcept;
  // How many events to take at once: kSendBatch for an adapter that batches sends, else 1.
  std::size_t batch_limit() const noexcept;
  // Forwards what pop_batch() took (one event alone, several as a batch); then none is in hand.
  void hand_over(std::span<LaneItem> items) noexcept;
  // Before a send: the event as it leaves, or nullopt (the item discarded, its drop counted)
  // when it is not to be sent (channel gone, lane reset, expired).
  // A typed channel's event is converted into its hop's representation in scratch_[slot].
  std::optional<OutboundEvent> still_wanted(LaneItem& item, std::size_t slot) noexcept;
  // The bytes the hop carries: the compact event in the hop's representation (in scratch_[slot]),
  // or the payload as it is for an untyped channel; nullopt when the conversion refused it (the
  // drop counted, the item discarded).
  std::optional<std::span<const std::uint8_t>> hop_bytes(LaneItem& item, std::size_t slot) noexcept;
  // After a send: counters and residence by the adapter's answer; the item is released.
  void account(LaneItem& item, SendStatus status) noexcept;
  void discard(LaneItem& item) noexcept;
  void worker(const ThreadPolicy& policy);

  LaneContext& context_;
  const std::size_t segment_;
  const std::size_t byte_budget_;

  mutable PiMutex mutex_;                                 // the ring; held for moves only, never across send()
  std::vector<LaneItem> ring_ COSMIC_GUARDED_BY(mutex_);  // its size is the depth; sized at activation
  std::size_t head_ COSMIC_GUARDED_BY(mutex_) = 0;
  std::size_t count_ COSMIC_GUARDED_BY(mutex_) = 0;
  std::size_t bytes_ COSMIC_GUARDED_BY(mutex_) = 0;
  bool active_ COSMIC_GUARDED_BY(mutex_) = false;
  bool sending_ COSMIC_GUARDED_BY(mutex_) = false;         // someone is sending (see above)
  bool direct_sending_ COSMIC_GUARDED_BY(mutex_) = false;  // ... and it is an ingress thread
  bool direct_allowed_ COSMIC_GUARDED_BY(mutex_) = false;  // a lane thread runs and is not stopping
  // Taken out by pop_batch() and not yet handed to the adapter and accounted: size() counts
  // them, so a lane blocked inside a send shows its events as queued (the watchdog's stall).
  std::atomic<std::size_t> in_hand_{0};
  std::uint64_t generation_ COSMIC_GUARDED_BY(mutex_) = 0;

  // Where this lane's sender writes typed events in their hop's form, one buffer per event of a
  // batch (the adapter reads them all in one send_batch); each grows to the largest message it
  // has held and is then reused. Only the sender holding `sending_` (or run_once's caller)
  // touches them.
  std::array<std::vector<std::uint8_t>, kSendBatch> scratch_;

  // Only the sender holding `sending_` touches it (handed from sender to sender under mutex_);
  // `loaded_` is its verdict for every ingress thread to read.
  SendDuty duty_;
  std::atomic<bool> loaded_{false};

  std::atomic<SegmentAdapter*> adapter_{nullptr};
  std::atomic<std::uint64_t> current_generation_{0};
  // Notified by a push (but for one behind an ingress thread's send, which notifies when it ends:
  // the lane's thread and deactivate() waiting for that send) and by deactivate.
  WakeSignal wake_;
  std::atomic<bool> running_{false};
  std::thread thread_;
};

}  // namespace cosmic

// An in-memory segment for tests of the router and the gateway runtime: events are injected by
// the test as if they arrived from the network, and what the gateway sends is recorded.
// Thread-safe: inject() may run on any thread (it stands for the adapter's receive thread).
#pragma once

#include <chrono>
#include <condition_variable>
#include <map>
#include <string>
#include <vector>

#include "cosmic/mutex.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic {

struct RecordedEvent {
  std::string channel;
  EventHeader header;
  std::vector<std::uint8_t> payload;
};

class MemoryAdapter final : public SegmentAdapter {
 public:
  explicit MemoryAdapter(std::string segment_name) : segment_name_(std::move(segment_name)) {}

  Status start(EventSink& sink) override;
  Status configure(std::span<const ChannelBinding> bindings) override;
  SendStatus send(const OutboundEvent& event) override;
  // Records how many events each hand-over held (batches()), then sends them one by one.
  void send_batch(std::span<const OutboundEvent> events, std::span<SendStatus> results) override;
  bool batches_sends() const override { return true; }  // so router tests see the lanes' batches
  HealthReport health() const override;
  AdapterStatistics statistics() const override;
  // nullopt (no discovery, as LCM and CAN) unless simulate_discovery() was called.
  std::optional<std::size_t> matched_peers(ChannelId channel) const override;
  void stop() override;

  // Delivers an event on `channel` as if received from the network. False when the channel is
  // not bound here as publisher (the event is then reported to the router as unknown).
  bool inject(const std::string& channel, std::vector<std::uint8_t> payload, EventHeader header = {});
  // Delivers bytes that fail to decode.
  void inject_garbage(const std::string& channel);
  std::vector<RecordedEvent> sent() const;
  // The size of each send_batch() hand-over so far (a single send() is not one).
  std::vector<std::size_t> batches() const;
  // Waits until at least `count` events were sent, or the deadline passes; returns the count.
  std::size_t wait_sent(std::size_t count, std::chrono::milliseconds timeout) const;
  void set_health(SegmentHealth state, std::string detail);
  // Makes send() answer queue_full (a congested network).
  void set_congested(bool congested);
  // While held, send() blocks (a stuck network driver): the router stalls.
  void hold_sends(bool hold);
  std::vector<ChannelBinding> bindings() const;
  // Makes configure() refuse channel `name` with `reason` (named in Status::refused, as a
  // transport that cannot carry that channel) and take the other bindings; "" accepts it again.
  void refuse_channel(const std::string& name, std::string reason);
  // From now on the segment has discovery, as DDS: matched_peers() of a channel carried here is
  // what set_matched() said of it (0 until then), nullopt for a channel not carried.
  void simulate_discovery();
  void set_matched(const std::string& channel, std::size_t peers);
  // Makes configure() fail as a whole with `reason`, naming no channel and keeping the bindings it
  // had (as a transport that rolls back); "" lets configure() succeed again.
  void fail_configure(std::string reason);

 private:
  const ChannelBinding* find(const std::string& name) const COSMIC_REQUIRES(mutex_);
  std::string segment_name_;
  mutable Mutex mutex_;
  mutable std::condition_variable sent_changed_;
  EventSink* sink_ COSMIC_GUARDED_BY(mutex_) = nullptr;
  std::vector<ChannelBinding> bindings_ COSMIC_GUARDED_BY(mutex_);
  std::vector<RecordedEvent> sent_ COSMIC_GUARDED_BY(mutex_);
  std::vector<std::size_t> batches_ COSMIC_GUARDED_BY(mutex_);
  HealthReport health_ COSMIC_GUARDED_BY(mutex_);
  AdapterStatistics stats_ COSMIC_GUARDED_BY(mutex_);
  std::map<std::string, std::string> refuse_ COSMIC_GUARDED_BY(mutex_);  // channel name -> reason
  std::string fail_configure_ COSMIC_GUARDED_BY(mutex_);
  bool discovery_ COSMIC_GUARDED_BY(mutex_) = false;
  std::map<std::string, std::size_t> matched_ COSMIC_GUARDED_BY(mutex_);  // channel name -> peers
  bool congested_ COSMIC_GUARDED_BY(mutex_) = false;
  bool held_ COSMIC_GUARDED_BY(mutex_) = false;
  mutable std::condition_variable released_;
};

}  // namespace cosmic

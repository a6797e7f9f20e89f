// The LCM adapter's transmit side: one connected socket per channel class, each with its own LCM
// sequence number, envelope headers and batch, under its own mutex held across sendmsg/sendmmsg,
// so an NRT send stalled in the kernel never holds what an HRT send needs (issue 20, item 2). Only
// the class's own lane and the control thread (open, close, joining) ever take a class's mutex; it
// inherits priority, so a control thread holding it runs at the lane's priority until it lets go.
// What a send logs is written after its mutex is let go.
//
// Threads: open()/close() on the control thread (close() waits for sends in flight); send() and
// send_batch() on the egress lanes; is_own() on the receive thread. A socket whose source
// address went away (the interface renumbered: EADDRNOTAVAIL, EINVAL, ENETUNREACH, ENODEV) is
// reopened by the lane that meets the failure, at most once a second per class, and the receive
// socket's filter follows the new source. While a class cannot send, the segment is degraded.
// On a segment with `auth` each class's socket is a sender of its own to the receivers' replay
// windows: its signer (cosmic/lcm_auth.hpp), a random sender number drawn at open(), appends
// the authentication trailer to every message under the class's mutex.
#pragma once

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "cosmic/adapter_counters.hpp"
#include "cosmic/health_cell.hpp"
#include "cosmic/lcm_auth.hpp"
#include "cosmic/lcm_url.hpp"
#include "cosmic/lcm_wire.hpp"
#include "cosmic/log.hpp"
#include "cosmic/log_prefix.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/segment_adapter.hpp"
#include "cosmic/thread_annotations.hpp"
#include "lcm_channel.hpp"
#include "lcm_sockets.hpp"

namespace cosmic::lcm_detail {

class LcmTransmitter {
 public:
  // `receive_failing` is the receive side's own trouble: a transmit recovery does not clear it.
  // `auth`: the segment's authentication (null: none); it outlives the transmitter.
  LcmTransmitter(const std::string& segment_name, const LcmAuthSpec* auth, Logger& log, AdapterCounters& counters,
                 HealthCell& health, const std::atomic<bool>& receive_failing);

  // Opens the three sockets, or says why one failed (none is left open then).
  Result<void> open(const LcmUrl& url);
  // The receive socket whose filter follows our sources (-1: none), cutting or dropping what
  // they send (`mode`); attaches it now, or says why the filter cannot be attached.
  Result<void> follow_with_filter(int receive_fd, LcmOwnDatagrams mode);
  // Datagrams our transmit sockets handed the kernel since open() while the receive socket was a
  // member of the group and its filter dropped our own: each is one drop of that socket's (the
  // segment's own_datagrams_dropped; its overflow count leaves them out). Counted before each
  // send, so never fewer than the kernel dropped (a failed send's stay counted). Any thread.
  std::uint64_t own_drops() const { return own_drops_.load(std::memory_order_acquire); }
  // Whether what is sent from now on loops back to the receive socket (it is a member of the
  // group; open() starts counting). The control thread calls it before joining, and it returns
  // once no send that missed it is still in flight, and after leaving, so the count never falls
  // short of what the kernel dropped.
  void count_looped_back(bool counting);
  void close();

  // True when `from` is one of our transmit sockets (looped back to us).
  bool is_own(Endpoint from) const;

  // One event of `channel` (bound for sending).
  SendStatus send(const Channel& channel, const OutboundEvent& event);
  // events[i] of channels[i] (each bound for sending, or null: refused as failed), in order: a run
  // of one class that fits single datagrams leaves in one sendmmsg.
  void send_batch(std::span<const OutboundEvent> events, std::span<const Channel* const> channels,
                  std::span<SendStatus> results);

  SendStatus unbound();

 private:
  // The lines one send has to log, written once its sender's mutex is free (empty: no allocation).
  using SendLog = std::vector<std::pair<LogLevel, std::string>>;
  struct ClassSender {
    PiMutex mutex;
    int fd COSMIC_GUARDED_BY(mutex) = -1;
    std::uint32_t sequence COSMIC_GUARDED_BY(mutex) = 0;  // LCM's per-sender message number
    // Envelope headers of the messages in flight, one per batch slot.
    std::array<std::array<std::uint8_t, kLcmEnvelopeHeaderSize>, SendBatch::kCapacity> envelope_headers
        COSMIC_GUARDED_BY(mutex){};
    SendBatch batch COSMIC_GUARDED_BY(mutex);
    // On a segment with auth: the signer, and the trailers of the messages in flight.
    std::optional<LcmAuthSigner> signer COSMIC_GUARDED_BY(mutex);
    std::array<LcmAuthTrailer, SendBatch::kCapacity> trailers COSMIC_GUARDED_BY(mutex){};
    std::chrono::steady_clock::time_point last_reopen COSMIC_GUARDED_BY(mutex){};
    std::atomic<bool> failing{false};  // a run of failures is logged once
  };

  using WireParts = std::array<std::span<const std::uint8_t>, SendBatch::kMaxParts>;
  // The parts of `event`'s message as it goes on the wire, batch slot `slot`'s buffers holding its
  // header and trailer: their count, or 0 with why not in `refusal`.
  std::size_t wire_parts(ClassSender& sender, std::size_t slot, const Channel& channel, const OutboundEvent& event,
                         WireParts& wire, const char*& refusal) COSMIC_REQUIRES(sender.mutex);
  SendStatus send_one(ClassSender& sender, const Channel& channel, const OutboundEvent& event, SendLog& later)
      COSMIC_REQUIRES(sender.mutex);
  bool stage(ClassSender& sender, const Channel& channel, const OutboundEvent& event) COSMIC_REQUIRES(sender.mutex);
  SendStatus sent(ClassSender& sender);
  SendStatus failed(ClassSender& sender, const Channel& channel, SendFailure why, SendLog& later)
      COSMIC_REQUIRES(sender.mutex);
  void reopen(ClassSender& sender, std::size_t index, SendLog& later) COSMIC_REQUIRES(sender.mutex);
  void write(SendLog& later) noexcept;
  Result<void> attach_filter();
  // Before `datagrams` leave: counted while they loop back to a filter that drops them.
  void note_sending(std::size_t datagrams);

  const std::string prefix_;  // "LCM segment NAME: " (cosmic/log_prefix.hpp)
  const LcmAuthSpec* const auth_;
  Logger& log_;
  AdapterCounters& counters_;
  HealthCell& health_;
  const std::atomic<bool>& receive_failing_;

  std::optional<LcmUrl> url_;           // set by open() before any send, cleared by close() after them
  std::array<ClassSender, 3> senders_;  // indexed by ChannelClass
  // Each sender's source (Endpoint::key()), 0 when closed: written under its sender's mutex,
  // read by the receive thread.
  std::array<std::atomic<std::uint64_t>, 3> own_keys_{};
  Mutex filter_mutex_;  // one filter (re)attachment at a time
  int receive_fd_ COSMIC_GUARDED_BY(filter_mutex_) = -1;
  LcmOwnDatagrams filter_mode_ COSMIC_GUARDED_BY(filter_mutex_) = LcmOwnDatagrams::drop;
  std::atomic<std::uint64_t> own_drops_{0};
  std::atomic<bool> counting_looped_back_{true};
  std::atomic<bool> filter_drops_{false};  // the attached filter drops our own (attach_filter)
};

}  // namespace cosmic::lcm_detail

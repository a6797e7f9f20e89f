// SecOC on a CAN segment's frames (issue 36, item 4; docs/security.md, docs/can-wire-format.md
// "SecOC"): the sending and receiving state of one channel's hop, around the codec in
// cosmic/secoc.hpp. Internal to the CAN adapter.
//
// The secured PDU of a frame is data || truncated freshness || truncated MAC (cosmic/secoc.hpp).
// On classic CAN the frame's length is the PDU's; CAN FD rounds lengths up to its DLC steps, so
// there the data is padded with zeros to the hop's payload first: the receiver then knows where the
// data ends (its events arrive as `payload` bytes).
//
// Freshness across restarts: a sender may use freshness values only up to what its
// SecocFreshness store (secoc_freshness.hpp) has persisted; the store persists ahead in steps of
// secoc_lease_step() (half an epoch of the truncated value, at most 2^16), so a restarted sender
// starts past every value it used before, by less than a receiver can follow. A sender whose
// persisted lease runs out refuses to protect (the frame is not sent, and counted).
//
// Threads: SecocTx::protect() is called by the egress lanes (its own lock, no I/O); SecocRx::verify()
// by the adapter's receive thread; the store reads both (persisted(), snapshot()) from its thread.
#pragma once

#include <linux/can.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "cosmic/model.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/result.hpp"
#include "cosmic/secoc.hpp"
#include "cosmic/thread_annotations.hpp"

namespace cosmic::can_detail {

// The data ID of a frame's MAC input when the hop's `secoc` names none: the native identifier,
// or in this project's layout the TxNode and etag (the identifier's low 21 bits; the priority is
// the channel's and says nothing of the sender).
// `layout`: the frame is in this project's layout (else a native identifier). `can_id` with its flags.
std::uint32_t secoc_data_id(const SecocSpec& spec, canid_t can_id, bool layout);

// How far a sender's freshness may run ahead of what is persisted: half an epoch of the
// truncated value, at most 2^16 (see above).
std::uint64_t secoc_lease_step(std::uint32_t freshness_bits);
// The first lease after a start, before the sender sent anything: a sixteenth of the step (8 with
// 8-bit freshness), so starts that send nothing (a crash loop) move the counter little.
std::uint64_t secoc_start_step(std::uint32_t freshness_bits);

// Who sent a frame, as a receiver keeps its freshness apart: the native identifier, or in this
// project's layout the TxNode and etag (whatever data ID the MAC uses).
std::uint32_t secoc_source(canid_t can_id, bool layout);

// Secured PDU size of `data_size` bytes of data on a hop whose events are at most `payload`
// bytes: on CAN FD the data is padded to `payload` (see above).
std::size_t secoc_pdu_size(const SecocSpec& spec, std::size_t data_size, std::size_t payload, bool fd);

// One channel's sending state on the segment (the gateway sends it as one identifier).
class SecocTx {
 public:
  // Keyed with spec.key, its last used freshness value `last_used`, allowed to use values up to
  // `persisted` (the store's lease); else why not (the parameters).
  static Result<std::shared_ptr<SecocTx>> make(const SecocSpec& spec, std::uint32_t data_id, std::uint64_t last_used,
                                               std::uint64_t persisted);

  // The secured PDU of `data` into `out` (see secoc_pdu_size); 0 when it cannot be protected: the
  // lease is used up, the counter is at its end, or `out` is too small. Any lane.
  std::size_t protect(std::span<const std::uint8_t> data, std::size_t payload, bool fd,
                      std::span<std::uint8_t> out) noexcept;

  std::uint32_t data_id() const noexcept { return data_id_; }
  const SecocSpec& spec() const noexcept { return spec_; }
  // The last used freshness value. Any thread.
  std::uint64_t last_used() const noexcept { return last_used_.load(std::memory_order_acquire); }
  // Whether the store should persist a new lease now (used past half of it). Any thread.
  bool lease_due() const noexcept;
  // Whether a frame was protected since this state was made (the next lease is a whole step).
  bool sent() const noexcept { return sent_.load(std::memory_order_acquire); }
  // The store persisted `value`: the sender may use values up to it (never lowered). Store thread.
  void persisted(std::uint64_t value) noexcept;
  std::uint64_t lease() const noexcept { return lease_.load(std::memory_order_acquire); }
  // No further frame: the lease is cut back to the last used value, which is returned (a clean
  // stop persists it; a state that replaces this one continues from it). Any thread.
  std::uint64_t retire() noexcept;

 private:
  SecocTx(const SecocSpec& spec, std::uint32_t data_id, SecocSender sender, std::uint64_t persisted);

  const SecocSpec spec_;
  const std::uint32_t data_id_;
  const std::uint64_t step_;
  PiMutex mutex_;
  SecocSender sender_ COSMIC_GUARDED_BY(mutex_);
  std::atomic<std::uint64_t> last_used_;
  std::atomic<std::uint64_t> lease_;
  std::atomic<bool> sent_{false};
};

// What the receive thread does with one frame of a SecOC hop.
struct SecocCheck {
  SecocStatus status = SecocStatus::unauthenticated;
  std::span<const std::uint8_t> data;  // the authentic data (status authentic)
};

// One channel's receiving state on the segment: a receiver per sender (secoc_source), made when its
// first frame arrives (or restored by the store), at most kMaxSources; one never heard authentic
// makes room for another.
class SecocRx {
 public:
  static constexpr std::size_t kMaxSources = 128;  // a TxNode has 7 bits

  // `restored`: the last accepted freshness value per sender, as the store kept it.
  SecocRx(const SecocSpec& spec, bool layout, std::map<std::uint32_t, std::uint64_t> restored);

  // Checks the frame `data` (cut to the frame's length) of identifier `can_id` on a hop whose
  // events are at most `payload` bytes. Receive thread.
  SecocCheck verify(canid_t can_id, std::span<const std::uint8_t> data, std::size_t payload, bool fd) noexcept;

  // The last accepted freshness value per sender. Store thread.
  std::map<std::uint32_t, std::uint64_t> snapshot() const;
  const SecocSpec& spec() const noexcept { return spec_; }
  bool layout() const noexcept { return layout_; }

 private:
  SecocReceiver* receiver_of(std::uint32_t source, std::uint32_t data_id) COSMIC_REQUIRES(mutex_);

  const SecocSpec spec_;
  const bool layout_;      // the channel's frames are in this project's layout (else a native identifier)
  mutable PiMutex mutex_;  // the receive thread against the store's snapshot; never held across I/O
  std::map<std::uint32_t, std::uint64_t> restored_ COSMIC_GUARDED_BY(mutex_);
  std::map<std::uint32_t, SecocReceiver> receivers_ COSMIC_GUARDED_BY(mutex_);
};

}  // namespace cosmic::can_detail

// The wire formats of CAN bindings, one per binding (DESIGN.md section 7; docs/can-wire-format.md),
// after the DDS adapter's sample formats and the LCM adapter's message formats:
//   cosmic   this project's identifier layout: an event that fits one frame is the frame's data,
//            a channel whose events may not fit sends every event as numbered fragments (section 6);
//   famouso  FAMOUSO's layout: events of up to 8 bytes are plain frames, longer ones AFP fragments
//            under the identifier's fragment flag (section 8);
//   native   a device's own identifier, standard or extended: one frame is one event, no etag.
// configure() gives each binding the format its plan names (CanHopPlan::native and ::profile); the
// transport (can_send.cpp, can_receive.cpp) writes and reads frames, a format turns an event into
// its frames and frames into the event. None of them carries an event's origin, sequence or hop
// count (a TxNode names a node, not an event). Internal to the CAN adapter; fuzzed by
// fuzz/can_{cosmic,famouso,native}_frames_fuzzer.cpp.
//
// Threads: the encoding side is const, shared by the egress lanes without a lock; decode(),
// expire() and clear() keep the reassembly state of the fragmenting formats and are called by the
// adapter's receive thread only (stop() calls clear() once that thread has ended).
#pragma once

#include <linux/can.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "cosmic/can_fragment.hpp"
#include "cosmic/event.hpp"
#include "cosmic/model.hpp"
#include "cosmic/result.hpp"
#include "famouso_afp.hpp"

namespace cosmic::can_detail {

class CanFrameFormat;
class SecocTx;
class SecocRx;

// Frames one submit hands the kernel at most (one sendmmsg).
inline constexpr std::size_t kFramesPerSubmit = 16;

// A channel the gateway sends on the bus (bound as subscriber), as configure() planned it.
struct CanTxBinding {
  ChannelId id = kNoChannel;
  const CanFrameFormat* format = nullptr;  // the adapter's; lives as long as the adapter
  std::uint32_t can_id = 0;                // a single frame's: 29 bits in the layout, or the native identifier
  std::uint32_t fragment_id = 0;           // fragments' (FAMOUSO: with the fragment flag)
  bool extended = true;                    // native: an extended (29-bit) or a standard identifier
  std::uint16_t etag = 0;                  // none for native
  std::size_t payload = 0;                 // the channel's largest event
  bool fragmented = false;                 // cosmic: every event goes as numbered fragments
  std::shared_ptr<SecocTx> secoc{};        // the hop's SecOC (secoc_streams.hpp): frames are protected
};

// A channel the gateway receives from the bus (bound as publisher).
struct CanRxBinding {
  ChannelId id = kNoChannel;
  CanFrameFormat* format = nullptr;  // the adapter's; lives as long as the adapter
  std::uint64_t subject = 0;
  std::size_t payload = 0;
  bool fragmented = false;
  std::shared_ptr<SecocRx> secoc{};  // the hop's SecOC (secoc_streams.hpp): frames are verified first
};

// Takes an event's frames in order, at most kFramesPerSubmit at a time (the transport's submit).
class CanFrameBatchSink {
 public:
  virtual ~CanFrameBatchSink() = default;
  // False when the batch was refused: the event is lost and encode() stops.
  virtual bool take(std::span<const canfd_frame> frames) = 0;
};

// A sink that calls `take` (any callable taking the span and returning bool); no allocation.
template <typename Take>
class CanFrameBatchTo final : public CanFrameBatchSink {
 public:
  explicit CanFrameBatchTo(Take take) : take_(std::move(take)) {}
  bool take(std::span<const canfd_frame> frames) override { return take_(frames); }

 private:
  Take take_;
};

// What one received frame did.
struct CanDecoded {
  std::optional<std::span<const std::uint8_t>> event;  // a whole event, valid until the next decode()
  bool lost = false;                                   // an event of this binding was lost on this frame
  std::optional<std::uint32_t> displaced;              // the source of another partial event given up
};

// The bus a format writes for: its frames' capacity and CAN FD's padding and bit-rate switch.
struct CanBus {
  std::uint32_t capacity = 8;  // data bytes of one frame
  bool fd = false;
  bool brs = false;
};

// Reassembly bounds: partial events at once, idle time before one is dropped.
struct CanReassemblyBounds {
  std::size_t max_partials = 32;
  Nanos timeout{1'000'000'000};
};

class CanFrameFormat {
 public:
  virtual ~CanFrameFormat() = default;
  virtual const char* name() const noexcept = 0;
  // What the format carries of an event's identity (the router asks it: InboundEvent::identity).
  FormatIdentity identity() const noexcept { return FormatIdentity{false, false, false, false}; }

  // configure(): whether a channel whose events are at most `payload` bytes can be carried (the
  // error says why not).
  virtual Result<void> check_payload(std::uint64_t payload) const = 0;
  // Whether the binding's events go out as fragments (the planned fragment count then sizes the backlog).
  virtual bool fragments(std::uint64_t payload) const = 0;
  // Frames one event of `bytes` takes; 1 means single_frame() writes it.
  virtual std::size_t frame_count(const CanTxBinding& binding, std::size_t bytes) const = 0;
  // Whether each event takes the binding's next sequence number (the sender's, under its lock).
  virtual bool numbered(const CanTxBinding& binding) const = 0;
  // The frame of an event that frame_count() counts as one.
  virtual canfd_frame single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const = 0;
  // Every frame of the event, in order, to `sink`; false at the first batch it refuses.
  virtual bool encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t sequence,
                      CanFrameBatchSink& sink) const = 0;

  // Receive thread only. One data frame of the binding, `data` cut to the frame's length.
  virtual CanDecoded decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data,
                            bool fd_frame, Nanos now) = 0;
  // Drops partial events idle for too long, calling dropped(source) for each.
  virtual void expire(Nanos, const std::function<void(std::uint32_t)>&) {}
  // When the earliest partial event times out (nullopt: none pending).
  virtual std::optional<Nanos> next_deadline() const { return std::nullopt; }
  virtual void clear() {}
};

// This project's layout (docs/can-wire-format.md sections 3 and 6).
class CosmicFrames final : public CanFrameFormat {
 public:
  CosmicFrames(CanBus bus, CanReassemblyBounds bounds);
  const char* name() const noexcept override { return "cosmic"; }
  Result<void> check_payload(std::uint64_t payload) const override;
  bool fragments(std::uint64_t payload) const override { return needs_fragmentation(payload, bus_.capacity); }
  std::size_t frame_count(const CanTxBinding& binding, std::size_t bytes) const override;
  bool numbered(const CanTxBinding& binding) const override { return binding.fragmented; }
  canfd_frame single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const override;
  bool encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t sequence,
              CanFrameBatchSink& sink) const override;
  CanDecoded decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data, bool fd_frame,
                    Nanos now) override;
  void expire(Nanos now, const std::function<void(std::uint32_t)>& dropped) override;
  std::optional<Nanos> next_deadline() const override { return reassembler_.next_deadline(); }
  void clear() override { reassembler_.clear(); }

 private:
  const CanBus bus_;
  Reassembler reassembler_;
};

// FAMOUSO's layout and its AFP fragmentation (section 8); classic CAN only.
class FamousoFrames final : public CanFrameFormat {
 public:
  explicit FamousoFrames(CanReassemblyBounds bounds);
  const char* name() const noexcept override { return "famouso"; }
  Result<void> check_payload(std::uint64_t payload) const override;
  bool fragments(std::uint64_t payload) const override { return payload > famouso::kAfpMtu; }
  std::size_t frame_count(const CanTxBinding& binding, std::size_t bytes) const override;
  bool numbered(const CanTxBinding&) const override { return false; }
  canfd_frame single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const override;
  bool encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t sequence,
              CanFrameBatchSink& sink) const override;
  CanDecoded decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data, bool fd_frame,
                    Nanos now) override;
  void expire(Nanos now, const std::function<void(std::uint32_t)>& dropped) override;
  std::optional<Nanos> next_deadline() const override { return afp_.next_deadline(); }
  void clear() override { afp_.clear(); }

 private:
  famouso::AfpReassembler afp_;
};

// A device's own identifier (section "Native frames"; native_frames.hpp holds the identifier table).
class NativeFrames final : public CanFrameFormat {
 public:
  explicit NativeFrames(CanBus bus) : bus_(bus) {}
  const char* name() const noexcept override { return "native"; }
  Result<void> check_payload(std::uint64_t payload) const override;
  bool fragments(std::uint64_t) const override { return false; }
  std::size_t frame_count(const CanTxBinding&, std::size_t) const override { return 1; }
  bool numbered(const CanTxBinding&) const override { return false; }
  canfd_frame single_frame(const CanTxBinding& binding, std::span<const std::uint8_t> payload) const override;
  bool encode(const CanTxBinding& binding, std::span<const std::uint8_t> payload, std::uint8_t sequence,
              CanFrameBatchSink& sink) const override;
  CanDecoded decode(const CanRxBinding& binding, canid_t can_id, std::span<const std::uint8_t> data, bool fd_frame,
                    Nanos now) override;

 private:
  const CanBus bus_;
};

// The reassembly key of a frame's sender and channel: its TxNode and etag (either layout keeps
// the etag in the low 14 bits).
std::uint32_t frame_source(canid_t can_id);

}  // namespace cosmic::can_detail

// Which representation each hop of a typed channel takes (issue 35; docs/typed-layout.md), and the
// forms that need no wire-format unit of their own:
//   - a hop in the gateway's own format (the envelope on DDS and LCM, the COSMIC identifier layout
//     on CAN) carries the compact layout;
//   - a native CAN hop carries the DBC message's frame when the type comes from a DBC file (or the
//     compact layout with `representation: compact`);
//   - a native LCM hop carries the LCM type's encoding when the type comes from an LCM file, the
//     compact layout, or JSON for tools (`representation: json`), written and read;
//   - a native DDS hop carries CDR of the type as an IDL struct, in the version its `representation`
//     names (xcdr1, xcdr2), and reads either.
// An untyped channel has no representation: its contents cross as the bytes they came in.
//
// Pure: builds objects from the channel's spec, no I/O. Called on the control thread (configuration
// checks, route tables); the representations it returns are then shared read-only by the
// forwarding threads.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/e2e_protection.hpp"
#include "cosmic/json_event_reader.hpp"
#include "cosmic/json_representation.hpp"
#include "cosmic/model.hpp"
#include "cosmic/representation.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

// The compact layout itself: what the gateway's own envelopes and frames carry of a typed event.
// Reading checks the event (check_compact) and copies it.
class CompactRepresentation final : public Representation {
 public:
  explicit CompactRepresentation(ChannelType type);
  std::string describe() const override { return "compact"; }
  std::size_t max_wire_size() const noexcept override { return max_size_; }
  std::size_t max_compact_size() const noexcept override { return max_size_; }
  Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept override;
  Conversion from_compact(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) const noexcept override;

 private:
  ChannelType type_;
  std::size_t max_size_ = 0;
};

// A DBC message's frame (cosmic/dbc_frames.hpp) with the channel's range policy, and its
// end-to-end protection where the type declares one (the codec then packs the other signals).
class DbcFrameRepresentation final : public Representation {
 public:
  DbcFrameRepresentation(DbcFrameCodec codec, std::string name, RangePolicy policy,
                         std::optional<E2eProtection> e2e = std::nullopt);
  std::string describe() const override { return name_; }
  const E2eProtection* e2e() const noexcept override { return e2e_ ? &*e2e_ : nullptr; }
  std::string narrowed() const override;
  std::size_t max_wire_size() const noexcept override { return codec_.frame_length(); }
  std::size_t max_compact_size() const noexcept override { return codec_.compact_size(); }
  Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept override;
  Conversion from_compact(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) const noexcept override;

 private:
  DbcFrameCodec codec_;
  std::string name_;
  RangePolicy policy_;
  std::optional<E2eProtection> e2e_;
};

// JSON text for tools: written as cosmic/json_representation.hpp sets out, read back (a tool
// publishing on the hop) as cosmic/json_event_reader.hpp does. max_wire_size() is what write()
// needs; a text read may be longer (a producer's whitespace), up to the reader's max_text_size().
class JsonHopRepresentation final : public Representation {
 public:
  explicit JsonHopRepresentation(ChannelType type);
  std::string describe() const override { return "JSON"; }
  std::size_t max_wire_size() const noexcept override { return json_.max_size(); }
  std::size_t max_compact_size() const noexcept override { return reader_.max_compact_size(); }
  Conversion to_compact(std::span<const std::uint8_t> wire, std::span<std::uint8_t> compact) const noexcept override;
  Conversion from_compact(std::span<const std::uint8_t> compact, std::span<std::uint8_t> wire) const noexcept override;

 private:
  JsonRepresentation json_;
  JsonEventReader reader_;
};

// The representation of `channel` on `segment` (one of its publishers or subscribers): null for an
// untyped channel; else the hop's form as set out above, or why the hop cannot carry the type (the
// error names the segment).
Result<std::shared_ptr<const Representation>> hop_representation(const ChannelSpec& channel,
                                                                 const SegmentSpec& segment);

// What every hop of a typed channel takes, by segment: its representation's largest message and
// name, or why the hop cannot carry the type, and what it narrows (HopPayload). The configuration
// sets the channel's payload from the hops that fit (ChannelSpec::hop_payloads); admission counts
// each hop at its own size (ChannelSpec::payload_on) and judges the unfit and narrowed ones.
struct TypedHops {
  std::vector<HopPayload> payloads;  // one per hop, in publishers-then-subscribers order
  std::size_t compact_size = 0;      // the most bytes of one event in the compact layout
  // The largest message of the hops that fit, at least compact_size.
  std::uint64_t largest() const;
};
TypedHops typed_hops(const ChannelSpec& channel, const std::vector<SegmentSpec>& segments);

}  // namespace cosmic

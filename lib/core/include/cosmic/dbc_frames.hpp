// A typed channel's hop on a CAN bus in a DBC message's own frame (issue 35, "each hop in its
// network's own form"): the message's signals packed as the DBC says, converted to and from the
// compact layout (cosmic/compact_layout.hpp) of the message's type (cosmic/dbc_type.hpp). A unit
// of its own (its fuzz target: fuzz_dbc_frames).
//
// Built once per binding (at bind, on the control thread), then only read: to_compact() and
// to_frame() run on the forwarding threads, allocate nothing and never throw.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cosmic/channel_type.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/dbc.hpp"
#include "cosmic/result.hpp"

namespace cosmic {

class DbcFrameCodec {
 public:
  // The codec of `message` for `type`, which must be the message's own type (channel_type_from_dbc);
  // else why not.
  static Result<DbcFrameCodec> make(const DbcMessage& message, const ChannelType& type);
  // The signal gateway's codec (issue 35: a typed channel from one DBC message re-packed into another
  // message, AUTOSAR COM's signal gateway): `type` is a record of numbers and nested records of
  // numbers (another message's type, a ROS 2 Twist), each number (named by its path, "linear.x")
  // carried by the signal of `message` of its name, or the one `field_map` names for it (field ->
  // signal), unless `omitted` lists it (not carried: sent as nothing, received as 0). Else why not,
  // naming the field: a field without a signal, a map or omit entry of no field, a field both mapped
  // and omitted, a signal that is not the message's, two fields in one signal, an array, string or
  // sequence, an integer field in a signal whose scaling is
  // not whole, a signal too narrow for an enumeration's values, a multiplexed message. A signal
  // narrower than its field's declared range is no refusal here: narrowed() names it, and the hop
  // decides (cosmic/hop_representation.hpp: refused under on_range: drop, saturated otherwise).
  // The message's other signals are sent as 0.
  static Result<DbcFrameCodec> make_mapped(const DbcMessage& message, const ChannelType& type,
                                           const std::map<std::string, std::string>& field_map,
                                           const std::vector<std::string>& omitted = {});

  // The signal gateway's fields whose declared range their signal holds only in part ("signal
  // Speed holds 0..655.35, narrower than field speed's range 0..1000"); empty for make()'s codecs.
  const std::vector<std::string>& narrowed() const { return narrowed_; }

  std::size_t frame_length() const { return message_.length; }
  std::size_t compact_size() const { return layout_.size(); }

  // A received frame's data (at least frame_length() bytes; CAN FD padding beyond is ignored) as
  // one event in the compact layout (compact_size() bytes): each signal the frame carries at its
  // physical value (an enumeration at its raw value), the others zero. False, writing nothing, when
  // the frame is shorter than the message.
  bool to_compact(std::span<const std::uint8_t> frame, std::span<std::uint8_t> compact) const;

  struct Packed {
    bool sent = false;               // false: a value out of range under RangePolicy::drop
    std::uint32_t out_of_range = 0;  // values the signals could not hold (saturated or the reason to drop)
  };
  // An event in the compact layout (compact_size() bytes) as the frame's data (frame_length()
  // bytes; unused bits 0): the present fields packed into their signals.
  Packed to_frame(std::span<const std::uint8_t> compact, std::span<std::uint8_t> frame, RangePolicy policy) const;

 private:
  struct FieldCodec {
    std::size_t signal = 0;  // index in message_.signals
    std::size_t slot = 0;    // index of the field and of its slot in the compact layout
    bool raw = false;        // an enumeration: the raw value; else the physical one
    bool whole = false;      // an integer field: raw * factor + offset in whole numbers
    std::int64_t factor = 1, offset = 0;
  };

  // The codec of `field` (slot `slot`) in `signal`; when `mapped` (the field is not the signal's
  // own), why not when the field cannot go there.
  static Result<FieldCodec> field_codec(const DbcSignal& signal, std::size_t signal_index, const TypeField& field,
                                        std::size_t slot, bool mapped);

  DbcMessage message_;
  std::optional<std::size_t> switch_;  // index of message_'s multiplexor switch, if any (found once, at make)
  CompactLayout layout_;
  std::vector<FieldCodec> fields_;
  std::vector<std::string> narrowed_;
};

}  // namespace cosmic

#include "cosmic/hop_representation.hpp"

#include <algorithm>
#include <cstring>

#include "cosmic/can_background.hpp"
#include "cosmic/cdr_representation.hpp"
#include "cosmic/compact_layout.hpp"
#include "cosmic/lcm_representation.hpp"

namespace cosmic {

CompactRepresentation::CompactRepresentation(ChannelType type)
    : type_(std::move(type)), max_size_(cosmic::max_compact_size(type_)) {}

Conversion CompactRepresentation::to_compact(std::span<const std::uint8_t> wire,
                                             std::span<std::uint8_t> compact) const noexcept {
  if (compact.size() < wire.size()) return {0, ConversionFault::too_small, 0};
  // A refusal builds its text (check_compact's reason): only an event that is not one of the type
  // pays for it, never the sound ones.
  if (!check_compact(type_, wire)) return {0, ConversionFault::malformed, 0};
  if (!wire.empty()) std::memcpy(compact.data(), wire.data(), wire.size());
  return {wire.size(), ConversionFault::none, 0};
}

Conversion CompactRepresentation::from_compact(std::span<const std::uint8_t> compact,
                                               std::span<std::uint8_t> wire) const noexcept {
  if (wire.size() < compact.size()) return {0, ConversionFault::too_small, 0};
  if (!compact.empty()) std::memcpy(wire.data(), compact.data(), compact.size());
  return {compact.size(), ConversionFault::none, 0};
}

namespace {
std::string semicolon_list(const std::vector<std::string>& parts) {
  std::string text;
  for (const std::string& part : parts) text += (text.empty() ? "" : "; ") + part;
  return text;
}
}  // namespace

DbcFrameRepresentation::DbcFrameRepresentation(DbcFrameCodec codec, std::string name, RangePolicy policy,
                                               std::optional<E2eProtection> e2e)
    : codec_(std::move(codec)), name_(std::move(name)), policy_(policy), e2e_(std::move(e2e)) {}

std::string DbcFrameRepresentation::narrowed() const { return semicolon_list(codec_.narrowed()); }

Conversion DbcFrameRepresentation::to_compact(std::span<const std::uint8_t> wire,
                                              std::span<std::uint8_t> compact) const noexcept {
  if (compact.size() < codec_.compact_size()) return {0, ConversionFault::too_small, 0};
  if (!codec_.to_compact(wire, compact)) return {0, ConversionFault::malformed, 0};
  return {codec_.compact_size(), ConversionFault::none, 0};
}

Conversion DbcFrameRepresentation::from_compact(std::span<const std::uint8_t> compact,
                                                std::span<std::uint8_t> wire) const noexcept {
  if (wire.size() < codec_.frame_length()) return {0, ConversionFault::too_small, 0};
  if (compact.size() != codec_.compact_size()) return {0, ConversionFault::malformed, 0};
  const DbcFrameCodec::Packed packed = codec_.to_frame(compact, wire, policy_);
  if (!packed.sent) return {0, ConversionFault::out_of_range, packed.out_of_range};
  return {codec_.frame_length(), ConversionFault::none, packed.out_of_range};
}

JsonHopRepresentation::JsonHopRepresentation(ChannelType type) : json_(type), reader_(std::move(type)) {}

Conversion JsonHopRepresentation::to_compact(std::span<const std::uint8_t> wire,
                                             std::span<std::uint8_t> compact) const noexcept {
  if (compact.size() < reader_.max_compact_size()) return {0, ConversionFault::too_small, 0};
  // Without the reason: a malformed text is counted (decode_error), and the forwarding path
  // allocates nothing for it.
  const std::string_view text(reinterpret_cast<const char*>(wire.data()), wire.size());
  const std::optional<std::size_t> read = reader_.read_unexplained(text, compact);
  if (!read) return {0, ConversionFault::malformed, 0};
  return {*read, ConversionFault::none, 0};
}

Conversion JsonHopRepresentation::from_compact(std::span<const std::uint8_t> compact,
                                               std::span<std::uint8_t> wire) const noexcept {
  if (wire.size() < json_.max_size()) return {0, ConversionFault::too_small, 0};
  const std::span<char> text(reinterpret_cast<char*>(wire.data()), wire.size());
  const std::optional<std::size_t> written = json_.write(compact, text);
  if (!written) return {0, ConversionFault::malformed, 0};
  return {*written, ConversionFault::none, 0};
}

namespace {

using Made = Result<std::shared_ptr<const Representation>>;

Error hop_error(const std::string& why) { return Error{why, 0, kNoChannel}; }

// The frame's end-to-end protection, if declared; why not.
Result<std::optional<E2eProtection>> protection_of(const DbcMessage& message, const std::optional<E2eSpec>& spec) {
  if (!spec) return std::optional<E2eProtection>();
  Result<E2eProtection> made = E2eProtection::make(message, *spec);
  if (!made) return hop_error("end-to-end protection: " + made.error().text);
  return std::optional<E2eProtection>(std::move(made).value());
}

std::string frame_name(const DbcMessage& message, const std::optional<E2eSpec>& e2e) {
  std::string name = "DBC frame " + can_id_text(message.can_id, message.extended) + " " + message.name;
  if (e2e) name += " with E2E (counter " + e2e->counter + ", CRC " + e2e->crc + ")";
  return name;
}

// The signal gateway: the channel's fields re-packed into another DBC message's signals.
Made mapped_frame_on(const ChannelSpec& channel, const NativeCanFrame& frame) {
  const DbcMessage& message = *frame.dbc_message;
  const DbcMessage payload = frame.e2e ? e2e_payload_message(message, *frame.e2e) : message;
  Result<DbcFrameCodec> codec =
      DbcFrameCodec::make_mapped(payload, *channel.type, frame.field_map, frame.omitted_fields);
  if (!codec) return hop_error(codec.error().text);
  // Events inside the field's range that the signal cannot hold would be lost: refused, unless
  // the channel chose to saturate them (admission then degrades it, naming the fields).
  if (!codec.value().narrowed().empty() && channel.on_range == RangePolicy::drop) {
    return hop_error("message " + message.name + ": " + semicolon_list(codec.value().narrowed()) +
                     "; its events beyond would be dropped (on_range: saturate sends them at the signal's limit)");
  }
  Result<std::optional<E2eProtection>> e2e = protection_of(message, frame.e2e);
  if (!e2e) return e2e.error();
  return std::shared_ptr<const Representation>(std::make_shared<DbcFrameRepresentation>(
      std::move(codec).value(),
      frame_name(message, frame.e2e) + " of " + frame.dbc_file.substr(frame.dbc_file.rfind('/') + 1), channel.on_range,
      std::move(e2e).value()));
}

Made dbc_frame_on(const ChannelSpec& channel, const NativeCanFrame& frame) {
  if (frame.dbc_message) return mapped_frame_on(channel, frame);
  const ChannelType& type = *channel.type;
  if (!type.source || type.source->format != TypeSource::Format::dbc || !type.source->dbc_message) {
    return hop_error(
        "a native CAN frame of a typed channel is its DBC message's frame, and this type does "
        "not come from a DBC file (give the type as {dbc: FILE, message: NAME}, or "
        "representation: compact)");
  }
  const DbcMessage& message = *type.source->dbc_message;
  if (message.can_id != frame.can_id || message.extended != frame.extended) {
    return hop_error("native frame " + can_id_text(frame.can_id, frame.extended) + " is not DBC message " +
                     message.name + "'s identifier " + can_id_text(message.can_id, message.extended));
  }
  const std::optional<E2eSpec>& e2e_spec = type.source->e2e;
  Result<DbcFrameCodec> codec = DbcFrameCodec::make(e2e_spec ? e2e_payload_message(message, *e2e_spec) : message, type);
  if (!codec) return hop_error(codec.error().text);
  Result<std::optional<E2eProtection>> e2e = protection_of(message, e2e_spec);
  if (!e2e) return e2e.error();
  return std::shared_ptr<const Representation>(std::make_shared<DbcFrameRepresentation>(
      std::move(codec).value(), frame_name(message, e2e_spec), channel.on_range, std::move(e2e).value()));
}

Made lcm_encoding_on(const ChannelSpec& channel) {
  const ChannelType& type = *channel.type;
  if (!type.source || type.source->format != TypeSource::Format::lcm || !type.source->lcm_file) {
    return hop_error(
        "a native LCM channel carries the LCM type's encoding, and this type does not come "
        "from an LCM type file (give the type as {lcm: FILE, name: PKG.NAME}, or "
        "representation: compact or json)");
  }
  const LcmTypeFile& file = *type.source->lcm_file;
  const LcmStruct* definition = file.find(type.source->name);
  if (definition == nullptr) return hop_error("no struct " + type.source->name + " in " + type.source->file);
  Result<LcmRepresentation> lcm = LcmRepresentation::make(file, *definition, type);
  if (!lcm) return hop_error(lcm.error().text);
  return std::shared_ptr<const Representation>(std::make_shared<LcmRepresentation>(std::move(lcm).value()));
}

Made cdr_on(const ChannelSpec& channel, const NativeDdsTopic& topic) {
  const bool appendable = channel.type->source && channel.type->source->appendable;
  Result<CdrRepresentation> cdr = CdrRepresentation::make(
      *channel.type, topic.representation, appendable ? CdrExtensibility::appendable : CdrExtensibility::final_type);
  if (!cdr) return hop_error(cdr.error().text);
  return std::shared_ptr<const Representation>(std::make_shared<CdrRepresentation>(std::move(cdr).value()));
}

Made native_form(const ChannelSpec& channel, const NativeBinding& native) {
  const ChannelType& type = *channel.type;
  if (native.dds) return cdr_on(channel, *native.dds);
  switch (native.form) {
    case NativeForm::compact:
      return std::shared_ptr<const Representation>(std::make_shared<CompactRepresentation>(type));
    case NativeForm::json:
      if (!native.lcm_channel) return hop_error("JSON is written on LCM channels only");
      return std::shared_ptr<const Representation>(std::make_shared<JsonHopRepresentation>(type));
    case NativeForm::source:
      break;
  }
  if (native.can) return dbc_frame_on(channel, *native.can);
  return lcm_encoding_on(channel);
}

}  // namespace

Made hop_representation(const ChannelSpec& channel, const SegmentSpec& segment) {
  if (!channel.type) return std::shared_ptr<const Representation>();
  const NativeBinding* native = channel.native_on(segment.name);
  // Without a native identity the hop is the gateway's own format: the compact layout, also for
  // an LCM segment's `encoding: raw` channel (its datagrams are the compact event).
  return native != nullptr
             ? native_form(channel, *native)
             : Made(std::shared_ptr<const Representation>(std::make_shared<CompactRepresentation>(*channel.type)));
}

std::uint64_t TypedHops::largest() const {
  std::uint64_t most = compact_size;
  for (const HopPayload& hop : payloads) most = std::max(most, hop.bytes);
  return most;
}

TypedHops typed_hops(const ChannelSpec& channel, const std::vector<SegmentSpec>& segments) {
  TypedHops hops;
  if (!channel.type) return hops;
  hops.compact_size = max_compact_size(*channel.type);
  auto visit = [&](const std::string& name) {
    const auto segment =
        std::find_if(segments.begin(), segments.end(), [&](const SegmentSpec& s) { return s.name == name; });
    if (segment == segments.end()) return;  // the configuration reports an unknown segment itself
    const auto already = std::find_if(hops.payloads.begin(), hops.payloads.end(),
                                      [&](const HopPayload& h) { return h.segment == name; });
    if (already != hops.payloads.end()) return;
    Made made = hop_representation(channel, *segment);
    HopPayload hop;
    hop.segment = name;
    if (made) {
      const Representation& form = *made.value();
      hop.bytes = form.max_wire_size();
      hop.form = form.describe();
      hop.narrowed = form.narrowed();
    } else {
      hop.unfit = made.error().text;
    }
    hops.payloads.push_back(std::move(hop));
  };
  for (const std::string& name : channel.publishers) visit(name);
  for (const std::string& name : channel.subscribers) visit(name);
  return hops;
}

}  // namespace cosmic

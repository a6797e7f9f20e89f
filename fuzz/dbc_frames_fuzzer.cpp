// A typed channel's DBC frames (cosmic::DbcFrameCodec, cosmic/dbc_frames.hpp): a DBC message made
// from the input (up to 16 signals, Intel and Motorola, signed, IEEE float, scaled, multiplexed, a
// classic or a 64-byte frame) and a received frame of the input's bytes. Every frame becomes an event
// that check_compact() accepts and JSON writes; the event packs into a frame (saturating) that reads
// back to a frame packed the same way: the second trip changes nothing. Dropping refuses exactly
// the events saturating had to clamp. End-to-end protection (cosmic/e2e_protection.hpp) on two of the
// signals, where they can carry it: a protected frame checks intact with its counter, and one flipped
// bit anywhere in the message is caught.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "cosmic/compact_layout.hpp"
#include "cosmic/dbc_codec.hpp"
#include "cosmic/dbc_frames.hpp"
#include "cosmic/dbc_type.hpp"
#include "cosmic/e2e_protection.hpp"
#include "cosmic/json_representation.hpp"
#include "fuzz_input.hpp"

using cosmic::fuzz::FuzzInput;
using cosmic::fuzz::require;

namespace {

constexpr std::array kFactors{1.0, 0.01, 0.1, 0.5, 2.0, 10.0, -1.0, 0.001, 2.5, 1e-6};
constexpr std::array kOffsets{0.0, -40.0, 100.0, 0.5, -1000.0, 3.0};

cosmic::DbcSignal make_signal(FuzzInput& in, std::size_t index, std::uint32_t length) {
  cosmic::DbcSignal s;
  s.name = "S" + std::to_string(index);
  const std::uint8_t shape = in.byte();
  s.order = (shape & 1) != 0 ? cosmic::DbcByteOrder::big_endian : cosmic::DbcByteOrder::little_endian;
  s.is_signed = (shape & 2) != 0;
  s.size = 1 + in.byte() % 64;
  s.start_bit = in.byte() % (length * 8);
  if ((shape & 0x0C) == 0x04 && s.size == 32) s.value_type = cosmic::DbcValueType::float32;
  if ((shape & 0x0C) == 0x08 && s.size == 64) s.value_type = cosmic::DbcValueType::float64;
  s.factor = kFactors[in.byte() % kFactors.size()];
  s.offset = kOffsets[in.byte() % kOffsets.size()];
  // Where a second trip is exact: IEEE signals unscaled (scaled ones are held against canmatrix in
  // tests/integration/dbc), and an integer signal whose field is a float64 (a scaling that is not
  // whole, or physical values beyond 64-bit integers) no wider than a double's mantissa holds with
  // room to spare.
  if (s.value_type != cosmic::DbcValueType::integer) {
    s.factor = 1.0;
    s.offset = 0.0;
  }
  const cosmic::FieldType field = cosmic::dbc_field_type(s);
  const bool float_field = field.kind == cosmic::FieldType::Kind::scalar && !cosmic::is_integer(field.scalar) &&
                           field.scalar != cosmic::ScalarKind::boolean;
  if (float_field && s.value_type == cosmic::DbcValueType::integer && s.size > 48) s.size = 48;
  if ((shape & 0x30) == 0x10 && index > 0) {
    s.multiplex = cosmic::DbcMultiplex::multiplexed;
    s.multiplex_value = in.byte() % 4;
  }
  if ((shape & 0xC0) == 0x40 && s.value_type == cosmic::DbcValueType::integer) {
    for (std::int64_t v = 0; v < 1 + in.byte() % 4; ++v) s.value_names.push_back({v, "V" + std::to_string(v)});
  }
  return s;
}

void check_e2e(FuzzInput& in, const cosmic::DbcMessage& message, std::vector<std::uint8_t> frame) {
  const std::size_t n = message.signals.size();
  if (n < 2) return;
  const auto& counter = message.signals[in.byte() % n].name;
  const auto& crc = message.signals[in.byte() % n].name;
  const auto data_id = static_cast<std::uint16_t>(in.byte() << 8 | in.byte());
  const auto mode = static_cast<cosmic::E2eDataIdMode>(in.byte() % 3);
  const auto e2e = cosmic::E2eProtection::make(message, cosmic::E2eSpec{counter, crc, data_id, mode});
  if (!e2e.ok()) return;
  std::uint64_t sequence = 0;
  for (std::uint8_t b : in.bytes(8)) sequence = sequence << 8 | b;
  e2e.value().protect(frame, sequence);
  const cosmic::E2eReading reading = e2e.value().check(frame);
  require(reading.intact && reading.counter == sequence % e2e.value().counter_modulus());
  // alt: a flipped counter bit also changes which data ID byte the CRC covers, two changes at once.
  if (mode == cosmic::E2eDataIdMode::alt) return;
  const std::size_t bit = static_cast<std::size_t>(in.byte() << 8 | in.byte()) % (message.length * 8);
  frame[bit / 8] = static_cast<std::uint8_t>(frame[bit / 8] ^ (1u << (bit % 8)));
  require(!e2e.value().check(frame).intact);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in(data, size);
  cosmic::DbcMessage message;
  message.name = "M";
  message.length = (in.byte() & 1) != 0 ? 64 : 8;
  const std::size_t count = 1 + in.byte() % 16;
  bool has_switch = false;
  for (std::size_t i = 0; i < count; ++i) {
    cosmic::DbcSignal s = make_signal(in, i, message.length);
    if (!cosmic::dbc_signal_fits(s, message.length)) continue;
    if (i == 0 && s.size <= 8 && !s.is_signed && s.value_type == cosmic::DbcValueType::integer) {
      s.multiplex = cosmic::DbcMultiplex::multiplexor;
      has_switch = true;
    }
    if (s.multiplex == cosmic::DbcMultiplex::multiplexed && !has_switch) s.multiplex = cosmic::DbcMultiplex::none;
    message.signals.push_back(std::move(s));
  }
  const cosmic::DbcChannelType typed = cosmic::channel_type_from_dbc(message);
  if (!typed.ok()) return 0;
  const auto codec = cosmic::DbcFrameCodec::make(message, typed.type);
  require(codec.ok());
  const auto frame = in.bytes(message.length);
  std::vector<std::uint8_t> received(frame.begin(), frame.end());
  received.resize(message.length);
  std::vector<std::uint8_t> event(codec.value().compact_size());
  require(codec.value().to_compact(received, event));
  require(cosmic::check_compact(typed.type, event).ok());
  const cosmic::JsonRepresentation json{cosmic::ChannelType(typed.type)};
  std::string text(json.max_size(), '\0');
  require(json.write(event, std::span<char>(text.data(), text.size())).has_value());

  std::vector<std::uint8_t> once(message.length), twice(message.length), again(event.size());
  const auto packed = codec.value().to_frame(event, once, cosmic::RangePolicy::saturate);
  require(packed.sent);
  require(codec.value().to_compact(once, again));
  require(codec.value().to_frame(again, twice, cosmic::RangePolicy::saturate).sent);
  require(once == twice);
  // Dropping sends nothing exactly when saturating had to clamp.
  std::vector<std::uint8_t> dropped(message.length);
  require(codec.value().to_frame(event, dropped, cosmic::RangePolicy::drop).sent == (packed.out_of_range == 0));
  check_e2e(in, message, once);
  return 0;
}
